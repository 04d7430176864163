"""``gtecat replay`` of a recording that does not hold what it should: refused, never a pass,
never a crash or a huge allocation; the line or the count named."""

from __future__ import annotations

import gzip
import json
from pathlib import Path

import pytest

from gtecat.cli.main import main
from gtecat.faults.record import Divergence
from tests.conftest import EXAMPLES

HEAD = {"gtecat_recording": 1, "program": "python3 app.py", "cwd": "/", "env": {}}
STS = '{"t":0,"c":"GT_GetSts","a":[1,{"ref":{"c":"c_long","v":0}},1,null],"r":1}'


def replay(tmp_path: Path, calls: int, lines: list[str], capsys: pytest.CaptureFixture[str]):
    f = tmp_path / "r.gtrec"
    f.write_text("\n".join([json.dumps({**HEAD, "calls": calls}), *lines]) + "\n")
    rc = main(["replay", str(f)])
    out = capsys.readouterr()
    return rc, out.out + out.err


def test_a_recording_cut_at_a_line_end_is_not_a_pass(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    rc, text = replay(tmp_path, 3, [STS, STS], capsys)
    assert rc == 1 and "calls match" not in text
    assert "the recording ends early: its header counts 3 calls, the file holds 2" in text
    rc, text = replay(tmp_path, 58681, [], capsys)  # the header alone
    assert rc == 1 and "header counts 58681 calls, the file holds 0" in text
    rc, text = replay(tmp_path, 1, [STS, STS], capsys)  # lines added after the header's count
    assert rc == 1 and "damaged recording" in text and "header counts 1 calls" in text
    rc, text = replay(tmp_path, "many", [STS], capsys)  # type: ignore[arg-type]
    assert rc == 1 and "line 1: calls 'many' is not a count" in text


def test_a_recording_cut_in_the_middle_of_a_line_says_so(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    f = tmp_path / "r.gtrec"
    f.write_text(json.dumps({**HEAD, "calls": 3}) + "\n" + STS + "\n" + STS + "\n" + STS[:57])
    rc = main(["replay", str(f)])
    text = "".join(capsys.readouterr())
    assert rc == 1 and "calls match" not in text
    assert "the recording is cut short: its last line (4) stops in the middle of an entry" in text
    f.write_text(json.dumps({**HEAD, "calls": 2}) + "\n" + STS + "\n" + STS)  # no newline
    main(["replay", str(f)])  # (a whole last entry, only its newline missing: replayed)
    text = "".join(capsys.readouterr())
    assert "cut short" not in text and "diverged at call 1" in text


@pytest.mark.parametrize(
    "arg",
    [
        '{"arr":"c_long","n":1000000000,"v":[]}',  # a size the values do not back
        '{"arr":"c_ubyte","n":1000000000,"hex":"00"}',
        '{"arr":"c_long","n":-1,"v":[]}',
        '{"st":"TTrapPrm","v":{"acc":{"arr":"c_double","n":99999999999,"v":[1]}}}',
    ],
)
def test_an_array_size_is_bounded_by_its_values(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], arg: str
) -> None:
    line = f'{{"t":0,"c":"GT_GetSts","a":[1,{arg},1,null],"r":0}}'
    rc, text = replay(tmp_path, 2, [line, STS], capsys)
    assert rc == 1 and "damaged recording" in text and "line 2" in text, text
    assert "internal error" not in text


def test_deep_nesting_is_a_damaged_line(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    deep = "[" * 100_000 + "]" * 100_000
    line = f'{{"t":0,"c":"GT_GetSts","a":[1,{deep},1,null],"r":0}}'
    rc, text = replay(tmp_path, 2, [STS, line], capsys)
    assert rc == 1 and "damaged recording: line 3: nested too deeply" in text, text
    assert "internal error" not in text and "RecursionError" not in text
    f = tmp_path / "deep_head.gtrec"
    f.write_text(deep + "\n")
    assert main(["replay", str(f)]) == 1
    assert "is not a gtecat recording" in capsys.readouterr().err


def test_a_cut_compressed_recording_a_newer_format_an_unknown_type(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    whole = gzip.compress(
        ("\n".join([json.dumps({**HEAD, "calls": 400}), *[STS] * 400]) + "\n").encode()
    )
    for name, data, want in [
        ("cut.gtrec.gz", whole[: len(whole) // 2], "ends early: the compressed file is cut short"),
        ("bad.gtrec.gz", whole[:12] + b"\xff" * 40, "damaged recording: the compressed file"),
    ]:
        f = tmp_path / name
        f.write_bytes(data)
        assert main(["replay", str(f)]) == 1
        err = capsys.readouterr().err
        assert want in err and "internal error" not in err, err
    f = tmp_path / "v2.gtrec"
    f.write_text(json.dumps({**HEAD, "gtecat_recording": 2, "calls": 1}) + "\n" + STS + "\n")
    assert main(["replay", str(f)]) == 1
    err = capsys.readouterr().err
    assert (
        "was written by a newer gtecat (recording format 2; this one reads up to format 1)" in err
    )
    bogus = '{"t":0,"c":"GT_GetClock","a":[{"ref":{"c":"c_bogus","v":0}}],"r":0}'
    rc, text = replay(tmp_path, 1, [bogus], capsys)
    assert rc == 1 and "damaged recording" in text and "argument 1: the type 'c_bogus'" in text
    assert "recorded 0, replay gives 0" not in text


def test_a_divergence_of_type_alone_names_the_types() -> None:
    div = Divergence(
        4,
        "GT_GetClock",
        "argument 1",
        {"ref": {"c": "c_ulong", "v": 0}},
        {"ref": {"c": "c_long", "v": 0}},
    )
    assert str(div) == "call 4 GT_GetClock: argument 1 recorded c_ulong 0, replay gives c_long 0"


def test_a_missing_eni_is_named_before_the_replay(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    eni = tmp_path / "cell.eni"
    eni.write_bytes((EXAMPLES / "full_servo.eni").read_bytes())
    head = {**HEAD, "cwd": str(tmp_path), "calls": 3}
    lines = [
        '{"t":0,"c":"GT_Open","a":[],"r":0,"k":{"eni":"cell.eni"}}',
        '{"t":0,"c":"GT_InitEcatComm","a":[],"r":0}',
        '{"t":0,"c":"GT_Close","a":[],"r":0}',
    ]
    f = tmp_path / "r.gtrec"
    f.write_text("\n".join([json.dumps(head), *lines]) + "\n")
    assert main(["replay", str(f)]) == 0, capsys.readouterr().err
    eni.rename(tmp_path / "moved.eni")
    assert main(["replay", str(f)]) == 1
    err = capsys.readouterr().err
    assert err.strip() == (
        f"error: the ENI file the recorded session used is missing: {eni} (put it back, or "
        "give it with --eni FILE)"
    ), err
    assert main(["replay", str(f), "--eni", str(tmp_path / "moved.eni")]) == 0
    capsys.readouterr()
