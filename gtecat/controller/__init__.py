"""The controller core: axis resources, motion modes, configuration file, recorder.

Depends on :mod:`gtecat.master` (bus, clock, process image); the master knows nothing of it.
"""

from .core import Controller, Options

__all__ = ["Controller", "Options"]
