"""Compiled logical datagrams (the cyclic fast path) do exactly what the general path does."""

from __future__ import annotations

import struct

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from gtecat.drives.esc import Chain, Command, Datagram, decode_frame, encode_frame
from gtecat.drives.esc import chain as chain_mod
from gtecat.drives.esc.registers import Reg
from gtecat.drives.slave import AlState
from tests.conftest import examples
from tests.drives.esc.mini import MiniMaster, mini_chain

FM = struct.Struct("<IHBBHBBB3x")
SM = struct.Struct("<HHBBBB")


def configured(general_only: bool) -> tuple[Chain, MiniMaster]:
    """Three slaves mapped as SOEM maps them, one bit-packed; SAFEOP."""
    chain = mini_chain(3)
    if general_only:

        def general(cmd: int, laddr: int, dlen: int) -> list:
            hit = [e for ls, le, e in chain._logical_map() if ls < laddr + dlen and laddr < le]
            return list(dict.fromkeys(hit))  # each ESC once, in bus order

        chain._compile = general  # type: ignore[method-assign]
    m = MiniMaster(chain)
    for pos in range(3):
        assert m.apwr(pos, Reg.STATION_ADDRESS, struct.pack("<H", 0x1001 + pos)) == 1
    m.fpwr(
        0x1001, Reg.SM0, SM.pack(0x1000, 128, 0x26, 0, 1, 0) + SM.pack(0x1080, 128, 0x22, 0, 1, 0)
    )
    for pos in range(3):
        assert m.set_state(0x1001 + pos, AlState.PREOP) == (2, 0)
    m.fpwr(0x1001, Reg.SM0 + 16, SM.pack(0x1100, 6, 0x64, 0, 1, 0))
    m.fpwr(0x1001, Reg.SM0 + 24, SM.pack(0x1400, 10, 0x20, 0, 1, 0))
    m.fpwr(
        0x1001,
        Reg.FMMU0,
        FM.pack(0, 6, 0, 7, 0x1100, 0, 2, 1) + FM.pack(9, 10, 0, 7, 0x1400, 0, 1, 1),
    )
    m.fpwr(0x1002, Reg.SM0, SM.pack(0x1000, 2, 0x64, 0, 1, 0))
    m.fpwr(0x1002, Reg.SM0 + 8, SM.pack(0x1400, 2, 0x20, 0, 1, 0))
    m.fpwr(
        0x1002,
        Reg.FMMU0,
        FM.pack(6, 2, 0, 7, 0x1000, 0, 2, 1) + FM.pack(19, 2, 0, 7, 0x1400, 0, 1, 1),
    )
    m.fpwr(0x1003, Reg.SM0, SM.pack(0x1000, 1, 0x64, 0, 1, 0))
    m.fpwr(0x1003, Reg.SM0 + 8, SM.pack(0x1400, 1, 0x20, 0, 1, 0))
    m.fpwr(
        0x1003,
        Reg.FMMU0,
        FM.pack(8, 1, 0, 1, 0x1000, 0, 2, 1) + FM.pack(21, 1, 0, 2, 0x1400, 0, 1, 1),
    )
    for pos in range(3):
        assert m.set_state(0x1001 + pos, AlState.SAFEOP) == (4, 0)
    return chain, m


ops = st.one_of(
    st.tuples(
        st.sampled_from([Command.LRD, Command.LWR, Command.LRW]),
        st.integers(0, 24),
        st.binary(min_size=1, max_size=28),
    ),
    st.tuples(st.just("state"), st.integers(0, 2), st.sampled_from([4, 8])),
    st.tuples(st.just("step"), st.just(0), st.just(b"")),
)


@settings(max_examples=examples(60, 10), deadline=None)
@given(st.lists(ops, min_size=1, max_size=25))
def test_plans_and_the_general_path_agree(sequence: list) -> None:
    fast, mf = configured(False)
    slow, ms = configured(True)
    t = 0
    for op, a, b in sequence:
        if op == "state":
            assert mf.set_state(0x1001 + a, b) == ms.set_state(0x1001 + a, b)
        elif op == "step":
            t += 1_000_000
            fast.step(t, 1_000_000)
            slow.step(t, 1_000_000)
        else:
            frame = encode_frame([Datagram.logical(op, a, b)])
            assert fast.exchange(frame) == slow.exchange(frame)
    for ef, es in zip(fast.escs, slow.escs, strict=True):
        assert ef.mem == es.mem
        assert ef.slave.rx == es.slave.rx and ef.slave.outputs_valid == es.slave.outputs_valid


def test_the_cyclic_frame_is_compiled_once() -> None:
    chain, m = configured(False)
    for pos in range(3):
        assert m.set_state(0x1001 + pos, AlState.OP) == (8, 0)
    for _ in range(5):
        _data, wkc = m.lrw(0, bytes(22))
        assert wkc == 9
    assert len(chain._plans) == 1
    (parts,) = chain._plans.values()
    assert [type(p).__name__ for p in parts] == ["LogicalPlan", "LogicalPlan", "Esc"]  # bits
    assert m.set_state(0x1001, AlState.SAFEOP) == (4, 0)  # a state change: recompiled
    assert not chain._plans
    assert decode_frame(chain.exchange(encode_frame([Datagram.logical(12, 0, bytes(22))])) or b"")


#: a few datagram shapes, as a master's cycle repeats them (the fast path serves repeats)
cyclic = st.tuples(
    st.sampled_from([Command.LRD, Command.LWR, Command.LRW]),
    st.sampled_from([0, 2, 9]),
    st.sampled_from([22, 13, 8, 12]),
    st.integers(0, 255),
    st.sampled_from([0, 0, 7]),  # bytes after the EtherCAT frame (Ethernet padding)
)
_zero = st.just(0)
#: the master's cycle: the same two frames again and again (what the shortcut serves)
#: (byte-aligned slaves only: the bit-mapped third slave keeps a frame off the fast path)
repeated = st.tuples(
    st.sampled_from([Command.LRW, Command.LWR]), _zero, st.just(8), st.integers(0, 255), _zero
) | st.tuples(st.just(Command.LRW), st.just(9), st.just(12), st.integers(0, 255), st.just(7))
cyclic_ops = st.one_of(
    cyclic,
    repeated,
    repeated,
    repeated,
    st.tuples(st.just("state"), st.integers(0, 2), st.sampled_from([2, 4, 8]), _zero, _zero),
    st.tuples(st.just("step"), _zero, _zero, _zero, _zero),
    st.tuples(st.just("fprd"), st.integers(0, 2), st.sampled_from([0x1100, 0x1000]), _zero, _zero),
)


@settings(max_examples=examples(120, 20), deadline=None)
@given(st.lists(cyclic_ops, min_size=1, max_size=40))
@pytest.mark.long
def test_repeated_cyclic_frames_agree_with_the_general_path(sequence: list) -> None:
    """Also covers the one-datagram shortcut (Chain._cyclic: a repeat of the last fast
    frame skips the walk), with and without Ethernet padding after the frame."""
    fast, mf = configured(False)
    slow, ms = configured(True)
    t = 0
    for op, a, b, c, pad in sequence:
        if op == "state":
            assert mf.set_state(0x1001 + a, b) == ms.set_state(0x1001 + a, b)
        elif op == "step":
            t += 1_000_000
            fast.step(t, 1_000_000)
            slow.step(t, 1_000_000)
        elif op == "fprd":
            assert mf.fprd(0x1001 + a, b, 2) == ms.fprd(0x1001 + a, b, 2)
        else:
            frame = bytearray(encode_frame([Datagram.logical(op, a, bytes([c]) * b)]))
            struct.pack_into("<H", frame, 26 + b, c & 3)  # a working counter already counted
            frame += b"\xee" * pad
            buf_f, buf_s = bytearray(frame), bytearray(frame)
            assert fast.process(buf_f) == slow.process(buf_s)  # no flush: as the serve loop
            assert buf_f == buf_s
            fast.service()
            slow.service()
    fast.flush()
    for ef, es in zip(fast.escs, slow.escs, strict=True):
        assert ef.mem == es.mem
        assert ef.slave.rx == es.slave.rx and ef.slave.outputs_valid == es.slave.outputs_valid


def test_byte_aligned_cyclic_frames_are_answered_from_the_snapshot() -> None:
    chain, m = configured(False)
    for pos in range(3):
        assert m.set_state(0x1001 + pos, AlState.OP) == (8, 0)
    outputs = b"\x01\x02\x03\x04\x05\x06\xab\xcd"
    for _ in range(3):
        assert m.lrw(0, outputs)[1] == 4  # two slaves, outputs only: 2 + 2
    assert type(chain._fast[(Command.LRW, 0, 8)]).__name__ == "_Fast"
    chain.step(0, 1_000_000)
    assert bytes(chain.slaves[0].rx) == outputs[:6] and bytes(chain.slaves[1].rx) == outputs[6:]
    data, _wkc = m.lrw(9, bytes(12))
    assert data[:6] == outputs[:6] and data[10:12] == outputs[6:]  # echoed by the step


def test_a_repeated_cyclic_frame_takes_the_shortcut_and_answers_alike() -> None:
    """The shortcut is really taken for the master's repeated frame (not only the walk), gives
    the general path's bytes, and is forgotten when the mapping changes."""
    fast, mf = configured(False)
    slow, ms = configured(True)
    for m in (mf, ms):
        for pos in range(3):
            assert m.set_state(0x1001 + pos, AlState.OP) == (8, 0)
    frame = encode_frame([Datagram.logical(Command.LRW, 0, bytes(8))])
    walks = 0
    real_walk = chain_mod.walk

    def counting_walk(*args):
        nonlocal walks
        walks += 1
        return real_walk(*args)

    chain_mod.walk = counting_walk
    try:
        for i in range(5):
            out = bytearray(frame)
            out[26:34] = bytes([i]) * 8
            ref = bytearray(out)
            assert fast.process(out) and slow.process(ref)
            assert out == ref
            fast.service()
            slow.service()
            fast.step(i, 1_000_000)
            slow.step(i, 1_000_000)
    finally:
        chain_mod.walk = real_walk
    assert walks == 2 + 5  # fast: the first (compiles) and second (fast path) only; slow: all
    assert fast._cyclic is not None
    assert mf.set_state(0x1001, AlState.SAFEOP) == (4, 0)
    assert fast._cyclic is None  # a state change forgets the plans and the shortcut


def test_a_dc_datagram_beside_the_cyclic_one_answers_as_if_it_came_alone() -> None:
    """The DC frame (LRW + FRMW of the system time 0910h): the FRMW does not wait for the
    LRW's outputs to be applied (DC registers cannot see them), and every byte and WKC of
    the answer is what the two datagrams give in separate frames."""
    together, mt = configured(False)
    apart, ma = configured(False)
    for m in (mt, ma):
        for pos in range(3):
            assert m.set_state(0x1001 + pos, AlState.OP) == (8, 0)
    flushes = 0
    real_flush = together.flush

    def counting_flush() -> None:
        nonlocal flushes
        flushes += 1
        real_flush()

    together.flush = counting_flush  # type: ignore[method-assign]
    for i in range(4):
        lrw = Datagram.logical(Command.LRW, 0, bytes([i]) * 8)
        frmw = Datagram(Command.FRMW, 0x1001, Reg.DC_SYSTEM_TIME, bytes(8))
        both = bytearray(encode_frame([lrw, frmw]))
        before = flushes
        t = i * 1_000_000 + 500  # both chains see the frames at the same time
        assert together.process(both, t_ns=t)
        assert flushes == before  # the FRMW did not force the outputs in
        one = bytearray(encode_frame([lrw]))
        two = bytearray(encode_frame([frmw]))
        assert apart.process(one, t_ns=t)
        apart.flush()
        assert apart.process(two, t_ns=t)
        got = decode_frame(bytes(both)).datagrams
        alone = decode_frame(bytes(one)).datagrams + decode_frame(bytes(two)).datagrams
        assert [(d.data, d.wkc) for d in got] == [(d.data, d.wkc) for d in alone]
        for chain in (together, apart):
            chain.flush()
            chain.service()
            chain.step(i * 1_000_000, 1_000_000)
