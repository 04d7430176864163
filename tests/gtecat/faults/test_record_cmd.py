"""``gtecat record -o FILE -- python3 SCRIPT``: a script that raises, an output that cannot be
written."""

from __future__ import annotations

import json
import os
from pathlib import Path

import pytest

from gtecat.cli.main import main
from tests.conftest import EXAMPLES


def test_a_script_that_raises_keeps_its_recording_and_its_traceback(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    app = tmp_path / "crash.py"
    app.write_text(
        "from gtecat import gt\n"
        f"gt.GT_Open(eni={str(EXAMPLES / 'full_servo.eni')!r}, log='')\n"
        "gt.GT_InitEcatComm()\n"
        "1/0\n"
    )
    out = tmp_path / "crash.gtrec"
    assert main(["record", "-o", str(out), "--", "python3", str(app)]) == 1  # as python's
    err = capsys.readouterr().err
    assert "internal error" not in err, err
    assert "Traceback" in err and f'"{app}", line 4' in err and "ZeroDivisionError" in err
    assert f"error: {app} raised ZeroDivisionError" in err
    head = json.loads(out.read_text().splitlines()[0])
    assert head["calls"] >= 2  # GT_Open, GT_InitEcatComm
    assert "GT_Close" not in out.read_text()  # gtecat's clean-up is not the program's call
    assert main(["replay", str(out)]) == 0, capsys.readouterr().err
    assert "calls match" in capsys.readouterr().out


def test_a_recording_lists_the_program_s_calls_only(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """The script's one GT_Close is recorded once: closing what a script leaves open when it
    ends is gtecat's own clean-up, not a call of the program."""
    app = tmp_path / "closes.py"
    app.write_text(
        "from gtecat import gt\n"
        f"gt.GT_Open(eni={str(EXAMPLES / 'full_servo.eni')!r}, log='')\n"
        "gt.GTE_Wait(3)\n"
        "gt.GT_Close()\n"
    )
    out = tmp_path / "closes.gtrec"
    assert main(["record", "-o", str(out), "--", "python3", str(app)]) == 0
    lines = [json.loads(x) for x in out.read_text().splitlines()]
    assert lines[0]["calls"] == 3
    assert [x["c"] for x in lines[1:]] == ["GT_Open", "GTE_Wait", "GT_Close"]
    assert main(["replay", str(out)]) == 0, capsys.readouterr().err


def test_an_output_that_cannot_be_written_is_refused_first_with_why(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    app = tmp_path / "never.py"
    app.write_text("raise SystemExit('the script ran')\n")
    cmd = ["--", "python3", str(app)]
    assert main(["record", "-o", str(tmp_path / "no" / "x.gtrec"), *cmd]) == 1
    assert "the folder" in (err := capsys.readouterr().err) and "does not exist" in err
    assert main(["record", "-o", str(app / "x.gtrec"), *cmd]) == 1
    assert "is not a folder" in capsys.readouterr().err
    if Path("/proc/self").is_dir():  # a folder that exists and takes no new file
        assert main(["record", "-o", "/proc/x.gtrec", *cmd]) == 1
        err = capsys.readouterr().err
        assert "cannot be written: the folder /proc does not take new files" in err, err
    if os.geteuid() != 0:  # root writes anywhere
        locked = tmp_path / "locked"
        locked.mkdir(mode=0o500)
        assert main(["record", "-o", str(locked / "x.gtrec"), *cmd]) == 1
        assert "permission denied" in capsys.readouterr().err
    assert "the script ran" not in capsys.readouterr().err
    assert not (tmp_path / "x.gtrec").exists()


_FOREVER = (
    "import sys\n"
    "from gtecat import gt\n"
    "gt.GT_Open(eni={eni!r}, log='')\n"
    "gt.GT_InitEcatComm()\n"
    "print('ready', flush=True)\n"
    "while True:\n"
    "    gt.GTE_Wait(10)\n"
)


@pytest.mark.parametrize(
    "how",
    [
        "script",
        # (the default run: ``shell`` passes the signal on to a command's processes, the
        # one it started among them)
        pytest.param("child", marks=pytest.mark.long("a command that execs the program")),
        "shell",
    ],
)
def test_a_recording_ended_by_sigterm_is_written_and_replays(tmp_path: Path, how: str) -> None:
    """A CI job's time-out sends SIGTERM: the session up to there is kept (before, nothing
    was written).  ``script``: run inside gtecat record; ``child``: a command it starts;
    ``shell``: a shell that starts the program without ``exec`` (the shell dies of the
    signal: the program was left running, unrecorded, when only the shell got it)."""
    import signal
    import subprocess
    import sys

    app = tmp_path / "forever.py"
    app.write_text(_FOREVER.format(eni=str(EXAMPLES / "full_servo.eni")))
    out = tmp_path / "t.gtrec"
    cmd = [sys.executable, str(app)]
    if how == "child":  # not a Python script by its name: started as a child
        cmd = ["sh", "-c", f'exec "{sys.executable}" "{app}"']
    elif how == "shell":
        cmd = ["sh", "-c", f'"{sys.executable}" "{app}"; echo after']
    rec = subprocess.Popen(
        [sys.executable, "-m", "gtecat", "record", "-o", str(out), "--", *cmd],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )
    try:
        assert rec.stdout is not None
        assert rec.stdout.readline().strip() == "ready"
        rec.send_signal(signal.SIGTERM)
        _, err = rec.communicate(timeout=60)
    finally:
        if rec.poll() is None:
            rec.kill()
            rec.wait(10)
    assert rec.returncode == 128 + signal.SIGTERM, err
    assert "Traceback" not in err, err
    head = json.loads(out.read_text().splitlines()[0])
    assert head["calls"] >= 2, head  # GT_Open, GT_InitEcatComm (and the waits it made)
    assert main(["replay", str(out)]) == 0


@pytest.mark.skipif(not os.path.isdir("/proc/self"), reason="needs Linux /proc")
def test_a_process_that_ended_but_is_not_reaped_is_not_waited_for() -> None:
    """The recorder waits for the processes it passed a signal on to while they run; one that
    ended and that its parent has not reaped yet (a zombie) has nothing left to write."""
    import subprocess
    import time

    from gtecat.cli.record_cmd import _running

    child = subprocess.Popen(["sleep", "0"])
    try:
        deadline = time.monotonic() + 10.0
        while _running(child.pid) and time.monotonic() < deadline:
            time.sleep(0.01)
        assert os.path.exists(f"/proc/{child.pid}")  # still there: not reaped yet
        assert not _running(child.pid)
    finally:
        child.wait()
    assert _running(os.getpid())
    assert not _running(child.pid)
