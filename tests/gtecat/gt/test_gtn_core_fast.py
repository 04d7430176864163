"""The GTN_ twin of a fast reader whose first parameter is an axis, called with a core
beyond 1 (manual: a multi-core controller's GTN_ functions; gtecat.controller.core_view:
core c's axes 1..32 are the bus axes 32(c-1)+1..32c) takes that bus axis on core 1's fast
path: its answers (code, values, reason) are the table path's, call by call, through
smart homing, CiA-402 homing, Trap parameters and a capture, and a core or axis the bus
does not have is still the table's refusal."""

from __future__ import annotations

import ctypes
from ctypes import byref, c_long, c_short
from pathlib import Path
from typing import Any

from gtecat import gt
from gtecat.controller.epoch import EPOCH
from gtecat.drives.machine import AxisMachine, MachineDescription
from tools.gen_axes_eni import write_axes_eni

from .conftest import bring_up

AXES = 40


def _both(name: str, core: int, axis: int, make: Any) -> tuple[Any, Any]:
    """(code, bytes written, reason) through GTN_<name>(core, axis, p) and through the
    table path of GT_<name> for the bus axis."""
    out = []
    for call, args in (
        (getattr(gt, "GTN_" + name), (core, axis)),
        (getattr(gt, "GT_" + name).slow, (32 * (core - 1) + axis,)),
    ):
        o = make()
        rc = call(*args, byref(o))
        out.append((rc, bytes(o), gt.GTE_GetLastError() if rc else ""))
    return out[0], out[1]


def test_core_2s_axes_answer_as_the_table(tmp_path: Path) -> None:
    eni = write_axes_eni(AXES, tmp_path / "axes40.eni")
    m = MachineDescription(
        {a: AxisMachine(home_switch=((3000, 5000),), positive_limit=1e9) for a in (33, 34)}
    )
    bring_up(str(eni), machine=m, clock="lockstep")  # (an absolute path: the file itself)
    try:
        for a in (1, 2, 3):
            assert gt.GTN_AxisOn(2, a) == 0, gt.GTE_GetLastError()
        gt.GTE_Wait(20)
        readers = {
            "GetHomeStatus": gt.THomeStatus,
            "GetEcatHomingStatus": c_short,
            "GetEcatEncPos": c_long,
            "GetTrapPrm": gt.TTrapPrm,
        }

        def check(when: str) -> None:
            for name, make in readers.items():
                for axis in (1, 2, 3, 8):
                    a, b = _both(name, 2, axis, make)
                    assert a == b, (when, name, axis)
                # an axis or a core the bus does not have: the GTN_ table path's refusal
                for core, axis in ((2, 9), (2, 33), (3, 1)):
                    a, _ = _both(name, core, axis, make)
                    assert a[0] == 7 and "core" in a[2], (when, name, a)

        check("at rest")
        assert gt.GTN_PrfTrap(2, 1) == 0
        prm = gt.THomePrm(
            mode=20, moveDir=1, indexDir=1, edge=0, velHigh=5, velLow=1, triggerIndex=-1
        )
        prm.acc = prm.dec = 0.5
        prm.searchHomeDistance, prm.escapeStep = 20_000, 500
        assert gt.GTN_GoHome(2, 1, byref(prm)) == 0, gt.GTE_GetLastError()
        st, v = c_short(), c_long()
        assert gt.GTN_GetCaptureStatus(2, 2, byref(st), byref(v)) == 0
        for k in range(40):
            gt.GTE_Wait(25)
            check(f"homing, {25 * (k + 1)} ms")
            a = [gt.GTN_GetCaptureStatus(2, 2, byref(st), byref(v)), st.value, v.value]
            b = [gt.GT_GetCaptureStatus.slow(34, byref(st), byref(v)), st.value, v.value]
            assert a == b
        hs = gt.THomeStatus()
        assert gt.GTN_GetHomeStatus(2, 1, byref(hs)) == 0 and hs.stage != 0
        before = EPOCH.n  # (answered by core 1's C entry: no table call makes it grow)
        assert gt.GTN_GetHomeStatus(2, 1, byref(hs)) == 0 and EPOCH.n == before
        assert gt.GTN_GetEcatEncPos(2, 3, byref(c_long())) == 0 and EPOCH.n == before
    finally:
        gt.GT_Close()


def test_a_pulse_cards_own_second_core_is_not_a_view(tmp_path: Path) -> None:
    """A GTS card's own core 2 (before any bus): its axes are its own, not bus axes."""
    assert gt.GT_Open(card="gts:8", clock="lockstep", log="") == 0
    try:
        assert gt.GTN_Reset(2) == 0
        s = ctypes.c_long()
        got = gt.GTN_GetEcatEncPos(2, 1, byref(s))
        assert got != 0  # (a pulse card has no EtherCAT PDO: the table's refusal)
    finally:
        gt.GT_Close()


def test_a_view_cores_axes_read_through_core_1s_entry_as_the_table(tmp_path: Path) -> None:
    """Each reader of :data:`gtecat.gt.fast.READERS` as ``GTN_<name>(core, axis, p)`` with a
    core beyond 1 (its shape one the Python path takes: ``byref(x)``, ``x``, count 1 and a
    NULL clock, a ctypes array) goes to core 1's C entry with the bus axis: the code, the
    value and the reason of the table path for that bus axis, between waits of axes moving
    in Trap and jogging, a servo-off axis and one in homing mode."""
    from ctypes import c_double

    from gtecat.gt import fast

    eni = write_axes_eni(72, tmp_path / "axes72.eni")
    bring_up(str(eni), clock="lockstep")
    for bus in range(33, 73):
        if bus != 40:
            assert gt.GT_AxisOn(bus) == 0, gt.GTE_GetLastError()
    gt.GTE_Wait(20)
    prm = gt.TTrapPrm()
    prm.acc = prm.dec = 0.5
    for bus in range(33, 73, 3):
        assert gt.GT_PrfTrap(bus) == 0 and gt.GT_SetTrapPrm(bus, byref(prm)) == 0
        assert gt.GT_SetPos(bus, 40_000 * (1 if bus % 2 else -1)) == 0
        assert gt.GT_SetVel(bus, 5.0 + bus % 7) == 0
        assert gt.GTN_Update((bus - 1) // 32 + 1, 1 << (bus - 1) % 32) == 0
    jog = gt.TJogPrm()
    jog.acc = jog.dec = 0.2
    for bus in range(34, 73, 3):
        if bus == 40:  # (servo off)
            continue
        assert gt.GT_PrfJog(bus) == 0 and gt.GT_SetJogPrm(bus, byref(jog)) == 0
        assert gt.GT_SetVel(bus, -3.0) == 0
        assert gt.GTN_Update((bus - 1) // 32 + 1, 1 << (bus - 1) % 32) == 0
    assert gt.GT_SetHomingMode(35, 6) == 0
    axes = [(2, 1), (2, 2), (2, 3), (2, 8), (3, 1), (3, 5), (3, 8)]
    for step in range(12):
        gt.GTE_Wait((1, 7, 40)[step % 3])
        for name in fast.READERS:
            twin = getattr(gt, "GTN_" + name[3:])
            slow = getattr(gt, name).slow
            ints = name in ("GT_GetSts", "GT_GetPrfMode", "GT_GetPrfSts")
            kind = c_long if ints else c_double
            for core, axis in axes:
                bus = 32 * (core - 1) + axis
                for shape in ("byref", "obj", "count", "array"):
                    got, want = [], []
                    for call, first in ((twin, (core, axis)), (slow, (bus,))):
                        x = (kind * 1)() if shape == "array" else kind()
                        p = byref(x) if shape in ("byref", "count") else x
                        more = (1, None) if shape == "count" else ()
                        rc = call(*first, p, *more)
                        out = got if call is twin else want
                        out += [rc, bytes(x), gt.GTE_GetLastError() if rc else ""]
                    assert got == want, (step, name, core, axis, shape)
