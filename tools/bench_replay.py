"""Replay speed: a recorded 12-axis, 60-virtual-second session replayed against real time.

The session is an application's loop on the 12-axis example bus: bring-up, servo on, axes 1
and 2 home (CiA-402 method 3 on a home switch with an index pulse) and join the others,
which run Trap moves (a new one as soon as an axis is at rest), axes 3 and 4 jog and
turn round every 3 s; every ``--poll-ms`` of controller time (default 10) the loop reads
the clock and GT_GetSts of each axis (and the homing status while an axis homes), every
100 ms the planned and encoder positions of each axis and the DIO slave's inputs, every
second it writes the DIO slave's outputs.

It is recorded (gtecat.faults.record), then replayed: the report gives the calls, the
recording's and the replay's wall and CPU time, and how many times faster than real time
the replay runs: virtual/wall (``times_real_time``) and virtual/CPU
(``times_real_time_cpu``, the same figure on a machine nobody else loads; the bar: at least
50).  ``--repeat N`` replays N times and reports the best of each.  The plain session
(no recording) is run too, to show what recording costs.  ``--against CHECKOUT`` replays the
same recording with another checkout's gtecat as well (each replay in a fresh process, the two
in turn): before and after in one run.  The CPU time a process gets done per second depends on
what else the machine runs: ``reference_12_axes_trap_one_cycle_at_a_time`` measures, in the same
run, a figure docs/performance.md took on a lightly loaded machine (219 times real time).

``--rich`` records and replays tools/session_rich.py's session instead: an application that
meets trouble (axis 1 homes, axis 2 jogs with a slow ramp and reverses every 3 s, Trap moves
on the others, SDO reads, the drive of axis 5 faults at 20 s for 5 s and the application
brings it back, the limit switch of axis 6 chatters at 30 s for 300 ms).

``--arrays`` records and replays tools/session_arrays.py's session: an application that polls
every axis in one call (``GT_GetSts(1, sts, 12, NULL)``, the planned and encoder positions as
arrays too) every 4 to 8 ms, Trap moves and two jogs.

``--file FILE`` times an existing recording (an application's own: the outside check's 12-axis
session) as whole ``gtecat replay FILE`` processes run in the file's folder, the best of
``--repeat``, with the times real time against the recording's last call's controller time
(the bar: the whole process at least 50 times real time); ``--against CHECKOUT`` times that
checkout's gtecat too, the two in turn.

``--cell`` records tools/session_cell.py's 12-axis cell the way an outside check records its
own (``gtecat record -o FILE -- python tools/session_cell.py``: two homings, one of them
interrupted by a link loss, a drive fault and safe torque off mid-Trap, a chattering limit, a
lost SDO answer, polling every 5 ms one by one and as arrays, an error handler), times whole
``gtecat replay FILE`` processes as ``--file`` does, and checks that a copy with one call's
recorded return code changed diverges (exits non-zero).

``--hard`` records tools/session_hard.py's HMI-like session twice - every axis polled every
4 ms one by one (``single``), and as count-12 arrays (``arrays``): homing, jogs, Trap moves, a
drive fault and a chattering limit switch with the application's error handler, SDO reads -
and times each recording's replay in this process and as a whole ``gtecat replay FILE``
process (the interpreter's start, the imports, reading the file and the replay: what a user
waits for); ``--against CHECKOUT`` times the whole process with that checkout's gtecat too,
the two in turn.

    python tools/bench_replay.py [--seconds 60] [--poll-ms 10] [--repeat 3] [--against DIR]
                                 [--simple | --rich | --arrays | --hard | --cell | --file FILE]
                                 [--json]
"""

from __future__ import annotations

import argparse
import json
import os
import resource
import subprocess
import sys
import tempfile
import time
from ctypes import byref, c_double, c_long, c_short, c_ubyte
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))
ENI = ROOT / "examples" / "twelve_axes.eni"
AXES = 12
HOMING = (1, 2)  # home first (method 3: home switch, index pulse)
JOG = (3, 4)  # jog, turning round every JOG_TURN_MS
JOG_TURN_MS = 3000
#: axes 1 and 2 stand inside the home switch's window, like bench_homing_gt's axis
MACHINE = """\
[axis.1]
position = 60500
counts_per_rev = 10000
negative_limit = -400000
positive_limit = 400000
home_switch = [[100000, 400000]]
index_offset = 3000

[axis.2]
position = 70500
counts_per_rev = 10000
negative_limit = -400000
positive_limit = 400000
home_switch = [[100000, 400000]]
index_offset = 3000
"""


def session(
    gt, seconds: float, poll_ms: int = 10, machine: str | None = None, simple: bool = False
) -> int:
    """The application (module docstring); returns the loop's passes.  ``simple``: Trap moves
    on every axis and the status polling only (the first version of this benchmark)."""
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
    homing = set(HOMING if machine and not simple else ())
    jogging = () if simple else JOG
    for a in homing:
        gt.GT_SetHomingMode(a, 6)
        gt.GT_SetEcatHomingPrm(a, 3, 5000, 3000, 100000, 0, 0)
        gt.GT_StartEcatHoming(a)
    prm = gt.TTrapPrm()
    prm.acc = prm.dec = 0.5
    jog = gt.TJogPrm()
    jog.acc = jog.dec = 0.25
    for a in jogging:
        gt.GT_PrfJog(a)
        gt.GT_SetJogPrm(a, byref(jog))
        gt.GT_SetVel(a, 8.0)
        gt.GT_Update(1 << (a - 1))
    sts, pos, enc, hs = c_long(), c_double(), c_double(), c_short()
    clock = c_long()
    di = (c_ubyte * 2)()
    do = (c_ubyte * 2)()
    target = [0] * (AXES + 1)
    jog_dir = {a: 1 for a in jogging}
    t_end = seconds * 1000
    step = 0
    per_100ms = max(1, 100 // poll_ms)
    per_s = max(1, 1000 // poll_ms)
    per_turn = max(1, JOG_TURN_MS // poll_ms)
    while True:
        gt.GT_GetClock(byref(clock))
        if clock.value >= t_end:
            break
        for a in sorted(homing):
            gt.GT_GetEcatHomingStatus(a, byref(hs))
            if hs.value & 1:  # done: back to CSP and into the Trap moves
                homing.discard(a)
                gt.GT_SetHomingMode(a, 8)
        for a in range(1, AXES + 1):
            gt.GT_GetSts(a, byref(sts))
            if a in homing or a in jogging:
                continue
            if not sts.value & 0x400:  # at rest: the next move
                target[a] = 20_000 if target[a] <= 0 else -20_000
                gt.GT_PrfTrap(a)
                gt.GT_SetTrapPrm(a, byref(prm))
                gt.GT_SetPos(a, target[a])
                gt.GT_SetVel(a, 10 + a)
                gt.GT_Update(1 << (a - 1))
        if step % per_turn == per_turn - 1:
            for a in jogging:
                jog_dir[a] = -jog_dir[a]
                gt.GT_SetVel(a, 8.0 * jog_dir[a])
                gt.GT_Update(1 << (a - 1))
        if step % per_100ms == 0:
            for a in range(1, AXES + 1):
                gt.GT_GetPrfPos(a, byref(pos))
                if not simple:
                    gt.GT_GetEncPos(a, byref(enc))
            if not simple:
                gt.GT_EcatIOReadInput(6, 0, 2, di)
        if step % per_s == 0 and not simple:
            do[0] = (step // per_s) & 0xFF
            gt.GT_EcatIOWriteOutput(6, 0, 2, do)
        step += 1
        gt.GTE_Wait(poll_ms)
    gt.GT_Close()
    return step


#: the reference figure on a lightly loaded machine (docs/performance.md, load 1.2-1.5)
REFERENCE_QUIET = 219.0


def reference() -> dict[str, object]:
    """How loaded this machine is now: 12 axes moving in Trap, one cycle at a time (the
    compiled cycle alone, as docs/performance.md measured it: 219 times real time per CPU
    second on a lightly loaded machine)."""
    from gtecat.controller.core import Controller
    from tools.bench_scaling import run_bus

    run = Controller.run_cycles
    Controller.run_cycles = lambda self, n: 0  # type: ignore[method-assign]
    try:
        r = run_bus(12, dict.fromkeys(range(1, 13), "moving"), seconds=1.0, repeat=3)
    finally:
        Controller.run_cycles = run  # type: ignore[method-assign]
    rtf = r.get("rtf_cpu")
    return {
        "rtf_cpu": rtf,
        "quiet_machine": REFERENCE_QUIET,
        "slower_than_quiet": round(REFERENCE_QUIET / rtf, 2) if rtf else None,
    }


def _best(runs: list[tuple[float, float]]) -> tuple[float, float]:
    return min(r[0] for r in runs), min(r[1] for r in runs)


_CHILD = """
import json, sys, time
sys.path.insert(0, sys.argv[1])
from gtecat import gt  # imported before the clock starts, as in this process
from gtecat.faults.record import replay
t0, c0 = time.perf_counter(), time.process_time()
n, div = replay(sys.argv[2])
wall, cpu = time.perf_counter() - t0, time.process_time() - c0
print(json.dumps([wall, cpu, n, str(div) if div else None]))
"""


def replay_in(root: Path, path: Path) -> tuple[float, float, int, str | None]:
    """(wall, CPU, calls, divergence) of a replay of ``path`` by the gtecat of checkout ``root``,
    in a fresh process (its start and imports not counted)."""
    out = subprocess.run(
        [sys.executable, "-c", _CHILD, str(root), str(path)],
        capture_output=True,
        text=True,
        check=True,
    )
    wall, cpu, n, div = json.loads(out.stdout.strip().splitlines()[-1])
    return wall, cpu, n, div


def replay_process(root: Path, path: Path) -> tuple[float, float, str]:
    """(wall, CPU, its last line) of a whole ``gtecat replay FILE`` process run with the gtecat
    of checkout ``root``; RuntimeError when it does not exit 0."""
    env = dict(os.environ, PYTHONPATH=str(root))
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    t0 = time.perf_counter()
    out = subprocess.run(
        [sys.executable, "-m", "gtecat", "replay", str(path)],
        capture_output=True,
        text=True,
        env=env,
        cwd=str(path.parent),
    )
    wall = time.perf_counter() - t0
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    if out.returncode != 0:
        raise RuntimeError(f"gtecat replay {path} ({root}): {out.stderr.strip()[-500:]}")
    return wall, cpu, out.stdout.strip().splitlines()[-1]


def recorded_seconds(path: Path) -> float:
    """The controller time the recording reached, in seconds: the largest of its last calls'
    ``"t"`` (ns; a GT_Close after the others has none left: 0)."""
    with open(path, "rb") as f:
        f.seek(0, os.SEEK_END)
        size = f.tell()
        f.seek(max(0, size - (1 << 16)))
        tail = f.read().decode("utf-8", "replace")
    times = [
        int(line[5 : line.index(",")])
        for line in tail.splitlines()[1:]
        if line.startswith('{"t":') and "," in line
    ]
    if not times or max(times) <= 0:
        raise ValueError(f"{path}: no call with a time in its last 64 KiB")
    return max(times) / 1e9


def processes(
    path: Path, seconds: float, repeat: int, against: Path | None = None
) -> tuple[dict[str, object], str]:
    """``path`` replayed as whole ``gtecat replay FILE`` processes, ``repeat`` times, by this
    checkout (and ``against``'s, the two in turn): each side's best wall and CPU seconds and
    times real time against ``seconds`` (``process``, or ``process_before`` /
    ``process_after``), and the last replay's last line."""
    sides = [("after", ROOT)] if against is None else [("before", against), ("after", ROOT)]
    procs: dict[str, list[tuple[float, float]]] = {k: [] for k, _ in sides}
    last = ""
    for _ in range(repeat):  # the sides in turn
        for key, root in sides:
            w, c, last = replay_process(root, path)
            procs[key].append((w, c))
    rows: dict[str, object] = {}
    for key, root in sides:
        w, c = _best(procs[key])
        rows[f"process_{key}" if against is not None else "process"] = {
            "checkout": str(root),
            "wall_s": round(w, 3),
            "cpu_s": round(c, 3),
            "times_real_time": round(seconds / w, 1),
            "times_real_time_cpu": round(seconds / c, 1),
            "walls_s": [round(x, 3) for x, _ in procs[key]],
        }
    return rows, last


def measure_file(path: Path, repeat: int, against: Path | None = None) -> dict[str, object]:
    """An existing recording replayed as whole ``gtecat replay FILE`` processes (``--file``)."""
    path = path.resolve()
    seconds = recorded_seconds(path)
    out: dict[str, object] = {
        "file": str(path),
        "virtual_s": round(seconds, 3),
        "load_average_before": round(os.getloadavg()[0], 2),
    }
    rows, last = processes(path, seconds, repeat, against)
    out |= rows
    out["replay_says"] = last
    out["load_average_after"] = round(os.getloadavg()[0], 2)
    out["diverged"] = None  # (replay_process raises when the replay does not exit 0)
    return out


def tampered(path: Path, out: Path) -> str:
    """Copy the recording ``path`` to ``out`` with the return code of one call in its middle
    changed (a GT_GetSts that returned 0 now says 1); what was changed."""
    lines = path.read_bytes().split(b"\n")
    for i in range(len(lines) // 2, len(lines)):
        if lines[i].startswith(b'{"t":') and b'"c":"GT_GetSts"' in lines[i]:
            if b'"r":0' in lines[i]:
                lines[i] = lines[i].replace(b'"r":0', b'"r":1', 1)
                out.write_bytes(b"\n".join(lines))
                return f"line {i + 1}: GT_GetSts's return code 0 -> 1"
    raise ValueError(f"{path}: no GT_GetSts returning 0 in its second half")


def measure_cell(
    seconds: float, repeat: int, against: Path | None = None, keep: Path | None = None
) -> dict[str, object]:
    """tools/session_cell.py recorded by ``gtecat record`` in a child process, its whole
    ``gtecat replay FILE`` processes timed (:func:`measure_file`), a tampered copy replayed."""
    with tempfile.TemporaryDirectory() as tmp:
        folder = keep if keep is not None else Path(tmp)
        folder.mkdir(parents=True, exist_ok=True)
        path, machine = folder / "cell.gtrec", folder / "cell.toml"
        env = dict(os.environ, PYTHONPATH=str(ROOT))
        t0 = time.perf_counter()
        session = [sys.executable, str(ROOT / "tools" / "session_cell.py")]
        session += ["--seconds", str(seconds), "--machine", str(machine)]
        subprocess.run(
            [sys.executable, "-m", "gtecat", "record", "-o", str(path), "--", *session],
            check=True,
            capture_output=True,
            env=env,
            cwd=str(folder),
        )
        recorded = time.perf_counter() - t0
        out = measure_file(path, repeat, against)
        out = {"session": "cell", "record_wall_s": round(recorded, 3), **out}
        out["file_bytes"] = path.stat().st_size
        bad = folder / "cell_tampered.gtrec"
        what = tampered(path, bad)
        r = subprocess.run(
            [sys.executable, "-m", "gtecat", "replay", str(bad)],
            capture_output=True,
            text=True,
            env=env,
            cwd=str(folder),
        )
        out["tampered"] = {
            "changed": what,
            "exit": r.returncode,
            "says": (r.stdout.strip() or r.stderr.strip()).splitlines()[-1:],
        }
        if r.returncode == 0:
            out["diverged"] = f"the tampered copy replayed without a divergence ({what})"
        bad.unlink()
    return out


def measure_hard(
    seconds: float, repeat: int, against: Path | None = None, keep: Path | None = None
) -> dict[str, object]:
    """The hard session (module docstring), recorded polling one by one and as arrays."""
    from gtecat import faults, gt
    from gtecat.faults.record import Recorder, replay
    from tools import session_hard

    out: dict[str, object] = {
        "session": "hard",
        "virtual_s": seconds,
        "poll_ms": session_hard.POLL_MS,
        "load_average_before": round(os.getloadavg()[0], 2),
    }
    diverged = None
    with tempfile.TemporaryDirectory() as tmp:
        folder = keep if keep is not None else Path(tmp)
        folder.mkdir(parents=True, exist_ok=True)
        machine = folder / "hard.toml"
        machine.write_text(session_hard.MACHINE)
        for form, single in (("single", True), ("arrays", False)):
            path = folder / f"hard_{form}.gtrec"
            rec = Recorder(path).start()
            t0, c0 = time.perf_counter(), time.process_time()
            try:
                session_hard.session(gt, faults, seconds, str(machine), single)
            finally:
                rec.stop()
            recorded = (time.perf_counter() - t0, time.process_time() - c0)
            rec.write()
            runs, n, div = [], 0, None
            for _ in range(repeat):
                t0, c0 = time.perf_counter(), time.process_time()
                n, div = replay(path)
                runs.append((time.perf_counter() - t0, time.process_time() - c0))
                if div is not None:
                    diverged = diverged or f"{form}: {div}"
                    break
            wall, cpu = _best(runs)
            row: dict[str, object] = {
                "calls": n,
                "file_bytes": path.stat().st_size,
                "record_wall_s": round(recorded[0], 3),
                "replay_wall_s": round(wall, 3),
                "replay_cpu_s": round(cpu, 3),
                "times_real_time": round(seconds / wall, 1),
                "times_real_time_cpu": round(seconds / cpu, 1),
                "diverged": str(div) if div else None,
            }
            row |= processes(path, seconds, repeat, against)[0]
            out[form] = row
    out["load_average_after"] = round(os.getloadavg()[0], 2)
    out["diverged"] = diverged
    out["reference_12_axes_trap_one_cycle_at_a_time"] = reference()
    return out


def measure(
    seconds: float,
    poll_ms: int,
    repeat: int,
    against: Path | None = None,
    simple: bool = False,
    rich: bool = False,
    arrays: bool = False,
) -> dict[str, object]:
    from gtecat import faults, gt
    from gtecat.faults.record import Recorder, replay
    from tools import session_arrays, session_rich

    def run_session(machine: Path) -> None:
        if arrays:
            session_arrays.session(gt, seconds, str(machine))
        elif rich:
            session_rich.session(gt, faults, seconds, str(machine))
        else:
            session(gt, seconds, poll_ms, str(machine), simple)

    with tempfile.TemporaryDirectory() as tmp:
        machine = Path(tmp) / "machine.toml"
        machine.write_text(
            session_arrays.MACHINE if arrays else session_rich.MACHINE if rich else MACHINE
        )
        path = Path(tmp) / "session.gtrec"
        plain = []
        for _ in range(repeat):
            t0, c0 = time.perf_counter(), time.process_time()
            run_session(machine)
            plain.append((time.perf_counter() - t0, time.process_time() - c0))
        rec = Recorder(path).start()
        t0, c0 = time.perf_counter(), time.process_time()
        try:
            run_session(machine)
        finally:
            rec.stop()
        recorded = (time.perf_counter() - t0, time.process_time() - c0)
        rec.write()
        runs = []
        n, div = 0, None
        for _ in range(repeat):
            t0, c0 = time.perf_counter(), time.process_time()
            n, div = replay(path)
            runs.append((time.perf_counter() - t0, time.process_time() - c0))
            if div is not None:
                break
        size = path.stat().st_size
        before: dict[str, object] = {}
        if against is not None:  # the same recording, old and new, in fresh processes, in turn
            old_runs, new_runs = [], []
            for _ in range(repeat):
                old_runs.append(replay_in(against, path))
                new_runs.append(replay_in(ROOT, path))
            for key, rr in (("before", old_runs), ("after", new_runs)):
                w, c = _best([(r[0], r[1]) for r in rr])
                before[key] = {
                    "checkout": str(against if key == "before" else ROOT),
                    "replay_wall_s": round(w, 3),
                    "replay_cpu_s": round(c, 3),
                    "times_real_time": round(seconds / w, 1),
                    "times_real_time_cpu": round(seconds / c, 1),
                    "diverged": rr[-1][3],
                }
    wall, cpu = _best(runs)
    pw, pc = _best(plain)
    return {
        "session": "arrays" if arrays else "rich" if rich else "simple" if simple else "full",
        "virtual_s": seconds,
        "poll_ms": "4-8" if arrays else 10 if rich else poll_ms,
        "load_average": round(os.getloadavg()[0], 2),
        "calls": n,
        "session_wall_s": round(pw, 3),
        "session_cpu_s": round(pc, 3),
        "record_wall_s": round(recorded[0], 3),
        "record_cpu_s": round(recorded[1], 3),
        "record_cost": round(recorded[1] / pc, 2),
        "replay_wall_s": round(wall, 3),
        "replay_cpu_s": round(cpu, 3),
        "times_real_time": round(seconds / wall, 1),
        "times_real_time_cpu": round(seconds / cpu, 1),
        "file_bytes": size,
        "diverged": str(div) if div else None,
        **before,
        "reference_12_axes_trap_one_cycle_at_a_time": reference(),
    }


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seconds", type=float, default=60.0)
    ap.add_argument("--poll-ms", type=int, default=10, help="the application's loop period")
    ap.add_argument("--repeat", type=int, default=3, help="runs; the best is reported")
    ap.add_argument(
        "--against",
        type=Path,
        help="another checkout: replay the same recording with its gtecat too (before/after)",
    )
    kind = ap.add_mutually_exclusive_group()
    kind.add_argument(
        "--simple",
        action="store_true",
        help="Trap moves and status polling only (no homing, jog, IO)",
    )
    kind.add_argument(
        "--rich",
        action="store_true",
        help="the session that meets trouble: a jog's ramps, a drive fault and its recovery, "
        "a chattering limit switch, SDO reads (tools/session_rich.py)",
    )
    kind.add_argument(
        "--hard",
        action="store_true",
        help="the HMI-like session that polls every axis every 4 ms, one by one and as "
        "count-12 arrays (two recordings), each also replayed as a whole gtecat replay "
        "process (tools/session_hard.py)",
    )
    kind.add_argument(
        "--cell",
        action="store_true",
        help="the 12-axis cell that meets trouble (tools/session_cell.py), recorded by "
        "gtecat record and replayed as whole gtecat replay processes, and a tampered copy",
    )
    kind.add_argument(
        "--arrays",
        action="store_true",
        help="the session that polls all 12 axes in one call each (status, planned and "
        "encoder positions as arrays) every 4 to 8 ms (tools/session_arrays.py)",
    )
    kind.add_argument(
        "--file",
        type=Path,
        help="an existing recording: time whole gtecat replay FILE processes run in its folder",
    )
    ap.add_argument(
        "--keep",
        type=Path,
        help="--hard, --cell: write the recordings into this folder and keep them",
    )
    ap.add_argument("--json", action="store_true")
    args = ap.parse_args()
    if args.file is not None:
        out = measure_file(args.file, max(1, args.repeat), args.against)
        print(json.dumps(out) if args.json else "\n".join(f"{k}: {v}" for k, v in out.items()))
        return 0
    if args.cell:
        out = measure_cell(args.seconds, max(1, args.repeat), args.against, args.keep)
        print(json.dumps(out) if args.json else "\n".join(f"{k}: {v}" for k, v in out.items()))
        return 0 if out["diverged"] is None else 1
    if args.hard:
        out = measure_hard(args.seconds, max(1, args.repeat), args.against, args.keep)
        print(json.dumps(out) if args.json else "\n".join(f"{k}: {v}" for k, v in out.items()))
        return 0 if out["diverged"] is None else 1
    out = measure(
        args.seconds,
        args.poll_ms,
        max(1, args.repeat),
        args.against,
        args.simple,
        args.rich,
        args.arrays,
    )
    print(json.dumps(out) if args.json else "\n".join(f"{k}: {v}" for k, v in out.items()))
    return 0 if out["diverged"] is None else 1


if __name__ == "__main__":
    raise SystemExit(main())
