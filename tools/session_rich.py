"""A 12-axis application that meets trouble: the rich session of the replay benchmark.

The application (:func:`session`) runs on the 12-axis example bus for ``seconds`` of
controller time, polling every 10 ms like a PLC task:

* axis 1 homes (CiA-402 method 3: home switch and index pulse) and then stands in CSP;
* axis 2 jogs with a slow ramp (0.1 pulse/ms²) and reverses every ``seconds / 20``, so it
  spends a good part of the session accelerating;
* axes 3 to 12 run Trap moves between 0 and 50 000 pulses, a new one as soon as an axis is
  at rest with no flag set;
* every 100 ms it reads the homing status, the planned and the encoder position of every
  axis; at each reversal of the jog (every 3 s in a minute) it reads the first drive's
  6061h over SDO;
* at a third of the session the drive of axis 5 faults (over current, 2310h) for a
  twelfth of it; the application sees the alarm bit, reads GT_GetEcatErrorCode, and tries
  GT_ClrSts + GT_AxisOn every 500 ms until the axis is back;
* at half of it the positive limit switch of axis 6 chatters (it toggles every 4 cycles)
  for ``seconds * 5`` ms (300 ms in a minute); the application clears the latched limit
  flags every 200 ms until they stay clear.

``python tools/session_rich.py -o FILE [--seconds S]`` records it into FILE (with the ENI
and machine description it used beside it); tools/bench_replay.py ``--rich`` replays it
against real time, tests/gtecat/faults/test_replay_rich.py with the axis bank on and off.
"""

from __future__ import annotations

import argparse
import sys
from ctypes import byref, c_double, c_long, c_short, c_ubyte, c_ulong, c_ushort
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
ENI = ROOT / "examples" / "twelve_axes.eni"
AXES = 12
#: axis 1 starts inside its home switch's window, far from the limits
MACHINE = """\
[axis.1]
position = 80000
counts_per_rev = 10000
negative_limit = -4000000
positive_limit = 4000000
home_switch = [[100000, 4000000]]
index_offset = 3000
following_error_window = 20000
"""
ALARM, POS_LIMIT, NEG_LIMIT, MOVING = 0x2, 0x20, 0x40, 0x400


def session(gt, faults, seconds: float = 60.0, machine: str | None = None) -> int:
    """The application (module docstring); returns its scans."""
    kw = {"machine": machine} if machine else {}
    assert gt.GT_Open(eni=str(ENI), log="", **kw) == 0
    assert gt.GT_InitEcatComm() == 0
    st, clock = c_short(), c_ulong()

    def now() -> int:
        gt.GT_GetClock(byref(clock))
        return clock.value

    t0 = now()
    while not (gt.GT_IsEcatReady(byref(st)) == 0 and st.value == 1):
        assert now() - t0 < 5000, "the bus did not come up"
        gt.GTE_Wait(1)
    gt.GT_StartEcatComm()
    gt.GT_Reset()
    for ax in range(1, AXES + 1):
        gt.GT_AxisOn(ax)
    ms = seconds * 1000.0
    start = now()
    faults.inject(
        "drive_fault", axis=5, code=0x2310, at_ms=start + ms / 3, duration_ms=round(ms / 12)
    )
    faults.inject(
        "switch_chatter",
        axis=6,
        switch="positive",
        period_cycles=4,
        at_ms=start + ms / 2,
        duration_ms=round(seconds * 5),
    )
    gt.GT_SetHomingMode(1, 6)
    gt.GT_SetEcatHomingPrm(1, 3, 5000, 3000, 100000, 0, 0)
    gt.GT_StartEcatHoming(1)
    trap = gt.TTrapPrm()
    trap.acc = trap.dec = 0.2
    jog = gt.TJogPrm()
    jog.acc = jog.dec = 0.1
    gt.GT_PrfJog(2)
    gt.GT_SetJogPrm(2, byref(jog))
    gt.GT_SetVel(2, 10.0)
    gt.GT_Update(1 << 1)
    turn = max(1, round(seconds * 5))  # scans between two reversals of the jog (3 s in 60)
    sts, hs = c_long(), c_ushort()
    pos, enc = c_double(), c_double()
    data, abort = (c_ubyte * 4)(), c_ulong()
    target = dict.fromkeys(range(3, AXES + 1), 0)
    homed = False
    alarm_since: int | None = None
    limits_since: dict[int, int] = {}
    jog_dir = 1
    k = 0
    while now() - start < ms:
        k += 1
        t = now()
        for ax in range(1, AXES + 1):
            gt.GT_GetSts(ax, byref(sts), 1, None)
            s = sts.value
            if s & (POS_LIMIT | NEG_LIMIT) and ax not in limits_since:
                limits_since[ax] = t
            if ax >= 3 and not s & (MOVING | ALARM | POS_LIMIT | NEG_LIMIT):
                target[ax] = 50_000 if target[ax] == 0 else 0
                gt.GT_PrfTrap(ax)
                gt.GT_SetTrapPrm(ax, byref(trap))
                gt.GT_SetPos(ax, target[ax])
                gt.GT_SetVel(ax, 10.0 + ax)
                gt.GT_Update(1 << (ax - 1))
            if ax == 5 and s & ALARM:
                if alarm_since is None:
                    alarm_since = t
                    code = c_ushort()
                    gt.GT_GetEcatErrorCode(5, byref(code))
                elif t - alarm_since >= 500:  # try again every 500 ms
                    alarm_since = t
                    gt.GT_ClrSts(5, 1)
                    gt.GT_AxisOn(5)
        for ax, since in list(limits_since.items()):
            if t - since >= 200:  # the flags latched: clear them until they stay clear
                gt.GT_ClrSts(ax, 1)
                gt.GT_GetSts(ax, byref(sts), 1, None)
                if sts.value & (POS_LIMIT | NEG_LIMIT):
                    limits_since[ax] = t
                else:
                    del limits_since[ax]
        if k % 10 == 0:
            gt.GT_GetEcatHomingStatus(1, byref(hs))
            if hs.value == 3 and not homed:
                homed = True
                gt.GT_SetHomingMode(1, 8)
            for ax in range(1, AXES + 1):
                gt.GT_GetPrfPos(ax, byref(pos), 1, None)
                gt.GT_GetEncPos(ax, byref(enc), 1, None)
        if k % turn == 0:
            jog_dir = -jog_dir
            gt.GT_SetVel(2, 10.0 * jog_dir)
            gt.GT_Update(1 << 1)
            gt.GT_EcatSDOUpload(0, 0x6061, 0, data, 1, None, byref(abort))
        gt.GTE_Wait(10)
    gt.GT_Close()
    return k


def record(path: Path, seconds: float = 60.0) -> Path:
    """Record :func:`session` into ``path`` (its machine description beside it); the file."""
    from gtecat import faults, gt
    from gtecat.faults.record import Recorder

    machine = path.with_suffix(".toml")
    machine.write_text(MACHINE)
    rec = Recorder(path).start()
    try:
        session(gt, faults, seconds, str(machine))
    finally:
        rec.stop()
    return rec.write()


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("-o", "--output", type=Path, required=True, help="the recording to write")
    ap.add_argument("--seconds", type=float, default=60.0, help="controller time to run")
    args = ap.parse_args()
    sys.path.insert(0, str(ROOT))
    print(record(args.output, args.seconds))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
