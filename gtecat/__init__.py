"""gtecat: an EtherCAT master emulator with the Googol GT_* motion API on top."""

__version__ = "0.1.0"

from ._bytecode import install as _install_bytecode_cache
from ._bytecode import install_dataclass_cache as _install_dataclass_cache

_install_bytecode_cache(__version__)
_install_dataclass_cache(__version__)

#: set by a process that runs no program of its own (``gtecat replay``) before it imports
#: ``gtecat.gt``: that module then makes its vendor surface at the first name asked of it
_SURFACE_LATER = False
