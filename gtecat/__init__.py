"""gtecat: an EtherCAT master emulator with the Googol GT_* motion API on top."""

__version__ = "0.1.0"

from ._bytecode import install as _install_bytecode_cache

_install_bytecode_cache(__version__)
