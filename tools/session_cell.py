"""A 12-axis machine cell that meets trouble: the cell session of the replay benchmark.

Run as a program, the way an outside check records its own cell::

    gtecat record -o cell.gtrec -- python tools/session_cell.py [--machine cell.toml]

It writes its machine description (``--machine``, default ``cell.toml`` in the current
folder; the recording names it, so it must stay there for the replay) and runs the cell on the
12-axis example bus for ``--seconds`` of controller time (default 60), paced by ``GTE_Wait``:

* axis 1 homes in the drive (6060h = 6, CiA-402 method 3 on its home switch and index), axis 5
  by smart homing (``GT_GoHome``, mode 20 on its home switch); the others run Trap moves back
  and forth, a new one as soon as an axis is at rest;
* every 5 ms an HMI reads the clock and the status of each axis one by one, the planned and
  encoder positions as count-12 arrays (the encoder readers take 8 axes at most: 1-8, 9-12),
  and every 50 ms the positions one by one; every 2 s the first drive's 1001h by SDO;
* the faults (at these times in a minute; a session of ``--seconds`` meets them at the same
  fractions of it, for as long; the SDO's period and the second homing scale too): from the
  machine description (``[[fault]]`` tables) a link loss behind slave 3 (axes 5-12) at 25 s for
  300 ms, 150 ms into a second smart homing of axis 5; the positive limit of axis 3
  chattering at 35 s for 400 ms; the answer to the fifth SDO request to 1001h lost (the master
  waits its mailbox timeout); from Python (``gtecat.faults.inject``) an overcurrent of axis 7
  at 15 s for 3 s and safe torque off of axis 10 at 45 s for 1 s, both in the middle of a
  Trap move;
* its error handler: an alarm read (GT_GetEcatErrorCode) then the drive reset every 100 ms
  (GT_ClrSts, GT_AxisOn) until it stays; a latched limit cleared; a bus not ready
  (GT_IsEcatReady, every 50 ms) waited for with a time limit of 2 s, then the axes behind it
  reset and both homed axes home again once at rest.

The same kind of application as tools/session_hard.py (whose bus and axes it shares) with the
faults of tools/session_rich.py and docs/faults.md's four ways in; tools/bench_replay.py
``--cell`` records it with ``gtecat record`` and times whole ``gtecat replay FILE`` processes.
"""

from __future__ import annotations

import argparse
import sys
from ctypes import byref, c_double, c_long, c_short, c_ubyte, c_ulong, c_ushort
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from tools.session_hard import AXES, ENI, trap_move  # the 12-axis example bus, a Trap move

POLL_MS = 5
DRIVE_HOMING = 1  # CiA-402 method 3 in the drive
SMART_HOMING = 5  # GT_GoHome mode 20, behind the cut
RESET_MS = 100  # the handler's drive reset period
READY_LIMIT_MS = 2000  # how long the handler waits for the bus
ALARM, POS_LIMIT, NEG_LIMIT, MOVING = 0x2, 0x20, 0x40, 0x400
_AXIS = (
    "[axis.{a}]\nposition = {p}\ncounts_per_rev = 10000\nindex_offset = 3000\n"
    "negative_limit = -2000000\npositive_limit = 2000000\nfollowing_error_window = 50000\n{sw}\n"
)


def machine(seconds: float = 60.0) -> str:
    """The machine description: axis 1 starts on its home switch (the drive's method 3
    leaves it), axis 5 below its own; the ``[[fault]]`` tables at their times in a minute,
    scaled to ``seconds`` (:func:`at`)."""
    return (
        "".join(
            _AXIS.format(
                a=a,
                p=150000 if a == DRIVE_HOMING else 0,
                sw="home_switch = [[100000, 2000000]]\n"
                if a in (DRIVE_HOMING, SMART_HOMING)
                else "",
            )
            for a in range(1, AXES + 1)
        )
        + '[[fault]]\nkind = "link_down"\nafter_slave = 3\n'
        f"at_ms = {at(25000, seconds)}\nduration_ms = 300\n"
        'name = "cut"\n\n'
        '[[fault]]\nkind = "switch_chatter"\naxis = 3\nswitch = "positive"\nperiod_cycles = 3\n'
        f"at_ms = {at(35000, seconds)}\nduration_ms = 400\n\n"
        '[[fault]]\nkind = "mailbox_lost"\nslave = 0\nindex = 0x1001\non_sdo = [0, 0x1001, 5]\n'
    )


def at(ms: int, seconds: float) -> int:
    """The time ``ms`` of the minute-long cell in a session of ``seconds`` (a fault then lasts
    as long as in a minute: a shorter session meets every fault as the minute does)."""
    return round(ms * seconds / 60.0)


MACHINE = machine()


def session(gt, faults, seconds: float = 60.0, machine: str | None = None) -> int:
    """The cell (module docstring); returns the HMI's passes."""
    kw = {"machine": machine} if machine else {}
    assert gt.GT_Open(eni=str(ENI), log="", **kw) == 0
    assert gt.GT_InitEcatComm() == 0
    clock, st = c_ulong(), c_short()

    def now() -> int:
        gt.GT_GetClock(byref(clock))
        return clock.value

    def wait_ready() -> bool:
        """GT_IsEcatReady polled until the bus is up or READY_LIMIT_MS has passed."""
        t0 = now()
        while not (gt.GT_IsEcatReady(byref(st)) == 0 and st.value == 1):
            if now() - t0 >= READY_LIMIT_MS:
                return False
            gt.GTE_Wait(1)
        return True

    assert wait_ready(), "the bus did not come up"
    gt.GT_StartEcatComm()
    gt.GT_Reset()
    for a in range(1, AXES + 1):
        gt.GT_AxisOn(a)
    faults.inject("drive_fault", axis=7, code=0x2310, at_ms=at(15000, seconds), duration_ms=3000)
    faults.inject("sto", axis=10, at_ms=at(45000, seconds), duration_ms=1000)
    trap = gt.TTrapPrm()
    trap.acc = trap.dec = 0.25
    home = gt.THomePrm()
    gt.GT_GetHomePrm(SMART_HOMING, byref(home))
    home.mode, home.moveDir, home.velHigh, home.velLow = gt.HOME_MODE_HOME, 1, 40.0, 4.0
    home.acc = home.dec = 1.0

    def drive_homing() -> None:
        gt.GT_SetHomingMode(DRIVE_HOMING, 6)
        gt.GT_SetEcatHomingPrm(DRIVE_HOMING, 3, 40000, 4000, 400000, 0, 0)
        gt.GT_StartEcatHoming(DRIVE_HOMING)
        state[DRIVE_HOMING] = "homing"

    def smart_homing() -> None:
        gt.GT_PrfTrap(SMART_HOMING)
        if gt.GT_GoHome(SMART_HOMING, byref(home)) == 0:
            state[SMART_HOMING] = "homing"

    state = dict.fromkeys(range(1, AXES + 1), "trap")
    drive_homing()
    smart_homing()
    one, pos, epos = c_long(), c_double(), c_double()
    sts = [0] * AXES
    prf, enc, enc_hi = (c_double * AXES)(), (c_double * 8)(), (c_double * 4)()
    hs, code, home_st = c_ushort(), c_ushort(), gt.THomeStatus()
    sdo, size, abort = (c_ubyte * 4)(), c_ulong(), c_ulong()
    target = [0] * (AXES + 1)
    alarm: dict[int, int] = {}
    start = now()
    t_end = seconds * 1000
    sdo_at = 0
    sdo_ms = at(2000, seconds)
    second_homing = False
    k = 0
    while (t := now() - start) < t_end:
        k += 1
        for a in range(1, AXES + 1):
            gt.GT_GetSts(a, byref(one))
            sts[a - 1] = one.value
        gt.GT_GetPrfPos(1, prf, AXES, None)
        gt.GT_GetEncPos(1, enc, 8, None)
        gt.GT_GetEncPos(9, enc_hi, 4, None)
        if k % 10 == 0:
            for a in range(1, AXES + 1):
                gt.GT_GetPrfPos(a, byref(pos))
                gt.GT_GetEncPos(a, byref(epos))
        if k % 10 == 0 and not (gt.GT_IsEcatReady(byref(st)) == 0 and st.value == 1):
            # the bus is down: wait for it, then reset what it took and home again
            if wait_ready():
                for a in range(1, AXES + 1):
                    gt.GT_ClrSts(a, 1)
                    gt.GT_AxisOn(a)
                    alarm.pop(a, None)
                state[DRIVE_HOMING] = state[SMART_HOMING] = "rehome"
            continue
        if not second_homing and t >= at(24850, seconds) and state[SMART_HOMING] == "trap":
            second_homing = True  # a new reference, which the cut interrupts
            smart_homing()
        for a in range(1, AXES + 1):
            s = sts[a - 1]
            if s & ALARM:  # the drive's alarm: why, then a reset every RESET_MS
                if a not in alarm:
                    gt.GT_GetEcatErrorCode(a, byref(code))
                    alarm[a] = t
                elif t - alarm[a] >= RESET_MS:
                    alarm[a] = t
                    gt.GT_ClrSts(a, 1)
                    gt.GT_AxisOn(a)
                continue
            alarm.pop(a, None)
            if s & (POS_LIMIT | NEG_LIMIT):
                gt.GT_ClrSts(a, 1)
                continue
            if state[a] == "homing":
                if a == DRIVE_HOMING and k % 10 == 0:
                    gt.GT_GetEcatHomingStatus(a, byref(hs))
                    if hs.value & 1:
                        gt.GT_SetHomingMode(a, 8)
                        state[a] = "trap"
                elif a == SMART_HOMING and k % 10 == 0:
                    gt.GT_GetHomeStatus(a, byref(home_st))
                    if not home_st.run:
                        state[a] = "trap"
            elif s & MOVING:
                pass
            elif state[a] == "rehome" and a == DRIVE_HOMING:  # at rest: a new reference
                drive_homing()
            elif state[a] == "rehome":
                smart_homing()
            else:
                target[a] = 30_000 + 2000 * a if target[a] == 0 else 0
                trap_move(gt, a, target[a], trap)
        if t - sdo_at >= sdo_ms:
            sdo_at += sdo_ms
            gt.GT_EcatSDOUpload(0, 0x1001, 0, sdo, 1, byref(size), byref(abort))
        gt.GTE_Wait(POLL_MS)
    gt.GT_Close()
    return k


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seconds", type=float, default=60.0, help="controller time to run")
    ap.add_argument(
        "--machine", type=Path, default=Path("cell.toml"), help="the machine description to write"
    )
    args = ap.parse_args()
    from gtecat import faults, gt

    args.machine.write_text(machine(args.seconds))
    print("passes", session(gt, faults, args.seconds, str(args.machine.resolve())))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
