"""The axis bank's coordinate systems compiled: the cycles inside a motion segment in one C call.

:meth:`CoordSystem.run <gtecat.controller.crd.system.CoordSystem.run>` fills a system's
tables a window of cycles at a time; most of those cycles lie inside a line or an arc, where a
cycle is the path time plus one cycle, the trapezoid's distance and speed at it, the point
of the geometry there and each axis's position, speed and acceleration.  ``csrc/bank_crd.c``
transcribes those with the same IEEE operations in the same order, built like the bank's
kernel (``-ffp-contract=off``, no fast-math; the cosines and sines of an arc are the C
library's, which Python's ``math`` calls too), so its samples are the scalar cycle's, bit for
bit.  Without a C compiler (or with ``GTECAT_BANK_KERNEL=numpy``) the system's own numpy
version fills them (``CoordSystem._run_segment``), the same bits again.
"""

from __future__ import annotations

import ctypes
import logging
from typing import Any

import numpy as np

from ..cbuild import Background
from .bank_kernel import CFLAGS, PLAIN_CFLAGS, _source, build
from .crd.path import Arc, Line
from .crd.velocity import Trapezoid

log = logging.getLogger(__name__)

#: a segment's fields, in the C side's CR_* order (start, delta, end and origin: 4 each)
FIELDS = (
    "kind dims acc v0 vp t1 tc d1 dc v_end plen duration "
    "len i j axis3 r0 r1 theta0 sweep cx cy rise"
).split()
_START = len(FIELDS)
_DELTA, _END, _ORIGIN = _START + 4, _START + 8, _START + 12
N_FIELDS = _START + 16
#: a call's state, in the C side's IO_* order
IO_T, IO_DT, IO_CYC, IO_S, IO_SPEED, IO_POS = range(6)
IO_VEL, IO_ACC = IO_POS + 4, IO_POS + 8
N_IO = IO_POS + 12
KIND_LINE, KIND_ARC = 1.0, 2.0
#: the unused positions of a system of d coordinates
_PAD = [[0.0] * (4 - d) for d in range(5)]

_LIB: Any = None
_LIB_REASON = ""


#: the build started in a process of its own (:func:`library` with ``wait`` False)
_AHEAD: list[Background] = []


def library(wait: bool = True) -> tuple[Any, str]:
    """(the loaded library or None, why not); built and loaded once per process.  ``wait``
    False: (None, "") while its build, started in a process of its own the first time (a
    compiler's second on a machine's first run), goes on; the cycles meanwhile fill the tables
    with numpy (the same samples)."""
    global _LIB, _LIB_REASON
    if _LIB is not None or _LIB_REASON:
        return _LIB, _LIB_REASON
    if not wait:
        if not _AHEAD:
            try:
                src = _source("bank_crd")
                builds = [("bank_crd", src, f, ("-lm",)) for f in (CFLAGS, PLAIN_CFLAGS)]
                _AHEAD.append(Background(builds))
            except Exception as e:  # no compiler, no cache folder, no builder process
                _LIB_REASON = f"{type(e).__name__}: {e}"
                return None, _LIB_REASON
        if not _AHEAD[0].done():
            return None, ""
    try:
        path = _AHEAD[0].wait() if _AHEAD else build(CFLAGS, "bank_crd")
        lib = ctypes.CDLL(str(path))
        lib.bank_crd_sizes.restype = ctypes.c_int
        fn = lib.bank_crd_segment
        fn.restype = ctypes.c_int64
        fn.argtypes = (ctypes.c_void_p, ctypes.c_void_p, ctypes.c_void_p) + (ctypes.c_int64,) * 3
        fn.argtypes += (ctypes.c_void_p,)
        if lib.bank_crd_sizes() != N_FIELDS * 100 + N_IO:
            raise RuntimeError("the compiled segment's fields are not the ones this module packs")
        _LIB = lib
    except Exception as e:  # no compiler, a failed build: numpy
        _LIB_REASON = f"{type(e).__name__}: {e}"
    return _LIB, _LIB_REASON


def pack(e: Any, plan: Trapezoid, origin: list[float]) -> np.ndarray:
    """Motion segment ``e`` run by ``plan`` from ``origin``, as the C side reads it."""
    g = np.zeros(N_FIELDS)
    geom = e.geom
    dims = len(geom.start)
    f = dict(
        dims=dims,
        acc=plan.acc,
        v0=plan.v0,
        vp=plan.vp,
        t1=plan.t1,
        tc=plan.tc,
        d1=plan.d1,
        dc=plan.dc,
        v_end=plan.v_end,
        plen=plan.length,
        duration=plan.duration,
        len=geom.length,
        axis3=-1,
    )
    if type(geom) is Line:
        f["kind"] = KIND_LINE
        g[_DELTA : _DELTA + dims] = geom._delta
    else:
        assert type(geom) is Arc
        f.update(kind=KIND_ARC, r0=geom.r0, r1=geom.r1, theta0=geom.theta0, sweep=geom.sweep)
        f.update(i=geom.plane[0], j=geom.plane[1], cx=geom.center[0], cy=geom.center[1])
        f.update(rise=geom.rise, axis3=-1 if geom.axis3 is None else geom.axis3)
    for k, name in enumerate(FIELDS):
        if name in f:
            g[k] = f[name]
    g[_START : _START + dims] = geom.start
    g[_END : _END + dims] = geom.end
    g[_ORIGIN : _ORIGIN + dims] = origin
    return g


class CrdFill:
    """The compiled segment of a bank's coordinate systems (they run one after the other)."""

    def __init__(self, lib: Any) -> None:
        self.fn = lib.bank_crd_segment
        self.io = np.zeros(N_IO)
        self.io_ptr = self.io.ctypes.data
        self.speeds = np.zeros(64)
        self.speeds_ptr = self.speeds.ctypes.data
        #: id(system) -> (its plan, its entry, the packed segment, its address)
        self.packed: dict[int, tuple[Any, Any, np.ndarray, int]] = {}
        #: id(an output array) -> (the array, its address): a system's run reuses its array
        self.addr: dict[int, tuple[np.ndarray, int]] = {}
        #: samples written (statistics: the tests check the compiled fill ran)
        self.samples = 0

    def segment(self, c: Any, e: Any, plan: Trapezoid, out: np.ndarray, j: int, speeds: Any) -> int:
        """``CoordSystem._run_segment``, compiled: the same samples into ``out``, the same
        state after them; the cycles taken."""
        got = self.packed.get(id(c))
        if got is None or got[0] is not plan or got[1] is not e:
            g = pack(e, plan, c.origin)
            got = self.packed[id(c)] = (plan, e, g, g.ctypes.data)
        _, d, n = out.shape
        m = n - j
        if len(self.speeds) < m:
            self.speeds = np.zeros(m)
            self.speeds_ptr = self.speeds.ctypes.data
        at = self.addr.get(id(out))
        if at is None or at[0] is not out:
            if len(self.addr) > 64:
                self.addr.clear()
            at = self.addr[id(out)] = (out, out.ctypes.data)
        io = self.io
        slots = c.slots
        cyc = c._cycle_ms()
        # IO_T, IO_DT, IO_CYC, IO_S, IO_SPEED, IO_POS..., IO_VEL...
        state = [c.t, cyc * c.override, cyc, c.s, c.speed]
        state += [s._pos for s in slots]
        state += _PAD[d]
        state += [s._vel for s in slots]
        io[: IO_VEL + d] = state
        k = self.fn(got[3], self.io_ptr, at[1] + 8 * j, d * n, n, m, self.speeds_ptr)
        if k == 0:
            return 0
        st = io.tolist()
        for i, slot in enumerate(slots):
            slot._pos, slot._vel, slot._acc = st[IO_POS + i], st[IO_VEL + i], st[IO_ACC + i]
            slot._fresh = False  # the axis took it
        c.t, c.s, c.speed = st[IO_T], st[IO_S], st[IO_SPEED]
        if speeds is not None:
            speeds.extend(self.speeds[:k].tolist())
        self.samples += k
        return k


def crd_fill(bank: Any) -> CrdFill | None:
    """The bank's :class:`CrdFill` (made on first use), or None where the bank's cycle is not
    compiled, this library does not build, or its build has not ended yet."""
    if bank._kernel_lib is None:
        return None
    cf = bank.__dict__.get("_crd_fill")
    if cf is None:
        lib, reason = library(wait=False)
        if lib is None:
            if reason:  # (else: the build goes on; numpy until it is there)
                log.info("bank crd: numpy fills the coordinate systems' tables (%s)", reason)
                bank._crd_fill = False
            return None
        cf = bank._crd_fill = CrdFill(lib)
    return cf or None
