"""The controller's fast answer (gtecat.gt.fast.wire_reader) is the table path's answer, byte
for byte, over generated request shapes: long of 4 and 8 bytes, pointer sizes, counts, pClock,
axes that do not exist."""

from __future__ import annotations

import ctypes
import itertools
import struct

import pytest

from gtecat import gt
from gtecat.gt.fast import READERS
from gtecat.native import server as srv_mod
from gtecat.native.protocol import CALL, I64, MSG_CALL, PTR, PTR_NULL, plans_by_name

from .conftest import FIG5_2


@pytest.fixture(scope="module")
def moving():
    """A bus with axis 1 moving in Trap (nonzero positions, velocities, status bits)."""
    gt.GT_Close()
    assert gt.GT_Open(eni=str(FIG5_2), clock="lockstep", log="") == 0
    assert gt.GT_InitEcatComm() == 0
    gt.GTE_Wait(50)
    assert gt.GT_StartEcatComm() == 0
    assert gt.GT_AxisOn(1) == 0
    gt.GTE_Wait(10)
    assert gt.GT_PrfTrap(1) == 0
    prm = gt.TTrapPrm(acc=0.5, dec=0.5, velStart=0, smoothTime=0)
    assert gt.GT_SetTrapPrm(1, prm) == 0
    assert gt.GT_SetVel(1, 20.0) == 0
    assert gt.GT_SetPos(1, 100000) == 0
    assert gt.GT_Update(1) == 0
    gt.GTE_Wait(30)
    server = srv_mod.Server("unix:@gtecat-test-fast", wall_floor=False)
    yield server
    server._cleanup()
    gt.GT_Close()


def _clients(long_size: int) -> tuple[srv_mod._Client, srv_mod._Client]:
    fast = srv_mod._Client(sock=None, peer="fast", long_size=long_size, cards={0})  # type: ignore[arg-type]
    slow = srv_mod._Client(sock=None, peer="slow", long_size=long_size, cards={0})  # type: ignore[arg-type]
    return fast, slow


def _pointer(size: int | None) -> bytes:
    return PTR.pack(PTR_NULL) if size is None else PTR.pack(size) + b"\xa5" * size


@pytest.mark.long
def test_fast_and_table_answer_alike(moving):
    """Every combination (11 readers x 2 long sizes x axes x pointer sizes x counts x pClock x
    a trailing byte): about 19,000 requests, each answered twice."""
    shapes = itertools.product(
        [4, 8],
        [1, 2, 0, -1, 9, 32767],
        [None, 0, 4, 8, 16, 3],
        [1, 0, 2, -1],
        [None, 4, 8],
        [b"", b"\x00"],
    )
    shapes = list(shapes)
    fast_taken = 0
    for name in sorted(READERS):
        plan = plans_by_name()[name]
        for long_size, axis, psize, count, clock, extra in shapes:
            body = (
                CALL.pack(MSG_CALL, 0, plan.fid, 1)
                + I64.pack(axis)
                + _pointer(psize)
                + I64.pack(count)
                + _pointer(clock)
                + extra
            )
            fast, slow = _clients(long_size)
            dec = moving._decoder(long_size, plan.fid)
            assert dec.fast is not None
            slow.decoders[plan.fid] = table_only = srv_mod._Decoder(dec.plan, long_size)
            table_only.fast = None
            fast_taken += dec.fast(memoryview(body)) is not None
            want, got = _answer(moving, slow, body), _answer(moving, fast, body)
            assert got == want, (name, long_size, axis, psize, count, clock, extra)
    assert fast_taken >= len(READERS) * 2  # the fast handler really answered some


def _answer(server, c, body):
    try:
        return server._message(c, memoryview(body))
    except srv_mod.ProtocolError as e:
        return f"protocol error: {e}"


def test_the_fast_answer_is_taken_and_carries_the_value(moving):
    """GT_GetSts of a moving axis: the fast handler answers (not None), the block holds the
    status word the Python API reads."""
    plan = plans_by_name()["GT_GetSts"]
    dec = moving._decoder(8, plan.fid)
    body = CALL.pack(MSG_CALL, 0, plan.fid, 1) + I64.pack(1) + _pointer(8) + I64.pack(1)
    body += _pointer(None)
    out = dec.fast(memoryview(body))
    assert out is not None
    total, rc, blocks, text, size, value = struct.unpack("<IhHHIq", out)
    sts = ctypes.c_long()
    assert gt.GT_GetSts(1, ctypes.byref(sts)) == 0
    assert (total, rc, blocks, text, size) == (len(out) - 4, 0, 1, 0, 8)
    assert value == sts.value and value & 0x400  # bit 10: the profile is moving
