"""gtecat: an EtherCAT master emulator with the Googol GT_* motion API on top."""

__version__ = "0.1.0"

from ._bytecode import install as _install_bytecode_cache
from ._bytecode import install_dataclass_cache as _install_dataclass_cache

_install_bytecode_cache(__version__)
_install_dataclass_cache(__version__)
