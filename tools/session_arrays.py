"""A 12-axis application that polls every axis in one call: the array session of the
replay benchmark.

The application (:func:`session`) runs on the 12-axis example bus for ``seconds`` of
controller time.  Its loop reads the clock (``unsigned long``, the vendor's type) and
``GT_GetSts(1, sts, 12, NULL)`` - the status of all twelve axes in one call - every 4 to 8
ms (the period walks 4, 5, 6, 7, 8 ms); every second pass it reads the planned positions of
all twelve (``GT_GetPrfPos(1, prf, 12, NULL)``) and the encoder positions in the two calls
the encoder readers allow (at most 8 at once: axes 1-8, then 9-12).  Axes 3 and 4 jog and
reverse every 3 s; the others run Trap moves, a new one as soon as an axis is at rest.

``python tools/session_arrays.py -o FILE [--seconds S]`` records it into FILE;
tools/bench_replay.py ``--arrays`` replays it against real time.
"""

from __future__ import annotations

import argparse
import sys
from ctypes import byref, c_double, c_long, c_short, c_ulong
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
ENI = ROOT / "examples" / "twelve_axes.eni"
AXES = 12
JOG = (3, 4)
#: limits far from the moves
MACHINE = "".join(
    f"[axis.{a}]\ncounts_per_rev = 10000\nnegative_limit = -2000000\npositive_limit = 2000000\n\n"
    for a in range(1, AXES + 1)
)


def session(gt, seconds: float = 60.0, machine: str | None = None) -> int:
    """The application (module docstring); returns the loop's passes."""
    kw = {"machine": machine} if machine else {}
    assert gt.GT_Open(eni=str(ENI), clock="auto", log="", **kw) == 0
    assert gt.GT_InitEcatComm() == 0
    st = c_short()
    while gt.GT_IsEcatReady(byref(st)) == 0 and st.value != 1:
        gt.GTE_Wait(1)
    gt.GT_StartEcatComm()
    gt.GT_Reset()
    for a in range(1, AXES + 1):
        gt.GT_AxisOn(a)
    jog = gt.TJogPrm()
    jog.acc = jog.dec = 0.1
    for a in JOG:
        gt.GT_PrfJog(a)
        gt.GT_SetJogPrm(a, byref(jog))
        gt.GT_SetVel(a, 6.0)
        gt.GT_Update(1 << (a - 1))
    prm = gt.TTrapPrm()
    prm.acc = prm.dec = 0.25
    sts = (c_long * AXES)()
    prf = (c_double * AXES)()
    enc = (c_double * AXES)()
    enc_hi = (c_double * 4)()
    clock = c_ulong()
    target = [0] * (AXES + 1)
    direction = 1
    t_end = seconds * 1000
    turn = 3000
    k = 0
    while True:
        gt.GT_GetClock(byref(clock))
        now = clock.value
        if now >= t_end:
            break
        gt.GT_GetSts(1, sts, AXES, None)
        if k % 2 == 0:
            gt.GT_GetPrfPos(1, prf, AXES, None)
            gt.GT_GetEncPos(1, enc, 8, None)
            gt.GT_GetEncPos(9, enc_hi, 4, None)
        for a in range(1, AXES + 1):
            if a in JOG or sts[a - 1] & 0x400:
                continue
            target[a] = 30_000 + 1000 * a if target[a] <= 0 else -(30_000 + 1000 * a)
            gt.GT_PrfTrap(a)
            gt.GT_SetTrapPrm(a, byref(prm))
            gt.GT_SetPos(a, target[a])
            gt.GT_SetVel(a, 10.0 + a)
            gt.GT_Update(1 << (a - 1))
        if now >= turn:
            turn += 3000
            direction = -direction
            for a in JOG:
                gt.GT_SetVel(a, 6.0 * direction)
                gt.GT_Update(1 << (a - 1))
        k += 1
        gt.GTE_Wait(4 + k % 5)
    gt.GT_Close()
    return k


def record(path: Path, seconds: float = 60.0) -> Path:
    """Record :func:`session` into ``path`` (its machine description beside it); the file."""
    from gtecat import gt
    from gtecat.faults.record import Recorder

    machine = path.with_suffix(".toml")
    machine.write_text(MACHINE)
    rec = Recorder(path).start()
    try:
        session(gt, seconds, str(machine))
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
