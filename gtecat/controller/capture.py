"""Position capture of one encoder (GT_SetCaptureMode & co.): home, index (Z) and probe edges.

One :class:`CaptureUnit` per encoder (encoder N = axis N).  Every cycle, after the axis
has read its inputs and sampled its encoder, the unit collects the edges its inputs made
during the cycle (:attr:`CaptureUnit.edges`: which signal, became active or inactive, the
encoder value at the edge) and, while a capture mode is armed, latches the first edge
that matches it: ``GT_GetCaptureStatus`` then reports status 1 and that value until
``GT_ClearCaptureStatus`` (which re-arms the same mode) or a new ``GT_SetCaptureMode``.
Smart homing (:mod:`gtecat.controller.smart_home`) uses the same units and the same edges.

Where the edges come from, and how exact they are:

* **On a GTS card** (:mod:`gtecat.master.card`) the card's latch hardware sees the home
  input, the index pulse and the probe input (probe 1 of the machine description) together
  with the encoder: the card backend reports each edge with the fraction ``f`` of the
  cycle at which the mechanics crossed it, and the captured value is the encoder value
  at that instant, ``enc_now - (1 - f) * step`` (``step`` = the encoder's change during
  the cycle).  The motor moves linearly within a cycle, so this is the encoder count at
  the switch edge: within 1 count (the encoder reads whole counts).
* **On an EtherCAT axis** the controller sees what the drive sends.  The home switch is
  60FDh bit 2, sampled once per cycle: an edge lies somewhere in the cycle's travel,
  and the unit reports the middle of it, ``enc_now - step / 2`` - within half a cycle's
  travel (``|v| * T / 2``: 25 counts at 50 pulse/ms and 1 ms).  The index and the probe
  input are latched by the drive's touch probe 1 (60B8h source "zero impulse" for the
  index, "probe input" for the probe; continuous mode, new values told by the 60B9h
  toggle bits 6/7, values 60BAh/60BBh): exact to the count like the card.  The touch
  probe objects are used as PDO when mapped, else by SDO (read every cycle while the
  capture is armed: fine on the emulated bus; on a real bus map 60B8h/60B9h/60BAh).  A
  drive without touch probe makes ``GT_SetCaptureMode(..., CAPTURE_INDEX)`` return 1.
  Arming the touch probe takes two cycles (60B8h off, then on).  An application's own
  ``GT_SetTouchProbeFunction`` and an armed capture share probe 1: the last writer wins.
  The axis bank runs an axis whose probe is armed between two of the probe's edges
  (:meth:`CaptureUnit.bank_ready`): a cycle that would latch one runs here.

Edge senses (``GT_SetCaptureSense(encoder, mode, sense)``, THomePrm ``edge``): the
vendor's 0 = falling edge, 1 = rising edge, of the card's terminal.  The card's inputs are
active low (a triggered sensor pulls the line low), so **0 captures where the input
becomes active** (the switch is reached) and **1 where it becomes inactive** (the switch
is left); 0 is the reset state, as a vendor configuration file writes it
(``captureHomeSense=0``).  An index pulse has no width: both senses capture it.  A
``[homeN] reverse=1`` of the configuration file swaps active and inactive of the home
input where it disagrees with how the machine's switch is wired
(:func:`gtecat.controller.config_file.switch_sense`: a switch the machine description
leaves unwired is wired as the configuration expects).

Values are in encoder units (``GT_GetEncPos``), rounded to the ``long`` the API returns.
"""

from __future__ import annotations

import weakref
from collections.abc import Callable
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

from gtecat.drives.abort import SdoAbort
from gtecat.eni.errors import GtecatError

from .._attrs import PerObject
from ..errors import CommandError, ParameterError
from . import input_sense
from .axis import Axis

if TYPE_CHECKING:
    from .resources import AxisResources

CAPTURE_NONE = 0
CAPTURE_HOME = 1
CAPTURE_INDEX = 2
CAPTURE_PROBE = 3
MODES = (CAPTURE_NONE, CAPTURE_HOME, CAPTURE_INDEX, CAPTURE_PROBE)
MODE_NAMES = {CAPTURE_HOME: "home", CAPTURE_INDEX: "index", CAPTURE_PROBE: "probe"}
_SIGNALS = {"home": CAPTURE_HOME, "index": CAPTURE_INDEX, "probe": CAPTURE_PROBE}

_get = object.__getattribute__  # an axis the bank holds read without giving it back
_HOME_BIT = 1 << 2  # 60FDh bit 2
# 60B8h probe 1: enable | continuous | source (bits 3:2) | rising (4) | falling (5)
_TP_INDEX = 0x0001 | 0x0002 | 0x0004 | 0x0010
_TP_PROBE = 0x0001 | 0x0002 | 0x0010 | 0x0020
_TOGGLE_RISE, _TOGGLE_FALL = 1 << 6, 1 << 7


@dataclass(frozen=True, slots=True)
class SeenEdge:
    """One edge an input of the encoder made in the last cycle."""

    signal: int  #: CAPTURE_HOME / CAPTURE_INDEX / CAPTURE_PROBE
    active: bool  #: the input became active (the switch was reached)
    pos: float  #: encoder value at the edge
    exact: bool  #: latched by hardware (card, touch probe), not estimated from samples


def _wrap32(d: int) -> int:
    return (d + 0x8000_0000) % 0x1_0000_0000 - 0x8000_0000


class CaptureUnit:
    """The capture of encoder ``number`` (the module docstring says what it sees)."""

    #: the axis bank may hold this unit's axis (:func:`gtecat.controller.bank.aware_hooks`):
    #: with the touch probe idle, :meth:`_post` only follows the home input, so the bank runs
    #: the cycles and the unit catches up at the release; where an edge matters (a home
    #: capture armed, a reader of the level: :attr:`bank_watch`) the bank gives the axis
    #: back before the input changes
    bank_post_hook = True

    def __init__(self, ctl: Any, res: AxisResources) -> None:
        self.ctl = ctl
        self.res = res
        self.number = res.number
        self.ax: Axis = res.ax
        #: the axis's process data and mailbox (fixed with the axis; kept here so that the
        #: unit reaches its drive's objects without touching the axis the bank may hold)
        self._io = io = _get(self.ax, "io")
        self._tp_pdo = io.get(0x60B9) is not None  # (60B9h mapped: fixed with the layout)
        self._din = io.get(0x60FD)
        self._act = io.get(0x6064)
        card = getattr(ctl, "card", None)
        self._card_edges: dict[int, list] | None = card.backend.edges if card else None
        self.home_reverse = False
        #: the inputs' sense count (input_sense.EPOCH) :meth:`refresh_wiring` last looked at
        self._wired = -1
        # touch probe (EtherCAT axes): the 60B8h value wanted, what was written, phase
        self._tp_want = 0
        self._tp_sent = 0
        self._tp_pending = False
        self._tp_seen = 0
        self._tp_error = ""
        #: settings changed by a call (arm, clear, sense, reset, wiring): a count a watcher
        #: compares (smart homing: :meth:`SmartHome.quiet`)
        self.changes = 0
        #: how the cycles the bank runs poll 60B9h (bank_ready): (None, 0) not by SDO, else
        #: (the backend, the slave) that counts the uploads not sent (bank_released)
        self._tp_uploads: tuple[Any, int] = (None, 0)
        #: of the cycles the bank ran since it took the axis up, those whose 60B9h read was
        #: made already (:meth:`bank_pending_post`): not counted again at the release
        self._tp_read = 0
        self._level_watch = 0  # readers of the home level or edges every cycle (watch_level)
        self.reset_settings()
        self.edges: list[SeenEdge] = []
        self.step = 0.0
        self._home_prev = self.home_level()
        # (made while the bank runs the axis - a first GT_GetHomePrm, GT_SetCaptureMode -
        # the hook joins the row's without giving it back: AxisBank.hook_added)
        _get(self.ax, "post_hooks").append(self._post)
        bank = res.bank
        if bank is not None:
            bank.hook_added(self.ax, self)

    # --- settings --------------------------------------------------------------------------
    def reset_settings(self) -> None:
        """GT_Reset: no capture, status 0, every sense 0 (falling edge: switch reached)."""
        self.changes += 1
        self.mode = CAPTURE_NONE
        self.status = 0
        self.value = 0
        self.pos = 0.0
        self.sense = {CAPTURE_HOME: 0, CAPTURE_INDEX: 0, CAPTURE_PROBE: 0}
        self._edge: int | None = None
        self._accept: Callable[[float], bool] | None = None
        if self._tp_want or self._tp_sent:
            try:
                self._want_probe(0)
            except CommandError:
                pass  # the drive is gone: nothing to switch off

    def refresh_wiring(self) -> None:
        """Take ``[homeN] reverse`` from the configuration file loaded last (looked up again
        only after a change of some input's sense: every writer of a configuration, of the
        wiring or of the bus counts it in :data:`input_sense.EPOCH`)."""
        seen = input_sense.EPOCH[0]
        if seen == self._wired:
            return
        from .config_file import switch_sense

        reverse = switch_sense(self.ctl, "home", self.number)[1]  # the wiring it meets
        self._wired = seen
        if reverse != self.home_reverse:
            self.changes += 1
            self.home_reverse = reverse
            self._home_prev = self.home_level()

    @property
    def on_card(self) -> bool:
        return self._card_edges is not None

    def available(self, mode: int) -> str:
        """Why ``mode`` cannot be captured here ("" when it can)."""
        if mode == CAPTURE_HOME and self._din is None:
            return (
                f"encoder {self.number}: the home input 60FDh is not mapped as PDO on axis "
                f"{self.number}; map it in the ENI"
            )
        if mode in (CAPTURE_INDEX, CAPTURE_PROBE) and not self.on_card:
            if self._act is None:
                return f"encoder {self.number}: 6064h is not mapped; no position to capture"
            if self._tp_error:
                return self._tp_error
        return ""

    def arm(
        self,
        mode: int,
        edge: int | None = None,
        accept: Callable[[float], bool] | None = None,
    ) -> None:
        """GT_SetCaptureMode: wait for the next ``mode`` edge (status 0).

        ``edge`` overrides the mode's sense (THomePrm ``edge``); ``accept`` filters the
        captured position (smart homing: an index beyond the home).  CommandError when
        the axis cannot capture ``mode`` (the touch probe of an EtherCAT drive is armed
        at once, so a drive without one fails here)."""
        if mode not in MODES:
            raise ParameterError(
                f"mode={mode}: capture modes are 0 none, 1 CAPTURE_HOME, 2 CAPTURE_INDEX, "
                "3 CAPTURE_PROBE"
            )
        why = self.available(mode)
        if why:
            raise CommandError(why)
        self.refresh_wiring()
        self.changes += 1
        self.mode = mode
        self.status = 0
        self._edge = edge
        self._accept = accept
        if mode == CAPTURE_HOME:
            self._watch_grew()
        if not self.on_card:
            self._want_probe(
                _TP_INDEX if mode == CAPTURE_INDEX else _TP_PROBE if mode == CAPTURE_PROBE else 0
            )

    def try_index(self) -> None:
        """Whether the index can be captured here, as :meth:`arm` with ``CAPTURE_INDEX`` then
        with 0 finds it (GT_GoHome's test: an EtherCAT drive's touch probe answers now or
        never), leaving what those two leave - nothing armed, 60B8h off - with 60B8h
        written once (both wrote it off).  CommandError with the reason when it cannot."""
        why = self.available(CAPTURE_INDEX)
        if why:
            raise CommandError(why)
        self.refresh_wiring()
        self.changes += 1
        self.mode = CAPTURE_NONE
        self.status = 0
        self._edge = None
        self._accept = None
        if not self.on_card:
            self._tp_want = 0
            self._tp_pending = False
            try:
                self._write_tp(0)
            except (SdoAbort, GtecatError) as e:  # (as _want_probe says it)
                self._tp_error = (
                    f"encoder {self.number}: the drive's touch probe (60B8h) cannot be used: {e}"
                )
                raise CommandError(self._tp_error) from None

    def clear(self) -> None:
        """GT_ClearCaptureStatus: status 0, the mode armed again."""
        self.changes += 1
        self.status = 0
        if self.mode == CAPTURE_HOME:
            self._watch_grew()
        bank = self.res.bank
        if bank is not None:  # (the call is one of the bank's readers: no release)
            bank.look_again()

    def set_sense(self, mode: int, sense: int) -> None:
        if mode not in MODE_NAMES:
            raise ParameterError(f"mode={mode}: 1 CAPTURE_HOME, 2 CAPTURE_INDEX or 3 CAPTURE_PROBE")
        if sense not in (0, 1):
            raise ParameterError(f"sense={sense}: 0 (falling edge) or 1 (rising edge)")
        self.changes += 1
        self.sense[mode] = sense

    # --- levels -----------------------------------------------------------------------------
    def home_level(self) -> bool:
        """The home input is active now (sampled 60FDh bit 2, ``reverse`` applied)."""
        if self._din is None:
            return False
        return bool(self._din.get() & _HOME_BIT) != self.home_reverse

    @property
    def enc(self) -> float:
        """The encoder value of this cycle."""
        return self.res.encoder.pos

    # --- the axis bank ------------------------------------------------------------------------
    @property
    def bank_watch(self) -> int:
        """The 60FDh bits whose change gives the axis back before its cycle: the home input
        while a home capture is armed or someone reads its level or edges every cycle
        (:meth:`watch_level`); else none (the unit takes the level up at the release, and
        nobody reads the edges the cycles in between made)."""
        if self._level_watch or (self.mode == CAPTURE_HOME and not self.status):
            return _HOME_BIT
        return 0

    def watch_level(self, on: bool) -> None:
        """A reader of the home level or edges after every cycle starts (stops): smart
        homing's waits on the home input."""
        self._level_watch += 1 if on else -1
        if on:
            self._watch_grew()

    def _watch_grew(self) -> None:
        """An axis the bank holds without watching the home input gives it back (its next
        claim watches it)."""
        bank = self.res.bank
        if bank is not None:
            bank.watch_grew(self.ax)

    def bank_ready(self) -> bool:
        """The next cycles' :meth:`_post` can find an edge only where the home input changes
        its level (which the bank watches) or where the drive's touch probe latches one
        (the bank gives the axis back before a cycle whose travel reaches such an edge:
        ``CspBank.tp_lo``/``tp_hi``): no card latch, the touch probe off or armed with
        nothing being written, its status read from the image or by SDO uploads the bus
        can count without sending (:meth:`bank_released`), the home level the one last
        seen."""
        if self._card_edges is not None:
            return False
        if self._tp_pending:  # (the bank writes the function after its next cycle, if it can)
            bank = getattr(self.ctl, "bank", None)
            if bank is None or not bank.probe_in_bank(self.ax):
                return False
        elif self._tp_want != self._tp_sent:
            return False
        polled = self._tp_polled() if self._tp_sent else (None, 0)
        if polled is None:
            return False
        # (the claim follows this answer: its release counts the uploads of the cycles the
        # bank ran the way found now, whatever the bus looks like at the release)
        self._tp_uploads = polled
        self._tp_read = 0
        return self._home_prev == self.home_level()

    @property
    def bank_post_next(self) -> bool:
        """The touch probe is being armed (60B8h off written, the function due at the next
        cycle's :meth:`_post`): the bank runs that part of the unit's cycle after its own
        (:meth:`bank_pending_post`) and holds the axis meanwhile."""
        return self._tp_pending

    def bank_pending_post(self, cycles: int) -> bool:
        """The bank ran ``cycles`` cycles of the axis since it took it up, the last of which
        is the one after which :meth:`_post` writes the touch probe's function (60B8h: its
        drive's probe arms at the next cycle) and reads 60B9h; the cycles before it polled
        nothing (the probe was being armed).  That write and read, as :meth:`_post` makes
        them; the rest of that cycle's :meth:`_post` (its encoder step, the home level: no
        edge of an input nobody watches) is what a release or a posted edge takes up, as for
        any cycle the bank ran.  False: the reads from now on cannot be counted unsent (the
        axis must go back)."""
        out: list[SeenEdge] = []
        self._touch_probe(out, 0.0)  # (the pending branch: no edge, no position)
        self._tp_read = cycles
        polled = self._tp_polled() if self._tp_sent else (None, 0)
        if polled is None:
            return False
        self._tp_uploads = polled
        return True

    def _tp_polled(self) -> tuple[Any, int] | None:
        """How :meth:`_touch_probe` reads 60B9h: (None, 0) from the process image; (the
        backend, the slave) by an SDO upload the backend can count without sending it
        (``uploads_unframed``); None by one it must send."""
        io = self._io
        if self._tp_pdo:
            return None, 0
        backend = getattr(self.ctl, "backend", None)
        unframed = getattr(backend, "uploads_unframed", None)
        if unframed is None or not unframed(io.slave):
            return None
        return backend, io.slave

    def bank_released(self, cycles: int) -> None:
        """The bank ran ``cycles`` cycles of the axis: what :meth:`_post` would have left (this
        cycle's encoder step, the home level; no edge: the input did not change where it was
        watched, and where it was not, nobody reads the edges; the touch probe latched
        nothing, and the 60B9h reads by SDO that found it so are counted)."""
        if cycles:
            enc = self.res.encoder
            self.step = enc.vel * self.res.cycle_ms if enc.active else 0.0
            self.edges = []
            self._home_prev = self.home_level()
            backend, slave = self._tp_uploads
            if backend is not None:
                backend.uploads_answered(slave, cycles - self._tp_read)
        self._tp_read = 0

    def bank_post_ready(self) -> bool:
        """An edge of a watched input (:attr:`bank_watch`) or of the drive's touch probe may
        be taken after a cycle the bank ran (:meth:`bank_posted`) instead of in a cycle of the
        scalar objects: this cycle's :meth:`_post` then reads what the image's 60FDh, the
        encoder and the drive's probe (its objects, as the bank leaves them) show - no card
        latch, nothing of the probe being written."""
        return self._card_edges is None and not self._tp_pending and self._tp_want == self._tp_sent

    def bank_posted(self, cycles: int, t_ns: int, dt_ns: int) -> None:
        """The bank ran ``cycles`` cycles of the axis, the last of which changed a watched
        input or reached an edge of the drive's probe (its objects hold that cycle's state):
        the ones before as :meth:`bank_released` leaves them (no edge: what changed was
        watched, and the rest nobody reads; the 60B9h reads by SDO counted), then the last
        one's :meth:`_post`."""
        backend, slave = self._tp_uploads
        if backend is not None and cycles > 1:
            backend.uploads_answered(slave, cycles - 1 - self._tp_read)
        self._tp_read = 0
        if not self.bank_watch:
            self._home_prev = self.home_level()  # (an unwatched level: taken up, no edge)
        self._post(self.ax, t_ns, dt_ns)

    # --- the cycle ---------------------------------------------------------------------------
    def _post(self, ax: Axis, t_ns: int, dt_ns: int) -> None:
        enc = self.res.encoder
        step = enc.vel * self.res.cycle_ms if enc.active else 0.0
        self.step = step
        now = enc.pos
        out: list[SeenEdge] = []
        card = self._card_edges
        if card is not None:
            rev = self.home_reverse
            for e in card.get(self.number, ()):
                signal = _SIGNALS[e.signal]
                active = e.rising != rev if signal == CAPTURE_HOME else e.rising
                out.append(SeenEdge(signal, active, now - (1.0 - e.fraction) * step, True))
            self._home_prev = self.home_level()
        else:
            level = self.home_level()
            if level != self._home_prev:
                self._home_prev = level
                out.append(SeenEdge(CAPTURE_HOME, level, now - 0.5 * step, False))
            if self._tp_want or self._tp_sent:
                self._touch_probe(out, now)
        self.edges = out
        if out and self.mode and not self.status:
            self._latch(out)

    def _latch(self, edges: list[SeenEdge]) -> None:
        mode = self.mode
        sense = self._edge if self._edge is not None else self.sense[mode]
        want_active = sense == 0
        for e in edges:
            if e.signal != mode:
                continue
            if mode != CAPTURE_INDEX and e.active != want_active:
                continue
            if self._accept is not None and not self._accept(e.pos):
                continue
            self.status = 1
            self.pos = e.pos
            self.value = round(e.pos)
            return

    # --- touch probe 1 of an EtherCAT drive ------------------------------------------------------
    def _want_probe(self, function: int) -> None:
        if function == self._tp_want and not self._tp_pending:
            return
        self._tp_want = function
        try:
            self._write_tp(0)  # off first: the drive arms on the enable edge
            self._tp_pending = function != 0
        except (SdoAbort, GtecatError) as e:
            self._tp_want = 0
            self._tp_error = (
                f"encoder {self.number}: the drive's touch probe (60B8h) cannot be used: {e}"
            )
            raise CommandError(self._tp_error) from None

    def _write_tp(self, value: int) -> None:
        io = self._io
        bank = self.res.bank  # (a drive the bank runs keeps its row: AxisBank.write_probe)
        write = lambda: io.write_or_sdo(0x60B8, 0, value, 2)  # noqa: E731
        if bank is None or not bank.write_probe(self.ax, write):
            write()
        self._tp_sent = value

    def _touch_probe(self, out: list[SeenEdge], now: float) -> None:
        io = self._io
        try:
            if self._tp_pending:
                self._write_tp(self._tp_want)
                self._tp_pending = False
                self._tp_seen = io.read_or_sdo(0x60B9, 0, 2)
                return
            if not self._tp_sent:
                return
            status = io.read_or_sdo(0x60B9, 0, 2)
            changed = (status ^ self._tp_seen) & (_TOGGLE_RISE | _TOGGLE_FALL)
            self._tp_seen = status
            if not changed:
                return
            raw_now = self._act.get() if self._act is not None else 0
            unit = self.res.unit * self.res.encoder.sense
            signal = CAPTURE_INDEX if self._tp_want == _TP_INDEX else CAPTURE_PROBE
            for bit, index, active in ((_TOGGLE_RISE, 0x60BA, True), (_TOGGLE_FALL, 0x60BB, False)):
                if changed & bit:
                    latched = io.read_or_sdo(index, 0, 4, signed=True)
                    pos = now + unit * _wrap32(latched - raw_now)
                    out.append(SeenEdge(signal, active, pos, True))
        except (SdoAbort, GtecatError) as e:  # never let a field error escape the cycle
            self._tp_error = f"encoder {self.number}: touch probe read failed: {e}"
            self._tp_want = self._tp_sent = 0
            self._tp_pending = False


# --- the controller side -------------------------------------------------------------------------
_UNITS: PerObject[CaptureUnit] = PerObject("capture")
_HOOKED: weakref.WeakSet[Any] = weakref.WeakSet()


def capture_unit(ctl: Any, encoder: int) -> CaptureUnit:
    """The capture of ``encoder`` (= axis), made on first use; 7 when there is no such axis."""
    from .resources import axis_resources

    return unit_of(ctl, axis_resources(ctl, encoder))


def unit_of(ctl: Any, res: AxisResources) -> CaptureUnit:
    """The capture of the axis whose resources are ``res`` (no numbering involved: a core
    beyond 1 has mapped its local axis to ``res`` already; the unit belongs to the bus
    controller)."""
    base = getattr(ctl, "_base", ctl)
    unit = _UNITS.get(res)
    if unit is None:
        unit = _UNITS[res] = CaptureUnit(base, res)
    if base not in _HOOKED:
        _HOOKED.add(base)
        base.on_reset.append(_reset_units)
    return unit


def _reset_units(ctl: Any) -> None:
    for ax in ctl.axes.values():
        unit = _UNITS.get(ax.motion) if ax.motion is not None else None
        if unit is not None:
            unit.reset_settings()


__all__ = [
    "CAPTURE_HOME",
    "CAPTURE_INDEX",
    "CAPTURE_NONE",
    "CAPTURE_PROBE",
    "CaptureUnit",
    "SeenEdge",
    "capture_unit",
    "unit_of",
]
