"""The coordinated-motion structures: TCrdPrm, TCrdData (vendor header, coordinated motion).

Fixed-width fields like :mod:`gtecat.gt.structs` (``short`` 16, ``long`` 32 bits).
``TCrdPrm`` is the vendor header's layout (reference: gts-header-facts.md).
``TCrdData`` is the look-ahead buffer element GT_InitLookAhead takes: the
controller keeps its own look-ahead state, so it never reads or writes the
buffer; the layout follows the public headers' shape (motion type, plane, 4
positions, radius, direction, centre, speeds) and only its size matters here.
"""

from __future__ import annotations

import ctypes

INTERPOLATION_AXIS_MAX = 4
CRD_FIFO_MAX = 4096
CRD_MAX = 2


class TCrdPrm(ctypes.Structure):
    """Coordinate system parameters: GT_SetCrdPrm / GT_GetCrdPrm.

    dimension 1..4; ``profile[k]`` the coordinate (1 = X .. 4 = A, 0 none) of
    profile ``k+1``; synVelMax pulse/ms, synAccMax pulse/ms²; evenTime ms (the
    shortest constant-speed time of a segment); setOriginFlag 1 = the origin is
    ``originPos`` (per coordinate, X first), 0 = the current planned positions.
    """

    _fields_ = (
        ("dimension", ctypes.c_int16),
        ("profile", ctypes.c_int16 * 8),
        ("synVelMax", ctypes.c_double),
        ("synAccMax", ctypes.c_double),
        ("evenTime", ctypes.c_int16),
        ("setOriginFlag", ctypes.c_int16),
        ("originPos", ctypes.c_int32 * 8),
    )


class TCrdData(ctypes.Structure):
    """One look-ahead buffer element (GT_InitLookAhead ``pLookAheadBuf``); never read."""

    _fields_ = (
        ("motionType", ctypes.c_int16),
        ("circlePlat", ctypes.c_int16),
        ("pos", ctypes.c_int32 * INTERPOLATION_AXIS_MAX),
        ("radius", ctypes.c_double),
        ("circleDir", ctypes.c_int16),
        ("lCenterX", ctypes.c_double),
        ("lCenterY", ctypes.c_double),
        ("vel", ctypes.c_double),
        ("acc", ctypes.c_double),
        ("velEndZero", ctypes.c_int16),
        ("velEnd", ctypes.c_double),
    )


__all__ = ["CRD_FIFO_MAX", "CRD_MAX", "INTERPOLATION_AXIS_MAX", "TCrdData", "TCrdPrm"]
