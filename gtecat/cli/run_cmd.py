"""``gtecat run SCRIPT.py``: run a user's GT script with chosen emulator settings.

The options become the ``GTECAT_*`` environment the script's ``GT_Open`` reads, so the
script itself needs no change (the environment is restored afterwards).  ``--trace``
records signals every cycle once the bus is up (see :mod:`gtecat.controller.recorder` for the
names) and writes ``<stem>.csv`` and ``<stem>.png``.  On a terminal a status line shows
controller time against wall time while the script runs.

Precedence: an option given on the command line wins over the same argument of the script's
own ``GT_Open(eni=..., ...)`` (a note on stderr says so, once per option); the script's
arguments win over the ``GTECAT_*`` environment, which wins over the defaults.

The script's own exit code is the command's; an exception in the script prints its
traceback (the script's frames only) and exits 1.  With ``--check``, a script that ends
well (0) but drew findings exits :data:`CHECK_FINDINGS` (3), so CI can gate on it; a
script that fails keeps its own code (its failure says more than the findings).
"""

from __future__ import annotations

import argparse
import os
import runpy
import sys
import time
import traceback
from collections.abc import Callable
from pathlib import Path
from typing import TYPE_CHECKING, TextIO

from gtecat.eni.errors import GtecatError

from ..errors import ParameterError

if TYPE_CHECKING:  # loaded by run(), not by every other verb's start
    from ..controller.core import Controller

ENV = ("GTECAT_ENI", "GTECAT_MACHINE", "GTECAT_CLOCK", "GTECAT_BACKEND", "GTECAT_IFACE")


def _add_options(p: argparse.ArgumentParser) -> None:
    p.add_argument("--eni", help="configuration file (GTECAT_ENI)")
    p.add_argument("--machine", help="machine description TOML (GTECAT_MACHINE)")
    p.add_argument("--clock", choices=("auto", "lockstep", "realtime"), help="GTECAT_CLOCK")
    p.add_argument("--backend", choices=("emulated", "pysoem"), help="GTECAT_BACKEND")
    p.add_argument("--iface", help="network interface for pysoem (GTECAT_IFACE)")
    p.add_argument(
        "--trace",
        help="comma-separated signals recorded every cycle, e.g. "
        "axis1.prf,axis1.enc,axis1.err,0:0x6041:0 (see `gtecat map` for SLAVE:INDEX:SUB)",
    )
    p.add_argument("--trace-out", default=None, help="output stem (default: the script's name)")
    p.add_argument("--no-progress", action="store_true", help="no status line on stderr")
    p.add_argument(
        "--check",
        action="store_true",
        help="warn (check: FILE:LINE: ...) where a real drive or controller would punish the "
        "script: skipped CiA-402 states, enable in fault, CSP steps past the following-error "
        "window, mode changes in motion, SDO writes to mapped objects in OP, endless "
        "GT_IsEcatReady polls, moves on an axis in alarm; exit 3 when it finds any (the "
        "script's own non-zero code wins)",
    )


#: the exit code of ``gtecat run --check`` when the script ended well but drew findings
CHECK_FINDINGS = 3


EPILOG = """\
Options given here win over the script's own GT_Open(eni=..., machine=..., clock=...,
backend=..., iface=...) arguments; a note on stderr names each one replaced.

examples:
  gtecat run first_script.py --eni manual_fig5_2.eni
  gtecat run --check first_script.py --eni manual_fig5_2.eni    warnings with file and line

exit codes: the script's own (0 when it ends well, 1 on an exception); with --check, 3 when
the script ended with 0 but a check found something.
  gtecat run home.py --machine machine.toml --trace axis1.enc,axis1.sw,0:0x60FD:0
  gtecat run my_machine.py --clock realtime --backend pysoem --iface eth0

signals for --trace: axisN.prf (planned, pulse), .enc (6064h, counts), .err (planned - actual),
.vel (planned velocity, pulse/ms), .encvel (encoder velocity, counts/ms), .sw (6041h bits),
.cw (6040h bits), .mode (6061h), .state (the CiA-402 state), .machine (true position);
SLAVE:INDEX:SUB for any mapped PDO entry (`gtecat map FILE.eni` lists them)."""


def add_parser(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser(
        "run",
        help="run a GT script under the emulator",
        description="Run SCRIPT.py (which uses `from gtecat import gt`) with the given "
        "emulator settings.  Options may come before or after the script; the script's "
        "own arguments follow it (after `--` when they look like options).",
        epilog=EPILOG,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    _add_options(p)
    p.add_argument("script", help="Python script using `from gtecat import gt`")
    p.add_argument("args", nargs=argparse.REMAINDER, help="arguments for the script")
    p.set_defaults(func=run)


def split_arguments(args: argparse.Namespace) -> list[str]:
    """Take ``run`` options written after the script out of ``args.args``.

    ``gtecat run s.py --trace x -- -v`` and ``gtecat run --trace x s.py -v`` both give
    the script ``["-v"]``; ``gtecat run s.py a b`` gives it ``["a", "b"]``.
    """
    rest = list(args.args)
    if rest and rest[0] == "--":
        return rest[1:]
    raw = getattr(args, "raw_argv", None)
    n = len(rest)
    if (
        rest
        and type(raw) is list
        and len(raw) >= n + 2
        and raw[-n - 2 :][:2] == [args.script, "--"]
    ):
        return rest  # ``gtecat run s.py -- --seconds 1``: argparse took the `--` away
    if not rest or not rest[0].startswith("--"):
        return rest
    cut = rest.index("--") if "--" in rest else len(rest)
    opts = argparse.ArgumentParser(prog="gtecat run SCRIPT", add_help=False)
    _add_options(opts)
    extra, unknown = opts.parse_known_args(rest[:cut])
    if unknown:
        raise ParameterError(
            f"run: {' '.join(unknown)} after the script is not a run option; give the "
            "script's own arguments after `--` (gtecat run SCRIPT [options] -- ARGS)"
        )
    for k, v in vars(extra).items():
        if v not in (None, False):
            setattr(args, k, v)
    return rest[cut + 1 :]


class Progress:
    """One status line (a terminal only): controller time, wall time and their ratio.

    The total length of a script's run is unknown, so this is a live counter rather
    than a bar: it answers "is it still going, and how fast?".  The line is erased
    before anything the script prints (:meth:`guard`) and when the run ends, so the
    script's own output reads as without it.
    """

    SPIN = "|/-\\"
    ERASE = "\r\033[K"

    def __init__(
        self,
        enabled: bool,
        stream: TextIO | None = None,
        wall: Callable[[], float] = time.perf_counter,
        every_s: float = 0.25,
    ) -> None:
        self.stream = stream if stream is not None else sys.stderr
        self.enabled = enabled and self.stream.isatty()
        self.wall = wall
        self.every_s = every_s
        self.t0 = wall()
        self.last = self.t0
        self.shown = 0
        self.visible = False

    def __call__(self, ctl: Controller) -> None:
        if not self.enabled:
            return
        now = self.wall()
        if now - self.last < self.every_s:
            return
        self.last = now
        virt = ctl.clock.now_ns / 1e9
        wall = now - self.t0
        ratio = f"{virt / wall:7.1f}x real time" if wall > 0 else ""
        self.shown += 1
        self.stream.write(
            f"{self.ERASE}  {self.SPIN[self.shown % 4]} {virt:9.2f} s controller time, "
            f"{ctl.clock.cycles:>9} cycles, {wall:6.1f} s wall {ratio}"
        )
        self.stream.flush()
        self.visible = True

    def clear(self) -> None:
        if self.visible:
            self.stream.write(self.ERASE)
            self.stream.flush()
            self.visible = False

    def done(self) -> None:
        self.clear()

    def guard(self, out: TextIO) -> TextIO:
        """``out`` wrapped so that each write first erases the status line."""
        return _Erasing(out, self) if self.enabled else out


class _Erasing:
    """A text stream that erases the progress line before writing (see Progress.guard)."""

    def __init__(self, inner: TextIO, progress: Progress) -> None:
        self._inner = inner
        self._progress = progress

    def write(self, text: str) -> int:
        if text:
            self._progress.clear()
        return self._inner.write(text)

    def __getattr__(self, name: str):
        return getattr(self._inner, name)


class _TraceFailed(BaseException):
    """A ``--trace`` signal that does not exist on this bus: stops the script.

    A BaseException, so the GT layer (which turns every Exception into a return
    code) lets it through to :func:`run`.
    """


def script_traceback(e: BaseException, script: Path) -> str:
    """The traceback from the script's first frame on (runpy and gtecat.cli frames dropped)."""
    tb = traceback.TracebackException.from_exception(e)
    frames = tb.stack
    first = next(
        (i for i, f in enumerate(frames) if Path(f.filename).resolve() == script.resolve()), 0
    )
    tb.stack = traceback.StackSummary.from_list(frames[first:])
    return "".join(tb.format())


def check_script(script: Path) -> None:
    """Refuse what is not a Python script before anything runs (one line, no traceback)."""
    if not script.is_file():
        raise ParameterError(
            f"script {script} not found"
            + (" (that is a folder)" if script.is_dir() else f" (working directory {Path.cwd()})")
        )
    source = script.read_bytes()
    if b"\0" in source:
        raise ParameterError(
            f"{script} is not a Python script (it holds NUL bytes: a binary file?); "
            "gtecat run takes a .py file that uses `from gtecat import gt`"
        )
    try:
        compile(source, str(script), "exec", dont_inherit=True)
    except SyntaxError as e:
        where = f" at line {e.lineno}" if e.lineno else ""
        raise ParameterError(
            f"{script} is not valid Python: {e.msg}{where} (`python3 {script}` shows where)"
        ) from None
    except ValueError as e:  # an encoding the source cannot be read in
        raise ParameterError(f"{script} cannot be read as Python source: {e}") from None


def check_trace_out(stem: Path) -> None:
    """The folder the traces go to must exist before the script runs, not after."""
    folder = stem.parent
    if not folder.is_dir():
        raise ParameterError(
            f"--trace-out {stem}: the folder {folder} does not exist; create it or choose another"
        )
    if not os.access(folder, os.W_OK):
        raise ParameterError(f"--trace-out {stem}: the folder {folder} is not writable")


#: GT_Open keyword -> environment variable; the command line's value wins over the script's
OPEN_OPTIONS = {
    "eni": "GTECAT_ENI",
    "machine": "GTECAT_MACHINE",
    "clock": "GTECAT_CLOCK",
    "backend": "GTECAT_BACKEND",
    "iface": "GTECAT_IFACE",
}


def _same(key: str, a: object, b: str) -> bool:
    if key in ("eni", "machine") and isinstance(a, str | os.PathLike):
        return Path(a).resolve() == Path(b).resolve()
    return str(a) == b


def overriding_open(
    real: Callable[..., int], forced: dict[str, str], noted: set[str], *, core_first: bool
) -> Callable[..., int]:
    """``GT_Open`` (or ``GTN_Open``) whose ``forced`` keywords are the command line's."""

    def gt_open(*a: object, **kw: object) -> int:
        for key, value in forced.items():
            given = kw.get(key)
            if given is not None and not _same(key, given, value) and key not in noted:
                noted.add(key)
                print(
                    f"gtecat run: --{key} {value} replaces the script's GT_Open({key}={given!r})",
                    file=sys.stderr,
                )
            kw[key] = value
        return real(*a, **kw)

    gt_open.__name__ = "GTN_Open" if core_first else "GT_Open"
    gt_open.__doc__ = real.__doc__
    return gt_open


def run(args: argparse.Namespace) -> int:
    script_args = split_arguments(args)
    script = Path(args.script)
    check_script(script)
    options = {
        "GTECAT_ENI": args.eni,
        "GTECAT_MACHINE": args.machine,
        "GTECAT_CLOCK": args.clock,
        "GTECAT_BACKEND": args.backend,
        "GTECAT_IFACE": args.iface,
    }
    for k in ("GTECAT_ENI", "GTECAT_MACHINE"):
        v = options[k]
        what = "ENI" if k == "GTECAT_ENI" else "machine description"
        if v and Path(v).is_dir():
            raise ParameterError(f"{what} {v} is a folder, not a file (--{k[7:].lower()})")
        if v and not Path(v).is_file():
            raise ParameterError(f"{what} {v} not found (--{k[7:].lower()})")
    from .busview import check_toml_kind

    check_toml_kind(options["GTECAT_MACHINE"], "machine")
    specs = [s.strip() for s in (args.trace or "").split(",") if s.strip()]
    stem = Path(args.trace_out) if args.trace_out else script.with_suffix("")
    if specs:
        check_trace_out(stem)
    forced = {
        key: str(Path(v).resolve()) if key in ("eni", "machine") else v
        for key, env in OPEN_OPTIONS.items()
        if (v := options[env])
    }
    saved_env = {k: os.environ.get(k) for k in ENV}
    saved_argv = sys.argv
    for k, v in options.items():
        if v:
            os.environ[k] = str(Path(v).resolve()) if k in ("GTECAT_ENI", "GTECAT_MACHINE") else v
    recorders = []
    progress = Progress(not args.no_progress)

    def attach(ctl: Controller) -> None:
        if specs:
            from ..controller.recorder import Recorder

            try:
                recorders.append(Recorder(ctl, specs).start())
            except GtecatError as e:
                raise _TraceFailed(str(e)) from None
        if progress.enabled:
            # looked at after each cycle or run of cycles (Controller.watch), not a per-cycle
            # sample: the axis bank keeps running many cycles at once under it
            ctl.watch.append(lambda: progress(ctl))

    from .. import gt as gt_module
    from ..controller.core import Controller

    real_open, real_gtn_open = gt_module.GT_Open, gt_module.GTN_Open
    noted: set[str] = set()
    gt_module.GT_Open = overriding_open(real_open, forced, noted, core_first=False)
    gt_module.GTN_Open = overriding_open(real_gtn_open, forced, noted, core_first=True)
    Controller.bus_up_hooks.append(attach)
    checker = None
    if getattr(args, "check", False):
        from ..faults.checks import Checker

        checker = Checker(sys.stderr).start()
    saved_streams = sys.stdout, sys.stderr
    sys.stdout, sys.stderr = progress.guard(sys.stdout), progress.guard(sys.stderr)
    sys.argv = [str(script), *script_args]
    saved_path = list(sys.path)
    sys.path.insert(0, str(script.resolve().parent))  # as `python SCRIPT` does: its imports
    rc = 0
    try:
        runpy.run_path(str(script), run_name="__main__")
    except SystemExit as e:
        rc = e.code if isinstance(e.code, int) else (0 if e.code is None else 1)
        if isinstance(e.code, str):
            print(e.code, file=sys.stderr)
    except _TraceFailed as e:
        raise ParameterError(
            f"--trace: {e}; the script was stopped at GT_InitEcatComm "
            "(`gtecat map ENI` lists what each slave maps)"
        ) from None
    except Exception as e:  # the user's own bug: show where, in their script
        progress.done()
        sys.stderr.write(script_traceback(e, script))
        print(f"error: {script} raised {type(e).__name__}: {e}", file=sys.stderr)
        rc = 1
    finally:
        if checker is not None:
            checker.stop()
        Controller.bus_up_hooks.remove(attach)
        gt_module.GT_Open, gt_module.GTN_Open = real_open, real_gtn_open
        progress.done()
        sys.stdout, sys.stderr = saved_streams
        sys.argv = saved_argv
        sys.path[:] = saved_path
        for k, v in saved_env.items():
            if v is None:
                os.environ.pop(k, None)
            else:
                os.environ[k] = v
        from ..gt._core import close_all

        close_all()  # a script that forgot it (every card): stop realtime threads, flush logs
    if specs and not any(rec.n for rec in recorders):
        print(
            "trace: nothing recorded (the script never brought the bus up with GT_InitEcatComm)",
            file=sys.stderr,
        )
    for i, rec in enumerate(recorders):
        base = stem if i == 0 else stem.with_name(f"{stem.name}_{i}")
        if rec.n == 0:
            continue
        try:
            csv_path = rec.to_csv(base.with_suffix(".csv"))
            png_path = rec.plot(base.with_suffix(".png"), title=f"{script.name}")
        except OSError as e:
            raise ParameterError(
                f"--trace-out {stem}: cannot write the trace: {e.strerror or e}"
            ) from None
        print(f"trace: {rec.n} cycles -> {csv_path}, {png_path}")
    if checker is not None and checker.findings:
        n = len(checker.findings)
        print(f"check: {n} finding{'s' if n != 1 else ''}", file=sys.stderr)
        if rc == 0:
            return CHECK_FINDINGS
    return rc
