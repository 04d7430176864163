"""A recording's plan: kept by the recorder, a replay makes its steps from it exactly as from
the text (the same calls, values, entries, in the same order), and a recording that changed,
a damaged plan or one this gtecat does not make the same is never used: the text is read
(and a tampered call is reported as before).

The session is tools/session_hard.py's (per-axis polling, a drive fault, SDO reads), for a
fraction of a virtual second.
"""

from __future__ import annotations

import dataclasses
import gc
import json
import marshal
import os
from pathlib import Path

import pytest

from gtecat import gt
from gtecat.errors import ParameterError
from gtecat.faults import record as rec
from tools import session_hard

SECONDS = 0.4


@pytest.fixture(scope="module")
def cache(tmp_path_factory: pytest.TempPathFactory):
    """gtecat's cache folder for these tests (its plans only)."""
    folder = tmp_path_factory.mktemp("cache")
    saved = {k: os.environ.get(k) for k in ("GTECAT_CACHE_DIR", "GTECAT_REPLAY_CACHE")}
    os.environ["GTECAT_CACHE_DIR"] = str(folder)
    os.environ.pop("GTECAT_REPLAY_CACHE", None)
    yield folder
    for k, v in saved.items():
        if v is None:
            os.environ.pop(k, None)
        else:
            os.environ[k] = v


@pytest.fixture(scope="module")
def recorded(cache: Path, tmp_path_factory: pytest.TempPathFactory) -> Path:
    out = tmp_path_factory.mktemp("plan") / "session.gtrec"
    try:
        session_hard.record(out, SECONDS, single=True)
    finally:
        gt.GT_Close()
    return out


def _where(path: Path) -> Path:
    where = rec._plan_file(path.read_bytes())
    assert where is not None
    return where


def _shape(steps: list) -> list:
    """The steps as comparable data: an entry itself, a call by its name, values, code and
    whether it runs compiled; the forms' sharing as the number of the first step of each."""
    first: dict[int, int] = {}
    out = []
    for i, (p, vals) in enumerate(steps):
        if p is None:
            out.append(("entry", vals))
        else:
            out.append((p.name, vals, p.rc, p.run is None, first.setdefault(id(p), i)))
    return out


def test_the_recorder_keeps_the_plan_and_it_makes_the_same_steps(recorded: Path) -> None:
    where = _where(recorded)
    assert where.is_file()
    head, plan = rec._load_plan(where)
    p, head_text, body = rec._open_text(recorded)
    assert head == head_text
    gc.disable()
    try:
        from_text = rec._steps(p, body)
        from_plan = rec._steps(p, "", plan=plan)
    finally:
        gc.enable()
    assert len(from_plan) == len(from_text) > 1000
    assert _shape(from_plan) == _shape(from_text)
    kinds = {p.name for p, _ in from_plan if p is not None}
    assert {"GT_GetSts", "GT_GetPrfPos", "GTE_Wait", "GT_Open"} <= kinds
    assert any(p is None and "cp" in e for p, e in from_plan)  # checkpoints
    # the calls the plan counts (the header's count is checked against it): the steps' calls
    assert rec._plan_calls(plan) == sum(p is not None for p, _ in from_text) == head["calls"]
    # where the opens and bring-ups are (what the check of the files looks at)
    marks = [i for i, (p, _) in enumerate(from_text) if rec._asked(p)]
    assert plan[5] == marks and len(marks) >= 2
    n, div = rec.replay(recorded)
    assert div is None, str(div)
    assert n == head["calls"]
    # an ENI file the open named that is gone: named, with the plan's marks and without
    i = marks[0]
    gone = dataclasses.replace(from_plan[i][0], kw={"eni": str(recorded.parent / "gone.eni")})
    steps = list(from_plan)
    steps[i] = (gone, from_plan[i][1])
    for way in (plan[5], None):
        with pytest.raises(ParameterError, match=r"gone\.eni"):
            rec._check_files(steps, None, None, None, way)


def test_a_changed_recording_never_takes_the_plan_of_the_old(
    recorded: Path, tmp_path: Path
) -> None:
    """One value of one call changed: another plan's name; the replay reads the text and
    names the call (as it does without plans)."""
    lines = recorded.read_text().splitlines()
    k, e = next(
        (i, json.loads(x))
        for i, x in enumerate(lines)
        if '"c":"GT_GetSts"' in x and '"o":' in x and i > len(lines) // 2
    )
    e["o"]["1"]["ref"]["v"] += 1
    lines[k] = json.dumps(e, separators=(",", ":"))
    bad = tmp_path / "bad.gtrec"
    bad.write_text("\n".join(lines) + "\n")
    assert _where(bad) != _where(recorded)
    assert not _where(bad).exists()
    div = rec.replay(bad)[1]
    assert div is not None and div.call == "GT_GetSts" and "argument 2" in div.what
    assert _where(bad).is_file()  # (kept for the next replay: the same report)
    assert str(rec.replay(bad)[1]) == str(div)


def test_a_damaged_or_foreign_plan_is_not_used(recorded: Path) -> None:
    where = _where(recorded)
    good = where.read_bytes()
    try:
        where.write_bytes(good[:-10] + bytes(10))  # (its digest no longer holds)
        assert rec._load_plan(where) is None
        # a plan that holds together but does not make the same steps (forms of one more
        # value than their lines hold)
        head, plan = rec._plan_from_bytes(good)
        forms = [(key, n + 1) for key, n in plan[1]]
        rec._keep_plan(where, head, (plan[0], forms, *plan[2:]))
        with pytest.raises(ValueError):
            rec._steps(Path("x"), "", plan=rec._load_plan(where)[1])
        div = rec.replay(recorded)[1]
        assert div is None, str(div)
        assert rec._load_plan(where)[1][1] == plan[1]  # made again from the text
    finally:
        where.write_bytes(good)


def test_plans_off_and_the_few_kept(tmp_path: Path, monkeypatch) -> None:
    monkeypatch.setenv("GTECAT_REPLAY_CACHE", "0")
    assert rec._plan_file(b"x") is None
    monkeypatch.delenv("GTECAT_REPLAY_CACHE")
    monkeypatch.setattr(rec, "PLANS_KEPT", 2)
    for k in range(3):
        rec._keep_plan(tmp_path / f"{k}.plan", {}, None)
        os.utime(tmp_path / f"{k}.plan", ns=(10**15 * (k + 1), 10**15 * (k + 1)))
    rec._keep_plan(tmp_path / "3.plan", {}, None)
    assert sorted(f.name for f in tmp_path.glob("*.plan")) == ["2.plan", "3.plan"]
    assert rec._load_plan(tmp_path / "3.plan") == ({}, None)
    # at most PLAN_BYTES: the newest stays whatever its size
    monkeypatch.setattr(rec, "PLANS_KEPT", 10)
    monkeypatch.setattr(rec, "PLAN_BYTES", 1000)
    rec._keep_plan(tmp_path / "4.plan", {"x": "y" * 2000}, None)
    assert sorted(f.name for f in tmp_path.glob("*.plan")) == ["4.plan"]


def test_a_settled_file_finds_its_plan_by_name_and_times(
    recorded: Path, tmp_path: Path, monkeypatch
) -> None:
    """A replay notes which plan a recording's file holds (by its name, size and times): the
    next replay of the same file reads none of its bytes; a file changed since (whatever its
    size) is read again and a tampered call reported; a file changed a moment ago gets no
    note (a change within the clock's tick could leave its times as they were)."""
    copy = tmp_path / "copy.gtrec"
    copy.write_bytes(recorded.read_bytes())
    assert rec.replay(copy)[1] is None
    assert rec._plan_ref(rec._file_key(copy)) is None  # changed a moment ago: no note
    monkeypatch.setattr(rec, "_SETTLED_NS", 0)
    assert rec.replay(copy)[1] is None  # (the bytes read, their plan noted)
    assert rec._plan_ref(rec._file_key(copy)) == _where(recorded)
    read = rec._read_raw

    def unread(p: Path) -> bytes:
        raise AssertionError("the recording's bytes were read")

    monkeypatch.setattr(rec, "_read_raw", unread)
    n, div = rec.replay(copy)
    assert div is None and n == json.loads(recorded.read_text().split("\n", 1)[0])["calls"]
    monkeypatch.setattr(rec, "_read_raw", read)
    # the same size, one value changed; its times moved (as any write moves them)
    text = copy.read_text()
    k = text.index('"c":"GT_GetSts"', len(text) // 2)
    line_end = text.index("\n", k)
    line = text[text.rindex("\n", 0, k) + 1 : line_end]
    e = json.loads(line)
    if "o" not in e:
        pytest.skip("no GT_GetSts with a value written back after the middle")
    v = e["o"]["1"]["ref"]["v"]
    w = v + 1 if v % 10 != 9 else v - 1  # (as many digits)
    e["o"]["1"]["ref"]["v"] = w
    bad = json.dumps(e, separators=(",", ":"))
    assert len(bad) == len(line)
    copy.write_text(text.replace(line, bad, 1))
    st = copy.stat()
    os.utime(copy, ns=(st.st_atime_ns, st.st_mtime_ns + 1_000_000_000))
    div = rec.replay(copy)[1]
    assert div is not None and div.call == "GT_GetSts" and "argument 2" in div.what


def test_equal_arrays_are_one_object_in_the_steps_and_the_plan() -> None:
    """A polling loop's array before a call holds what the call before left in it: equal
    arrays are one bytes object in the steps and in the plan (marshal keeps it once), and the
    plan makes the same steps."""
    line = (
        '{{"t":{t},"c":"GT_GetEncPos","a":[1,{{"arr":"c_double","n":2,"v":[{a}]}},2,null],'
        '"r":0,"o":{{"1":{{"arr":"c_double","n":2,"v":[{b}]}}}}}}'
    )
    vals = ["0.0,0.0", "1.5,2.0", "3.0,-4.25", "3.0,-4.25"]
    text = "\n".join(
        line.format(t=k * 1_000_000, a=vals[k], b=vals[k + 1]) for k in range(len(vals) - 1)
    )
    keep: list = []
    gc.disable()
    try:
        steps = rec._steps(Path("x"), text + "\n", keep)
    finally:
        gc.enable()
    (p0, v0), (p1, v1), (p2, v2) = steps
    assert p0 is p1 is p2  # (one form)
    assert v0[1] is v1[0] and v1[1] is v2[0] is v2[1]  # (what a call left: the next one's)
    assert len({id(b) for v in (v0, v1, v2) for b in v}) == 3
    plan = marshal.loads(marshal.dumps(keep[0]))
    again = rec._steps(Path("x"), "", plan=plan)
    assert [v for _, v in again] == [v0, v1, v2]
    assert again[0][1][1] is again[1][1][0]  # (kept once in the plan, one object loaded)


def test_a_replays_plan_is_frozen_after_the_gt_imports_own_freeze(
    recorded: Path, monkeypatch
) -> None:
    """gtecat.gt's import freezes what it made (controller.core.freeze_import); that is not
    a freeze of the process's own, so a replay still moves its plan out of the collector's
    walks while the calls run, and gives it back after; a process's own freeze leaves it."""
    from gtecat.controller import core

    frozen: list[int] = []
    real = gc.freeze

    def spy() -> None:
        frozen.append(1)
        real()

    core._thaw_bus()
    gc.unfreeze()
    monkeypatch.setattr(core, "_IMPORT_FROZEN", [0])
    try:
        core.freeze_import()
        monkeypatch.setattr(gc, "freeze", spy)
        assert rec.replay(recorded)[1] is None
        assert frozen and not core.process_froze()
        frozen.clear()
        real()  # the process's own
        assert rec.replay(recorded)[1] is None
        assert not frozen and core.process_froze()
    finally:
        gt.GT_Close()
        core._thaw_bus()
        gc.unfreeze()
