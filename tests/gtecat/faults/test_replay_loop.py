"""The replay's loop: a compiled call that says it may differ is compared in full as a call
made alone is, the replay goes on after one that matched in full, and no call after the
first divergence is made (the Python loop: these calls' compiled runs say what they say;
the C entries' loop, which makes the calls themselves, in test_replay_c_loop)."""

from __future__ import annotations

from typing import Any

import pytest

from gtecat.faults import record as rec


@pytest.fixture(autouse=True)
def _python_loop(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(rec, "C_LOOP", False)


def _step(log: list[str], name: str, said: Any, rc: int = 0) -> tuple[Any, Any]:
    """A compiled call that logs itself and says ``said`` (None: all matched)."""

    def run(vals: Any) -> Any:
        log.append(name)
        return said

    call = rec._Call(
        fn=lambda: log.append(name) or rc,
        name=name,
        args=[],
        sets=[],
        fresh=[],
        kw=None,
        rc=rc,
        quick=[],
        checks=[],
        before=None,
        opens=False,
        run=run,
    )
    return call, ()


def _alone(log: list[str], name: str, rc: int = 0) -> tuple[Any, Any]:
    """A call the loop makes alone (no compiled run)."""
    call, vals = _step(log, name, None, rc)
    call.run = None
    return call, vals


def test_a_call_that_may_differ_but_matches_in_full_lets_the_run_go_on() -> None:
    log: list[str] = []
    steps = [
        _step(log, "a", None),
        _step(log, "b", (0,)),  # (may differ: the same code, nothing else to compare)
        _step(log, "c", (0,)),
        (None, {}),  # (an entry that is neither a checkpoint nor a fault)
        _step(log, "d", None),
        _alone(log, "e"),
        _step(log, "f", (0,)),
        _step(log, "g", None),
    ]
    assert rec._replay(steps, None, None) == (7, None)
    assert log == ["a", "b", "c", "d", "e", "f", "g"]


def test_the_first_divergence_in_a_run_stops_it_there() -> None:
    log: list[str] = []
    steps = [
        _step(log, "a", None),
        _step(log, "b", (0,)),
        _step(log, "c", None),
        _step(log, "d", (1,)),  # (return code 1, recorded 0)
        _step(log, "e", None),
        _alone(log, "f"),
    ]
    n, div = rec._replay(steps, None, None)
    assert n == 4
    assert div == rec.Divergence(4, "d", "return code", 0, 1)
    assert log == ["a", "b", "c", "d"]


def test_a_divergence_of_a_call_made_alone_counts_every_call_before_it() -> None:
    log: list[str] = []
    steps = [_step(log, "a", None), _step(log, "b", None), _alone(log, "c", rc=3)]
    steps[2][0].fn = lambda: log.append("c") or 0  # (recorded 3, gives 0)
    n, div = rec._replay(steps, None, None)
    assert (n, div) == (3, rec.Divergence(3, "c", "return code", 3, 0))
    assert log == ["a", "b", "c"]
