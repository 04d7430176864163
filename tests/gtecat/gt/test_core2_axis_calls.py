"""Core 2 of a bus of more than 32 axes: every GTN_ function that takes an axis, on its axis 1.

Core 2 addresses bus axes 33..64 as its axes 1..32 (gtecat.controller.core_view), mapped
once where the call names the axis.  A function that maps the number a second time (the bus
number 33 looked up again through the core) refuses a valid axis with "core 2: axis 33 out
of range 1..32": smart homing did.  The walk calls each such function with arguments built
from the function table and fails on that refusal; other refusals (a profile in another
mode, an object the ENI does not map) are the function's business, not this test's.
"""

from __future__ import annotations

import ctypes
import re
from collections.abc import Iterator
from ctypes import byref, c_double, c_long, c_short
from pathlib import Path
from typing import Any

import pytest

from gtecat import gt
from gtecat.drives.machine import AxisMachine, MachineDescription
from gtecat.gt import _core
from gtecat.gt._core import REGISTRY
from gtecat.gt.args import _struct_types
from gtecat.gt.table import ENUMS, FUNCTIONS, NO_CORE_TWINS, SAME_PARAM_TWINS, SCALARS, Param
from tools.gen_axes_eni import write_axes_eni

AXES = 36  # core 2 has axes 1..4 (bus axes 33..36)
#: the parameter that names the call's axis (the first of these a function has)
AXIS = ("axis", "profile", "encoder")
#: further axes a function names (a gear or follow master, a crd's buffered axis): core 2's 3
OTHER_AXES = ("master", "masterIndex", "gearAxis", "moveAxis")
#: the refusal of a core-2 axis number mapped twice (CoreView.axis)
MAPPED_TWICE = re.compile(r"core 2: axis \d+ out of range")
STRUCTS = _struct_types()
MOVING = 1 << 10


@pytest.fixture(autouse=True)
def _closed_controller() -> Iterator[None]:
    """Overrides the package's per-test close: the module shares one bus (``bus``)."""
    yield


@pytest.fixture(scope="module")
def bus(tmp_path_factory: pytest.TempPathFactory) -> Iterator[None]:
    eni = write_axes_eni(AXES, Path(tmp_path_factory.mktemp("eni")) / "axes36.eni")
    _core.close_all()
    machine = MachineDescription({34: AxisMachine(negative_limit=-1000, positive_limit=1000)})
    opened = gt.GT_Open(eni=str(eni), machine=machine, clock="lockstep", log="")
    assert opened == 0, gt.GTE_GetLastError()
    assert gt.GT_InitEcatComm() == 0, gt.GTE_GetLastError()
    ready = c_short()
    for _ in range(1000):
        if gt.GT_IsEcatReady(byref(ready)) == 0 and ready.value == 1:
            break
        gt.GTE_Wait(1)
    assert gt.GT_StartEcatComm() == 0, gt.GTE_GetLastError()
    for local in range(1, 5):
        assert gt.GTN_AxisOn(2, local) == 0, gt.GTE_GetLastError()
    gt.GTE_Wait(5)
    yield
    _core.close_all()


def _axis_functions() -> list[tuple[str, tuple[Param, ...]]]:
    """(GTN_ name, parameters after the core) of every emulated twin that takes an axis or
    an axis mask."""
    out = []
    for name in sorted(REGISTRY):
        if not name.startswith("GTN_"):
            continue
        own = FUNCTIONS.get(name)
        if own is not None and not own.twin:  # a GTN_x line of its own
            if not own.params or own.params[0].name != "core":
                continue
            params = own.params[1:]
        else:
            twin = FUNCTIONS.get("GT_" + name[4:])
            if twin is None or twin.name in NO_CORE_TWINS or twin.name in SAME_PARAM_TWINS:
                continue
            params = twin.params
        scalars = {p.name for p in params if not p.pointer}
        if scalars & {*AXIS, *OTHER_AXES} or any(p.mask for p in params if not p.pointer):
            out.append((name, params))
    return out


FUNCTIONS_WITH_AXIS = _axis_functions()


def _fill(obj: ctypes.Structure) -> None:
    """Every number field 1 (a plausible value for most: a direction, a speed, a mode)."""
    for fname, ftype in obj._fields_:
        if ftype in (ctypes.c_double, ctypes.c_float):
            setattr(obj, fname, 1.0)
        elif isinstance(ftype, type) and issubclass(ftype, ctypes._SimpleCData):
            try:
                setattr(obj, fname, 1)
            except TypeError:
                pass


def _args(params: tuple[Param, ...]) -> list[Any]:
    """Valid-looking arguments: core 2's axis 1, its axis 3 for a second axis, buffers with
    room for 64 elements, 1 for the other numbers (within a declared range)."""
    first = next(p.name for p in params if p.name in AXIS or p.name in OTHER_AXES or p.mask)
    out: list[Any] = []
    for p in params:
        if p.pointer:
            if p.is_struct:
                s = STRUCTS[p.ctype]()
                _fill(s)
                out.append(byref(s))
            elif p.text or p.ctype in ("char", "unsigned char", "void"):
                out.append(ctypes.create_string_buffer(256))
            else:
                ctype = getattr(ctypes, SCALARS[p.ctype][0])
                out.append((ctype * 64)())
        elif p.name == first or p.mask:
            out.append(1)
        elif p.name in OTHER_AXES or (p.name == "slave" and "master" in (q.name for q in params)):
            out.append(3)
        elif p.ctype in ENUMS:
            out.append(1)
        elif SCALARS[p.ctype][3]:
            lo = 1.0 if p.lo is None or p.lo <= 1 <= (p.hi if p.hi is not None else 2) else p.lo
            out.append(float(lo))
        else:
            ok = p.lo is None or p.lo <= 1 <= (p.hi if p.hi is not None else 2)
            out.append(1 if ok else int(p.lo))
    return out


def _standing_in_trap(local: int = 1) -> None:
    """Core 2's axis ``local`` standing in Trap mode, whatever the last call left."""
    sts = c_long()
    gt.GTN_GetSts(2, local, byref(sts))
    if sts.value & MOVING:
        gt.GTN_Stop(2, 1 << (local - 1), 1 << (local - 1))
        gt.GTE_Wait(5)
    gt.GTN_ClrSts(2, local, 1)
    gt.GTN_AxisOn(2, local)
    gt.GTN_PrfTrap(2, local)


def _call(name: str, params: tuple[Param, ...]) -> tuple[int, str]:
    """Call ``name`` on core 2; a profile in the wrong mode gets that mode and one retry."""
    fn = getattr(gt, name)
    rc = fn(2, *_args(params))
    why = gt.GTE_GetLastError() if rc else ""
    m = re.search(r"call (GT_Prf\w+) first", why)
    if m:
        getattr(gt, "GTN_" + m[1][3:])(2, 1)
        rc = fn(2, *_args(params))
        why = gt.GTE_GetLastError() if rc else ""
    return rc, why


def test_every_gtn_function_taking_an_axis_takes_core_2_axis_1(bus: None) -> None:
    crd = gt.TCrdPrm(dimension=2, synVelMax=100.0, synAccMax=1.0, evenTime=0)
    crd.profile[0], crd.profile[1] = 1, 2  # core 2's axes 1, 2 as X, Y of its system 1
    assert gt.GTN_SetCrdPrm(2, 1, byref(crd)) == 0, gt.GTE_GetLastError()
    answered, refused = [], []
    for name, params in FUNCTIONS_WITH_AXIS:
        _standing_in_trap()
        rc, why = _call(name, params)
        if MAPPED_TWICE.search(why):
            refused.append(f"{name}: {why}")
        elif rc == 0:
            answered.append(name)
    assert not refused, "\n".join(refused)
    # the walk reaches the functions, not only their argument checks
    assert len(FUNCTIONS_WITH_AXIS) > 100
    assert len(answered) > len(FUNCTIONS_WITH_AXIS) // 2, sorted(answered)
    homing = {"GTN_GetHomePrm", "GTN_GetHomeStatus", "GTN_HomeSts", "GTN_Index", "GTN_Home"}
    assert homing <= set(answered)


def test_smart_homing_of_a_core_2_axis_completes(bus: None) -> None:
    prm = gt.THomePrm(mode=gt.HOME_MODE_LIMIT, moveDir=-1, indexDir=1, edge=0, triggerIndex=-1)
    prm.velHigh, prm.velLow, prm.acc, prm.dec, prm.escapeStep = 50.0, 10.0, 5.0, 5.0, 200
    _standing_in_trap(2)
    assert gt.GTN_GoHome(2, 2, byref(prm)) == 0, gt.GTE_GetLastError()
    status = gt.THomeStatus()
    for _ in range(100):  # the negative limit of bus axis 34 is 1000 pulses away
        assert gt.GTN_GetHomeStatus(2, 2, byref(status)) == 0, gt.GTE_GetLastError()
        if not status.run:
            break
        gt.GTE_Wait(10)
    assert status.run == 0 and status.error == gt.HOME_ERROR_NONE, (status.error, status.stage)
    assert status.stage == gt.HOME_STAGE_END
    # core 1 sees the same homing on bus axis 34
    assert gt.GT_GetHomeStatus(34, byref(status)) == 0 and status.stage == gt.HOME_STAGE_END
    got = gt.THomePrm()
    assert gt.GTN_GetHomePrm(2, 2, byref(got)) == 0 and got.moveDir == -1
    pos = c_double()
    assert gt.GTN_GetPrfPos(2, 2, byref(pos)) == 0 and pos.value == status.targetPos


def test_gantry_pair_of_core_2_axes_moves_the_slave_with_the_master(bus: None) -> None:
    assert gt.GTN_SetGantryMode(2, 1, 0, 0, gt.GANTRY_MODE_NONE, 1000) == 0  # the walk's pair
    for local in (3, 4):
        _standing_in_trap(local)
    assert gt.GTN_SetGantryMode(2, 1, 4, 3, 1, 500) == 0, gt.GTE_GetLastError()
    got = [c_short(), c_short(), c_short(), c_long()]
    assert gt.GTN_GetGantryMode(2, 1, *map(byref, got)) == 0
    assert [v.value for v in got] == [4, 3, 1, 500]  # in core 2's numbering
    # bus axis 36 is core 2's axis 4: in a pair already, whichever core names it
    assert gt.GT_SetGantryMode(1, 36, 1, 1, 500) == 7
    assert "gantry group 1 of core 2" in gt.GTE_GetLastError()
    before = c_double()
    assert gt.GTN_GetPrfPos(2, 3, byref(before)) == 0
    trap = gt.TTrapPrm(acc=1.0, dec=1.0)
    assert gt.GTN_SetTrapPrm(2, 4, byref(trap)) == 0
    assert gt.GTN_SetPos(2, 4, 400) == 0 and gt.GTN_SetVel(2, 4, 20.0) == 0
    assert gt.GTN_Update(2, 1 << 3) == 0, gt.GTE_GetLastError()
    gt.GTE_Wait(60)
    master, slave = c_double(), c_double()
    assert gt.GTN_GetPrfPos(2, 4, byref(master)) == 0 and master.value == 400
    assert gt.GTN_GetPrfPos(2, 3, byref(slave)) == 0 and slave.value == before.value + 400
    assert gt.GTN_SetGantryMode(2, 1, 0, 0, gt.GANTRY_MODE_NONE, 500) == 0
