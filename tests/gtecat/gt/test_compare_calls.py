"""Position compare and triggers as a laser or camera station uses them: the GTS 2D compare
fires along a diagonal path, the GTN position compare in FIFO and linear modes, and
triggers latching the encoder at the home switch and at a general input."""

from __future__ import annotations

from ctypes import byref, c_double, c_long, c_short, c_ushort

from gtecat import gt
from gtecat.drives.machine import AxisMachine, MachineDescription

HOME_LO, HOME_HI = 5000, 6000


def _open() -> None:
    m = MachineDescription({1: AxisMachine(home_switch=((HOME_LO, HOME_HI),))})
    assert gt.GT_Open(card="gts:4", machine=m, clock="lockstep", log="") == 0
    for a in (1, 2, 3):
        assert gt.GT_AxisOn(a) == 0, gt.GTE_GetLastError()


def trap(axis: int, target: int, vel: float = 20.0) -> None:
    assert gt.GT_PrfTrap(axis) == 0
    assert gt.GT_SetTrapPrm(axis, byref(gt.TTrapPrm(acc=1, dec=1))) == 0
    assert gt.GT_SetPos(axis, target) == 0 and gt.GT_SetVel(axis, vel) == 0


def run(mask: int) -> None:
    assert gt.GT_Update(mask) == 0, gt.GTE_GetLastError()
    s = c_long()
    for _ in range(5000):
        gt.GTE_Wait(1)
        busy = 0
        for a in range(1, 4):
            gt.GT_GetSts(a, byref(s))
            busy |= s.value & 1 << 10
        if not busy:
            return
    raise AssertionError("the axes never stopped")


def gpo() -> int:
    v = c_long()
    assert gt.GT_GetDo(gt.MC_GPO, byref(v)) == 0
    return v.value


def status2d(chn: int) -> tuple[int, int, int, int, int]:
    st, cnt, fifo, room, buf = c_short(), c_long(), c_short(), c_short(), c_short()
    assert (
        gt.GT_2DCompareStatus(chn, byref(st), byref(cnt), byref(fifo), byref(room), byref(buf)) == 0
    )
    return st.value, cnt.value, fifo.value, room.value, buf.value


def test_2d_compare_fires_along_the_diagonal_and_waits_for_a_point_off_the_path():
    _open()
    prm = gt.T2DComparePrm(encx=1, ency=2, source=0, outputType=0, startLevel=0, time=100, maxerr=5)
    assert gt.GT_2DCompareClear(0) == 0
    assert gt.GT_2DCompareMode(0, 1) == 0
    assert gt.GT_2DCompareSetPrm(0, byref(prm)) == 0
    pts = (gt.T2DCompareData * 4)(*[gt.T2DCompareData(k * 1000, k * 1000) for k in (1, 2, 3, 4)])
    assert gt.GT_2DCompareData(0, 4, pts, 0) == 0
    late = (gt.T2DCompareData * 2)(gt.T2DCompareData(6000, 6003), gt.T2DCompareData(7000, 9000))
    assert gt.GT_2DCompareData(0, 2, late, 1) == 0  # the second FIFO takes over
    assert status2d(0)[0] == 1  # not started: finished
    assert gt.GT_2DCompareStart(0) == 0
    st, cnt, fifo, room, buf = status2d(0)
    assert (st, cnt, fifo) == (0, 0, 1) and room == gt.COMPARE_DATA_MAX - 2 and buf == 512 - 4
    trap(1, 8000, 37.0)  # fast: several points may lie in one cycle's path
    trap(2, 8000, 37.0)
    run(0b11)
    st, cnt, *_ = status2d(0)
    assert (st, cnt) == (0, 5)  # (7000, 9000) is off the path: the channel waits for it
    assert gt.GT_2DComparePulse(0, 1, 0, 50) == 0 and status2d(0)[1] == 6
    assert gt.GT_2DCompareStop(0) == 0 and status2d(0)[0] == 1
    assert gt.GT_2DCompareClearData(0) == 0 and status2d(0)[1] == 6  # the count stays
    assert gt.GT_2DCompareClear(0) == 0 and status2d(0)[1] == 0
    assert gt.GT_2DCompareStart(0) == 1  # no points
    assert gt.GT_2DCompareData(0, 0, pts, 0) == 7
    # one dimension: X alone, whatever Y does
    assert gt.GT_2DCompareMode(1, 0) == 0
    assert gt.GT_2DCompareSetPrm(1, byref(prm)) == 0
    xs = (gt.T2DCompareData * 3)(*[gt.T2DCompareData(x, -99999) for x in (7000, 5000, 3000)])
    assert gt.GT_2DCompareData(1, 3, xs, 0) == 0 and gt.GT_2DCompareStart(1) == 0
    trap(1, 2000)
    run(0b1)
    assert status2d(1)[:2] == (1, 3)
    assert gt.GT_2DCompareStart(3) == 7
    # a level output on general output 3 (COMPARE_PORT_GPO, hsio 2): it toggles at each point
    assert gt.GT_SetComparePort(gt.COMPARE_PORT_GPO, 2, 5) == 0
    assert gt.GT_SetDoBit(gt.MC_GPO, 3, 1) == 0  # high first, as the vendor says
    prm.outputType = 1
    assert gt.GT_2DCompareMode(0, 0) == 0 and gt.GT_2DCompareSetPrm(0, byref(prm)) == 0
    xs = (gt.T2DCompareData * 2)(gt.T2DCompareData(3000, 0), gt.T2DCompareData(5000, 0))
    assert gt.GT_2DCompareData(0, 2, xs, 0) == 0 and gt.GT_2DCompareStart(0) == 0
    trap(1, 4000)
    run(0b1)
    assert gpo() & 0b100 == 0  # toggled once
    trap(1, 6000)
    run(0b1)
    assert gpo() & 0b100 and status2d(0)[:2] == (1, 2)
    assert gt.GT_2DComparePulse(0, 1, 1, 0) == 0 and not gpo() & 0b100
    assert gt.GT_SetComparePort(gt.COMPARE_PORT_HSIO, 0, 1) == 0


def test_gtn_position_compare_fifo_and_linear():
    _open()
    mode = gt.TPosCompareMode(
        mode=gt.POS_COMPARE_MODE_FIFO, dimension=1, sourceMode=1, sourceX=3,
        outputMode=gt.POS_COMPARE_OUTPUT_PULSE, outputPulseWidth=10, errorBand=0,
    )  # fmt: skip
    assert gt.GT_SetPosCompareMode(1, 1, byref(mode)) == 0, gt.GTE_GetLastError()
    back = gt.TPosCompareMode()
    assert gt.GTN_GetPosCompareMode(1, 1, byref(back)) == 0 and back.sourceX == 3
    for k, pos in enumerate((1500, 2500, 4000), 1):
        d = gt.TPosCompareData(pos=pos, hso=1, gpo=k, segmentNumber=10 + k)
        assert gt.GTN_PosCompareData(1, 1, byref(d)) == 0
    space = c_ushort()
    assert gt.GTN_PosCompareSpace(1, 1, byref(space)) == 0 and space.value == 4096 - 3
    assert gt.GT_PosCompareData2D(1, 1, byref(gt.TPosCompareData2D())) == 1  # 1D unit
    assert gt.GTN_PosCompareStart(1, 1) == 0
    trap(3, 3000)
    run(0b100)
    st = gt.TPosCompareStatus()
    assert gt.GT_PosCompareStatus(1, 1, byref(st)) == 0
    assert (st.run, st.pulseCount, st.gpo, st.segmentNumber) == (1, 2, 2, 12)
    info = gt.TPosCompareInfo()
    assert gt.GTN_PosCompareInfo(1, 1, byref(info)) == 0
    assert (info.config, info.fifoEmpty, info.commandReceive, info.commandSend) == (1, 0, 3, 2)
    assert info.posX == 3000
    assert gt.GT_PosCompareStop(1, 1) == 0 and gt.GT_PosCompareClear(1, 1) == 0
    # linear, two dimensions: every 500 pulses of axis 1 with axis 2 standing at 0
    mode.mode, mode.dimension, mode.sourceX, mode.sourceY, mode.errorBand = 1, 2, 1, 2, 2
    assert gt.GTN_SetPosCompareMode(1, 2, byref(mode)) == 0
    lin = gt.TPosCompareLinear2D(count=4, startPosX=500, startPosY=0, intervalX=500, intervalY=0)
    assert gt.GT_SetPosCompareLinear2D(1, 2, byref(lin)) == 0
    assert gt.GT_SetPosCompareLinear(1, 2, byref(gt.TPosCompareLinear(count=1))) == 1
    got = gt.TPosCompareLinear2D()
    assert gt.GTN_GetPosCompareLinear2D(1, 2, byref(got)) == 0 and got.intervalX == 500
    assert gt.GT_PosCompareStart(1, 2) == 0
    trap(1, 1900)
    run(0b1)
    assert gt.GTN_PosCompareStatus(1, 2, byref(st)) == 0
    assert (st.mode, st.run, st.pulseCount, st.segmentNumber) == (1, 1, 3, 3)
    trap(1, 2100)
    run(0b1)
    assert gt.GT_PosCompareStatus(1, 2, byref(st)) == 0 and (st.run, st.pulseCount) == (0, 4)
    one = gt.TPosCompareLinear(count=2, startPos=100, interval=50)
    mode.mode, mode.dimension = 1, 1
    assert gt.GT_SetPosCompareMode(1, 3, byref(mode)) == 0
    assert gt.GTN_SetPosCompareLinear(1, 3, byref(one)) == 0
    assert gt.GT_GetPosCompareLinear(1, 3, byref(got := gt.TPosCompareLinear())) == 0
    assert got.interval == 50
    assert gt.GTN_GetPosCompareLinear(1, 3, byref(got)) == 0 and got.count == 2
    assert gt.GTN_PosCompareStop(1, 2) == 0 and gt.GTN_PosCompareClear(1, 2) == 0
    # FIFO, two dimensions: a point of the plane reached on the way back
    mode.mode, mode.dimension = 0, 2
    assert gt.GT_SetPosCompareMode(1, 4, byref(mode)) == 0
    assert gt.GTN_PosCompareData2D(1, 4, byref(gt.TPosCompareData2D(posX=1000, posY=0))) == 0
    assert gt.GTN_SetPosCompareLinear2D(1, 4, byref(lin)) == 1  # a FIFO unit
    assert gt.GTN_PosCompareStart(1, 4) == 0
    trap(1, 0)
    run(0b1)
    assert gt.GT_PosCompareStatus(1, 4, byref(st)) == 0 and (st.run, st.pulseCount) == (0, 1)
    assert gt.GT_PosCompareStart(1, 5) == 1  # no mode
    assert gt.GT_SetPosCompareMode(1, 9, byref(mode)) == 7


def test_triggers_latch_the_encoder_at_the_home_switch_and_a_general_input():
    _open()
    t = gt.TTrigger(encoder=1, probeType=gt.MC_HOME, probeIndex=1, sense=0, offset=7, loop=1)
    assert gt.GT_SetTrigger(1, byref(t)) == 0, gt.GTE_GetLastError()
    ex = gt.TTriggerEx(
        latchType=23, latchIndex=1, probeType=gt.MC_GPI, probeIndex=3, sense=0, loop=2,
        windowOnly=1, firstPosition=0, lastPosition=20000,
    )  # fmt: skip
    assert gt.GT_SetTriggerEx(2, byref(ex)) == 0, gt.GTE_GetLastError()
    st = (gt.TTriggerStatusEx * 2)()
    assert gt.GT_GetTriggerStatusEx(1, st, 2) == 0
    assert (st[0].execute, st[0].done, st[1].execute) == (1, 0, 1)
    trap(1, 8000)
    run(0b1)
    s1 = gt.TTriggerStatus()
    assert gt.GT_GetTriggerStatus(1, byref(s1)) == 0
    assert (s1.execute, s1.done) == (0, 1) and abs(s1.position - (HOME_LO + 7)) <= 1
    enc = c_double()
    for k in range(2):  # the general input, twice: two latches where the axis stands
        trap(1, 9000 + 500 * k)
        run(0b1)
        assert gt.GTE_SetGpi(3, 1) == 0
        gt.GTE_Wait(2)
        assert gt.GTE_SetGpi(3, 0) == 0
        gt.GTE_Wait(2)
    assert gt.GT_GetEncPos(1, byref(enc)) == 0
    assert gt.GT_GetTriggerStatusEx(2, st, 1) == 0
    assert (st[0].done, st[0].loopCount, st[0].position) == (1, 2, round(enc.value))
    clock = c_long()
    gt.GT_GetClock(byref(clock))
    assert 0 < st[0].clock <= clock.value
    back = gt.TTriggerEx()
    assert gt.GT_GetTriggerEx(2, byref(back)) == 0 and back.probeIndex == 3
    assert gt.GT_GetTriggerEx(1, byref(back)) == 0 and (back.latchType, back.latchIndex) == (23, 1)
    assert gt.GT_GetTrigger(1, byref(t2 := gt.TTrigger())) == 0 and t2.offset == 7
    assert gt.GT_ClearTriggerStatus(1) == 0
    assert gt.GT_GetTriggerStatus(1, byref(s1)) == 0 and (s1.execute, s1.done) == (1, 0)
    assert gt.GT_ClearTriggerStatus(3) == 1  # never set
    bad = gt.TTriggerEx(latchType=99, probeType=gt.MC_HOME, probeIndex=1)
    assert gt.GT_SetTriggerEx(1, byref(bad)) == 7
    assert gt.GT_SetTrigger(9, byref(t)) == 7
