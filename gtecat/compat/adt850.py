"""The ADT850 four-axis card's C API (ADT850 manual, chapters 6, 7 and appendix B) over our axes.

``from gtecat.compat import adt850 as adt`` then ``adt.adt850_initial()`` opens the card
(the controller's ``gts:4`` pulse card, :mod:`gtecat.compat._card`) and every function of
chapter 7 works with the manual's names, argument order, ranges and return codes: 0 right,
1 error (a card number adt850_initial did not find, an axis outside 1-4, a value outside
the manual's range, a command the card refuses now); ``read_bit`` 0/1 and -1 on error;
``adt850_initial`` the number of cards (1..16), 0 when the open controller is no pulse
card, -1 when a card cannot be opened.  Nothing raises: :func:`last_error` gives the reason of
the last failure.  Pointer outputs (``int *value``, ``long *pos``) take ctypes ``byref``
/ ``pointer`` / instances or a one-element list.

Decisions where the manual is silent (besides the shared ones of :mod:`._card`):

* **Cards**: up to 16 (chapter 1), numbered from 0; how many the emulated PC holds is
  ``adt850_initial(cards=N)`` or ``GTECAT_ADT850_CARDS`` (default 1).  Card 0 is the
  controller GT_Open opens (its options: ``clock``, ``machine``, ...; a controller
  already open is used), the others separate ``gts:4`` controllers that keep card 0's
  time (:func:`adt850_initial`).  Appendix B works on card 0.
* **Registers after initialisation** ("值不确定", 3.x): R = 8000000 (M = 1), SV = V = A =
  D = 1, K = 1, dec_pos 0.  The modes are the manual's 1.1 list.
* **Interpolation speed** is the master axis's (X for X-Y, X-Y-Z, X-Y-Z-W; Z for Z-W) in
  base pulses (:mod:`gtecat.controller.crd.base_pulse`): the long axis of a line, the
  faster axis of each octant of an arc.  A 3/4-axis line needs Z set as 5.8/5.9 say
  (refused with 1 otherwise), and one that stopped early needs ``inp_clear`` (9.3).
  Interpolation deceleration is disabled at start (9.2.6: "默认情况是插补减速禁止"): a
  node then accelerates and stops at once at its end; ``inp_dec_enable`` before a node
  decelerates it (automatically for lines, at ``set_dec_pos`` base pulses from the
  node's start in manual mode).  Returned 1: an arc with acceleration and automatic
  deceleration, an S-curve arc, an S-curve node written while one runs (continuous
  interpolation, 5.4).
* **Continuous interpolation**: ``get_inp_status2`` is 1 while the interpolation runs
  and no next node waits (the chip's one-node buffer); a node written then is run right
  after the current one, at the base speed the current one ends with.
* **get_status** while pulses go out always has one of D2/D3/D4 set (D3 also for a
  constant-speed drive), so "0 = drive over" holds; D0/D1 compare with COMP+/COMP-.
  A drive whose pulses are out but that is not over - INPOS valid and not yet active
  (1.12, 9.5), or Z and W held in the drive state by a 3/4-axis interpolation that
  stopped early (5.12, 9.3) - reads D8 (0x100) alone: the manual leaves D8-D15 unused,
  and the value must not be 0 while the card still drives.
* **read_di / read_bit** give electrical levels (6.1; the wiring model and the logic
  settings are gtecat.compat._card's "Electrical levels").  Outputs are the card's 32-bit
  register (``write_do``).
* **Settings with nothing to act on** in an emulation - ``set_pulse_mode`` (the emulated
  amplifier takes any mode) and the input filters - return 0 and say so in
  :func:`last_error`.
* **Appendix B** (the application library): distances in units of ``AppParams.pulses``
  pulses, speeds in units/s, ``addtime`` in s; the blocking calls run the controller
  cycle by cycle, calling ``pfn`` (if given) every cycle; a ``one_stop``/``all_stop``
  from ``pfn`` ends them with 0.  ``adt850_init_board(params)`` takes the parameters
  the vendor's tool would save (``AppParams`` per axis), -3 when none are given.
"""

from __future__ import annotations

import functools
import math
import os
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from typing import Any

from ..controller.crd import bank
from ..controller.epoch import changed as readers_changed
from ..controller.motion.scurve import SCurveParams
from ._card import (
    AXES,
    GPIN,
    SIGNALS,
    WAITING,
    CompatError,
    PulseCard,
    integer,
    open_card,
    open_follower,
    out,
    real,
)
from ._card import last_error as last_error
from ._card import set_last_error as _set_error

MAX_CARDS = 16
#: the cards adt850_initial found, by card number (None: no such card)
_CARD: list[PulseCard | None] = [None] * MAX_CARDS
PULSE_MAX = 268_435_455
INP_MIN, INP_MAX = -8_388_608, 8_388_607
POS_MIN, POS_MAX = -2_147_483_648, 2_147_483_647


@dataclass(slots=True)
class _Layer:
    """What one ADT850 card keeps besides the chip registers of :class:`PulseCard`."""

    #: interpolation deceleration enabled (5.10/5.11), by ``no`` (1 X-Y/3-4 axes, 2 Z-W)
    dec_enabled: dict[int, bool] = field(default_factory=lambda: {1: False, 2: False})
    #: where a 3/4-axis interpolation sends Z and W (LP), until it is over or inp_clear
    inp34: dict[int, float] = field(default_factory=dict)


def _layer(card: PulseCard) -> _Layer:
    if not isinstance(card.layer, _Layer):
        card.layer = _Layer()
    return card.layer


def _api(error: int = 1) -> Callable:
    """Seed return codes: the body's result (None = 0), ``error`` with a reason on failure."""

    def wrap(fn: Callable[..., int | None]) -> Callable[..., int]:
        @functools.wraps(fn)
        def call(*args: Any, **kwargs: Any) -> int:
            card = _CARD[0]  # card 0's controller keeps the time of every card
            try:
                rc = fn(*args, **kwargs)
            except Exception as e:  # the manual's C API never raises
                _set_error(f"{fn.__name__}: {e}")
                rc = error
            readers_changed()  # (the card changed without a GT call: controller/epoch.py)
            if card is not None:
                card.tick()
            return 0 if rc is None else rc

        return call

    return wrap


def _card(cardno: Any) -> PulseCard:
    if _CARD[0] is None:
        raise CompatError("no card: call adt850_initial first")
    k = integer("cardno", cardno, 0, MAX_CARDS - 1)
    card = _CARD[k]
    if card is None:
        count = sum(c is not None for c in _CARD)
        raise CompatError(f"cardno={k}: adt850_initial found {count} card(s), 0..{count - 1}")
    return card


def _axis(cardno: Any, axis: Any) -> tuple[PulseCard, int]:
    return _card(cardno), integer("axis", axis, 1, 4)


def _flag(name: str, value: Any) -> bool:
    return bool(integer(name, value, 0, 1))


def _close_all() -> None:
    if _CARD[0] is not None:
        _CARD[0].close()  # closes the other cards' controllers too
    _CARD[:] = [None] * MAX_CARDS


def _card_count(cards: Any) -> int:
    if cards is not None:
        return integer("cards", cards, 1, MAX_CARDS)
    env = os.environ.get("GTECAT_ADT850_CARDS", "").strip()
    if not env:
        return 1
    if not env.isdigit() or not 1 <= int(env) <= MAX_CARDS:
        raise CompatError(f"GTECAT_ADT850_CARDS={env!r}: the number of cards, 1..{MAX_CARDS}")
    return int(env)


# --- 1. basic parameters ------------------------------------------------------------------
def adt850_initial(
    cards: int | None = None, machines: Mapping[int, Any] | None = None, **options: Any
) -> int:
    """1.1: open the cards; the number of cards (1..16), 0 when the open controller is no
    pulse card, -1 when a card cannot be opened (the reason in :func:`last_error`).

    The manual's PC holds up to 16 cards (chapter 1), numbered 0, 1, 2, ... in the
    order ``adt850_initial`` counts them.  Decision: ``cards`` (ours; else the
    ``GTECAT_ADT850_CARDS`` environment variable, else 1) says how many the emulated PC
    has.  Card 0 is the controller ``GT_Open`` opens (or the pulse card open already; the
    ``options`` are GT_Open's); every other card is a controller of its own, a ``gts:4``
    card with ``machines[k]`` (a machine description or its TOML file; none: no
    switches), whose time is card 0's.  After 1.1 every card stands in the power-up
    state the manual lists."""
    _close_all()
    try:
        n = _card_count(cards)
        machines = dict(machines or {})
        for k in machines:
            integer("machines key", k, 0, n - 1)
        if 0 in machines:
            options.setdefault("machine", machines[0])
        base = open_card("ADT850", **options)
    except Exception as e:
        _set_error(f"adt850_initial: {e}")
        return 0 if "EtherCAT master" in str(e) else -1
    _CARD[0] = base
    try:
        for k in range(1, n):
            _CARD[k] = open_follower(base, f"ADT850 card {k}", machines.get(k))
    except Exception as e:
        _set_error(f"adt850_initial: card {k}: {e}")
        _close_all()
        return -1
    for card in _CARD[:n]:
        assert card is not None
        card.stop2_clears_ep = True
        card.layer = _Layer()
    return n


@_api()
def adt850_end() -> int:
    """1.2: release the cards (card 0's controller stays open - GT_Close closes it -, the
    other cards' controllers close)."""
    if _CARD[0] is None:
        raise CompatError("no card open")
    _close_all()
    return 0


def _stop_mode(k: int) -> Callable[..., int]:
    @_api()
    def set_stop_mode(cardno: int, axis: int, value: int, logic: int) -> int:
        card, n = _axis(cardno, axis)
        card.regs[n].stop_on[k] = _flag("value", value)
        card.regs[n].logic[2 + k] = integer("logic", logic, 0, 1)
        return 0

    set_stop_mode.__name__ = set_stop_mode.__qualname__ = f"set_stop{k}_mode"
    set_stop_mode.__doc__ = (
        f"1.{3 + k}: STOP{k} valid (1) / invalid (0) and the level that stops (0 low, 1 "
        "high): the card sees the signal active at that level (module docstring of "
        'gtecat.compat._card, "Electrical levels"); valid and active, it stops a drive '
        "(decelerating, a constant-speed drive at once: 1.3 note)."
        + (
            " A STOP2 stop also clears the real position counter at the signal (1.5 note, 9.4)."
            if k == 2
            else ""
        )
    )
    return set_stop_mode


set_stop0_mode = _stop_mode(0)
set_stop1_mode = _stop_mode(1)
set_stop2_mode = _stop_mode(2)


def _no_effect(name: str, why: str) -> None:
    """A setting the emulation takes and that changes nothing observable: 0, and the
    reason in :func:`last_error` (a program that checks it learns so)."""
    _set_error(f"{name}: kept; {why}")


@_api()
def set_actualcount_mode(cardno: int, axis: int, value: int, dir: int, freq: int) -> int:
    """1.6: the real position counter's input: A/B (0) or up/down pulses (1), its
    direction (1 reversed) and the A/B multiplication (0 4x, 1 2x, 2 1x).  The counter
    keeps its reading and counts from now on as set; up/down input fed with the emulated
    amplifier's A/B signals holds its reading (gtecat.compat._card ``counted``)."""
    card, n = _axis(cardno, axis)
    card.count_mode(
        n, integer("value", value, 0, 1), integer("dir", dir, 0, 1), integer("freq", freq, 0, 2)
    )
    return 0


@_api()
def set_pulse_mode(cardno: int, axis: int, value: int, logic: int, dir_logic: int) -> int:
    """1.7: pulse + pulse (0) or pulse + direction (1), pulse and direction logic.

    Decision: the emulated amplifier is set up for whatever the card puts out (as the
    manual's chapter 11 asks of a real one), so the motor follows the logic counter in
    every mode: the call returns 0 and :func:`last_error` says it changes nothing here."""
    card, n = _axis(cardno, axis)
    card.regs[n].settings["pulse_mode"] = (
        integer("value", value, 0, 1),
        integer("logic", logic, 0, 1),
        integer("dir_logic", dir_logic, 0, 1),
    )
    _no_effect("set_pulse_mode", "the emulated amplifier takes any pulse output mode")
    return 0


@_api()
def set_inpos_mode(cardno: int, axis: int, value: int, logic: int) -> int:
    """1.12: nINPOS valid (1) and its active level: valid, a drive (and an
    interpolation, 5 "伺服马达的到位信号") ends only when the card sees INPOS active -
    the amplifier within 1 pulse of the plan, its output low.  9.5: valid without an
    INPOS the card can see active, the drive never ends."""
    card, n = _axis(cardno, axis)
    card.regs[n].inpos_on = _flag("value", value)
    card.regs[n].logic[5] = integer("logic", logic, 0, 1)
    return 0


@_api()
def set_circle_mode(cardno: int, axis: int, value: int) -> int:
    """1.17 / 4.3: the variable ring: LP counts 0..COMP+, EP 0..COMP-, wrapping both ways;
    with it on, COMP+/COMP- are no soft limits."""
    card, n = _axis(cardno, axis)
    card.regs[n].ring = _flag("value", value)
    return 0


@_api()
def set_input_filter(cardno: int, axis: int, number: int, value: int) -> int:
    """1.18: the integral filter of an input group (1 LMT+/LMT-/STOP0/STOP1, 2 STOP2,
    3 INPOS/ALARM, 4 IN) on or off.  The emulated inputs do not bounce: the filter
    changes nothing (said in :func:`last_error`)."""
    card, n = _axis(cardno, axis)
    card.regs[n].settings[f"filter{integer('number', number, 1, 4)}"] = _flag("value", value)
    _no_effect("set_input_filter", "the emulated inputs have no noise for a filter to remove")
    return 0


@_api()
def set_filter_time(cardno: int, axis: int, value: int) -> int:
    """1.19: the filters' time constant, 1..8: kept, no effect (see set_input_filter)."""
    card, n = _axis(cardno, axis)
    card.regs[n].settings["filter_time"] = integer("value", value, 1, 8)
    _no_effect("set_filter_time", "the emulated inputs have no noise for a filter to remove")
    return 0


set_input_fiilter = set_input_filter  # the manual's chapter 6 spelling
set_filer_time = set_filter_time


@_api()
def set_limit_mode(cardno: int, axis: int, value: int, logic: int) -> int:
    """1.8: a limit stops at once (0) or decelerating (1); ``logic`` its active level
    (0 low, the power-up setting; 1 high), for LMT+ and LMT- both."""
    card, n = _axis(cardno, axis)
    card.regs[n].limit_decel = _flag("value", value)
    card.regs[n].logic[0] = card.regs[n].logic[1] = integer("logic", logic, 0, 1)
    card._limit_mode(n)
    return 0


@_api()
def set_softlimit_mode1(cardno: int, axis: int, value: int) -> int:
    """1.9: COMP+ as a soft limit (always a decelerating stop)."""
    card, n = _axis(cardno, axis)
    card.regs[n].soft[0] = _flag("value", value)
    return 0


@_api()
def set_softlimit_mode2(cardno: int, axis: int, value: int) -> int:
    """1.10: COMP- as a soft limit."""
    card, n = _axis(cardno, axis)
    card.regs[n].soft[1] = _flag("value", value)
    return 0


@_api()
def set_softlimit_mode3(cardno: int, axis: int, value: int) -> int:
    """1.11: the COMP registers compare with the logic (0) or real (1) position counter."""
    card, n = _axis(cardno, axis)
    card.regs[n].soft_ep = _flag("value", value)
    return 0


@_api()
def set_alarm_mode(cardno: int, axis: int, value: int, logic: int) -> int:
    """1.13: nALARM valid (1) and its active level: valid, ALARM active stops a drive at
    once (get_stopdata D5) and a drive started then ends at once with D5."""
    card, n = _axis(cardno, axis)
    card.regs[n].alarm_on = _flag("value", value)
    card.regs[n].logic[6] = integer("logic", logic, 0, 1)
    return 0


@_api()
def set_ad_mode(cardno: int, axis: int, value: int) -> int:
    """1.14: linear (0) or S-curve (1) acceleration."""
    card, n = _axis(cardno, axis)
    card.regs[n].s_curve = _flag("value", value)
    return 0


@_api()
def set_dec1_mode(cardno: int, axis: int, value: int) -> int:
    """1.15: decelerate with A (0, symmetric) or D (1, asymmetric)."""
    card, n = _axis(cardno, axis)
    card.regs[n].asym = _flag("value", value)
    return 0


@_api()
def set_dec2_mode(cardno: int, axis: int, value: int) -> int:
    """1.16: automatic (0) or manual (1) deceleration of fixed drives."""
    card, n = _axis(cardno, axis)
    card.regs[n].manual = _flag("value", value)
    return 0


# --- 2. drive status ----------------------------------------------------------------------
@_api()
def get_status(cardno: int, axis: int, value: Any) -> int:
    """2.1: 0 when the drive is over, else D0-D7; D8 alone while the card waits for
    INPOS (1.12) or holds Z/W in the drive state after a broken 3/4-axis interpolation
    (5.12: "Z、W轴会一直停在驱动状态", until inp_clear) - module docstring."""
    card, n = _axis(cardno, axis)
    word = card.status_word(n)
    if word == 0 and n in (3, 4) and _inp34_error(card):
        word = WAITING
    out(value, word)
    return 0


@_api()
def get_stopdata(cardno: int, axis: int, value: Any) -> int:
    """2.2: why the last drive stopped (D0-D2 STOP0-2, D3/D4 LMT+/-, D5 alarm, D6/D7 COMP)."""
    card, n = _axis(cardno, axis)
    out(value, card.regs[n].stopdata)
    return 0


def _no(no: Any) -> int:
    return integer("no", no, 1, 2)


@_api()
def get_inp_status(cardno: int, no: int, value: Any) -> int:
    """2.3: 1 while the interpolation ``no`` (1 X-Y and 3/4 axes, 2 Z-W) runs - with
    INPOS valid, until every axis of it sees INPOS active (chapter 5, "伺服马达的到位信号":
    the interpolation ends when the INPOS signals are active)."""
    card = _card(cardno)
    c = bank(card.ctl).get(_no(no))
    waiting = c.prm is not None and any(
        card.driving(a) and not card.pulsing(a) for a in c.prm.axes()
    )
    out(value, 1 if c.running or waiting else 0)
    return 0


@_api()
def get_inp_status2(cardno: int, no: int, value: Any) -> int:
    """2.4: 1 when the next node of a continuous interpolation may be written."""
    card = _card(cardno)
    c = bank(card.ctl).get(_no(no))
    out(value, 1 if c.running and not c.fifos[0] else 0)
    return 0


# --- 3. motion parameters -----------------------------------------------------------------
@_api()
def set_range(cardno: int, axis: int, value: int) -> int:
    """3.1: R in 16000..8000000; M = 8000000/R."""
    card, n = _axis(cardno, axis)
    card.regs[n].m = 8_000_000 / integer("value", value, 16_000, 8_000_000)
    card._limit_mode(n)
    return 0


def _reg(name: str, lo: int, hi: int, doc: str, live: bool = False) -> Callable[..., int]:
    @_api()
    def setter(cardno: int, axis: int, value: int) -> int:
        card, n = _axis(cardno, axis)
        setattr(card.regs[n], name, integer("value", value, lo, hi))
        if name in ("a", "d"):
            card._limit_mode(n)
        if live:
            card.change_speed(n)
        return 0

    return setter


set_acac = _reg("k", 1, 65_535, "3.2")
set_acc = _reg("a", 1, 8000, "3.3")
set_dec = _reg("d", 1, 8000, "3.4")
set_startv = _reg("sv", 1, 8000, "3.5")
set_speed = _reg("v", 1, 8000, "3.6", live=True)
set_dec_pos = _reg("dec_pos", 0, PULSE_MAX, "3.11")
set_acac.__name__, set_acc.__name__, set_dec.__name__ = "set_acac", "set_acc", "set_dec"
set_startv.__name__, set_speed.__name__, set_dec_pos.__name__ = (
    "set_startv",
    "set_speed",
    "set_dec_pos",
)
set_acac.__doc__ = "3.2: K in 1..65535; jerk PPS/s² = 62500000/K·M."
set_acc.__doc__ = "3.3: A in 1..8000; acceleration PPS/s = A·125·M."
set_dec.__doc__ = "3.4: D in 1..8000 (asymmetric mode, set_dec1_mode 1)."
set_startv.__doc__ = "3.5: SV in 1..8000; initial speed PPS = SV·M."
set_speed.__doc__ = "3.6: V in 1..8000; drive speed PPS = V·M; while driving: re-planned."
set_dec_pos.__doc__ = "3.11: the manual deceleration point, pulses from the drive's start."


@_api()
def set_command_pos(cardno: int, axis: int, value: int) -> int:
    """3.7: the logic position counter (any time; nothing moves)."""
    card, n = _axis(cardno, axis)
    card.set_lp(n, integer("value", value, POS_MIN, POS_MAX))
    return 0


@_api()
def set_actual_pos(cardno: int, axis: int, value: int) -> int:
    """3.8: the real position counter."""
    card, n = _axis(cardno, axis)
    card.set_ep(n, integer("value", value, POS_MIN, POS_MAX))
    return 0


@_api()
def set_comp1(cardno: int, axis: int, value: int) -> int:
    """3.9: COMP+."""
    card, n = _axis(cardno, axis)
    card.regs[n].comp[0] = integer("value", value, POS_MIN, POS_MAX)
    return 0


@_api()
def set_comp2(cardno: int, axis: int, value: int) -> int:
    """3.10: COMP-."""
    card, n = _axis(cardno, axis)
    card.regs[n].comp[1] = integer("value", value, POS_MIN, POS_MAX)
    return 0


# --- 4. motion readings -------------------------------------------------------------------
@_api()
def get_command_pos(cardno: int, axis: int, pos: Any) -> int:
    """4.1: the logic position (whole pulses)."""
    card, n = _axis(cardno, axis)
    out(pos, round(card.lp(n)))
    return 0


@_api()
def get_actual_pos(cardno: int, axis: int, pos: Any) -> int:
    """4.2: the real position (the encoder)."""
    card, n = _axis(cardno, axis)
    out(pos, round(card.ep(n)))
    return 0


@_api()
def get_speed(cardno: int, axis: int, speed: Any) -> int:
    """4.3: the drive speed in V units (PPS / M), 0 standing."""
    card, n = _axis(cardno, axis)
    out(speed, round(card.speed(n)))
    return 0


@_api()
def get_ad(cardno: int, axis: int, ad: Any) -> int:
    """4.4: the acceleration in A units (PPS/s / (125·M))."""
    card, n = _axis(cardno, axis)
    out(ad, round(card.accel(n)))
    return 0


# --- 5. drives ----------------------------------------------------------------------------
@_api()
def pmove(cardno: int, axis: int, pulse: int) -> int:
    """5.1: a fixed drive of ``pulse`` pulses (sign = direction)."""
    card, n = _axis(cardno, axis)
    p = integer("pulse", pulse, -PULSE_MAX, PULSE_MAX)
    _check_zw(card, n)
    card.drive(n, abs(p), 1 if p >= 0 else -1)
    return 0


@_api()
def continue_move(cardno: int, axis: int, dir: int) -> int:
    """5.2: a continuous drive, 0 positive, 1 negative, until a stop."""
    card, n = _axis(cardno, axis)
    _check_zw(card, n)
    card.drive(n, None, -1 if _flag("dir", dir) else 1)
    return 0


@_api()
def dec_stop(cardno: int, axis: int) -> int:
    """5.3: decelerating stop (a constant-speed drive stops at once); an axis of a running
    interpolation stops the interpolation."""
    card, n = _axis(cardno, axis)
    card.decel_stop(n)
    return 0


@_api()
def sudden_stop(cardno: int, axis: int) -> int:
    """5.4: immediate stop."""
    card, n = _axis(cardno, axis)
    card.sudden_stop(n)
    return 0


def _interp(card: PulseCard, no: int, axes: list[int], make: Callable, arc: bool) -> None:
    master = 3 if no == 2 else 1
    regs = card.regs[master]
    prm: SCurveParams = regs.params()
    c = bank(card.ctl).get(2 if no == 2 else 1)
    if prm.s_curve and arc:
        raise CompatError("S-curve acceleration cannot drive an arc (ADT850 manual 3.4, 5.4)")
    if prm.s_curve and c.running:
        raise CompatError("S-curve acceleration cannot drive a continuous interpolation (5.4)")
    enabled = _layer(card).dec_enabled[no]
    if not enabled:
        decel = "none"
    elif regs.manual:
        decel = "manual"
    elif arc and not prm.constant:
        raise CompatError(
            "an arc with acceleration decelerates only in manual mode (set_dec2_mode 1 and "
            "set_dec_pos, ADT850 manual 5.4)"
        )
    else:
        decel = "auto"
    card.interpolate(axes, master, make, prm, decel, float(regs.dec_pos))


def _inp(name: str, value: Any) -> int:
    return integer(name, value, INP_MIN, INP_MAX)


@_api()
def inp_move2(cardno: int, no: int, pulse1: int, pulse2: int) -> int:
    """5.5: two-axis line, ``no`` 1 X-Y, 2 Z-W, relative distances."""
    card = _card(cardno)
    k = _no(no)
    d = (_inp("pulse1", pulse1), _inp("pulse2", pulse2))
    _interp(card, k, [1, 2] if k == 1 else [3, 4], PulseCard.line(d), False)
    return 0


def _arc(cardno: Any, no: Any, x: Any, y: Any, i: Any, j: Any, ccw: bool) -> None:
    card = _card(cardno)
    k = _no(no)
    end = (_inp("x", x), _inp("y", y))
    ctr = (_inp("i", i), _inp("j", j))
    _interp(card, k, [1, 2] if k == 1 else [3, 4], PulseCard.arc(end, ctr, ccw), True)


@_api()
def inp_cw_arc(cardno: int, no: int, x: int, y: int, i: int, j: int) -> int:
    """5.6: clockwise arc to ``(x, y)`` around ``(i, j)``, both relative to the start;
    end (0, 0): a full circle."""
    _arc(cardno, no, x, y, i, j, False)
    return 0


@_api()
def inp_ccw_arc(cardno: int, no: int, x: int, y: int, i: int, j: int) -> int:
    """5.7: counter-clockwise arc."""
    _arc(cardno, no, x, y, i, j, True)
    return 0


@_api()
def inp_move3(cardno: int, pulse1: int, pulse2: int, pulse3: int) -> int:
    """5.8: X-Y-Z line."""
    card = _card(cardno)
    d = (_inp("pulse1", pulse1), _inp("pulse2", pulse2), _inp("pulse3", pulse3))
    _interp34(card, [1, 2, 3], d)
    return 0


@_api()
def inp_move4(cardno: int, pulse1: int, pulse2: int, pulse3: int, pulse4: int) -> int:
    """5.9: X-Y-Z-W line."""
    card = _card(cardno)
    d = tuple(_inp(f"pulse{k + 1}", p) for k, p in enumerate((pulse1, pulse2, pulse3, pulse4)))
    _interp34(card, [1, 2, 3, 4], d)
    return 0


def _inp34_error(card: PulseCard) -> bool:
    """9.3: a 3/4-axis interpolation that stopped before its distance leaves an error that
    makes Z and W move wrongly until ``inp_clear``."""
    inp34 = _layer(card).inp34
    if not inp34 or bank(card.ctl).get(1).running:
        return False
    return any(abs(card.lp(a) - t) > 0.5 for a, t in inp34.items())


def _check_zw(card: PulseCard, axis: int) -> None:
    if axis in (3, 4) and _inp34_error(card):
        raise CompatError(
            "a 3/4-axis interpolation stopped before its end: Z and W do not move right "
            "until inp_clear (9.3)"
        )


def _interp34(card: PulseCard, axes: list[int], d: tuple[int, ...]) -> None:
    """5.8/5.9: the speed is X's; the card needs Z's multiplier (range) and drive speed
    equal to X's, and Z's start speed equal to X's drive speed. Decision: other Z settings
    are refused with 1 and the rule (the card runs them wrongly)."""
    _check_zw(card, 3)
    x, z = card.regs[1], card.regs[3]
    if (z.m, z.v, z.sv) != (x.m, x.v, x.v):
        raise CompatError(
            f"3/4-axis interpolation (5.8/5.9): Z needs X's range and speed and a start "
            f"speed equal to X's speed: X M={x.m:g} V={x.v}, Z M={z.m:g} V={z.v} SV={z.sv}"
        )
    running = bank(card.ctl).get(1).running
    for a, delta in zip(axes, d, strict=True):
        if a in (3, 4):
            inp34 = _layer(card).inp34
            base = inp34.get(a, card.lp(a)) if running else card.lp(a)
            inp34[a] = base + delta
    _interp(card, 1, axes, PulseCard.line(d), False)


@_api()
def inp_dec_enable(cardno: int, no: int) -> int:
    """5.10: the next nodes decelerate at their end."""
    _layer(_card(cardno)).dec_enabled[_no(no)] = True
    return 0


@_api()
def inp_dec_disable(cardno: int, no: int) -> int:
    """5.11: the next nodes run on at speed (continuous interpolation; the default)."""
    _layer(_card(cardno)).dec_enabled[_no(no)] = False
    return 0


@_api()
def inp_clear(cardno: int) -> int:
    """5.12 / 9.3: clear the error a 3/4-axis interpolation that did not end leaves."""
    _layer(_card(cardno)).inp34.clear()
    return 0


# --- 6. digital inputs and outputs --------------------------------------------------------
def _input(card: PulseCard, number: int) -> int:
    """The electrical level of input ``number`` (6.1: 0 low, 1 high), D0 X LMT+ ... D31
    W IN (:data:`~gtecat.compat._card.SIGNALS` per axis).

    The level is the wiring's (gtecat.compat._card, "Electrical levels"), not the
    logic setting's: with the power-up settings an active limit, STOP, INPOS or ALARM
    reads 0, so code that tests ``read_bit(0, 0) == 0`` for "X LMT+ hit" works as on the
    card.  The general input IN reads high (1): nothing in the machine drives it."""
    n, k = number // 8 + 1, number % 8
    assert SIGNALS[GPIN] == "IN"
    return card.level(n, k)


@_api()
def read_di(cardno: int, value: Any) -> int:
    """6.1: all 32 inputs, D0 X LMT+ ... D31 W IN, as electrical levels (0 low, 1 high)."""
    card = _card(cardno)
    out(value, sum(_input(card, b) << b for b in range(32)))
    return 0


@_api()
def write_do(cardno: int, value: int) -> int:
    """6.2: all 32 outputs."""
    card = _card(cardno)
    card.outputs = integer("value", value, 0, 0xFFFFFFFF)
    return 0


@_api(error=-1)
def read_bit(cardno: int, number: int) -> int:
    """6.3: one input's level, 0 low / 1 high, -1 on a bad card or input number."""
    card = _card(cardno)
    return _input(card, integer("number", number, 0, 31))


@_api()
def write_bit(cardno: int, number: int, value: int) -> int:
    """6.4: one output."""
    card = _card(cardno)
    b = integer("number", number, 0, 31)
    if _flag("value", value):
        card.outputs |= 1 << b
    else:
        card.outputs &= ~(1 << b)
    return 0


def read_outputs() -> int:
    """Emulator-only: the 32-bit output register (what the terminals show)."""
    card = _CARD[0]
    return card.outputs if card is not None else 0


# --- appendix B: the application library ----------------------------------------------------
@dataclass(slots=True)
class AppParams:
    """One axis's parameters of the vendor's tool (appendix B), in units and units/s."""

    pulses: float = 1000.0  #: pulses per unit (距离方式)
    work_speed: float = 10.0  #: 加工速度
    rapid_speed: float = 50.0  #: 空移速度
    start_speed: float = 1.0
    acc_time: float = 0.1  #: s from start speed to speed
    hand_speed: float = 5.0
    home_dir: int = 1  #: 0 positive, 1 negative
    home_speed: float = 5.0
    home_signal: int = 0  #: 0 home switch (STOP0), 1 encoder Z (STOP1)
    enabled: bool = True


_APP: dict[int, AppParams] = {}
_EXTERNAL = [False]
FUNCTION = Callable[[], Any] | None


def adt850_init_board(params: dict[int, AppParams] | None = None, **options: Any) -> int:
    """B.1: -3 no parameters, -2/-1/0 as adt850_initial, 1 done (R fitted to the speeds)."""
    if params is None:
        _set_error("adt850_init_board: no parameters (the vendor's tool writes them)")
        return -3
    rc = adt850_initial(**options)
    if rc <= 0:
        return rc
    _APP.clear()
    _APP.update({n: params.get(n, AppParams()) for n in AXES})
    for n in AXES:
        p = _APP[n]
        fastest = max(p.work_speed, p.rapid_speed, p.hand_speed, p.home_speed) * p.pulses
        m = min(max(math.ceil(fastest / 8000.0), 1), 500)
        set_range(0, n, round(8_000_000 / m))
    return 1


def _app(axis: int) -> AppParams:
    p = _APP.get(axis)
    if p is None:
        raise CompatError("call adt850_init_board first")
    return p


def _setup(axis: int, speed: float, startv: float, addtime: float) -> None:
    """Registers for ``speed`` (units/s) from ``startv`` over ``addtime`` s (B: free_move)."""
    card = _card(0)
    p = _app(axis)
    regs = card.regs[axis]
    m = regs.m
    sv = min(max(round(startv * p.pulses / m), 1), 8000)
    v = min(max(round(speed * p.pulses / m), 1), 8000)
    regs.sv, regs.v = sv, v
    if v > sv and addtime > 0:
        regs.a = min(max(round((v - sv) / addtime / 125.0), 1), 8000)
    regs.s_curve = regs.manual = regs.asym = False


#: how long an appendix B call waits for INPOS after its pulses (ms of controller time)
INPOS_WAIT_MS = 10_000.0


def _run(axes: list[int], pfn: FUNCTION, limit_stop: bool = True) -> int:
    """Run cycles until ``axes`` stand: 1 done, 0 stopped from outside, -3/-2 limits.

    Decision: with INPOS valid and never active (9.5: the drive never ends), the call
    stops waiting :data:`INPOS_WAIT_MS` after the pulses and returns 0, with the reason
    in :func:`last_error` (the library would wait for ever; a test must end)."""
    card = _card(0)
    _EXTERNAL[0] = False
    waited = 0.0
    while any(card.driving(n) for n in axes):
        if pfn is not None:
            pfn()
        card.wait_cycle()
        if not any(card.pulsing(n) for n in axes):
            waited += card.cycle_ms
            if waited > INPOS_WAIT_MS:
                _set_error(
                    f"the pulses are out but INPOS never came within {INPOS_WAIT_MS:g} ms "
                    "(set_inpos_mode valid, 9.5); the call gives up with 0"
                )
                for n in axes:
                    card.regs[n].await_inpos = False
                return 0
    if _EXTERNAL[0]:
        return 0
    data = 0
    for n in axes:
        data |= card.regs[n].stopdata
    if limit_stop and data & 0x18:
        return -3
    if data & 0xC0:
        return -2
    return 1


def _work(moves: list[tuple[int, float]], oppmode: int, speedmode: int, pfn: FUNCTION) -> int:
    card = _card(0)
    for n, _ in moves:
        if not _app(n).enabled:
            return -1
    for n, d in moves:
        p = _app(n)
        speed = p.work_speed if integer("speedmode", speedmode, 0, 1) == 0 else p.rapid_speed
        _setup(n, speed, p.start_speed, p.acc_time)
        target = round(real("d", d) * p.pulses)
        if integer("oppmode", oppmode, 0, 1):
            target -= round(card.lp(n))
        card.drive(n, abs(target), 1 if target >= 0 else -1)
    return _run([n for n, _ in moves], pfn)


def _b(fn: Callable[..., int]) -> Callable[..., int]:
    return _api(error=-1)(fn)


@_b
def work_move1(axis: int, d: float, oppmode: int, speedmode: int, pfn: FUNCTION = None) -> int:
    """B.6: one axis to ``d`` (relative 0 / absolute 1), work (0) or rapid (1) speed."""
    return _work([(integer("axis", axis, 1, 4), d)], oppmode, speedmode, pfn)


@_b
def work_move2(axis1, d1, axis2, d2, oppmode, speedmode, pfn: FUNCTION = None) -> int:
    """B.7."""
    return _work(
        [(integer("axis1", axis1, 1, 4), d1), (integer("axis2", axis2, 1, 4), d2)],
        oppmode,
        speedmode,
        pfn,
    )


@_b
def work_move3(axis1, d1, axis2, d2, axis3, d3, oppmode, speedmode, pfn: FUNCTION = None) -> int:
    """B.8."""
    moves = [
        (integer(f"axis{k}", a, 1, 4), d)
        for k, (a, d) in enumerate(((axis1, d1), (axis2, d2), (axis3, d3)), 1)
    ]
    return _work(moves, oppmode, speedmode, pfn)


@_b
def work_move4(d1, d2, d3, d4, oppmode, speedmode, pfn: FUNCTION = None) -> int:
    """B.9."""
    return _work(list(zip(AXES, (d1, d2, d3, d4), strict=True)), oppmode, speedmode, pfn)


def _free(moves: list[tuple[Any, ...]], oppmode: int, pfn: FUNCTION) -> int:
    card = _card(0)
    axes = []
    for axis, d, startv, speed, addtime in moves:
        n = integer("axis", axis, 1, 4)
        p = _app(n)
        if not p.enabled:
            return -1
        _setup(n, real("speed", speed), real("startv", startv), real("addtime", addtime))
        target = round(real("d", d) * p.pulses)
        if integer("oppmode", oppmode, 0, 1):
            target -= round(card.lp(n))
        card.drive(n, abs(target), 1 if target >= 0 else -1)
        axes.append(n)
    return _run(axes, pfn)


@_b
def free_move1(axis, d, startv, speed, addtime, oppmode, pfn: FUNCTION = None) -> int:
    """B.19: one axis to ``d`` with its own speeds (units/s) and acceleration time (s)."""
    return _free([(axis, d, startv, speed, addtime)], oppmode, pfn)


@_b
def free_move2(
    axis1,
    d1,
    startv1,
    speed1,
    addtime1,
    axis2,
    d2,
    startv2,
    speed2,
    adtime2,
    oppmode,
    pfn: FUNCTION = None,
) -> int:
    """B.20."""
    return _free(
        [(axis1, d1, startv1, speed1, addtime1), (axis2, d2, startv2, speed2, adtime2)],
        oppmode,
        pfn,
    )


@_b
def free_move3(
    axis1,
    d1,
    startv1,
    speed1,
    addtime1,
    axis2,
    d2,
    startv2,
    speed2,
    adtime2,
    axis3,
    d3,
    startv3,
    speed3,
    addtime3,
    oppmode,
    pfn: FUNCTION = None,
) -> int:
    """B.21."""
    return _free(
        [
            (axis1, d1, startv1, speed1, addtime1),
            (axis2, d2, startv2, speed2, adtime2),
            (axis3, d3, startv3, speed3, addtime3),
        ],
        oppmode,
        pfn,
    )


@_b
def free_move4(
    d1,
    startv1,
    speed1,
    addtime1,
    d2,
    startv2,
    speed2,
    adtime2,
    d3,
    startv3,
    speed3,
    addtime3,
    d4,
    startv4,
    speed4,
    addtime4,
    oppmode,
    pfn: FUNCTION = None,
) -> int:
    """B.22."""
    return _free(
        [
            (1, d1, startv1, speed1, addtime1),
            (2, d2, startv2, speed2, adtime2),
            (3, d3, startv3, speed3, addtime3),
            (4, d4, startv4, speed4, addtime4),
        ],
        oppmode,
        pfn,
    )


def _continue(moves: list[tuple[Any, Any]], speedmode: int, pfn: FUNCTION) -> int:
    card = _card(0)
    axes = []
    for axis, dr in moves:
        n = integer("axis", axis, 1, 4)
        p = _app(n)
        if not p.enabled:
            return -1
        speed = p.work_speed if integer("speedmode", speedmode, 0, 1) == 0 else p.rapid_speed
        _setup(n, speed, p.start_speed, p.acc_time)
        card.drive(n, None, -1 if _flag("dir", dr) else 1)
        axes.append(n)
    rc = _run(axes, pfn)
    return -3 if rc == 1 else rc  # a continuous move ends by a limit or from outside


@_b
def continue_move1(axis, dir, speedmode, pfn: FUNCTION = None) -> int:
    """B.14: one axis on until a limit (-3) or a stop from outside (0)."""
    return _continue([(axis, dir)], speedmode, pfn)


@_b
def continue_move2(axis1, dir1, axis2, dir2, speedmode, pfn: FUNCTION = None) -> int:
    """B.15."""
    return _continue([(axis1, dir1), (axis2, dir2)], speedmode, pfn)


@_b
def continue_move3(axis1, dir1, axis2, dir2, axis3, dir3, speedmode, pfn: FUNCTION = None) -> int:
    """B.16."""
    return _continue([(axis1, dir1), (axis2, dir2), (axis3, dir3)], speedmode, pfn)


@_b
def continue_move4(dir1, dir2, dir3, dir4, speedmode, pfn: FUNCTION = None) -> int:
    """B.17."""
    return _continue(list(zip(AXES, (dir1, dir2, dir3, dir4), strict=True)), speedmode, pfn)


@_b
def hand_move(axis: int, dir: int, pfn: FUNCTION = None) -> int:
    """B.18: on at the hand speed until a limit (-3) or a stop from outside (0)."""
    card = _card(0)
    n = integer("axis", axis, 1, 4)
    p = _app(n)
    if not p.enabled:
        return -1
    _setup(n, p.hand_speed, p.start_speed, p.acc_time)
    card.drive(n, None, -1 if _flag("dir", dir) else 1)
    rc = _run([n], pfn)
    return -3 if rc == 1 else rc


def _work_inp(
    no: int,
    axes: list[int],
    ds: list[float],
    oppmode: int,
    speedmode: int,
    pfn: FUNCTION,
    arc: tuple | None = None,
) -> int:
    card = _card(0)
    for n in axes:
        if not _app(n).enabled:
            return -1
    master = axes[0]
    p = _app(master)
    speed = p.work_speed if integer("speedmode", speedmode, 0, 1) == 0 else p.rapid_speed
    _setup(master, speed, p.start_speed, p.acc_time)
    _layer(card).dec_enabled[no] = True
    if arc is not None:
        card.regs[master].sv = card.regs[master].v  # an arc at constant speed (no S, no auto)
        _interp(card, no, axes, PulseCard.arc(*arc), True)
        return _run(axes, pfn)
    delta = []
    for n, d in zip(axes, ds, strict=True):
        t = round(real("d", d) * _app(n).pulses)
        if integer("oppmode", oppmode, 0, 1):
            t -= round(card.lp(n))
        delta.append(t)
    _interp(card, no, axes, PulseCard.line(tuple(delta)), False)
    return _run(axes, pfn)


@_b
def work_inp2(axis1, d1, axis2, d2, oppmode, speedmode, pfn: FUNCTION = None) -> int:
    """B.10: line of X-Y or Z-W (-4 other axes)."""
    pair = (integer("axis1", axis1, 1, 4), integer("axis2", axis2, 1, 4))
    if pair not in ((1, 2), (3, 4)):
        return -4
    return _work_inp(1 if pair == (1, 2) else 2, list(pair), [d1, d2], oppmode, speedmode, pfn)


@_b
def work_inp3(d1, d2, d3, oppmode, speedmode, pfn: FUNCTION = None) -> int:
    """B.11: X-Y-Z line."""
    return _work_inp(1, [1, 2, 3], [d1, d2, d3], oppmode, speedmode, pfn)


@_b
def work_inp4(d1, d2, d3, d4, oppmode, speedmode, pfn: FUNCTION = None) -> int:
    """B.12: X-Y-Z-W line."""
    return _work_inp(1, [1, 2, 3, 4], [d1, d2, d3, d4], oppmode, speedmode, pfn)


@_b
def work_arc(axis1: int, axis2: int, cood: Any, speedmode: int, pfn: FUNCTION = None) -> int:
    """B.13: the arc through three points ``cood`` = (x1, y1, x2, y2, x3, y3) in units,
    absolute: from the first to the third through the second (-5 axes, -4 no arc)."""
    card = _card(0)
    pair = (integer("axis1", axis1, 1, 4), integer("axis2", axis2, 1, 4))
    if pair not in ((1, 2), (3, 4)):
        return -5
    pts = [real("cood", float(c)) for c in list(cood)[:6]]
    if len(pts) != 6:
        return -4
    ux, uy = _app(pair[0]).pulses, _app(pair[1]).pulses
    (x1, y1), (x2, y2), (x3, y3) = [(pts[k] * ux, pts[k + 1] * uy) for k in (0, 2, 4)]
    det = 2.0 * (x1 * (y2 - y3) + x2 * (y3 - y1) + x3 * (y1 - y2))
    if abs(det) < 1e-9:
        return -4
    s1, s2, s3 = x1 * x1 + y1 * y1, x2 * x2 + y2 * y2, x3 * x3 + y3 * y3
    cx = (s1 * (y2 - y3) + s2 * (y3 - y1) + s3 * (y1 - y2)) / det
    cy = (s1 * (x3 - x2) + s2 * (x1 - x3) + s3 * (x2 - x1)) / det
    here = (card.lp(pair[0]), card.lp(pair[1]))
    ccw = det > 0  # the three points turn counter-clockwise
    if (round(here[0]), round(here[1])) != (round(x1), round(y1)):
        _set_error("work_arc: the axes do not stand on the arc's first point")
        return -4
    end = (round(x3 - here[0]), round(y3 - here[1]))
    ctr = (round(cx - here[0]), round(cy - here[1]))
    return _work_inp(
        1 if pair == (1, 2) else 2, list(pair), [], 0, speedmode, pfn, arc=(end, ctr, ccw)
    )


@_b
def one_stop(axis: int, mode: int) -> int:
    """B.23: stop one axis, 0 at once, 1 decelerating (a blocking call returns 0)."""
    card = _card(0)
    n = integer("axis", axis, 1, 4)
    _EXTERNAL[0] = True
    (card.decel_stop if _flag("mode", mode) else card.sudden_stop)(n)
    return 0


@_b
def all_stop(mode: int) -> int:
    """B.24: stop every axis."""
    card = _card(0)
    m = _flag("mode", mode)
    _EXTERNAL[0] = True
    for n in AXES:
        (card.decel_stop if m else card.sudden_stop)(n)
    return 0


def _value(axis: Any, mode: Any, pulses: float) -> float:
    n = integer("axis", axis, 1, 4)
    return pulses if integer("mode", mode, 0, 1) else pulses / _app(n).pulses


def get_logical_pos(axis: int, mode: int) -> float:
    """B.25: the logic position, in units (mode 0) or pulses (1); NaN on error."""
    try:
        card = _card(0)
        return _value(axis, mode, card.lp(integer("axis", axis, 1, 4)))
    except Exception as e:
        _set_error(f"get_logical_pos: {e}")
        return math.nan


def get_fact_pos(axis: int, mode: int) -> float:
    """B.26: the real position."""
    try:
        card = _card(0)
        return _value(axis, mode, card.ep(integer("axis", axis, 1, 4)))
    except Exception as e:
        _set_error(f"get_fact_pos: {e}")
        return math.nan


def get_move_speed(axis: int, mode: int) -> float:
    """B.27: the drive speed, units/s (mode 0) or PPS (1)."""
    try:
        card = _card(0)
        n = integer("axis", axis, 1, 4)
        return _value(axis, mode, card.speed(n) * card.regs[n].m)
    except Exception as e:
        _set_error(f"get_move_speed: {e}")
        return math.nan


def get_input(number: int) -> int:
    """B.28: one input, 0/1, -1 on error."""
    return read_bit(0, number)


def set_output(number: int, value: int) -> int:
    """B.29: one output, 0 right, 1 error."""
    return write_bit(0, number, value)


def _home(axes: list[int], pfn: FUNCTION) -> int:
    """B.2-B.5: each axis searches its home signal (STOP0 home switch, STOP1 encoder Z) in
    its direction at the home speed; 1 found (the counters become 0 there), -2 a limit
    came first, -1 a disabled axis, 0 stopped from outside.

    Decision: "-2 未检测到原点信号" also when the machine has neither the signal nor a limit
    switch ahead of the axis: the search is refused at once (a card would drive until
    someone stops it; a test would never end)."""
    card = _card(0)
    for n in axes:
        if not _app(n).enabled:
            return -1
    for n in axes:
        p = _app(n)
        if not card.signal_ahead(n, p.home_signal, -1 if p.home_dir else 1):
            signal = ("home switch (STOP0)", "encoder index (STOP1)")[p.home_signal]
            _set_error(
                f"home: axis {n} has no {signal} and no limit switch in its search "
                "direction: the search would never end"
            )
            return -2
    for n in axes:
        p = _app(n)
        regs = card.regs[n]
        regs.stop_on = [p.home_signal == 0, p.home_signal == 1, False]
        _setup(n, p.home_speed, p.start_speed, p.acc_time)
        card.drive(n, None, -1 if p.home_dir else 1)
    rc = _run(axes, pfn, limit_stop=False)
    if rc == 0:
        return 0
    found = 1
    missed = []
    for n in axes:
        regs = card.regs[n]
        regs.stop_on = [False, False, False]
        if regs.stopdata & 0x03:
            card.set_lp(n, 0)
            card.set_ep(n, 0)
        else:
            found = -2
            missed.append(n)
    if missed:
        _set_error(
            f"home: axis {', '.join(map(str, missed))} stopped before its home signal "
            f"(stop data {', '.join(f'{card.regs[n].stopdata:#04x}' for n in missed)}: "
            "a limit or an error, B.2)"
        )
    return found


@_b
def home1(axis: int, pfn: FUNCTION = None) -> int:
    """B.2: one axis home."""
    return _home([integer("axis", axis, 1, 4)], pfn)


@_b
def home2(axis1: int, axis2: int, pfn: FUNCTION = None) -> int:
    """B.3."""
    return _home([integer("axis1", axis1, 1, 4), integer("axis2", axis2, 1, 4)], pfn)


@_b
def home3(axis1: int, axis2: int, axis3: int, pfn: FUNCTION = None) -> int:
    """B.4."""
    return _home(
        [integer(f"axis{k}", a, 1, 4) for k, a in enumerate((axis1, axis2, axis3), 1)], pfn
    )


@_b
def home4(pfn: FUNCTION = None) -> int:
    """B.5."""
    return _home(list(AXES), pfn)


def card() -> PulseCard | None:
    """Emulator-only: the open card object (None before adt850_initial)."""
    return _CARD[0]
