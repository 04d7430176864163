"""The smart-home structures of the GTS vendor header, as ctypes Structures.

Same conventions as :mod:`gtecat.gt.structs`: the vendor's field names, order and C types,
``short`` = ``c_int16``, ``long`` = ``c_int32`` (a Windows ``long``); the ``pad`` fields are
the header's reserved ones (the controller writes them 0).
"""

from __future__ import annotations

import ctypes


class THomePrm(ctypes.Structure):
    """Smart-home parameters: GT_GoHome / GT_GetHomePrm (GTS vendor header, "Smart Home").

    mode: HOME_MODE_*; moveDir, indexDir: -1 / 1; edge: 0 falling (the switch is
    reached), 1 rising (left); triggerIndex: -1 = this axis; velHigh (search) and velLow
    (final approach) pulse/ms; acc, dec pulse/ms²; smoothTime 0..50 ms; homeOffset,
    searchHomeDistance, searchIndexDistance (0 = unlimited), escapeStep: pulse.
    """

    _fields_ = (
        ("mode", ctypes.c_int16),
        ("moveDir", ctypes.c_int16),
        ("indexDir", ctypes.c_int16),
        ("edge", ctypes.c_int16),
        ("triggerIndex", ctypes.c_int16),
        ("pad1", ctypes.c_int16 * 3),
        ("velHigh", ctypes.c_double),
        ("velLow", ctypes.c_double),
        ("acc", ctypes.c_double),
        ("dec", ctypes.c_double),
        ("smoothTime", ctypes.c_int16),
        ("pad2", ctypes.c_int16 * 3),
        ("homeOffset", ctypes.c_int32),
        ("searchHomeDistance", ctypes.c_int32),
        ("searchIndexDistance", ctypes.c_int32),
        ("escapeStep", ctypes.c_int32),
        ("pad3", ctypes.c_int32 * 2),
    )


class THomeStatus(ctypes.Structure):
    """Smart-home status: GT_GetHomeStatus (GTS vendor header, "Smart Home").

    run: 1 while homing; stage: HOME_STAGE_*; error: HOME_ERROR_*; capturePos: the
    captured home (or index) encoder position; targetPos = capturePos + homeOffset.
    """

    _fields_ = (
        ("run", ctypes.c_int16),
        ("stage", ctypes.c_int16),
        ("error", ctypes.c_int16),
        ("pad1", ctypes.c_int16),
        ("capturePos", ctypes.c_int32),
        ("targetPos", ctypes.c_int32),
    )


__all__ = ["THomePrm", "THomeStatus"]
