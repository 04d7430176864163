"""Other pulse cards' C APIs on the emulated axes: ADT850, an MCX314 library, the GT-400.

``from gtecat.compat import adt850`` / ``mcx314`` / ``gt400``: module-level functions with the
vendors' names, argument order, units and return codes, over the controller core (the ``gts:4``
pulse-card personality, the T/S-curve drive planner, the coordinate systems).  The shared
decisions are in :mod:`gtecat.compat._card`; docs/compat.md has an overview.
"""

from ._card import CompatError, last_error

__all__ = ["CompatError", "last_error"]
