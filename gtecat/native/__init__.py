"""The native face of gtecat: ``gts.h``, ``libgts.so`` and the controller protocol.

See ``docs/native.md``.
"""
