"""A 12-axis session that meets trouble replays exactly with the axis bank on and off.

The session is tools/session_rich.py's (homing, a jog that ramps and reverses, Trap moves,
SDO reads, a drive fault and the application's recovery, a chattering limit switch), recorded
as it comes (the bank on, cycles many at once) and replayed three ways: without the bank
(the scalar reference), with its compiled cycle and with numpy alone.  Every return code and
value must be the recorded one; the compiled replay must have run the jog's ramps and the
faulted drive inside the bank, many cycles at once.  A few virtual seconds here, the whole
minute under GTECAT_LONG=1.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from gtecat import faults, gt
from gtecat.controller.core import Controller
from gtecat.faults.record import Recorder, replay
from tests.conftest import LONG
from tools import session_rich

SECONDS = 60.0 if LONG else 3.0


@pytest.fixture(scope="module")
def recorded(tmp_path_factory: pytest.TempPathFactory) -> Path:
    folder = tmp_path_factory.mktemp("rich")
    machine = folder / "machine.toml"
    machine.write_text(session_rich.MACHINE)
    out = folder / "session.gtrec"
    rec = Recorder(out).start()
    try:
        session_rich.session(gt, faults, SECONDS, str(machine))
    finally:
        rec.stop()
        gt.GT_Close()
    rec.write()
    return out


def _with_bank(path: Path, bank: str, folder: Path) -> Path:
    """The recording as if made with ``GTECAT_BANK=bank`` (its replay opens the same way)."""
    head, rest = path.read_text().split("\n", 1)
    meta = json.loads(head)
    meta["env"] = {**meta.get("env", {}), "GTECAT_BANK": bank}
    out = folder / f"{bank}.gtrec"
    out.write_text(json.dumps(meta) + "\n" + rest)
    return out


def test_the_recording_holds_the_trouble(recorded: Path) -> None:
    lines = recorded.read_text().splitlines()[1:]
    names = {json.loads(x).get("c") for x in lines if '"c":' in x}
    assert {"GT_StartEcatHoming", "GT_PrfJog", "GT_EcatSDOUpload", "GT_ClrSts"} <= names
    assert {"GT_GetEcatErrorCode", "GT_AxisOn"} <= names
    events = [json.loads(x) for x in lines if '"f":' in x]
    assert {e["v"]["kind"] for e in events if e["f"] == "inject"} == {
        "drive_fault",
        "switch_chatter",
    }


def test_the_scalar_path_replays_the_session_exactly(recorded: Path, tmp_path: Path) -> None:
    n, div = replay(_with_bank(recorded, "off", tmp_path))
    assert div is None, str(div)
    assert n > 12 * 100 * SECONDS


@pytest.mark.long
def test_the_numpy_bank_replays_the_session_exactly(
    recorded: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setenv("GTECAT_BANK_KERNEL", "numpy")
    _, div = replay(_with_bank(recorded, "on", tmp_path))
    assert div is None, str(div)


def test_the_compiled_bank_replays_it_exactly_and_runs_the_trouble_at_once(
    recorded: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    seen = {"batched": 0, "ramping": 0, "faulted": 0}
    run = Controller.run_cycles

    def counting(self: Controller, n: int) -> int:
        done = run(self, n)
        bank = self.bank
        if done and bank is not None:
            seen["batched"] += done
            alive = bank.alive
            if np.count_nonzero(bank.jog & alive & (bank.jrv != bank.jgoal)):
                seen["ramping"] += done
            if np.count_nonzero(bank.frz & alive & (bank.latched != 0)):
                seen["faulted"] += done
        return done

    monkeypatch.setattr(Controller, "run_cycles", counting)
    _, div = replay(_with_bank(recorded, "on", tmp_path))
    assert div is None, str(div)
    if seen["batched"] == 0:
        pytest.skip("no C compiler: the bank's compiled cycle was not built (numpy checked)")
    cycles = SECONDS * 1000
    assert seen["batched"] > 0.85 * cycles
    assert seen["ramping"] > 0.05 * cycles  # the jog ramps 200 ms of every reversal
    assert seen["faulted"] > 0.5 * cycles / 12  # most of the drive fault's time
