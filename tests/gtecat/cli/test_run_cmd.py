"""``gtecat run SCRIPT.py`` (issue 8 deliver 2): settings, --trace CSV/PNG, progress, exits."""

from __future__ import annotations

import csv
import functools
import io
import os
import textwrap
from pathlib import Path
from types import SimpleNamespace

import pytest

from gtecat.cli import run_cmd
from tests.conftest import EXAMPLES

from .conftest import Cli

FIG52 = str(EXAMPLES / "manual_fig5_2.eni")
ERASE = run_cmd.Progress.ERASE

SCRIPT = textwrap.dedent(
    """
    import os, sys
    from ctypes import byref, c_short, c_ubyte
    from gtecat import gt

    print("argv", sys.argv[1:])
    print("clock", os.environ.get("GTECAT_CLOCK"))
    assert gt.GT_Open(log="") == 0
    assert gt.GT_InitEcatComm() == 0, gt.GTE_GetLastError()
    st = c_short()
    while gt.GT_IsEcatReady(byref(st)) == 0 and st.value != 1:
        gt.GTE_Wait(1)
    gt.GT_StartEcatComm()
    for v in range(1, 11):                      # IO slave 2's first output byte, 1..10
        gt.GT_SetEcatRawData(32, 1, (c_ubyte * 1)(v))
        gt.GTE_Wait(10)
    print("axis on", gt.GT_AxisOn(1))
    gt.GTE_Wait(WAIT_MS)
    gt.GT_Close()
    sys.exit(EXIT)
    """
)


def _script(tmp_path: Path, wait_ms: int = 20, exit_code: int = 0) -> Path:
    path = tmp_path / "machine_test.py"
    path.write_text(SCRIPT.replace("WAIT_MS", str(wait_ms)).replace("EXIT", str(exit_code)))
    return path


@pytest.mark.long
def test_trace_writes_csv_and_png_with_one_row_per_cycle(
    cli: Cli, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.chdir(tmp_path)
    script = _script(tmp_path)
    rc, out, err = cli(
        "run", str(script), "--eni", FIG52, "--clock", "lockstep",
        "--trace", "2:0x7000:1,axis1.sw,axis1.enc",
    )  # fmt: skip
    assert rc == 0, err
    assert "clock lockstep" in out
    csv_path, png_path = tmp_path / "machine_test.csv", tmp_path / "machine_test.png"
    assert f"-> {csv_path}, {png_path}" in out
    with csv_path.open(newline="") as fh:
        rows = list(csv.reader(fh))
    assert rows[0] == ["time_ms", "2:0x7000:1", "axis1.sw", "axis1.enc"]
    n = int(out.split("trace: ")[1].split()[0])
    assert n == len(rows) - 1 >= 100 + 20
    written = [int(float(r[1])) for r in rows[1:]]
    assert sorted(set(written)) == list(range(11))  # 0 before the first write, then 1..10
    assert written == sorted(written)  # one value per 10 ms, in order
    sw = [int(float(r[2])) for r in rows[1:]]
    assert sw[-1] & 0x6F == 0x27  # GT_AxisOn: operation enabled at the end
    assert png_path.read_bytes()[:4] == b"\x89PNG"


def test_options_after_the_script_and_script_arguments(
    cli: Cli, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.chdir(tmp_path)
    script = _script(tmp_path)
    rc, out, _ = cli("run", str(script), "--eni", FIG52, "--no-progress", "--", "-v", "x")
    assert rc == 0 and "argv ['-v', 'x']" in out
    rc, out, _ = cli("run", "--eni", FIG52, str(script), "a", "b")
    assert rc == 0 and "argv ['a', 'b']" in out
    # the form the help gives, with `--` right after the script and options of the script's
    rc, out, _ = cli("run", "--eni", FIG52, "--no-progress", str(script), "--", "--seconds", "1")
    assert rc == 0 and "argv ['--seconds', '1']" in out
    rc, out, err = cli("run", str(script), "--eni", FIG52, "stray")
    assert rc == 1 and "stray after the script is not a run option" in err
    assert "--" in err  # says how to pass it


def test_environment_is_restored_after_the_run(
    cli: Cli, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.chdir(tmp_path)
    monkeypatch.setenv("GTECAT_CLOCK", "auto")
    rc, out, _ = cli("run", str(_script(tmp_path)), "--eni", FIG52, "--clock", "lockstep")
    assert rc == 0 and "clock lockstep" in out
    assert os.environ["GTECAT_CLOCK"] == "auto"
    assert "GTECAT_ENI" not in os.environ


def test_script_exit_code_is_the_commands(
    cli: Cli, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.chdir(tmp_path)
    rc, _, _ = cli("run", str(_script(tmp_path, exit_code=3)), "--eni", FIG52)
    assert rc == 3


def test_an_exception_in_the_script_shows_the_scripts_traceback_only(
    cli: Cli, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.chdir(tmp_path)
    bad = tmp_path / "bad.py"
    bad.write_text("def f():\n    return 1 / 0\n\nf()\n")
    rc, out, err = cli("run", str(bad))
    assert rc == 1 and out == ""
    assert 'bad.py", line 4' in err and "return 1 / 0" in err
    assert "runpy" not in err and "run_cmd" not in err
    assert (
        err.rstrip().splitlines()[-1] == f"error: {bad} raised ZeroDivisionError: division by zero"
    )


def test_an_unknown_trace_signal_stops_with_one_line(
    cli: Cli, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.chdir(tmp_path)
    rc, out, err = cli("run", str(_script(tmp_path)), "--eni", FIG52, "--trace", "0:0x6061:0")
    assert rc == 1
    assert err.count("\n") == 1
    assert "--trace: slave 0 maps no 0x6061:00" in err
    assert "gtecat map" in err  # what to do next
    assert "axis on" not in out  # the script stopped at GT_InitEcatComm


def test_a_trace_with_no_bus_says_nothing_was_recorded(
    cli: Cli, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.chdir(tmp_path)
    quiet = tmp_path / "quiet.py"
    quiet.write_text("print('no bus')\n")
    rc, out, err = cli("run", str(quiet), "--trace", "axis1.sw")
    assert rc == 0 and out == "no bus\n"
    assert "nothing recorded" in err
    assert not (tmp_path / "quiet.csv").exists()


def test_missing_script_and_missing_eni_are_one_line_errors(
    cli: Cli, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.chdir(tmp_path)
    rc, _, err = cli("run", "nope.py")
    assert rc == 1 and err.startswith("error: script nope.py not found") and err.count("\n") == 1
    rc, _, err = cli("run", str(_script(tmp_path)), "--eni", "missing.eni")
    assert rc == 1 and err == "error: ENI missing.eni not found (--eni)\n"


# --- the progress line ----------------------------------------------------------------------
class _Tty(io.StringIO):
    def isatty(self) -> bool:
        return True


def _fake_wall(step: float):
    t = [0.0]

    def wall() -> float:
        t[0] += step
        return t[0]

    return wall


def test_progress_line_shows_controller_and_wall_time() -> None:
    tty = _Tty()
    p = run_cmd.Progress(True, stream=tty, wall=_fake_wall(0.5))
    ctl = SimpleNamespace(clock=SimpleNamespace(now_ns=3_000_000_000, cycles=3000))
    p(ctl)
    p(ctl)
    p.done()
    lines = tty.getvalue().split(ERASE)
    assert lines[0] == "" and lines[-1] == ""  # each line erases the last; done() erases it too
    assert len(lines) == 4
    assert "3.00 s controller time" in lines[1] and "3000 cycles" in lines[1]
    assert "0.5 s wall" in lines[1] and "6.0x real time" in lines[1]


def test_the_scripts_output_erases_the_status_line_first() -> None:
    tty, out = _Tty(), io.StringIO()
    p = run_cmd.Progress(True, stream=tty, wall=_fake_wall(1))
    guarded = p.guard(out)
    p(SimpleNamespace(clock=SimpleNamespace(now_ns=0, cycles=0)))
    assert p.visible
    print("hello", file=guarded)
    assert out.getvalue() == "hello\n"
    assert tty.getvalue().endswith(ERASE) and not p.visible
    print("again", file=guarded)  # nothing shown: nothing to erase
    assert tty.getvalue().count(ERASE) == 2


def test_progress_is_silent_when_not_a_terminal_or_disabled() -> None:
    ctl = SimpleNamespace(clock=SimpleNamespace(now_ns=1, cycles=1))
    for p in (
        run_cmd.Progress(True, stream=io.StringIO(), wall=_fake_wall(1)),
        run_cmd.Progress(False, stream=_Tty(), wall=_fake_wall(1)),
    ):
        p(ctl)
        p.done()
        assert p.stream.getvalue() == ""


def test_progress_line_during_a_long_run(
    cli: Cli, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.chdir(tmp_path)
    tty = _Tty()
    monkeypatch.setattr(
        # (a wall clock a quarter second on per look: the axis bank runs up to 1000 cycles
        # between two looks, as many as make a quarter second of wall time on a slow machine)
        run_cmd,
        "Progress",
        functools.partial(run_cmd.Progress, stream=tty, wall=_fake_wall(0.25)),
    )
    rc, _, _ = cli("run", str(_script(tmp_path, wait_ms=2000)), "--eni", FIG52)
    assert rc == 0
    lines = [x for x in tty.getvalue().split(ERASE) if x]
    assert len(lines) > 10 and tty.getvalue().endswith(ERASE)
    # controller time only grows from one status line to the next
    shown = [float(x.split(" s controller")[0].split()[-1]) for x in lines]
    assert shown == sorted(shown) and shown[-1] >= 2.0


# --- precedence: the command line over the script's GT_Open over GTECAT_* ------------------------
PRECEDENCE = textwrap.dedent(
    """
    from ctypes import byref, c_short
    from gtecat import gt

    gt.GT_Open(eni=ENI, clock="auto", log="")
    gt.GT_InitEcatComm()
    n = c_short()
    gt.GT_GetEcatSlaves(byref(n))
    print("slaves", n.value, "clock", gt.GTE_Controller().clock.mode)
    gt.GT_Close()
    """
)


def _precedence(tmp_path: Path) -> Path:
    path = tmp_path / "own_open.py"
    path.write_text(PRECEDENCE.replace("ENI", repr(FIG52)))
    return path


def test_command_line_options_win_over_the_scripts_gt_open_with_a_note(
    cli: Cli, tmp_path: Path
) -> None:
    script = _precedence(tmp_path)
    one = str(EXAMPLES / "manual_fig5_4.eni")
    rc, out, err = cli("run", str(script), "--eni", one, "--clock", "lockstep")
    assert rc == 0 and out == "slaves 1 clock lockstep\n"
    assert err.splitlines() == [
        f"gtecat run: --eni {Path(one).resolve()} replaces the script's GT_Open(eni={FIG52!r})",
        "gtecat run: --clock lockstep replaces the script's GT_Open(clock='auto')",
    ]


def test_without_options_the_script_wins_over_the_environment_silently(
    cli: Cli, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setenv("GTECAT_ENI", str(EXAMPLES / "manual_fig5_4.eni"))
    rc, out, err = cli("run", str(_precedence(tmp_path)))
    assert (rc, out, err) == (0, "slaves 4 clock auto\n", "")


def test_the_same_value_as_the_script_needs_no_note(cli: Cli, tmp_path: Path) -> None:
    rc, out, err = cli("run", str(_precedence(tmp_path)), "--eni", FIG52)
    assert (rc, out, err) == (0, "slaves 4 clock auto\n", "")


def test_gt_open_is_restored_after_the_run(cli: Cli, tmp_path: Path) -> None:
    from gtecat import gt

    before = gt.GT_Open
    cli("run", str(_precedence(tmp_path)), "--eni", FIG52)
    assert gt.GT_Open is before


@pytest.mark.long
def test_axis_mode_and_state_come_from_the_drive_when_not_mapped(
    cli: Cli, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Figure 5-2 maps no 6061h: the emulated drive's own value is recorded."""
    monkeypatch.chdir(tmp_path)
    spec = "axis1.mode,axis1.state,axis1.vel,axis1.encvel,axis1.sw"
    rc, _, err = cli("run", str(_script(tmp_path)), "--eni", FIG52, "--trace", spec)
    assert rc == 0, err
    rows = list(csv.DictReader((tmp_path / "machine_test.csv").open()))
    assert rows[-1]["axis1.mode"] == "8"  # CSP once the drive is configured
    assert rows[-1]["axis1.state"] == "4"  # operation enabled (after GT_AxisOn)
    assert (tmp_path / "machine_test.png").stat().st_size > 10_000


def test_trace_plot_layout_bits_bands_and_value_groups() -> None:
    from types import SimpleNamespace

    import numpy as np

    from gtecat.controller import recorder as r
    from gtecat.controller.trace_plot import layout

    t = np.arange(6, dtype=float)
    sw = [0x0250, 0x0250, 0x0231, 0x0233, 0x0237, 0x1637]
    data = np.column_stack([t, t * 10, t * 9, sw, [8] * 6])
    rec = SimpleNamespace(
        data=data,
        names=["axis1.prf", "axis1.enc", "axis1.sw", "axis1.mode"],
        kinds=[
            r.Kind("value", "pulse"),
            r.Kind("value", "counts"),
            r.Kind("bits", bits=r.SW_BITS),
            r.Kind("mode"),
        ],
    )
    panels, bands, rows = layout(rec)
    assert [g for g, _ in panels] == ["position"]  # prf and enc share one panel
    assert [b[0] for b in bands] == ["axis1 CiA-402 state", "axis1.mode (6061h)"]
    assert list(bands[0][1]) == [1, 1, 2, 3, 4, 4]  # disabled, ready, switched on, enabled
    names = [row[0] for row in rows]
    assert "axis1.sw 2: operation enabled" in names and "axis1.sw 10: target reached" in names
    assert not any("fault" in n for n in names)  # a bit never set gets no row


HOOKS = textwrap.dedent(
    """
    from ctypes import byref, c_short
    from gtecat import gt

    gt.GT_Open(log="")
    gt.GT_InitEcatComm()
    st = c_short()
    while gt.GT_IsEcatReady(byref(st)) == 0 and st.value != 1:
        gt.GTE_Wait(1)
    ctl = gt.GTE_Controller()
    print("hooks", len(ctl.sample), len(ctl.watch))
    gt.GT_Close()
    """
)


def test_the_status_line_never_makes_the_cycles_run_one_by_one(
    cli: Cli, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    # a per-cycle sample stops the axis bank's runs of many cycles at once (several times the
    # CPU of `python SCRIPT`): the status line is no sample, and is not there when not shown
    script = tmp_path / "hooks.py"
    script.write_text(HOOKS)
    rc, out, _ = cli("run", "--no-progress", str(script), "--eni", FIG52)
    assert (rc, out.split("\n")[0]) == (0, "hooks 0 0")
    monkeypatch.setattr(
        run_cmd, "Progress", functools.partial(run_cmd.Progress, stream=_Tty(), wall=_fake_wall(1))
    )
    rc, out, _ = cli("run", str(script), "--eni", FIG52)
    assert (rc, out.split("\n")[0]) == (0, "hooks 0 1")
