"""The axis bank takes its compiled cycle when the kernel's first build ends, at whatever cycle
that is (a first run on a machine: the build runs in a process of its own beside the program,
and how long it takes depends on the machine's load).  On the lockstep clock the results must
not depend on it: a switch at any cycle of a scenario gives, bit for bit, what numpy alone and
the compiled cycle alone give (GT_GetSts, profile and encoder positions and speeds, the clock).

The build's end is put at the bank's k-th look (``bank_kernel.settled``, asked once a cycle),
for every k of the scenario."""

from __future__ import annotations

from ctypes import byref, c_double, c_long, c_short
from pathlib import Path
from typing import Any

import pytest

from gtecat import gt
from gtecat.controller import bank_kernel
from tools.gen_axes_eni import write_axes_eni


class _Landing:
    """A build started ahead that ends at the ``k``-th look (:meth:`done`)."""

    def __init__(self, k: int, path: Path) -> None:
        self.k, self.path, self.looks = k, path, 0

    def done(self) -> bool:
        self.looks += 1
        return self.looks > self.k

    def wait(self) -> Path:
        return self.path


def _read(n: int) -> list[Any]:
    s, p, e, v = c_long(), c_double(), c_double(), c_double()
    out: list[Any] = [gt.GTE_Controller().clock.now_ns]
    for a in range(1, n + 1):
        gt.GT_GetSts(a, byref(s))
        gt.GT_GetPrfPos(a, byref(p))
        gt.GT_GetEncPos(a, byref(e))
        gt.GT_GetPrfVel(a, byref(v))
        out.append((s.value, p.value, e.value, v.value))
    return out


def _trap(a: int, pos: int, vel: float, acc: float = 0.5, smooth: int = 0) -> None:
    prm = gt.TTrapPrm()
    prm.acc = prm.dec = acc
    prm.smoothTime = smooth
    assert gt.GT_PrfTrap(a) == 0
    assert gt.GT_SetTrapPrm(a, byref(prm)) == 0
    assert gt.GT_SetPos(a, pos) == 0
    assert gt.GT_SetVel(a, vel) == 0


def _scenario(eni: str, long: bool) -> list[Any]:
    """Enable axes one by one (the bank claims them as they come), Trap moves that start,
    change in flight, stop and end, axes switched off; the state after every cycle."""
    assert gt.GT_Open(eni=eni, clock="lockstep", log="", bank="on") == 0
    try:
        assert gt.GT_InitEcatComm() == 0
        st = c_short()
        while not (gt.GT_IsEcatReady(byref(st)) == 0 and st.value == 1):
            gt.GTE_Wait(1)
        assert gt.GT_StartEcatComm() == 0
        n = 12 if long else 3
        seen = []
        for a in range(1, n + 1):
            assert gt.GT_AxisOn(a) == 0
            seen.append(_read(n))
        mask = 0
        for a in range(1, n + 1):
            _trap(a, (-1) ** a * (150 + 40 * a), 2.0 + a, smooth=5 * (a % 2))
            mask |= 1 << (a - 1)
        assert gt.GT_Update(mask) == 0
        steps = 90 if long else 24
        off = 4 if long else 1
        for t in range(steps):
            gt.GTE_Wait(1)
            if t == 6:  # a new speed and target in flight
                assert gt.GT_SetVel(2, 1.5) == 0 and gt.GT_SetPos(2, 900) == 0
                assert gt.GT_Update(1 << 1) == 0
            if t == 9:
                assert gt.GT_Stop(1 << 2, 0) == 0  # a smooth stop
            if t == 14:  # (short: axis 1 off in its move)
                assert gt.GT_AxisOff(off) == 0
            if t == 20:  # on again, and a move started while the others run
                assert gt.GT_AxisOn(off) == 0
                _trap(off, 77, 4.0)
                assert gt.GT_Update(1 << (off - 1)) == 0
            seen.append(_read(n))
        gt.GTE_Wait(25 if long else 8)  # a longer wait (the compiled cycle runs them at once)
        seen.append(_read(n))
        return seen
    finally:
        gt.GT_Close()


@pytest.fixture(scope="module")
def enis(tmp_path_factory: pytest.TempPathFactory) -> dict[bool, str]:
    """The short scenario's bus (3 drives) and the long one's (12), by ``long``."""
    d = tmp_path_factory.mktemp("eni")
    return {long: str(write_axes_eni(n, d / f"axes{n}.eni")) for long, n in ((0, 3), (1, 12))}


@pytest.fixture(scope="module")
def kernel_path() -> Path:
    lib, why = bank_kernel.library()
    if lib is None:
        pytest.skip(f"the bank's compiled cycle is not available here: {why}")
    return bank_kernel._built()


def _run(
    monkeypatch: pytest.MonkeyPatch, mode: str, landing: _Landing | None, eni: str, long: bool
) -> list[Any]:
    with monkeypatch.context() as m:
        m.setenv("GTECAT_BANK_KERNEL", mode)
        if landing is not None:  # the build is under way when the bank is made
            m.setattr(bank_kernel, "_LIB", None)
            m.setattr(bank_kernel, "_LIB_REASON", "")
            m.setattr(bank_kernel, "_AHEAD", [landing])
            m.setattr(bank_kernel, "_DEFERRED", [])
        seen = _scenario(eni, long)
    return seen


@pytest.mark.parametrize("long", [False, pytest.param(True, marks=pytest.mark.long)])
def test_the_switch_to_the_compiled_cycle_at_any_cycle_changes_nothing(
    kernel_path: Path, enis: dict[bool, str], monkeypatch: pytest.MonkeyPatch, long: bool
) -> None:
    eni = enis[long]
    numpy_only = _run(monkeypatch, "numpy", None, eni, long)
    compiled = _run(monkeypatch, "c", None, eni, long)
    assert compiled == numpy_only
    k = 0
    while True:
        landing = _Landing(k, kernel_path)
        got = _run(monkeypatch, "auto", landing, eni, long)
        assert got == compiled, f"the compiled cycle taken at the bank's look {k}"
        if landing.looks <= k:  # it never landed: every cycle of the scenario was a switch
            break
        k += 1
    assert k > (120 if long else 40)  # (the scenario's cycles)
