"""Replays of an application that polls every axis in one call (count 12 arrays): exact, and
a tampered element of an array, a double or a return code is caught and named (the call,
the argument, the element's index, the recorded and the new value).

The session is tools/session_arrays.py's, for a fraction of a virtual second.
"""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from gtecat import gt
from gtecat.cli.main import main
from gtecat.faults.record import replay
from tools import session_arrays

SECONDS = 0.6


@pytest.fixture(scope="module")
def recorded(tmp_path_factory: pytest.TempPathFactory) -> Path:
    out = tmp_path_factory.mktemp("arrays") / "session.gtrec"
    try:
        session_arrays.record(out, SECONDS)
    finally:
        gt.GT_Close()
    return out


def _tampered(
    src: Path, dst: Path, name: str, nth: int, change, writes: bool = True
) -> tuple[int, dict]:
    """``src`` with the ``nth`` call of ``name`` that writes an array (``writes``; else that
    leaves it as it was) changed by ``change(entry)``, written as the recorder writes it;
    (its call number, the entry)."""
    lines = src.read_text().splitlines()
    calls = seen = 0
    for i, line in enumerate(lines[1:], 1):
        if '"c":' not in line:
            continue
        calls += 1
        e = json.loads(line)
        if e["c"] == name and ("o" in e) == writes and "arr" in json.dumps(e):
            seen += 1
            if seen == nth:
                change(e)
                lines[i] = json.dumps(e, separators=(",", ":"))
                dst.write_text("\n".join(lines) + "\n")
                return calls, e
    raise AssertionError(f"no call {nth} of {name} writing an array")


def test_the_session_replays_exactly(recorded: Path) -> None:
    calls = [x for x in recorded.read_text().splitlines()[1:] if '"c":' in x]
    assert sum('"c":"GT_GetSts","a":[1,{"arr":"c_long","n":12' in x for x in calls) >= 60
    n, div = replay(recorded)
    assert div is None, str(div)
    assert n == len(calls)


def test_one_element_of_an_array_is_named_with_its_index(recorded: Path, tmp_path: Path) -> None:
    """A double of one element of the planned positions (a line of a shared form, not the
    first), an integer of the status words: the call, argument 2, the element's index."""
    bad = tmp_path / "prf.gtrec"
    was: list[float] = []

    def nudge(e: dict) -> None:
        v = e["o"]["1"]["v"]
        was.append(v[5])
        v[5] = v[5] + 0.5

    at, e = _tampered(recorded, bad, "GT_GetPrfPos", 4, nudge)
    n, div = replay(bad)
    assert div is not None and n == at
    assert (div.index, div.call, div.what) == (at, "GT_GetPrfPos", "argument 2 element [5]")
    assert div.recorded == was[0] + 0.5 and div.now == was[0]
    assert "element [5] recorded" in str(div)

    def flip(e: dict) -> None:  # a status word the call left as it found it
        e["a"][1]["v"][11] ^= 0x400

    at, e = _tampered(recorded, bad, "GT_GetSts", 30, flip, writes=False)
    n, div = replay(bad)
    assert div is not None and (div.index, div.what) == (at, "argument 2 element [11]")
    assert div.recorded == e["a"][1]["v"][11] and div.now == div.recorded ^ 0x400


def test_a_return_code_and_an_unholdable_element_are_caught(recorded: Path, tmp_path: Path) -> None:
    bad = tmp_path / "rc.gtrec"
    at, _ = _tampered(recorded, bad, "GT_GetSts", 2, lambda e: e.update(r=7))
    _, div = replay(bad)
    assert div is not None and (div.index, div.what, div.recorded, div.now) == (
        at,
        "return code",
        7,
        0,
    )

    def fraction(e: dict) -> None:  # a value a long cannot hold: compared the general way
        e["o"]["1"]["v"][2] = 0.5

    at, _ = _tampered(recorded, bad, "GT_GetSts", 2, fraction)
    _, div = replay(bad)
    assert div is not None and (div.index, div.call, div.what) == (
        at,
        "GT_GetSts",
        "argument 2 element [2]",
    )
    assert div.recorded == 0.5


def test_the_command_reports_the_element(
    recorded: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    bad = tmp_path / "enc.gtrec"

    def nudge(e: dict) -> None:
        e["o"]["1"]["v"][0] = -1.25

    at, _ = _tampered(recorded, bad, "GT_GetEncPos", 2, nudge)
    assert main(["replay", str(bad)]) == 1
    out = capsys.readouterr()
    text = out.out + out.err
    assert f"call {at} GT_GetEncPos: argument 2 element [0] recorded -1.25" in text


def _offset_session(gt, machine: str) -> None:
    """Axes 1-8 into ``enc``, then 9-12 through a pointer into it (a C program's
    ``GT_GetEncPos(9, &enc[8], 4, NULL)``), every 5 ms while axes 9 and 10 jog."""
    from ctypes import byref, c_double, c_short

    assert gt.GT_Open(eni=str(session_arrays.ENI), clock="auto", log="", machine=machine) == 0
    assert gt.GT_InitEcatComm() == 0
    st = c_short()
    while gt.GT_IsEcatReady(byref(st)) == 0 and st.value != 1:
        gt.GTE_Wait(1)
    gt.GT_StartEcatComm()
    jog = gt.TJogPrm()
    jog.acc = jog.dec = 0.1
    for a in (9, 10):
        gt.GT_AxisOn(a)
        gt.GT_PrfJog(a)
        gt.GT_SetJogPrm(a, byref(jog))
        gt.GT_SetVel(a, 3.0 + a)
        gt.GT_Update(1 << (a - 1))
    enc = (c_double * 12)()
    for _ in range(60):
        gt.GT_GetEncPos(1, enc, 8, None)
        gt.GT_GetEncPos(9, byref(enc, 64), 4, None)
        gt.GTE_Wait(5)
    gt.GT_Close()


@pytest.fixture(scope="module")
def offsets(tmp_path_factory: pytest.TempPathFactory) -> Path:
    from gtecat.faults.record import Recorder

    out = tmp_path_factory.mktemp("offsets") / "session.gtrec"
    machine = out.with_suffix(".toml")
    machine.write_text(session_arrays.MACHINE)
    rec = Recorder(out).start()
    try:
        _offset_session(gt, str(machine))
    finally:
        rec.stop()
        gt.GT_Close()
    return rec.write()


def test_a_pointer_into_an_array_replays_as_one_form(offsets: Path, tmp_path: Path) -> None:
    """The reads through ``&enc[8]`` share one prepared call with the array pooled (its
    values, not the line, differ), replay exactly, and a changed element is named by its
    index in the whole array."""
    from gtecat.faults.record import _steps

    lines = offsets.read_text().splitlines()
    into = [x for x in lines if '"off":64' in x]
    assert len(into) == 60 and sum('"o":' in x for x in into) > 50  # (the jog: new values)
    steps = _steps(offsets, lines[1:])
    calls = {id(p) for p, _ in steps if p is not None and getattr(p, "name", "") == "GT_GetEncPos"}
    assert len(calls) <= 3  # (the two forms, a first line of each that may read as it stands)
    n, div = replay(offsets)
    assert div is None, str(div)
    assert n == sum('"c":' in x for x in lines[1:])

    bad = tmp_path / "into.gtrec"
    was: list[float] = []

    def nudge(e: dict) -> None:
        v = e["o"]["1"]["ref"]["v"]
        was.append(v[9])
        v[9] += 1.0

    seen = 0
    for i, line in enumerate(lines):
        if '"off":64' in line and '"o":' in line:
            seen += 1
            if seen == 20:
                e = json.loads(line)
                nudge(e)
                lines[i] = json.dumps(e, separators=(",", ":"))
                at = sum('"c":' in x for x in lines[1 : i + 1])
                break
    bad.write_text("\n".join(lines) + "\n")
    n, div = replay(bad)
    assert div is not None and n == at
    assert (div.call, div.what) == ("GT_GetEncPos", "argument 2 element [9]")
    assert div.recorded == was[0] + 1.0 and div.now == was[0]
