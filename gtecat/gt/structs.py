"""The vendor structures as ctypes Structures, fields in the manual's order and C types.

Code written for the vendor DLL through ctypes passes these by pointer
(``byref(prm)``) and reads the fields back, so the names, order and types are
the manual's (chapter 13).  The vendor DLL is a Windows library: ``short`` is
16 bits and ``long`` 32 bits, so fields are declared with fixed-width types
(``c_int16``/``c_int32``), never ``c_long`` (64 bits on Linux); ctypes' native
alignment is the MSVC default one (doubles on 8 bytes).
"""

from __future__ import annotations

import ctypes


class TTrapPrm(ctypes.Structure):
    """Trap (point-to-point) parameters: GT_SetTrapPrm / GT_GetTrapPrm (7.2, chapter 13).

    acc, dec: pulse/ms² (> 0; dec not set = acc); velStart: pulse/ms (>= 0,
    default 0); smoothTime: ms, integer in [0, 50].
    """

    _fields_ = (
        ("acc", ctypes.c_double),
        ("dec", ctypes.c_double),
        ("velStart", ctypes.c_double),
        ("smoothTime", ctypes.c_int16),
    )


class TJogPrm(ctypes.Structure):
    """Jog parameters: GT_SetJogPrm / GT_GetJogPrm (7.3, chapter 13).

    acc, dec: pulse/ms² (> 0; dec not set = acc); smooth: in [0, 1).
    """

    _fields_ = (
        ("acc", ctypes.c_double),
        ("dec", ctypes.c_double),
        ("smooth", ctypes.c_double),
    )


class TThreadSts(ctypes.Structure):
    """Motion-program thread status: GT_GetThreadSts (10.3.7, chapter 13)."""

    _fields_ = (
        ("run", ctypes.c_int16),  # running state
        ("error", ctypes.c_int16),  # return value of the instruction being executed
        ("result", ctypes.c_double),  # function return value
        ("line", ctypes.c_int16),  # line being executed
    )


class TVarInfo(ctypes.Structure):
    """Motion-program variable handle: GT_GetVarId / GT_GetVarValue / GT_SetVarValue (10.3).

    The manual uses it without spelling it out; the layout is the vendor
    header's: ``short id; short dataType; char name[32];``.
    """

    _fields_ = (
        ("id", ctypes.c_int16),
        ("dataType", ctypes.c_int16),
        ("name", ctypes.c_char * 32),
    )


class TCompileInfo(ctypes.Structure):
    """Compile error report of GT_Compile (10.3.2, chapter 13)."""

    _fields_ = (
        ("pFileName", ctypes.c_char_p),  # file compiled
        ("pLineNo", ctypes.POINTER(ctypes.c_int16)),  # line of the error
        ("pMessage", ctypes.c_char_p),  # error message
    )


from .crd_structs import TCrdData, TCrdPrm  # noqa: E402 - coordinated motion

__all__ = ["TCompileInfo", "TCrdData", "TCrdPrm", "TJogPrm", "TThreadSts", "TTrapPrm", "TVarInfo"]

from .home_structs import THomePrm, THomeStatus  # noqa: E402 - smart home

__all__ += ["THomePrm", "THomeStatus"]
