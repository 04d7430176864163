"""The GTN header's look-ahead in user units: GT_SetupLookAheadCrd, GT_InitLookAheadEx and
the ``...ModeLa`` settings of its planner.

A GSN application sets its look-ahead up as the vendor's samples do::

    GTN_SetupLookAheadCrd(core, crd, NORMAL_THREE_AXIS);
    GTN_SetAxisLimitModeLa(core, crd, axisLimitMode);     /* any of the ...ModeLa */
    GTN_InitLookAheadEx(core, crd, &lookAheadPara, fifo, 0);
    GTN_LnXYEx(core, crd, 20, 20, 50, 1000, 0, 0);        /* mm, mm/s, mm/s^2 */
    GTN_CrdDataEx(core, crd, NULL, 0);  GTN_CrdStart(core, 1, 0);

The vendor's samples say what the units are: after ``GT_InitLookAheadEx`` the ``Ex`` lines
and arcs of that FIFO are in the user's units (mm), their speed in units/s and their
acceleration in units/s², and ``TLookAheadParameter.scale[k]`` is the pulses per unit of
coordinate ``k``.  This maps onto the look-ahead of ``GT_InitLookAhead``
(:mod:`gtecat.controller.crd`); decisions where the header says no more:

* ``GT_InitLookAheadEx`` needs the coordinate system set up (``GT_SetCrdPrm``) and a FIFO
  that is not running (else 1).  For each coordinate ``k`` of the system ``scale[k]``,
  ``vMax[k]`` and ``aMax[k]`` must be above 0 and ``time`` above 0 (else 7);
  ``axisRelation[k]`` must be ``k + 1`` (the samples' one-to-one mapping; another mapping
  is 1: not emulated), ``lookAheadNum`` at least 1.  The FIFO's look-ahead is then
  ``GT_InitLookAhead(crd, fifo, T = time, accMax, n = lookAheadNum)`` with
  ``accMax = min(aMax[k] * scale[k]) / 10^6`` pulse/ms², and the path speed is held to
  ``min(vMax[k] * scale[k]) / 1000`` pulse/ms.  ``radiusRatio``, ``DVMax`` and
  ``machineCfgFileName`` tune the vendor's own planner and are not read.
* The ``Ex`` forms of that FIFO then take coordinates in units (times ``scale[k]``),
  ``synVel`` in units/s and ``synAcc`` in units/s² (converted with the X coordinate's
  scale); a radius uses the scale of the arc plane's first coordinate.  Without
  ``GT_InitLookAheadEx`` (or after ``GT_InitLookAhead`` on the FIFO) they stay in pulses.
* ``motionMode`` 0 is the look-ahead; other values are 1 (not emulated).
  ``pPreStartPos`` (NULL or 8 finite positions) is checked and not used: a path starts
  where the coordinate system stands, as every buffered path here.
* ``GT_SetupLookAheadCrd``: ``NORMAL_THREE_AXIS`` (0) and ``MULTI_AXES`` (1) are
  Cartesian and accepted (kept for nothing else to read); the kinematic machines
  (``FIVE_AXIS`` 2 .. ``ROBOT_WORK`` 5) are 1 (not emulated), other values 7.  It may come
  before or after ``GT_SetCrdPrm``; ``GT_InitLookAheadEx`` does not require it.
* The ``...ModeLa`` functions shape the speed curve of the vendor's planner (S-curve,
  which axes' limits and speeds count, following axes).  The emulated look-ahead plans a
  trapezoidal speed over the same points, so each is range-checked (enums: their header
  values; arrays: 8 values of 0 or more), kept with the coordinate system, and returns 0;
  the first call of each on a coordinate system writes a master-log line saying the path
  is planned without it.  ``GT_Reset`` forgets them.
"""

from __future__ import annotations

import ctypes
import importlib
import math
from typing import Any

from ..controller.core import Controller
from ..controller.crd.system import CoordSystem, LookAhead
from ..errors import CommandError, ParameterError
from ._core import gt_function, struct_arg
from .crd_calls import _crd

#: EMachineMode values of the header: the Cartesian ones are emulated
MACHINE_MODES = {0: "NORMAL_THREE_AXIS", 1: "MULTI_AXES"}
KINEMATIC_MODES = {2: "FIVE_AXIS", 3: "FIVE_AXIS_WORK", 4: "ROBOT", 5: "ROBOT_WORK"}


def _t(name: str) -> type[ctypes.Structure]:
    return vars(importlib.import_module("gtecat.gt"))[name]


@gt_function
def GT_SetupLookAheadCrd(ctl: Controller, crd: int, machineMode: int) -> int:
    """Name the machine of the look-ahead: Cartesian modes 0 and 1 are emulated."""
    c = _crd(ctl, crd)
    m = int(machineMode)
    if m in KINEMATIC_MODES:
        raise CommandError(
            f"machineMode={m} ({KINEMATIC_MODES[m]}): the kinematics of five-axis machines "
            "and robots are not emulated; NORMAL_THREE_AXIS (0) and MULTI_AXES (1) are"
        )
    if m not in MACHINE_MODES:
        raise ParameterError(f"machineMode={m}: 0 (NORMAL_THREE_AXIS) .. 5 (ROBOT_WORK)")
    c.la_modes["machineMode"] = m
    return 0


def _positive(name: str, value: Any) -> float:
    x = float(value)
    if not (math.isfinite(x) and x > 0.0):
        raise ParameterError(f"{name}={value}: must be > 0")
    return x


@gt_function
def GT_InitLookAheadEx(
    ctl: Controller,
    crd: int,
    pLookAheadPara: Any,
    fifo: int,
    motionMode: int = 0,
    pPreStartPos: Any = None,
) -> int:
    """The FIFO's look-ahead in user units (the module docstring)."""
    c = _crd(ctl, crd)
    prm = c.require_prm("GT_InitLookAheadEx")
    p = struct_arg(pLookAheadPara, _t("TLookAheadParameter"), "pLookAheadPara")
    if int(motionMode) != 0:
        raise CommandError(f"motionMode={motionMode}: only 0 (the look-ahead) is emulated")
    if pPreStartPos is not None:
        pre = struct_arg(pPreStartPos, _t("TPreStartPos"), "pPreStartPos")
        for k, v in enumerate(pre.Pos):
            if not math.isfinite(v):
                raise ParameterError(f"pPreStartPos->Pos[{k}]={v} is not a finite number")
    n = int(p.lookAheadNum)
    if n < 1:
        raise ParameterError(f"lookAheadNum={n}: at least 1")
    t = _positive("time", p.time)
    units, acc, vel = [], math.inf, math.inf
    for k in range(prm.dimension):
        rel = int(p.axisRelation[k])
        if rel != k + 1:
            raise CommandError(
                f"axisRelation[{k}]={rel}: only the one-to-one mapping (axisRelation[k] = k+1) "
                "is emulated"
            )
        scale = _positive(f"scale[{k}]", p.scale[k])
        acc = min(acc, _positive(f"aMax[{k}]", p.aMax[k]) * scale / 1e6)
        vel = min(vel, _positive(f"vMax[{k}]", p.vMax[k]) * scale / 1e3)
        units.append(scale)
    if c.running and c.fifo == int(fifo):
        raise CommandError(f"GT_InitLookAheadEx: FIFO {fifo} of coordinate system {crd} is running")
    c.look[int(fifo)] = LookAhead(t, acc, n, unit=tuple(units), vel_max=vel)
    return 0


def _mode(ctl: Controller, crd: int, name: str, value: Any, meaning: str) -> int:
    c: CoordSystem = _crd(ctl, crd)
    if name not in c.la_modes:
        ctl.log(
            f"{name} (coordinate system {c.number}): kept; the emulated look-ahead plans a "
            f"trapezoidal speed over the same points whatever the {meaning}"
        )
    c.la_modes[name] = value
    return 0


def _enum(name: str, value: int, names: tuple[str, ...]) -> int:
    v = int(value)
    if not 0 <= v < len(names):
        listed = ", ".join(f"{k} ({n})" for k, n in enumerate(names))
        raise ParameterError(f"{name}={v}: {listed}")
    return v


def _array8(name: str, ptr: Any) -> tuple[int, ...]:
    if ptr is None:
        raise ParameterError(f"{name} is NULL")
    values = tuple(int(v) for v in ptr.load_values(8))
    for k, v in enumerate(values):
        if v < 0:
            raise ParameterError(f"{name}[{k}]={v}: 0 or more")
    return values


@gt_function
def GT_SetAxisLimitModeLa(ctl: Controller, crd: int, pAxisLimitMode: Any) -> int:
    """Which axes' vMax/aMax limit the vendor's planner (8 values, kept)."""
    modes = _array8("pAxisLimitMode", pAxisLimitMode)
    return _mode(ctl, crd, "GT_SetAxisLimitModeLa", modes, "axes' limit modes")


@gt_function
def GT_SetWorkLimitModeLa(ctl: Controller, crd: int, workLimitMode: int) -> int:
    v = _enum("workLimitMode", workLimitMode, ("WORK_LIMIT_INVALID", "WORK_LIMIT_VALID"))
    return _mode(ctl, crd, "GT_SetWorkLimitModeLa", v, "work limit mode")


@gt_function
def GT_SetAccDefineModeLa(ctl: Controller, crd: int, accDefMode: int) -> int:
    v = _enum("accDefMode", accDefMode, ("NORMAL_DEF_ACC", "LONG_AXIS_ACC"))
    return _mode(ctl, crd, "GT_SetAccDefineModeLa", v, "acceleration definition")


@gt_function
def GT_SetAxisVelValidCompModeLa(ctl: Controller, crd: int, enable: int, pCompAxis: Any) -> int:
    axes = _array8("pCompAxis", pCompAxis)
    return _mode(ctl, crd, "GT_SetAxisVelValidCompModeLa", (int(enable), axes), "speed axes")


@gt_function
def GT_SetAxisVelValidModeLa(ctl: Controller, crd: int, velValidAxis: int) -> int:
    mask = int(velValidAxis) & 0xFFFFFFFF
    return _mode(ctl, crd, "GT_SetAxisVelValidModeLa", mask, "axes counted in the path speed")


@gt_function
def GT_SetVelDefineModeLa(ctl: Controller, crd: int, velDefMode: int) -> int:
    v = _enum("velDefMode", velDefMode, ("NORMAL_DEF_VEL", "NUM_DEF_VEL", "CUT_DEF_VEL"))
    return _mode(ctl, crd, "GT_SetVelDefineModeLa", v, "speed definition")


@gt_function
def GT_SetVelModeLa(ctl: Controller, crd: int, velMode: int) -> int:
    names = ("T_CURVE", "S_CURVE", "S_CURVE_NEW", "S_CURVE_SMOOTH")
    v = _enum("velMode", velMode, names)
    return _mode(ctl, crd, "GT_SetVelModeLa", v, f"speed curve ({names[v]})")


@gt_function
def GT_SetVelSmoothModeLa(ctl: Controller, crd: int, smoothMode: int) -> int:
    v = int(smoothMode)
    if v < 0:
        raise ParameterError(f"smoothMode={v}: 0 or more")
    return _mode(ctl, crd, "GT_SetVelSmoothModeLa", v, "speed smoothing")


@gt_function
def GT_SetAxisFollowModeLa(ctl: Controller, crd: int, pFollowMode: Any) -> int:
    modes = _array8("pFollowMode", pFollowMode)
    return _mode(ctl, crd, "GT_SetAxisFollowModeLa", modes, "axes' follow modes")


@gt_function
def GT_SetFollowAxisProcessModeLa(ctl: Controller, crd: int, AxisFollowMode: int) -> int:
    v = int(AxisFollowMode)
    if v < 0:
        raise ParameterError(f"AxisFollowMode={v}: 0 or more")
    return _mode(ctl, crd, "GT_SetFollowAxisProcessModeLa", v, "follow-axis processing")
