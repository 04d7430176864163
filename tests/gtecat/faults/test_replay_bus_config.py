"""An ENI file or machine description replaced at the same name between ``gtecat record`` and
``gtecat replay`` is named before anything runs (exit 1, the file, what to do), not found out
by a divergence later; the same bus written another way replays; ``--eni`` / ``--machine``
replay against the changed file on purpose; a recording made before the header kept the
configuration replays as before."""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import pytest

from gtecat.cli.main import main
from tests.conftest import EXAMPLES

APP = """\
from ctypes import byref, c_long, c_short
from gtecat import gt

gt.GT_Open(eni="cell.eni", machine="cell.toml", log="")
gt.GT_InitEcatComm()
st = c_short()
while not (gt.GT_IsEcatReady(byref(st)) == 0 and st.value == 1):
    gt.GTE_Wait(1)
gt.GT_StartEcatComm()
gt.GT_AxisOn(1)
gt.GT_PrfTrap(1)
gt.GT_SetPos(1, 30000)
gt.GT_SetVel(1, 50.0)
gt.GT_Update(1)
sts = c_long()
for _ in range(40):
    gt.GT_GetSts(1, byref(sts))
    gt.GTE_Wait(25)
"""
MACHINE = "[axis.1]\npositive_limit = 20000\n"


@pytest.fixture
def session(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    """A session on the figure 5-2 bus with a limit switch at 20000, recorded in its folder."""
    monkeypatch.chdir(tmp_path)
    shutil.copy(EXAMPLES / "manual_fig5_2.eni", "cell.eni")
    Path("cell.toml").write_text(MACHINE)
    Path("app.py").write_text(APP)
    assert main(["record", "-o", "cell.gtrec", "--", "python3", "app.py"]) == 0
    return tmp_path / "cell.gtrec"


def _replay(capsys: pytest.CaptureFixture[str], *args: str) -> tuple[int, str]:
    rc = main(["replay", *args])
    return rc, capsys.readouterr().err


def test_the_header_keeps_the_files_and_an_unchanged_session_replays(
    session: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    head = json.loads(session.read_text().splitlines()[0])
    assert [(n["what"], n["name"]) for n in head["bus_config"]] == [
        ("eni", "cell.eni"),
        ("machine", "cell.toml"),
    ]
    assert _replay(capsys, str(session)) == (0, "")


def test_an_eni_replaced_at_its_name_is_refused_up_front(
    session: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    shutil.copy(EXAMPLES / "full_servo.eni", "cell.eni")
    rc, err = _replay(capsys, str(session))
    assert rc == 1
    eni = session.parent / "cell.eni"
    assert f"the ENI file {eni} is not the one the session was recorded with" in err, err
    assert f"--eni {eni}" in err
    assert "diverged" not in err  # (said before anything ran)
    # on purpose: the replay runs against it (and shows where the session now differs)
    rc, err = _replay(capsys, str(session), "--eni", "cell.eni")
    assert "is not the one the session was recorded with" not in err, err


def test_the_same_bus_written_another_way_replays(
    session: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """An ENI exported again (other whitespace, a comment), a machine description with its
    keys in another order and a comment: the same configuration, not refused."""
    text = Path("cell.eni").read_text()
    head, _, rest = text.partition("\n")
    Path("cell.eni").write_text(head + "\n<!-- exported again -->\n" + rest.replace("  ", "\t"))
    Path("cell.toml").write_text("# the cell's switches\n[axis.1]\n\npositive_limit = 20_000\n")
    assert _replay(capsys, str(session)) == (0, "")


def test_a_machine_description_changed_is_refused_up_front(
    session: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    Path("cell.toml").write_text("[axis.1]\npositive_limit = 25000\n")
    rc, err = _replay(capsys, str(session))
    assert rc == 1
    toml = session.parent / "cell.toml"
    assert f"the machine description {toml} is not the one the session was recorded" in err
    assert f"--machine {toml}" in err
    rc, err = _replay(capsys, str(session), "--machine", "cell.toml")
    assert "is not the one the session was recorded with" not in err, err


def test_a_recording_without_the_configuration_replays_as_before(
    session: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    lines = session.read_text().splitlines()
    head = json.loads(lines[0])
    del head["bus_config"]
    old = session.with_name("old.gtrec")
    old.write_text("\n".join([json.dumps(head), *lines[1:]]) + "\n")
    Path("cell.toml").write_text("[axis.1]\npositive_limit = 25000\n")
    rc, err = _replay(capsys, str(old))
    assert "is not the one the session was recorded with" not in err
    assert rc == 1 and "diverged at call" in err  # (found out later, as before)


def test_a_relative_eni_is_named_from_where_the_replay_starts(
    session: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch
) -> None:
    """``gtecat replay DIR/cell.gtrec --eni other.eni`` from another folder takes that
    folder's other.eni (a command line's names are the user's), though the replay runs in the
    recorded folder: the session replays exactly on an equal copy, and diverges on another bus."""
    elsewhere = tmp_path / "elsewhere"
    elsewhere.mkdir()
    monkeypatch.chdir(elsewhere)
    shutil.copy(session.parent / "cell.eni", "other.eni")
    assert _replay(capsys, str(session), "--eni", "other.eni") == (0, "")
    shutil.copy(EXAMPLES / "full_servo.eni", "other.eni")
    rc, err = _replay(capsys, str(session), "--eni", "other.eni")
    assert rc == 1 and "diverge" in err, err
