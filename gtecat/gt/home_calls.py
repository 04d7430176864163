"""GT smart-home and capture calls: GT_GoHome, GT_GetHomePrm, GT_GetHomeStatus, GT_*Capture*.

The GTS vendor header's functions (the "Smart home" part of the vendor's GTS header);
the semantics live in :mod:`gtecat.controller.smart_home` (modes, stages, errors) and
:mod:`gtecat.controller.capture` (where edges come from, how exact they are).  They work on
every axis: a GTS card's (``GTECAT_CARD=gts:N``) and an EtherCAT drive in CSP.

Decisions where the header is silent:

* ``GT_GoHome`` returns 0 once the homing runs; 1 with the reason when it cannot start
  (not Trap mode, axis off, alarm, unknown mode, nothing to capture, a homing already
  running, the axis moving) - THomeStatus then shows ``run`` 0 and the error the header
  names for that case; 7 for a THomePrm field out of range (the status is unchanged).
* ``GT_GetHomePrm`` gives the parameters of the last ``GT_GoHome`` (the defaults after
  ``GT_Reset``: mode 20, moveDir 1, indexDir 1, edge 0, triggerIndex -1, velHigh 10,
  velLow 1, acc 1, dec 1, smoothTime 0, homeOffset 0, both distances 0, escapeStep 1000);
  the pads read 0.
* Capture: ``GT_SetCaptureMode(encoder, 0)`` stops a capture; a latched status stays 1
  until ``GT_ClearCaptureStatus`` (which arms the same mode again) or a new
  ``GT_SetCaptureMode``; ``GT_GetCaptureMode`` reads the mode last set; ``pClock`` of
  ``GT_GetCaptureStatus`` is the controller clock of the read.  A smart home uses the
  capture of its trigger's encoder, so afterwards ``GT_GetCaptureStatus`` shows its last
  capture (the home or index position).
"""

from __future__ import annotations

from typing import Any

from ..controller.capture import capture_unit
from ..controller.core import Controller
from ..controller.smart_home import HomeParams, smart_home
from ..errors import ParameterError
from ._core import check_range, gt_function, store, store_array, struct_arg
from .home_structs import THomePrm, THomeStatus

_FIELDS = (
    "mode",
    "moveDir",
    "indexDir",
    "edge",
    "triggerIndex",
    "velHigh",
    "velLow",
    "acc",
    "dec",
    "smoothTime",
    "homeOffset",
    "searchHomeDistance",
    "searchIndexDistance",
    "escapeStep",
)


# --- smart home --------------------------------------------------------------------------
@gt_function
def GT_GoHome(ctl: Controller, axis: int, pHomePrm: Any) -> int:
    """Start smart homing of ``axis`` with THomePrm (the module docstring's returns)."""
    prm = struct_arg(pHomePrm, THomePrm, "pHomePrm")
    home = smart_home(ctl, axis)
    home.start(HomeParams(**{name: getattr(prm, name) for name in _FIELDS}), ctl)
    return 0


@gt_function
def GT_GetHomePrm(ctl: Controller, axis: int, pHomePrm: Any) -> int:
    """The THomePrm of the last GT_GoHome (defaults after GT_Reset)."""
    out = struct_arg(pHomePrm, THomePrm, "pHomePrm")
    p = smart_home(ctl, axis).params
    for name in _FIELDS:
        setattr(out, name, getattr(p, name))
    for pad in ("pad1", "pad2", "pad3"):
        arr = getattr(out, pad)
        for i in range(len(arr)):
            arr[i] = 0
    return 0


@gt_function
def GT_GetHomeStatus(ctl: Controller, axis: int, pHomeStatus: Any) -> int:
    """run, stage, error, capturePos, targetPos of the axis's smart homing."""
    out = struct_arg(pHomeStatus, THomeStatus, "pHomeStatus")
    s = smart_home(ctl, axis).status
    out.run, out.stage, out.error, out.pad1 = int(s.run), int(s.stage), int(s.error), 0
    out.capturePos, out.targetPos = int(s.capturePos), int(s.targetPos)
    return 0


# --- capture -----------------------------------------------------------------------------
def _encoders(ctl: Controller, encoder: int, count: int) -> list:
    first = check_range("encoder", encoder, 1, 0x7FFF)
    n = check_range("count", count, 1, 0x7FFF)
    if first + n - 1 > max(ctl.axes, default=0):
        if not ctl.axes:
            capture_unit(ctl, first)  # raises with the reason (no axis yet)
        raise ParameterError(
            f"encoders {first}..{first + n - 1}: this controller has 1..{max(ctl.axes)}"
        )
    return [capture_unit(ctl, k) for k in range(first, first + n)]


@gt_function
def GT_SetCaptureMode(ctl: Controller, encoder: int, mode: int) -> int:
    """Arm the capture of ``encoder``: 0 none, 1 home, 2 index (Z), 3 probe."""
    capture_unit(ctl, encoder).arm(int(mode))
    return 0


@gt_function
def GT_GetCaptureMode(ctl: Controller, encoder: int, pMode: Any, count: int = 1) -> int:
    store_array(pMode, [u.mode for u in _encoders(ctl, encoder, count)])
    return 0


@gt_function
def GT_GetCaptureStatus(
    ctl: Controller, encoder: int, pStatus: Any, pValue: Any, count: int = 1, pClock: Any = None
) -> int:
    """Status (1 = captured) and captured encoder value of ``count`` encoders."""
    units = _encoders(ctl, encoder, count)
    store_array(pStatus, [u.status for u in units])
    store_array(pValue, [u.value for u in units])
    store(pClock, ctl.clock_ms() & 0xFFFFFFFF)
    return 0


@gt_function
def GT_SetCaptureSense(ctl: Controller, encoder: int, mode: int, sense: int) -> int:
    """Edge of ``mode``'s input: 0 falling (the switch is reached), 1 rising (left)."""
    capture_unit(ctl, encoder).set_sense(int(mode), int(sense))
    return 0


@gt_function
def GT_ClearCaptureStatus(ctl: Controller, encoder: int) -> int:
    """Status 0; the capture mode set last is armed again."""
    capture_unit(ctl, encoder).clear()
    return 0


__all__ = [
    "GT_ClearCaptureStatus",
    "GT_GetCaptureMode",
    "GT_GetCaptureStatus",
    "GT_GetHomePrm",
    "GT_GetHomeStatus",
    "GT_GoHome",
    "GT_SetCaptureMode",
    "GT_SetCaptureSense",
    "THomePrm",
    "THomeStatus",
]
