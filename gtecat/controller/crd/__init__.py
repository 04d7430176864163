"""Coordinated motion (interpolation): coordinate systems, segment geometry, vector speed."""

from .path import Arc, Line, arc_center, make_arc
from .system import CRD_COUNT, FIFO_SIZE, CoordSystem, CrdBank, CrdParams, bank
from .velocity import Trapezoid

__all__ = [
    "CRD_COUNT",
    "FIFO_SIZE",
    "Arc",
    "CoordSystem",
    "CrdBank",
    "CrdParams",
    "Line",
    "Trapezoid",
    "arc_center",
    "bank",
    "make_arc",
]
