"""GT status, safety and configuration calls: GT_GetSts, GT_ClrSts, alarm, limits, scaling, encoder.

Manual chapters 4 (configuration: 4.3-4.6, table 4-4), 6 (status, table 6-2),
9 (limits, alarm, stops), 11.7 (in-position band) and chapter 13 entries 2, 3,
8, 15-18, 25, 60, 69-71, 81-83, 91, 98, 116, 121, 122.  The semantics live in
:mod:`gtecat.controller.resources` (cycle, flags, GT_ClrSts), :mod:`gtecat.controller.safety`,
:mod:`gtecat.controller.encoder`, :mod:`gtecat.controller.scale` and
:mod:`gtecat.controller.config_file`.

Decisions where the manual is silent:

* GT_ClrSts(axis, count): axes of the span that the bus does not have are
  skipped (the manual's examples clear 8 axes, ``GT_ClrSts(1, 8)``, whatever is
  connected); it returns 0 even when a flag stays set because its cause
  persists.  Every other call returns 7 for an axis that does not exist.
* GT_ClrSts on an axis whose slave is offline (comm loss, :mod:`gtecat.controller.core`)
  leaves its flags as they are (bit 1's cause persists; no drive fault reset is
  tried on a drive that cannot be reached).  Once the slave is back it resets
  the fault the loss caused, clears bit 1 and lets GT_AxisOn enable again.
* Configuration calls act at once on what the controller watches; a flag
  latched under the old setting stays until GT_ClrSts, which is why 4.5.3 says
  a configuration "takes effect" after GT_ClrSts (example 4-3).
* GT_AlarmOn/Off and GT_LmtsOn/Off return 1 when a configuration file set that
  input to ``none`` (chapter 13: "配置文件是否已经配置了...无效").
* GT_SetAxisBand(axis, band, time): band > 0 switches the in-position check on,
  band 0 off; negative values are 7.  GT_GetAxisBand gives (0, 0) after GT_Reset.
* GT_ProfileScale / GT_EncScale / GT_SetPosScale: 1 while the profile moves;
  the axis values and the drive do not jump (:mod:`gtecat.controller.scale`).
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

from ..controller import motion, safety
from ..controller.config_file import apply_config, find_config, read_config
from ..controller.core import Controller
from ..controller.resources import AxisResources, axis_resources, axis_span, clear_status
from ..controller.scale import Scale
from ..errors import BusError, CommandError, ParameterError
from ._core import check_range, gt_function, load_bytes, store
from .constants import MC_LIMIT_NEGATIVE, MC_LIMIT_POSITIVE
from .fast import prf_sts_value
from .motion_calls import _read_many, long_arg, real_arg

#: GT_LoadConfig file names longer than this fail (manual 4.4 "注意")
_CONFIG_NAME_MAX = 125
_ENCODER_BITS = 12  # GT_EncSns: bit0..bit11 = encoders 1..12


# --- status ------------------------------------------------------------------------------------
@gt_function
def GT_GetSts(ctl: Controller, axis: int, pSts: Any, count: int = 1, pClock: Any = None) -> int:
    """32-bit axis status word of table 6-2 for ``count`` axes (entry 71)."""
    return _read_many(ctl, axis, pSts, count, pClock, AxisResources.status)


@gt_function
def GT_GetPrfSts(
    ctl: Controller, profile: int, pSts: Any, count: int = 1, pClock: Any = None
) -> int:
    """The status word of ``count`` profiles (GTN-era vendor header; the manual has no entry).

    Decision: a profile is the planner of table 6-2, so its word holds the bits the planner
    itself sets and nothing that comes from the axis's inputs or encoder: bit 10 (规划运动,
    "set while the planner moves") and no other.  Alarm (1), following error (4), limits
    (5, 6), IO stops (7, 8), servo on (9) and in position (11, which compares the encoder
    with the plan) are the axis's, read with GT_GetSts.  Profile n drives axis n (the default
    ``prfMap``), so profile n's bit 10 is axis n's bit 10 at the same instant.  ``count`` follows
    the one rule of GT_GetSts (:func:`~gtecat.controller.resources.axis_span`): a profile the
    controller has but no drive backs reads 0, as the field's ``GTN_GetPrfSts(1, 1, sts, 5)``
    expects on a machine of fewer axes; a span past the controller's profiles is 7.
    """
    return _read_many(ctl, profile, pSts, count, pClock, prf_sts_value)


@gt_function
def GT_ClrSts(ctl: Controller, axis: int, count: int = 1) -> int:
    """Clear latched flags whose cause is gone; reset faulted drives first (entry 8)."""
    check_range("axis", axis, 1, 0x7FFF)
    check_range("count", count, 1, 0x7FFF)
    if not ctl.axes:
        raise BusError("GT_ClrSts: no EtherCAT axis yet (call GT_InitEcatComm)")
    axes = [r for r in axis_span(ctl, axis, count) if r is not None]  # the count rule
    get = object.__getattribute__  # (past the bank's guard: clear_status says why)
    clear_status(ctl, [r for r in axes if not get(r.ax, "link_lost")])
    return 0


# --- alarm and limits -------------------------------------------------------------------------
def _alarm(ctl: Controller, axis: int, on: bool) -> None:
    res = axis_resources(ctl, axis)
    if res.safety.alarm_input is None:
        raise CommandError(
            f"axis {axis}: the configuration file set its alarm input to 'none'; "
            "GT_AlarmOn/GT_AlarmOff cannot change it (load another configuration or GT_Reset)"
        )
    res.safety.alarm_on = on


@gt_function
def GT_AlarmOn(ctl: Controller, axis: int) -> int:
    """Drive alarm (6041h fault) watched: bit 1, servo off, abrupt stop (entry 3, 9.3)."""
    _alarm(ctl, axis, True)
    return 0


@gt_function
def GT_AlarmOff(ctl: Controller, axis: int) -> int:
    """Drive alarm ignored (entry 2); a latched bit 1 stays until GT_ClrSts."""
    _alarm(ctl, axis, False)
    return 0


def _limits(ctl: Controller, axis: int, limit_type: int, on: bool) -> None:
    res = axis_resources(ctl, axis)
    t = check_range("limitType", limit_type, -1, 1)
    s = res.safety
    which = {MC_LIMIT_POSITIVE: ("positive",), MC_LIMIT_NEGATIVE: ("negative",)}.get(
        t, ("positive", "negative")
    )
    for side in which:
        if getattr(s, f"{side}_input") is None:
            raise CommandError(
                f"axis {axis}: the configuration file set its {side} limit input to 'none'; "
                "GT_LmtsOn/GT_LmtsOff cannot change it"
            )
    for side in which:
        setattr(s, f"{side}_on", on)


@gt_function
def GT_LmtsOn(ctl: Controller, axis: int, limitType: int = -1) -> int:
    """Limit switches (60FDh bits 1/0) watched: MC_LIMIT_POSITIVE, MC_LIMIT_NEGATIVE, -1 both."""
    _limits(ctl, axis, limitType, True)
    return 0


@gt_function
def GT_LmtsOff(ctl: Controller, axis: int, limitType: int = -1) -> int:
    """Limit switches ignored (entry 81); a latched bit 5/6 stays until GT_ClrSts."""
    _limits(ctl, axis, limitType, False)
    return 0


@gt_function
def GT_SetSoftLimit(ctl: Controller, axis: int, positive: int, negative: int) -> int:
    """Soft limits on the axis planned position; defaults 0x7FFFFFFF / 0x80000000 = off."""
    res = axis_resources(ctl, axis)
    res.safety.set_soft_limits(long_arg("positive", positive), long_arg("negative", negative))
    return 0


@gt_function
def GT_GetSoftLimit(ctl: Controller, axis: int, pPositive: Any, pNegative: Any) -> int:
    s = axis_resources(ctl, axis).safety
    store(pPositive, s.soft_positive)
    store(pNegative, s.soft_negative)
    return 0


@gt_function
def GT_SetPosErr(ctl: Controller, control: int, error: int) -> int:
    """Following-error limit, pulse, (0, 2147483648] (entry 116); default 32767."""
    res = axis_resources(ctl, control)
    res.safety.set_pos_err(check_range("error", error, 1, safety.POS_ERR_MAX))
    return 0


@gt_function
def GT_GetPosErr(ctl: Controller, control: int, pError: Any) -> int:
    store(pError, axis_resources(ctl, control).safety.pos_err)
    return 0


@gt_function
def GT_SetStopDec(ctl: Controller, profile: int, decSmoothStop: float, decAbruptStop: float) -> int:
    """GT_Stop decelerations, pulse/ms², (0, 32767] (entry 122; defaults 1 and 1000)."""
    res = axis_resources(ctl, profile)
    smooth = real_arg("decSmoothStop", decSmoothStop)
    abrupt = real_arg("decAbruptStop", decAbruptStop)
    if not (0 < smooth <= motion.STOP_DEC_MAX and 0 < abrupt <= motion.STOP_DEC_MAX):
        raise ParameterError(
            f"decSmoothStop={smooth:g}, decAbruptStop={abrupt:g}: each must be in (0, 32767]"
        )
    res.profile.stop_dec = motion.StopDecel(smooth, abrupt)
    return 0


@gt_function
def GT_GetStopDec(ctl: Controller, profile: int, pDecSmoothStop: Any, pDecAbruptStop: Any) -> int:
    d = axis_resources(ctl, profile).profile.stop_dec
    store(pDecSmoothStop, d.smooth)
    store(pDecAbruptStop, d.abrupt)
    return 0


@gt_function
def GT_SetAxisBand(ctl: Controller, axis: int, band: int, time: int) -> int:
    """In-position band (pulse) and hold time (250 µs units) for bit 11 (entry 98, 11.7)."""
    res = axis_resources(ctl, axis)
    b = check_range("band", band, 0, (1 << 31) - 1)
    t = check_range("time", time, 0, (1 << 31) - 1)
    res.band.set(b, t)
    return 0


@gt_function
def GT_GetAxisBand(ctl: Controller, axis: int, pBand: Any, pTime: Any) -> int:
    b = axis_resources(ctl, axis).band
    store(pBand, b.band)
    store(pTime, b.time)
    return 0


# --- scaling and encoders ----------------------------------------------------------------------
@gt_function
def GT_ProfileScale(ctl: Controller, axis: int, alpha: int, beta: int) -> int:
    """ΔP_profile / ΔP_axis = alpha / beta (4.3.1 item 2, entry 91; 1 while moving)."""
    res = axis_resources(ctl, axis)
    res.set_profile_scale(Scale.checked(alpha, beta))
    return 0


@gt_function
def GT_EncScale(ctl: Controller, axis: int, alpha: int, beta: int) -> int:
    """ΔE_enc / ΔE_axis = alpha / beta (4.3.1 item 3, entry 17; 1 while moving)."""
    res = axis_resources(ctl, axis)
    res.set_enc_scale(Scale.checked(alpha, beta))
    return 0


@gt_function
def GT_EncSns(ctl: Controller, sense: int) -> int:
    """Bit n-1 = 1: encoder n counts the other way (entry 18; reset state: 0, see encoder.py)."""
    bits = check_range("sense", sense, 0, 0xFFFF)
    if not ctl.axes:
        raise BusError("GT_EncSns: no EtherCAT axis yet (call GT_InitEcatComm)")
    for n in range(1, _ENCODER_BITS + 1):
        ax = ctl.axes.get(n)
        if ax is not None:
            ax.motion.encoder.sense = -1 if bits >> (n - 1) & 1 else 1
    return 0


@gt_function
def GT_EncOn(ctl: Controller, encoder: int) -> int:
    """Count the drive's position actual value 6064h ("外部编码器", the default; entry 16)."""
    axis_resources(ctl, encoder).set_encoder_source(True)
    return 0


@gt_function
def GT_EncOff(ctl: Controller, encoder: int) -> int:
    """Count what the controller sends, 607Ah ("脉冲计数器", entry 15)."""
    axis_resources(ctl, encoder).set_encoder_source(False)
    return 0


# --- configuration file -----------------------------------------------------------------------
def _file_name(pFile: Any) -> str:
    if isinstance(pFile, str):
        name = pFile
    elif isinstance(pFile, bytes | bytearray):
        name = bytes(pFile).split(b"\0", 1)[0].decode("utf-8", "replace")
    elif isinstance(pFile, Path):
        name = str(pFile)
    else:
        raw = getattr(pFile, "value", None)
        if isinstance(raw, bytes):
            name = raw.decode("utf-8", "replace")
        elif isinstance(raw, str):
            name = raw
        else:
            name = load_bytes(pFile, 126).split(b"\0", 1)[0].decode("utf-8", "replace")
    if not name:
        raise ParameterError("pFile is empty")
    if len(name) > _CONFIG_NAME_MAX:
        raise ParameterError(
            f"file name of {len(name)} characters: at most {_CONFIG_NAME_MAX} (manual 4.4)"
        )
    return name


@gt_function
def GT_LoadConfig(ctl: Controller, pFile: Any) -> int:
    """Load a configuration file (docs/config_file.md); flags update with GT_ClrSts (4.4)."""
    config = read_config(find_config(_file_name(pFile), ctl.log))
    if not ctl.axes:
        raise BusError("GT_LoadConfig: no EtherCAT axis yet (call GT_InitEcatComm first)")
    moving = [n for n, ax in sorted(ctl.axes.items()) if ax.motion.moving]
    if moving:
        raise CommandError(
            f"GT_LoadConfig: axes {moving} are moving; stop every axis first (entry 83)"
        )
    apply_config(ctl, config)
    return 0
