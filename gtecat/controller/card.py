"""The GTS pulse-card personality of the controller (``GTECAT_CARD=gts:N``).

A controller opened with a card is the same core as the EtherCAT one - profiles, axis
resources (chapter 4), motion modes, safety, status, smart homing - over the card's own
hardware instead of a bus (:mod:`gtecat.master.card`: N step/dir axes driving amplifiers
with the mechanics model, their encoders and inputs).  What differs, decided here:

* **Bring-up.**  ``GT_Open`` powers the card: its axes exist at once, the amplifiers are
  ready (switched off), motion control needs no ``GT_InitEcatComm`` /
  ``GT_StartEcatComm``; ``GT_AxisOn`` switches an axis's enable output (the amplifier
  walks to *enabled*, a few cycles) and every chapter 6/7/9 function works as on a card.
  The power-up takes the cycles the amplifiers need (about 12 ms of controller time,
  before ``GT_Reset`` starts ``GT_GetClock`` from 0).
* **EtherCAT functions** (every ``*Ecat*`` function, the drive homing and touch-probe
  calls, ``GT_SetPosScale``, the cable helpers ``GTE_UnplugSlave``/``GTE_ReplugSlave``)
  return 1 with a reason naming the card: the card has no bus (:data:`REFUSED_WORDS` and
  :data:`REFUSED_NAMES`; the GT layer applies them, :mod:`gtecat.gt._core`).
* **Inputs.**  The machine description of axis N is the card's terminals of axis N:
  positive/negative limit, home switch, index (Z) of the encoder, probe 1.  The alarm
  input of axis N is its amplifier's alarm output (the amplifier in fault: a scenario
  injects one with ``GTE_Slave(N - 1).channel(0).inject_fault(...)``).  A vendor
  configuration file (``GT_LoadConfig``) wires them as on the card (``limitNegativeIndex``
  etc.: index -1 = none).
* **Capture** is the card's hardware latch (exact to the count, :mod:`gtecat.controller.capture`).
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from ..errors import BusError, CommandError
from ..master.bus import Master
from ..master.card import CardBackend, CardSpec, card_layout, parse_card
from .axis import Axis, AxisIo
from .input_sense import changed as sense_changed
from .resources import install as install_resources

if TYPE_CHECKING:
    from .core import Controller

#: GT functions whose name holds one of these words need an EtherCAT bus
REFUSED_WORDS = ("Ecat",)
#: and these too (drive homing mode, touch probe, EtherCAT encoder scale, cable helpers)
REFUSED_NAMES = frozenset(
    {
        "GT_SetHomingMode",
        "GT_SetTouchProbeFunction",
        "GT_SetTouchProbeFunctionEx",
        "GT_GetTouchProbeStatus",
        "GT_SetPosScale",
        "GT_GetPosScale",
        "GTE_UnplugSlave",
        "GTE_ReplugSlave",
    }
)
#: cycles the amplifiers may take to come up at GT_Open
_POWER_UP_CYCLES = 200


def refused(name: str) -> bool:
    """Whether GT function ``name`` needs an EtherCAT bus (refused on a card)."""
    return name in REFUSED_NAMES or any(w in name for w in REFUSED_WORDS)


class Card:
    """What the controller knows of its card: the spec and the hardware below it."""

    def __init__(self, spec: CardSpec, backend: CardBackend) -> None:
        self.spec = spec
        self.backend = backend

    @property
    def description(self) -> str:
        return f"{self.spec.name} pulse card ({self.spec.kind}:{self.spec.axes})"

    def refusal(self, name: str) -> str:
        """The reason a refused function returns 1."""
        return (
            f"{name} needs an EtherCAT bus; this controller is a {self.description} "
            "(chosen by GTECAT_CARD, the machine file or GT_Open(card=...); a GTN core 2 is one by "
            "default): its axes work without GT_InitEcatComm, use the card's own "
            "functions (GT_GetDi, GT_GetEncPos, GT_GoHome, ...)"
        )


def open_card(ctl: Controller, text: str) -> Card:
    """Power up the card ``text`` names (``gts:4``) under controller ``ctl``."""
    spec = parse_card(text)
    layout = card_layout(spec, ctl.clock.cycle_ns / 1000)
    backend = CardBackend(spec, ctl.machine, layout)
    master = Master(layout, backend, op_delay_cycles=ctl.options.op_delay_cycles)
    ctl.layout, ctl.backend, ctl.master = layout, backend, master
    ctl.axes = {ref.axis: Axis(ref.axis, AxisIo.on(master, layout, ref)) for ref in layout.axes}
    ctl._axis_list = list(ctl.axes.values())
    sense_changed()  # (other axes: their inputs' sense is looked up again)
    install_resources(ctl)
    master.open()
    clock = ctl.clock
    for _ in range(_POWER_UP_CYCLES):
        if master.ready:
            break
        clock.cycle()  # GT_Open runs before any cycle thread: cycles run here, in order
    if not master.ready:
        raise BusError(f"{spec.name}: the amplifiers did not come up ({master.error})")
    ctl.started = True
    card = Card(spec, backend)
    ctl.card = card
    ctl.log(f"{card.description}: {spec.axes} axes powered up.")
    for hook in [*ctl.on_bus_up, *type(ctl).bus_up_hooks]:
        hook(ctl)
    return card


def require_card(ctl: Controller, what: str) -> Card:
    card = getattr(ctl, "card", None)
    if card is None:
        raise CommandError(f"{what}: this controller is not a pulse card (GTECAT_CARD)")
    return card


__all__ = ["REFUSED_NAMES", "REFUSED_WORDS", "Card", "open_card", "refused", "require_card"]
