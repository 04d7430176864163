"""gtecat: an EtherCAT master emulator with the Googol GT_* motion API on top."""

__version__ = "0.1.0"

import os as _os
import sys as _sys

from ._bytecode import install as _install_bytecode_cache
from ._bytecode import install_dataclass_cache as _install_dataclass_cache


def numpy_with_one_blas_thread() -> None:
    """numpy imported with one OpenBLAS thread, unless numpy is loaded already or the
    process chose a count (``OPENBLAS_NUM_THREADS``, ``GOTO_NUM_THREADS``, ``OMP_NUM_THREADS``).

    OpenBLAS starts a server thread per CPU when numpy is imported, and those threads spin
    before they sleep: ~0.1 s of CPU in every process that imports numpy, on a CPU the
    controller's cycle or another program needs (measured: ``from gtecat import gt`` 313 ->
    229 ms of CPU).  The emulator's arrays (one row per axis) are far below the sizes
    OpenBLAS splits across threads, so the threads never help it.  The count is set for
    numpy's import only (OpenBLAS reads it as it loads) and the environment is left as it
    was, so the processes this one starts, and a count the program sets later for another
    library, are its own.  Called where the emulator is first imported (``gtecat.gt``), not
    by ``import gtecat`` alone (the pytest plugin's import, a command's help).
    """
    if "numpy" in _sys.modules:
        return
    names = ("OPENBLAS_NUM_THREADS", "GOTO_NUM_THREADS", "OMP_NUM_THREADS")
    if any(n in _os.environ for n in names):
        return
    _os.environ["OPENBLAS_NUM_THREADS"] = "1"
    try:
        import numpy  # noqa: F401
    except ImportError:
        pass  # (the import that needs it says so)
    finally:
        _os.environ.pop("OPENBLAS_NUM_THREADS", None)


_install_bytecode_cache(__version__)
_install_dataclass_cache(__version__)

#: set by a process that runs no program of its own (``gtecat replay``) before it imports
#: ``gtecat.gt``: that module then makes its vendor surface at the first name asked of it
_SURFACE_LATER = False
