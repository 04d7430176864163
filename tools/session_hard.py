"""A 12-axis HMI-like application that polls hard: the hard session of the replay benchmark.

The application (:func:`session`) runs on the 12-axis example bus for ``seconds`` of
controller time, like an operator panel with an error handler.  Every 4 ms of controller time
its loop reads the status of all twelve axes - one by one (``GT_GetSts(axis, &sts, 1, NULL)``
twelve times, ``single``) or in one call (``GT_GetSts(1, sts, 12, NULL)``) - and every second
pass the planned and encoder positions of all twelve (one by one, or as arrays: the encoder
readers take at most 8 axes at once, so axes 1-8 and 9-12).  Axes 1 and 2 home (method 3 on a
home switch with an index pulse, method 19 on the switch alone) and join the others, which run
Trap moves (a new one as soon as an axis is at rest); axes 3 and 4 jog and reverse every 3 s.
The drive of axis 7 faults (overcurrent) at 20 s for 3 s (a ``[[fault]]`` table of the machine
description): the handler reads 603Fh, clears the alarm and switches the axis on again every
500 ms until it comes back.  The positive limit switch of axis 9 chatters at 35 s for 400 ms
(injected from Python): the handler clears the latched limit.  Every 2 s it reads two objects
of the first drive by SDO.

``python tools/session_hard.py -o FILE [--seconds S] [--single]`` records it into FILE (its
machine description beside it); tools/bench_replay.py ``--hard`` replays both forms against
real time.
"""

from __future__ import annotations

import argparse
import sys
from ctypes import byref, c_double, c_long, c_short, c_ubyte, c_ulong, c_ushort
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
ENI = ROOT / "examples" / "twelve_axes.eni"
AXES = 12
POLL_MS = 4
HOMING = ((1, 3), (2, 19))  # (axis, CiA-402 homing method)
JOG = (3, 4)
_SWITCH = "home_switch = [[100000, 2000000]]\n"
#: axis 1 starts on its home switch, axis 2 below it; a drive fault on axis 7 at 20 s
MACHINE = "".join(
    f"[axis.{a}]\nposition = {150000 if a == 1 else 0}\ncounts_per_rev = 10000\n"
    "index_offset = 3000\nnegative_limit = -2000000\npositive_limit = 2000000\n"
    f"following_error_window = 50000\n{_SWITCH if a <= 2 else ''}\n"
    for a in range(1, AXES + 1)
) + (
    '[[fault]]\nkind = "drive_fault"\naxis = 7\ncode = 0x2310\nat_ms = 20000\n'
    'duration_ms = 3000\nname = "overcurrent"\n'
)


def session(gt, faults, seconds: float = 60.0, machine: str | None = None, single=False) -> int:
    """The application (module docstring); returns the loop's passes."""
    kw = {"machine": machine} if machine else {}
    assert gt.GT_Open(eni=str(ENI), clock="auto", log="", **kw) == 0
    assert gt.GT_InitEcatComm() == 0
    clock = c_ulong()
    st = c_short()
    while gt.GT_IsEcatReady(byref(st)) == 0 and st.value != 1:
        gt.GTE_Wait(1)
    gt.GT_StartEcatComm()
    gt.GT_Reset()
    for a in range(1, AXES + 1):
        gt.GT_AxisOn(a)
    faults.inject(
        "switch_chatter", axis=9, switch="positive", period_cycles=3, at_ms=35000, duration_ms=400
    )
    prm = gt.TTrapPrm()
    prm.acc = prm.dec = 0.25
    jog = gt.TJogPrm()
    jog.acc = jog.dec = 0.05
    state = dict.fromkeys(range(1, AXES + 1), "trap")
    for a, method in HOMING:
        gt.GT_SetHomingMode(a, 6)
        gt.GT_SetEcatHomingPrm(a, method, 40000, 4000, 400000, 0, 0)
        gt.GT_StartEcatHoming(a)
        state[a] = "homing"
    for a in JOG:
        gt.GT_PrfJog(a)
        gt.GT_SetJogPrm(a, byref(jog))
        gt.GT_SetVel(a, 8.0 if a == 3 else -6.0)
        gt.GT_Update(1 << (a - 1))
        state[a] = "jog"
    sts = (c_long * AXES)()
    prf = (c_double * AXES)()
    enc = (c_double * 8)()
    enc_hi = (c_double * 4)()
    one, pos, epos = c_long(), c_double(), c_double()
    hs, code = c_ushort(), c_ushort()
    sdo = (c_ubyte * 4)()
    size, abort = c_ulong(), c_ulong()
    target = [0] * (AXES + 1)
    direction = 1
    alarm: dict[int, int] = {}
    gt.GT_GetClock(byref(clock))
    start = clock.value
    t_end = seconds * 1000
    turn = sdo_at = 0
    k = 0
    while True:
        gt.GT_GetClock(byref(clock))
        t = clock.value - start
        if t >= t_end:
            break
        k += 1
        if single:
            for a in range(1, AXES + 1):
                gt.GT_GetSts(a, byref(one), 1, None)
                sts[a - 1] = one.value
        else:
            gt.GT_GetSts(1, sts, AXES, None)
        if k % 2 == 0:
            if single:
                for a in range(1, AXES + 1):
                    gt.GT_GetPrfPos(a, byref(pos), 1, None)
                    gt.GT_GetEncPos(a, byref(epos), 1, None)
            else:
                gt.GT_GetPrfPos(1, prf, AXES, None)
                gt.GT_GetEncPos(1, enc, 8, None)
                gt.GT_GetEncPos(9, enc_hi, 4, None)
        for a in range(1, AXES + 1):
            s = sts[a - 1]
            if s & 0x2:  # the drive's alarm: read why, then try again every 500 ms
                if a not in alarm:
                    gt.GT_GetEcatErrorCode(a, byref(code))
                    alarm[a] = t
                elif t - alarm[a] >= 500 and (t - alarm[a]) % 500 < POLL_MS:
                    gt.GT_ClrSts(a, 1)
                    gt.GT_AxisOn(a)
                continue
            if a in alarm:  # back
                del alarm[a]
                if state[a] != "homing":
                    state[a] = "trap"
            if s & 0x60:  # a limit latched: cleared once the switch is free
                gt.GT_ClrSts(a, 1)
                continue
            if state[a] == "homing":
                if k % 5 == 0:
                    gt.GT_GetEcatHomingStatus(a, byref(hs))
                    if hs.value & 1:
                        gt.GT_SetHomingMode(a, 8)
                        state[a] = "trap"
            elif state[a] == "trap" and not s & 0x400:
                target[a] = 30_000 + 2000 * a if target[a] == 0 else 0
                trap_move(gt, a, target[a], prm)
        if t - turn >= 3000:
            turn += 3000
            direction = -direction
            for a in JOG:
                if state[a] == "jog" and not sts[a - 1] & 0x62:
                    gt.GT_SetVel(a, 8.0 * direction)
                    gt.GT_Update(1 << (a - 1))
        if t - sdo_at >= 2000:
            sdo_at += 2000
            gt.GT_EcatSDOUpload(0, 0x6061, 0, sdo, 1, byref(size), byref(abort))
            gt.GT_EcatSDOUpload(0, 0x1001, 0, sdo, 1, byref(size), byref(abort))
        gt.GTE_Wait(POLL_MS)
    gt.GT_Close()
    return k


def trap_move(gt, axis: int, target: int, prm) -> None:
    """A Trap move of ``axis`` to ``target`` with ``prm`` at 10 + ``axis`` pulse/ms, as these
    sessions start one as soon as an axis is at rest."""
    gt.GT_PrfTrap(axis)
    gt.GT_SetTrapPrm(axis, byref(prm))
    gt.GT_SetPos(axis, target)
    gt.GT_SetVel(axis, 10.0 + axis)
    gt.GT_Update(1 << (axis - 1))


def record(path: Path, seconds: float = 60.0, single: bool = False) -> Path:
    """Record :func:`session` into ``path`` (its machine description beside it); the file."""
    from gtecat import faults, gt
    from gtecat.faults.record import Recorder

    machine = path.with_suffix(".toml")
    machine.write_text(MACHINE)
    rec = Recorder(path).start()
    try:
        session(gt, faults, seconds, str(machine), single)
    finally:
        rec.stop()
    return rec.write()


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("-o", "--output", type=Path, required=True, help="the recording to write")
    ap.add_argument("--seconds", type=float, default=60.0, help="controller time to run")
    ap.add_argument("--single", action="store_true", help="poll the axes one by one")
    args = ap.parse_args()
    sys.path.insert(0, str(ROOT))
    print(record(args.output, args.seconds, args.single))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
