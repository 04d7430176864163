"""The manual's structures as ctypes Structures and its constants (chapter 13, DESIGN.md)."""

from __future__ import annotations

import ctypes

import pytest

from gtecat.gt import constants, structs


@pytest.mark.parametrize(
    "cls,fields",
    [
        (
            structs.TTrapPrm,
            [
                ("acc", ctypes.c_double),
                ("dec", ctypes.c_double),
                ("velStart", ctypes.c_double),
                ("smoothTime", ctypes.c_int16),
            ],
        ),
        (
            structs.TJogPrm,
            [("acc", ctypes.c_double), ("dec", ctypes.c_double), ("smooth", ctypes.c_double)],
        ),
        (
            structs.TThreadSts,
            [
                ("run", ctypes.c_int16),
                ("error", ctypes.c_int16),
                ("result", ctypes.c_double),
                ("line", ctypes.c_int16),
            ],
        ),
        (
            structs.TVarInfo,
            [("id", ctypes.c_int16), ("dataType", ctypes.c_int16), ("name", ctypes.c_char * 32)],
        ),
    ],
)
def test_fields_in_manual_order_and_types(cls, fields):
    assert [(n, t) for n, t in cls._fields_] == fields


def test_layout_is_the_windows_dll_one():
    """MSVC layout: doubles on 8 bytes, short 2 bytes (sizes the vendor DLL expects)."""
    assert ctypes.sizeof(structs.TTrapPrm) == 32 and structs.TTrapPrm.smoothTime.offset == 24
    assert ctypes.sizeof(structs.TJogPrm) == 24
    assert ctypes.sizeof(structs.TThreadSts) == 24 and structs.TThreadSts.result.offset == 8
    assert ctypes.sizeof(structs.TVarInfo) == 36


def test_pointer_round_trip_like_vendor_code():
    """Example 7-1 style: GT_GetTrapPrm(ADR(trap)) then set fields; byref works."""
    prm = structs.TTrapPrm()
    p = ctypes.cast(ctypes.byref(prm), ctypes.POINTER(structs.TTrapPrm))
    p.contents.acc, p.contents.smoothTime = 0.25, 25
    assert (prm.acc, prm.smoothTime) == (0.25, 25)
    prm.smoothTime = 70000  # a C short wraps, as in C
    assert prm.smoothTime == 70000 - 65536


def test_constants_from_the_manual():
    """GT_LmtsOn/Off: MC_LIMIT_POSITIVE 0 / NEGATIVE 1; 10.4.3: MC_GPO 12; 7.4-7.6 macros."""
    c = constants
    assert (c.MC_LIMIT_POSITIVE, c.MC_LIMIT_NEGATIVE, c.MC_GPO) == (0, 1, 12)
    assert (c.PT_SEGMENT_NORMAL, c.PT_SEGMENT_EVEN, c.PT_SEGMENT_STOP) == (0, 1, 2)
    assert (c.FOLLOW_MASTER_ENCODER, c.FOLLOW_MASTER_PROFILE, c.FOLLOW_MASTER_AXIS) == (1, 2, 3)
    assert (c.GEAR_MASTER_ENCODER, c.GEAR_MASTER_PROFILE, c.GEAR_MASTER_AXIS) == (1, 2, 3)
    assert (c.FOLLOW_EVENT_START, c.FOLLOW_EVENT_PASS) == (1, 2)
    assert c.FOLLOW_SEGMENT_CONTINUE == 3


def test_exported_through_gt():
    from gtecat import gt

    assert gt.TTrapPrm is structs.TTrapPrm and gt.TJogPrm is structs.TJogPrm
    assert gt.MC_LIMIT_NEGATIVE == 1
