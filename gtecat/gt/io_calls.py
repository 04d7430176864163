"""GT digital IO of the card: GT_GetDi, GT_GetDiRaw, GT_SetDo, GT_SetDoBit, GT_GetDo, GTE_SetGpi.

The GTS vendor header's IO functions.  ``diType`` / ``doType`` are the ``MC_*`` resource
types; bit ``i`` of a value is terminal ``i + 1`` (axis ``i + 1`` for the per-axis ones).
They work on both personalities (a card's axes and EtherCAT axes alike); what each type
reads or drives:

* ``MC_LIMIT_POSITIVE`` / ``MC_LIMIT_NEGATIVE`` / ``MC_HOME``: 60FDh bits 1 / 0 / 2 of each
  axis - on a card its terminals, from the machine description.  ``MC_ALARM``: the
  axis's amplifier (drive) is in fault.  ``MC_ARRIVE``: its in-position output (6041h
  bit 10).  ``MC_GPI``: the 16 general-purpose inputs (``GTE_SetGpi`` sets them).
  ``MC_MPG``: 0 (no hand wheel).  An axis that maps no 60FDh reads 0.
* ``GT_GetDi`` gives the levels with the configuration file's ``reverse`` of that
  terminal applied (``[limitPositiveN]``, ``[limitNegativeN]``, ``[homeN]``, ``[alarmN]``,
  ``[gpiN]``), 1 = active; ``GT_GetDiRaw`` the levels as the terminals see them.  The vendor
  card's terminals are active low; here 1 always means active (triggered).  A limit or home
  switch is wired as the machine description's ``switch_wiring`` says, else as the loaded
  configuration expects (``reverse=1``: normally closed, so ``GT_GetDiRaw`` reads 1 off the
  switch and ``GT_GetDi`` 0; :func:`gtecat.controller.config_file.switch_sense`).
* ``MC_ENABLE``: the servo-enable outputs: ``GT_SetDo`` switches each axis on or off as
  ``GT_AxisOn`` / ``GT_AxisOff`` do (a bit already in that state changes nothing; the
  first axis that cannot be switched on makes the call return 1 with its reason).
  ``MC_CLEAR``: the alarm-clear outputs: a rising bit resets that axis's faulted drive
  (as GT_ClrSts does, without clearing the status flags).  ``MC_GPO``: the 16
  general-purpose outputs, a register ``GT_GetDo`` reads back.  1 = on.
* ``GT_SetDoBit(doType, doIndex, value)``: one terminal, ``doIndex`` from 1.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

from .._code_store import compiled as _compiled_code
from ..controller.axis import PdsState
from ..controller.config_file import switch_sense, vendor_settings
from ..controller.core import Controller
from ..controller.digital_io import GPIO_COUNT, digital_io
from ..controller.input_sense import keep
from ..controller.resources import _fault_reset
from ..errors import ParameterError
from ._core import check_range, gt_function, store
from .axis_calls import axis_off, axis_on
from .constants import (
    MC_ALARM,
    MC_ARRIVE,
    MC_CLEAR,
    MC_ENABLE,
    MC_GPI,
    MC_GPO,
    MC_HOME,
    MC_LIMIT_NEGATIVE,
    MC_LIMIT_POSITIVE,
    MC_MPG,
)

_SW_FAULT = 0x0008
_SW_TARGET = 0x0400
#: per-axis inputs: type -> (object, bit, configuration section)
_AXIS_INPUTS: dict[int, tuple[int, int, str]] = {
    MC_LIMIT_POSITIVE: (0x60FD, 1 << 1, "limitPositive"),
    MC_LIMIT_NEGATIVE: (0x60FD, 1 << 0, "limitNegative"),
    MC_HOME: (0x60FD, 1 << 2, "home"),
    MC_ALARM: (0x6041, _SW_FAULT, "alarm"),
    MC_ARRIVE: (0x6041, _SW_TARGET, "arrive"),
}
_DI_TYPES = (*_AXIS_INPUTS, MC_GPI, MC_MPG)
_DO_TYPES = (MC_ENABLE, MC_CLEAR, MC_GPO)


def _reversed(ctl: Controller, kind: str) -> Callable[[int], bool]:
    settings = vendor_settings(ctl)
    return lambda n: bool(settings.get((kind, n), {}).get("reverse", False))


def read_di(ctl: Controller, di_type: int, raw: bool) -> int:
    t = check_range("diType", di_type, -1, 0x7FFF)
    if t not in _DI_TYPES:
        raise ParameterError(
            f"diType={t}: one of MC_LIMIT_POSITIVE 0, MC_LIMIT_NEGATIVE 1, MC_ALARM 2, "
            "MC_HOME 3, MC_GPI 4, MC_ARRIVE 5, MC_MPG 6"
        )
    if t == MC_MPG:
        return 0
    if t == MC_GPI:
        value = digital_io(ctl).gpi
        if not raw:
            rev = _reversed(ctl, "gpi")
            value ^= sum(1 << (k - 1) for k in range(1, GPIO_COUNT + 1) if rev(k))
        return value
    index, mask, kind = _AXIS_INPUTS[t]
    settings = vendor_settings(ctl)

    def rev(n: int) -> bool:  # raw: the electrical level (wiring); else as the card reads it
        reverse = bool(settings.get((kind, n), {}).get("reverse", False))
        return switch_sense(ctl, kind, n, reverse)[0 if raw else 1]

    value = 0
    for n, ax in ctl.axes.items():
        if not 1 <= n <= 32:
            continue
        # the axis's view of the process image, taken past the axis bank's guard: the bank
        # writes the drives' inputs into the image every cycle, so reading them there needs
        # no axis given back (GT_GetDi is one of the bank's readers, bank.BANK_READS)
        acc = object.__getattribute__(ax, "io").get(index)
        level = bool(acc.get() & mask) if acc is not None else False
        if level != rev(n):
            value |= 1 << (n - 1)
    return value


def di_reader(ctl: Controller, di_type: int, raw: bool) -> Callable[[], int]:
    """The value GT_GetDi (``raw``: GT_GetDiRaw) stores for ``di_type`` (one of its types)
    on ``ctl`` - ``_signed32(read_di(...))`` - as one call without the look-ups: each
    axis's input bit read where it lies in the process image, their sense (configuration,
    wiring) folded into one constant.  Valid until the next
    :func:`gtecat.controller.input_sense.changed` (the GT fast path keeps it that long; a
    bus brought up with other axes is a change too)."""
    if di_type == MC_MPG:
        return lambda: 0
    if di_type == MC_GPI:
        io = digital_io(ctl)
        flip = 0
        if not raw:
            rev = _reversed(ctl, "gpi")
            flip = sum(1 << (k - 1) for k in range(1, GPIO_COUNT + 1) if rev(k))
        return lambda: io.gpi ^ flip
    index, mask, kind = _AXIS_INPUTS[di_type]
    settings = vendor_settings(ctl)
    b = mask.bit_length() - 1
    env: dict[str, Any] = {}
    buffers: dict[int, str] = {}
    terms: list[str] = []
    flip = 0  # the axes read inverted (an axis that maps no object reads its sense alone)
    for n, ax in ctl.axes.items():
        if not 1 <= n <= 32:
            continue
        reverse = bool(settings.get((kind, n), {}).get("reverse", False))
        if switch_sense(ctl, kind, n, reverse)[0 if raw else 1]:
            flip |= 1 << (n - 1)
        acc = object.__getattribute__(ax, "io").get(index)  # (past the bank's guard: read_di)
        if acc is None:
            continue
        at = acc.bit_at(b)
        if at is None:  # (a bit past the entry's width: its get(), as read_di reads it)
            env[f"A{n}"] = acc
            terms.append(f"((A{n}.get() & {mask}) != 0) << {n - 1}")
            continue
        buf, byte, shift = at
        name = buffers.get(id(buf))
        if name is None:
            name = buffers[id(buf)] = f"B{len(buffers)}"
            env[name] = buf
        move = n - 1 - shift
        term = f"({name}[{byte}] & {1 << shift})"
        terms.append(
            term if not move else f"{term} << {move}" if move > 0 else f"{term} >> {-move}"
        )
    value = f"({' | '.join(terms)}) ^ {flip}" if terms else str(_signed32(flip))
    if terms and 32 in ctl.axes:  # (axis 32's bit: the sign of GT_GetDi's long)
        body = f"v = {value}\n    return v - {1 << 32} if v >> 31 else v"
    else:
        body = f"return {value}"
    exec(_compiled_code(f"def read():\n    {body}\n", f"<GT_GetDi {kind}>"), env)
    return env["read"]


def di_value(ctl: Controller, di_type: int, raw: bool = False) -> int:
    """:func:`read_di`'s value of an input type (checked before) through the reader the GT
    fast path keeps for ``ctl`` (made and kept here when none is): the
    same value without the look-ups (an input watched every cycle).  A view of a core
    beyond 32 axes keeps none: :func:`read_di` itself."""
    plans = vars(ctl).get("input_plans")  # (a CoreView's attributes are its base's)
    if plans is None:
        return read_di(ctl, di_type, raw)
    key = di_type + (16 if raw else 0)  # (the GT fast path's keys: gt.fast.IO_READERS)
    read = plans.get(key)
    if read is None:
        read = keep(ctl, key, di_reader(ctl, di_type, raw))
    return read() & 0xFFFFFFFF


def do_reader(ctl: Controller, do_type: int) -> Callable[[], int]:
    """The value GT_GetDo stores for ``do_type`` (one of its types) on ``ctl`` as one call;
    valid until the next :func:`gtecat.controller.input_sense.changed` (the axes of
    ``MC_ENABLE``: a bus brought up again is one)."""
    io = digital_io(ctl)
    if do_type == MC_GPO:
        return lambda: io.gpo
    if do_type == MC_CLEAR:
        return lambda: io.clear
    env: dict[str, Any] = {}
    terms = []
    resources = getattr(ctl, "resources", {})
    for n, ax in ctl.axes.items():
        if 1 <= n <= 32:
            env[f"a{n}"] = ax
            on = f"a{n}.servo_on"
            res = resources.get(n)
            if res is not None and res.ax is ax:
                # an axis the bank runs: its row's (a row is frozen servo-off exactly where
                # its axis was off when claimed, and the axis cannot be switched while
                # claimed), not its guarded object's, which would give the axis back
                env[f"r{n}"] = res
                on = f"(not r{n}.bank.frz_off.item(r{n}.bank_row) if r{n}.bank else {on})"
            terms.append(f"({_signed32(1 << (n - 1))} if {on} else 0)")
    body = " | ".join(terms) or "0"  # (axis 32's bit as the sign of GT_GetDo's long)
    exec(_compiled_code(f"def enabled():\n    return {body}\n", "<GT_GetDo enable>"), env)
    return env["enabled"]


def io_reader(ctl: Controller, name: str, t: int) -> Callable[[], int]:
    """GT function ``name``'s reader of type ``t`` (:func:`di_reader`, :func:`do_reader`)."""
    if name == "GT_GetDo":
        return do_reader(ctl, t)
    return di_reader(ctl, t, raw=name == "GT_GetDiRaw")


@gt_function
def GT_GetDi(ctl: Controller, diType: int, pValue: Any) -> int:
    """The inputs of type ``diType``, 1 = active (the module docstring)."""
    store(pValue, _signed32(read_di(ctl, diType, raw=False)))
    return 0


@gt_function
def GT_GetDiRaw(ctl: Controller, diType: int, pValue: Any) -> int:
    """The inputs of type ``diType`` before the configuration's ``reverse``."""
    store(pValue, _signed32(read_di(ctl, diType, raw=True)))
    return 0


def _do_type(do_type: int) -> int:
    t = check_range("doType", do_type, -1, 0x7FFF)
    if t not in _DO_TYPES:
        raise ParameterError(f"doType={t}: one of MC_ENABLE 10, MC_CLEAR 11, MC_GPO 12")
    return t


def write_do(ctl: Controller, do_type: int, value: int) -> None:
    t = _do_type(do_type)
    v = int(value) & 0xFFFFFFFF
    io = digital_io(ctl)
    if t == MC_GPO:
        io.set_gpo(v)
        return
    if t == MC_CLEAR:
        rising = v & ~io.clear
        io.clear = v & 0xFFFF
        faulted = [
            ax.motion
            for n, ax in sorted(ctl.axes.items())
            if 1 <= n <= 32
            and rising >> (n - 1) & 1
            and ax.motion is not None
            and ax.state in (PdsState.FAULT, PdsState.FAULT_REACTION_ACTIVE)
        ]
        if faulted:
            _fault_reset(ctl, faulted)
        return
    for n, ax in sorted(ctl.axes.items()):  # MC_ENABLE
        if not 1 <= n <= 32:
            continue
        on = bool(v >> (n - 1) & 1)
        if on and not ax.servo_on:
            axis_on(ctl, ax)
        elif not on and ax.servo_on:
            axis_off(ctl, ax)


def read_do(ctl: Controller, do_type: int) -> int:
    t = _do_type(do_type)
    io = digital_io(ctl)
    if t == MC_GPO:
        return io.gpo
    if t == MC_CLEAR:
        return io.clear
    return sum(1 << (n - 1) for n, ax in ctl.axes.items() if 1 <= n <= 32 and ax.servo_on)


@gt_function
def GT_SetDo(ctl: Controller, doType: int, value: int) -> int:
    write_do(ctl, doType, value)
    return 0


@gt_function
def GT_SetDoBit(ctl: Controller, doType: int, doIndex: int, value: int) -> int:
    """One output, ``doIndex`` from 1 (an axis for MC_ENABLE / MC_CLEAR)."""
    t = _do_type(doType)
    top = GPIO_COUNT if t == MC_GPO else 32
    i = check_range("doIndex", doIndex, 1, top)
    if t != MC_GPO and i not in ctl.axes:
        raise ParameterError(f"doIndex={i}: no axis {i} on this controller")
    bit = 1 << (i - 1)
    now = read_do(ctl, t)
    write_do(ctl, t, now | bit if value else now & ~bit)
    return 0


@gt_function
def GT_GetDo(ctl: Controller, doType: int, pValue: Any) -> int:
    store(pValue, _signed32(read_do(ctl, doType)))
    return 0


@gt_function
def GTE_SetGpi(ctl: Controller, gpi: int, value: int) -> int:
    """Emulator only: general-purpose input ``gpi`` (1..16) becomes active (1) or not (0)."""
    digital_io(ctl).set_gpi(int(gpi), bool(value))
    return 0


def _signed32(v: int) -> int:
    v &= 0xFFFFFFFF
    return v - (1 << 32) if v >= 1 << 31 else v


__all__ = ["GTE_SetGpi", "GT_GetDi", "GT_GetDiRaw", "GT_GetDo", "GT_SetDo", "GT_SetDoBit"]
