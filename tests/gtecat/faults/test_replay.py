"""Replays of a 12-axis session: exact, at the first divergence exit 1, and the controller's
many-cycles-at-once path (and the bank's Trap tables taken up again) gives the same bits as
one cycle at a time.

The session is tools/bench_replay.py's (homing, jogs, Trap moves, status polling, IO); a few
virtual seconds here, the whole minute under GTECAT_LONG=1.
"""

from __future__ import annotations

import json
import subprocess
import sys
from ctypes import byref, c_short, c_ubyte
from pathlib import Path

import pytest

from gtecat import gt
from gtecat.cli.main import main
from gtecat.controller.core import Controller
from gtecat.faults.record import replay
from tests.conftest import EXAMPLES, LONG
from tests.gtecat.faults.conftest import record_one_by_one
from tools import bench_replay

SECONDS = 60.0 if LONG else 3.0


@pytest.fixture(scope="module")
def recorded(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """The session recorded with every cycle run one by one and every Trap table computed
    afresh when an axis comes back to the bank (the reference)."""
    folder = tmp_path_factory.mktemp("replay")
    machine = folder / "machine.toml"
    machine.write_text(bench_replay.MACHINE)
    return record_one_by_one(
        folder / "session.gtrec", lambda: bench_replay.session(gt, SECONDS, 10, str(machine))
    )


def _calls(path: Path) -> list[dict]:
    return [json.loads(x) for x in path.read_text().splitlines()[1:] if '"c":' in x]


@pytest.mark.long
def test_the_session_replays_exactly_many_cycles_at_once(
    recorded: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    calls = _calls(recorded)
    names = {e["c"] for e in calls}
    assert {"GT_StartEcatHoming", "GT_PrfJog", "GT_PrfTrap", "GT_EcatIOWriteOutput"} <= names
    assert sum(e["c"] == "GT_GetSts" for e in calls) >= 12 * 100 * SECONDS * 0.9
    batches = []
    run = Controller.run_cycles

    def counting(self: Controller, n: int) -> int:
        done = run(self, n)
        batches.append(done)
        return done

    monkeypatch.setattr(Controller, "run_cycles", counting)
    n, div = replay(recorded)
    assert div is None, str(div)
    assert n == len(calls)
    # most cycles ran in batches (the compiled kernel), not one by one
    assert sum(batches) > 0.8 * SECONDS * 1000


@pytest.mark.long
def test_a_tampered_recording_reports_its_first_divergence(
    recorded: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    lines = recorded.read_text().splitlines()
    number, first, second = 0, None, None
    for i, line in enumerate(lines[1:], 1):
        if '"c":' not in line:
            continue
        number += 1
        e = json.loads(line)
        # a status the call left as it was (no "o"): compared all the same
        if first is None and number > 400 and e["c"] == "GT_GetSts" and "o" not in e:
            e["a"][1]["ref"]["v"] ^= 0x400
            first = (number, e["a"][1]["ref"]["v"])
            lines[i] = json.dumps(e)
        elif first is not None and e["c"] == "GT_GetPrfPos":  # a later one: not reported
            e["r"] = 7
            lines[i] = json.dumps(e)
            second = number
            break
    assert first is not None and second is not None
    bad = tmp_path / "tampered.gtrec"
    bad.write_text("\n".join(lines) + "\n")
    assert main(["replay", str(bad)]) == 1
    err = capsys.readouterr().err
    n, value = first
    assert f"diverged at call {n} GT_GetSts: argument 2 recorded {value}, replay gives" in err
    assert f"call {second} " not in err
    assert main(["replay", str(recorded)]) == 0
    assert "calls match" in capsys.readouterr().out


def test_the_replay_process_ends_at_once_with_its_exit_handlers_run(
    recorded: Path, tmp_path: Path
) -> None:
    """``gtecat replay`` as a program ends right after its verb (no teardown of the session
    object by object) with the exit code, the output flushed and every exit handler run."""
    bad = tmp_path / "bad.gtrec"
    lines = recorded.read_text().splitlines()
    for i, line in enumerate(lines):
        if '"c":"GT_GetSts"' in line:
            e = json.loads(line)
            e["r"] = 7
            lines[i] = json.dumps(e)
            break
    bad.write_text("\n".join(lines) + "\n")
    program = (
        "import atexit, sys\n"
        "atexit.register(lambda: print('exit handler ran'))\n"
        "class Kept:\n"
        "    def __del__(self):\n"
        "        print('taken apart')\n"
        "kept = Kept()\n"
        "from gtecat.cli.main import main\n"
        "sys.argv = ['gtecat', 'replay', *sys.argv[1:]]\n"
        "sys.exit(main())\n"
    )
    # (a divergence at the first status read: the same way out as a match, at less cost)
    run = subprocess.run(
        [sys.executable, "-c", program, str(bad)],
        capture_output=True,
        text=True,
        timeout=120,
        check=False,
    )
    assert run.returncode == 1, run.stderr
    assert "diverged at call" in run.stderr
    assert run.stdout.rstrip().endswith("exit handler ran"), run.stdout
    assert "taken apart" not in run.stdout  # (the normal exit would)


def test_an_input_set_between_cycles_reaches_the_image() -> None:
    """The bus runs many cycles at once only while every IO slave is at its fixed point: an
    input the field changes (not through a GT call) is in the next cycle's image."""
    assert gt.GT_Open(eni=str(EXAMPLES / "twelve_axes.eni"), clock="lockstep", log="") == 0
    ctl = gt.GTE_Controller()
    gt.GT_InitEcatComm()
    st = c_short()
    for _ in range(200):
        ctl.clock.advance(1)
        if gt.GT_IsEcatReady(byref(st)) == 0 and st.value == 1:
            break
    gt.GT_StartEcatComm()
    for a in range(1, 13):
        gt.GT_AxisOn(a)
    ctl.clock.advance(50)
    done = ctl.run_cycles(5)
    assert done == 5, "every axis in the bank and the bus steady: the batch runs"
    dio = ctl.backend.slaves[6]
    dio.set_input_bit(3, True)
    assert not ctl.master.steady()
    ctl.clock.advance(2)
    buf = (c_ubyte * 2)()
    assert gt.GT_EcatIOReadInput(6, 2, 2, buf) == 0
    assert buf[0] & 0x08


@pytest.mark.parametrize(
    "body",
    [
        '{"t":1,"c":"GT_Open","a":[],"r":0}\n{"t":2,"c":"GT_Clo\n',  # cut short
        '{"t":1,"c":"GT_Open","a":[],"r":0}, {"t":2}\n',  # two entries on a line
        "5\n",  # not an entry
        '{"t":1,"c":"GT_Open","r":0}\n',  # no arguments
        '{"t":1,"c":"GT_GetSts","a":[1,{"ref":{"c":"c_long","v":"x"}}],"r":0}\n',
    ],
)
def test_a_damaged_recording_is_a_clear_error(
    body: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    bad = tmp_path / "damaged.gtrec"
    bad.write_text('{"gtecat_recording": 1}\n' + body)
    assert main(["replay", str(bad)]) == 1
    err = capsys.readouterr().err
    assert "damaged recording" in err and "Traceback" not in err


def test_every_line_of_a_shared_form_is_compared(recorded: Path, tmp_path: Path) -> None:
    """Polling calls that differ only in the numbers their pointers held share one prepared
    call: a value the call left (``"o"``) changed in one line of such a form is reported at
    that call, and the lines before it still replay."""
    lines = recorded.read_text().splitlines()
    number, seen, at = 0, 0, None
    for i, line in enumerate(lines[1:], 1):
        if '"c":' not in line:
            continue
        number += 1
        e = json.loads(line)
        if e["c"] == "GT_GetClock" and "o" in e:
            seen += 1
            if seen == 50:
                e["o"]["0"]["ref"]["v"] += 1
                lines[i] = json.dumps(e, separators=(",", ":"))
                at = (number, e["o"]["0"]["ref"]["v"])
                break
    assert at is not None
    bad = tmp_path / "one_clock.gtrec"
    bad.write_text("\n".join(lines) + "\n")
    n, div = replay(bad)
    assert n == at[0] and div is not None
    assert (div.index, div.call, div.what) == (at[0], "GT_GetClock", "argument 1")
    assert div.recorded["ref"]["v"] == at[1] and div.now["ref"]["v"] == at[1] - 1


def test_the_numbers_of_a_form_are_read_as_json_reads_them() -> None:
    """The numbers of all call lines are read in one JSON parse; a structure's fields are
    left to the line's own parse, and a number JSON would refuse sends every line to its
    own parse (where the damaged one is reported)."""
    from gtecat.faults.record import _numbers

    ref = ',"c":"GT_GetPrfPos","a":[1,{{"ref":{{"c":"c_double","v":{}}}}}],"r":0}}'
    st = ',"c":"GT_SetTrapPrm","a":[1,{"ref":{"st":"TTrapPrm","v":{"acc":0.5}}}],"r":0}'
    got = _numbers([ref.format("-1.5e-3"), ref.format("12"), st, ',"c":"GT_Reset","a":[],"r":0}'])
    assert got is not None
    assert got[0][1] == (-1.5e-3,) and type(got[1][1][0]) is int and got[1][1] == (12,)
    assert got[0][0] == got[1][0]  # one form
    assert got[2] is None and got[3] == (',"c":"GT_Reset","a":[],"r":0}', ())
    assert _numbers([ref.format("12"), ref.format("012")]) is None
    arr = ',"c":"GT_GetSts","a":[1,{{"arr":"c_long","n":2,"v":[{}]}},2,null],"r":0}}'
    got = _numbers([arr.format("1,-2"), arr.format("3,4"), ref.format("5")])
    assert got is not None and got[0][0] == got[1][0] != got[2][0]  # an array's own form
    assert got[0][1] == ([1, -2],) and got[1][1] == ([3, 4],) and got[2][1] == (5,)
