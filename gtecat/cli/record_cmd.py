"""``gtecat record -o FILE -- COMMAND ...``: run a program and record its whole GT session.

Every GT call (name, arguments, values written back, return code, controller time), every
fault injected from the program or ``gtecat fault``, and the bus state every 100 ms of
controller time go into FILE (JSON lines; gzip when FILE ends in ``.gz``).  A Python script
(``python3 my_machine.py`` or ``my_machine.py``) runs in this process; any other command
runs as a child with ``GTECAT_RECORD=FILE`` in its environment: a Python program that
imports gtecat records itself, and the controller that libgts starts for a C, C++ or C#
program records that program's calls.  ``gtecat replay FILE`` re-runs the session.

A script that raises is reported as ``python3`` would (its traceback, exit code 1) and its
recording is written up to that point: it replays.  So is a program ended by SIGTERM or
SIGHUP (a CI job's time-out, ``kill``): exit code 128 + the signal, as a shell reports it.
FILE is refused before anything runs when it cannot be written, with the reason.
"""

from __future__ import annotations

import argparse
import contextlib
import os
import runpy
import subprocess
import sys
import time
from pathlib import Path
from typing import TYPE_CHECKING, Any

from ..errors import ParameterError
from . import output

if TYPE_CHECKING:
    from ..faults.record import Recorder

EPILOG = """\
examples:
  gtecat record -o session.gtrec -- python3 first_script.py
  gtecat record -o session.gtrec.gz -- first_script.py
  gtecat record -o c.gtrec -- ./my_machine            a C program linked with libgts
  gtecat replay session.gtrec"""


def add_parser(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser(
        "record",
        help="run a program and record its GT calls, faults and bus state (to replay)",
        description=output.describe(__doc__),
        epilog=EPILOG,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    p.add_argument("-o", "--output", required=True, type=Path, help="the recording to write")
    p.add_argument(
        "program",
        nargs=argparse.REMAINDER,
        metavar="-- COMMAND",
        help="the program and its arguments",
    )
    p.set_defaults(func=run)


def _script(command: list[str]) -> tuple[Path, list[str]] | None:
    """The Python script a command runs (to run it here), else None."""
    if command and command[0].endswith(".py"):
        return Path(command[0]), command[1:]
    if (
        len(command) >= 2
        and Path(command[0]).name.startswith("python")
        and command[1].endswith(".py")
    ):
        return Path(command[1]), command[2:]
    return None


def run(args: argparse.Namespace) -> int:
    command = list(args.program)
    if command and command[0] == "--":
        command = command[1:]
    if not command:
        raise ParameterError("no command to record: gtecat record -o FILE -- python3 SCRIPT.py")
    out: Path = args.output
    check_output(out)
    script = _script(command)
    if script is None:
        env = dict(os.environ, GTECAT_RECORD=str(out.resolve()))
        env["GTECAT_RECORD_PROGRAM"] = " ".join(command)
        rc = _run_child(command, env)
        from ..faults.record import read

        calls = 0
        if out.exists():
            try:
                calls = int(read(out)[0].get("calls", 0))
            except ParameterError:
                calls = 0
        if not calls:
            print(
                "record: nothing recorded: the program made no GT call through gtecat (a "
                "program attached to a controller that was already running is recorded by "
                "starting that controller under gtecat record)",
                file=sys.stderr,
            )
        else:
            print(f"record: {calls} GT calls -> {out}", file=sys.stderr)
        return rc
    path, script_args = script
    if not path.is_file():
        raise ParameterError(f"{path}: no such script")
    from .. import gt
    from ..faults.record import Recorder, end_on_signals
    from .run_cmd import script_traceback

    # (every thread's calls: a program's HMI thread beside its motion thread is its session)
    rec = Recorder(out, {"program": " ".join(command)}, any_thread=True).start()
    saved_argv, saved_path = sys.argv, list(sys.path)
    saved_signals = _signals()
    end_on_signals()  # a time-out's SIGTERM ends the script as SystemExit: the file is written
    sys.argv = [str(path), *script_args]
    sys.path.insert(0, str(path.resolve().parent))
    rc = 0
    try:
        runpy.run_path(str(path), run_name="__main__")
    except SystemExit as e:
        rc = e.code if isinstance(e.code, int) else (0 if e.code is None else 1)
        if isinstance(e.code, str):
            print(e.code, file=sys.stderr)
    except Exception as e:  # the script's own bug: its traceback, its exit code (as python's)
        sys.stderr.write(script_traceback(e, path))
        print(f"error: {path} raised {type(e).__name__}: {e}", file=sys.stderr)
        rc = 1
    finally:  # the session up to where the script ended (or was interrupted) is kept
        # the recorder stops first: closing what the script left open is gtecat's own
        # clean-up, not a call of the program (a recording lists the program's calls only)
        rec.stop()
        try:
            gt.GT_Close()
        finally:
            sys.argv, sys.path[:] = saved_argv, saved_path
            _write(rec, out)
            _restore(saved_signals)
    print(f"record: {rec.calls} GT calls -> {out}", file=sys.stderr)
    return rc


def _run_child(command: list[str], env: dict[str, str]) -> int:
    """Run the command and wait for it; SIGTERM and SIGHUP sent to ``gtecat record`` (a
    time-out, ``kill``) are passed on to it and every process it started (a shell that
    runs the program without ``exec`` dies of the signal and would leave the program
    running, unrecorded), so the program ends the way it ends when sent them itself (a
    Python program writes its recording, see ``end_on_signals``); the recorder then waits,
    up to :data:`DESCENDANTS_WAIT_S`, for those it signalled to end.  The code of a
    command ended by a signal is 128 + the signal, as a shell reports it."""
    import signal

    from ..faults.record import ENDING_SIGNALS

    try:
        child = subprocess.Popen(command, env=env)
    except OSError as e:
        raise ParameterError(f"cannot run {command[0]}: {e.strerror or e}") from None
    signalled: set[int] = set()

    def pass_on(num: int, _frame: object) -> None:
        for pid in (child.pid, *_descendants(child.pid)):
            with contextlib.suppress(OSError):
                os.kill(pid, num)
                signalled.add(pid)

    saved = _signals()
    for name in ENDING_SIGNALS:
        signal.signal(getattr(signal, name), pass_on)
    try:
        while True:
            try:
                rc = child.wait()
                break
            except KeyboardInterrupt:  # Ctrl-C reaches the child too (same process group)
                continue
        deadline = time.monotonic() + DESCENDANTS_WAIT_S
        while any(_running(p) for p in signalled - {child.pid}):
            if time.monotonic() > deadline:
                break
            time.sleep(0.02)
    finally:
        _restore(saved)
    return 128 - rc if rc < 0 else rc


#: how long the recorder waits for the processes of the program it passed a signal on to
#: (a Python program writing its recording) after the command itself ended (s)
DESCENDANTS_WAIT_S = 60.0


def _running(pid: int) -> bool:
    """Process ``pid`` still runs (Linux ``/proc``): one that ended but that its parent has not
    reaped yet (a zombie, state Z) has nothing left to write."""
    try:
        with open(f"/proc/{pid}/stat") as f:
            stat = f.read()
    except OSError:
        return False
    # (the state follows the command's name, which is in parentheses and may hold any byte)
    at = stat.rfind(")") + 2
    return stat[at : at + 1] not in ("Z", "X", "")


def _descendants(pid: int) -> list[int]:
    """The processes ``pid`` started, and theirs (Linux ``/proc``; none where it is not)."""
    out: list[int] = []
    todo = [pid]
    while todo:
        p = todo.pop()
        try:
            tasks = os.listdir(f"/proc/{p}/task")
        except OSError:
            continue
        for t in tasks:
            try:
                with open(f"/proc/{p}/task/{t}/children") as f:
                    kids = [int(k) for k in f.read().split()]
            except (OSError, ValueError):
                continue
            out.extend(kids)
            todo.extend(kids)
    return out


def _signals() -> dict[int, Any]:
    import signal

    from ..faults.record import ENDING_SIGNALS

    nums = [getattr(signal, n) for n in ENDING_SIGNALS if hasattr(signal, n)]
    return {n: signal.getsignal(n) for n in nums}


def _restore(saved: dict[int, Any]) -> None:
    import signal

    for num, handler in saved.items():
        if handler is not None:
            signal.signal(num, handler)


def _write(rec: Recorder, out: Path) -> None:
    try:
        rec.write()
    except OSError as e:
        raise ParameterError(f"-o {out}: cannot write the recording: {e.strerror or e}") from None


def check_output(out: Path) -> None:
    """Refuse, before the program runs, a recording file that cannot be written (and say why)."""
    if out.is_dir():
        raise ParameterError(f"-o {out} is a folder; name the recording file")
    folder = out.parent
    if not folder.is_dir():
        raise ParameterError(
            f"-o {out}: the folder {folder} "
            + ("is not a folder" if folder.exists() else "does not exist")
        )
    existed = out.exists()
    try:
        with open(out, "ab"):
            pass
    except OSError as e:
        why = e.strerror or str(e)
        if isinstance(e, FileNotFoundError):  # the folder is there but takes no new file
            why = f"the folder {folder} does not take new files ({why})"
        elif isinstance(e, PermissionError):
            why = f"permission denied ({'the file is' if existed else f'the folder {folder} is'} "
            why += "not writable)"
        raise ParameterError(f"-o {out}: the recording cannot be written: {why}") from None
    if not existed:
        out.unlink(missing_ok=True)  # written when the program ends
