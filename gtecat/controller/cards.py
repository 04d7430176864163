"""Several cards in one PC, and the second core of a card: what each one is.

Machines drive two to four cards from one program (AOI stations, dispensers): the vendor's
library keeps a *current card* that ``GT_SetCardNo(index)`` switches (cards 0..15) and every
later ``GT_*`` call addresses; ``GT_Open`` opens the current card.  The older multi-card
header puts ``short cardNum`` first in every function instead.  A GTN card has two cores,
each with its own axes, configuration file and status (``GTN_Reset(2)``,
``GTN_LoadConfig(2, "gtn_core2.cfg")``, ``GTN_ClrSts(2, 1, 12)``).  Decisions, where the
manual (``GT_Open(channel, param)``: channel the way to open the controller, param
reserved) and the headers say no more:

* **Each card is a controller of its own**: its own bus (or pulse hardware), axes,
  profiles, status, IO, configuration, MRAM and master log.  ``GT_Close`` closes the
  current card only; the others keep running.  ``channel`` and ``param`` of ``GT_Open``
  do not choose the card (they say how the host reaches it, and are not used).
* **The current card is one per process**, as in the vendor's library (a process-wide
  setting: a program with a thread per card takes its own lock around
  ``GT_SetCardNo`` and the calls that follow).  It may be set before ``GT_Open`` and
  is 0 at start.  The multi-card ABI needs no current card: each call carries its card,
  so its threads never race.  A program attached to a ``gtecat controller`` keeps its
  own current card; two programs on one controller do not disturb each other's.
* **What a card is**: card 0 is what ``GT_Open`` always opened (its keyword options,
  else ``GTECAT_*``, else the defaults).  Card N is **an identical controller** unless
  the machine description has a ``[card.N]`` table: the same ENI (its own emulated
  slaves), the same pulse-card personality, the same axes' mechanics, switches and
  extension modules; the ``[[fault]]`` tables stay with card 0.  A ``[card.N]`` table
  may say ``eni = "FILE"`` (relative to the description's folder), ``hardware =
  "gts:4"`` (a pulse card) or ``hardware = "ethercat"``, ``machine = "FILE.toml"`` (its
  own description), or hold the machine keys itself (``[card.N.axis.M]``,
  ``[card.N.ext.M]``, ``[[card.N.fault]]``: then they replace card 0's).  Python's
  ``GT_Open(eni=..., machine=..., ...)`` after ``GT_SetCardNo(N)`` wins over both.
* **Files**: the log, MRAM and pcap of card N are card 0's with ``.cardN`` before the
  suffix (``Gecat.card1.log``, ``Gecat.card1.mram``); of core 2, ``.core2``.
* **One time**: every card and core of the process shares one time
  (:class:`gtecat.master.clock.ClockGroup`): a call to card 0 lets time pass for card 1
  too, so an application polling one card sees the others move as on a real PC.
  ``GT_GetClock`` counts each card's own milliseconds since its ``GT_Reset``.
* **Core 2** of a card: while the card's EtherCAT bus has more than 32 axes, core *c*
  is bus axes 32·(c-1)+1 .. 32·c (:mod:`gtecat.controller.core_view`).  Otherwise core
  2 is the card's second core, a controller of its own like a second card, opened at its
  first call: by default a pulse core with the card's own pulse personality
  (``gts:N``), or ``gtn:12`` (twelve step/dir axes, the EtherCAT core's count) on an
  EtherCAT card; ``[core.2]`` of
  the description (``[card.N.core.2]`` for card N) says otherwise, with the keys of a
  ``[card.N]`` table.  A card has cores 1 and 2 (the vendor's GTN cards have two); core
  3 and up exist only as bus views.  ``GT_SetCore(core)`` (GTN header) chooses the core
  the ``GT_*`` functions address, 1 or 2, one per process like the current card.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Mapping
from pathlib import Path
from typing import Any

from gtecat.drives.machine import (
    MachineDescription,
    MachineError,
    machine_from_dict,
    refuse_unknown,
)

from ..errors import ParameterError
from .core import Controller, Options

#: the vendor numbers cards 0..15 (GT_SetCardNo)
MAX_CARDS = 16
#: the cores of one card (GTN)
CARD_CORES = 2
#: the pulse personality of core 2 on an EtherCAT card: 12 axes, as many as the EtherCAT
#: core's resources (chapter 13's axis range 1..12)
DEFAULT_CORE = "gtn:12"
#: keys of a [card.N] / [core.N] table besides the machine description's own
_KEYS = {"eni", "hardware", "machine", "log", "mram", "pcap", "core"}
_MACHINE_KEYS = {"axis", "ext", "glink", "fault", "card"}


def check_card(index: Any) -> int:
    try:
        i = int(index)
    except (TypeError, ValueError):
        raise ParameterError(f"card={index!r} is not an integer") from None
    if not 0 <= i < MAX_CARDS:
        raise ParameterError(f"card {i} out of range 0..{MAX_CARDS - 1}")
    return i


def tag(card: int, core: int) -> str:
    """``.card1``, ``.core2``, ``.card1.core2``; "" for card 0's core 1."""
    return (f".card{card}" if card else "") + (f".core{core}" if core != 1 else "")


def _suffixed(path: str | None, t: str) -> str | None:
    if not path or not t:
        return path
    p = Path(path)
    return str(p.with_name(p.stem + t + p.suffix))


def _machine(m: Any) -> MachineDescription:
    return Controller._load_machine(m)


def description(machine: MachineDescription, card: int, core: int) -> Mapping[str, Any]:
    """The ``[card.N]`` / ``[core.C]`` / ``[card.N.core.C]`` table of this unit ({}: none)."""
    table: Mapping[str, Any] = machine.cards.get(card, {}) if card else {}
    if core != 1:
        cores = table.get("core", {}) if card else {}
        if not card:
            return machine.cores.get(core, {})
        if not isinstance(cores, dict):
            raise MachineError(f"{machine.source}: [card.{card}.core.N] tables expected")
        return cores.get(str(core), cores.get(core, {}))
    return table


def options_for(
    base: Options,
    card: int,
    core: int,
    explicit: Options | None = None,
    *,
    hardware: str | None = None,
) -> Options:
    """The options of card ``card``, core ``core``: ``base`` (the first card's, resolved)
    changed by the machine description's table of that unit, then by the ``explicit``
    options of its own ``GT_Open`` (module docstring).  ``hardware``: the pulse
    personality of the card a core 2 belongs to (None: an EtherCAT card)."""
    machine = _machine(base.machine)
    where = f"{machine.source or 'machine description'}: [{_where(card, core)}]"
    desc = dict(description(machine, card, core))
    refuse_unknown(desc, _KEYS | _MACHINE_KEYS, where)
    folder = Path(machine.source).parent if machine.source else Path()

    def path(key: str) -> str:
        v = desc[key]
        if not isinstance(v, str) or not v:
            raise MachineError(f"{where}: {key} must be a file name")
        return str(folder / v)

    t = tag(card, core)
    o = dataclasses.replace(
        base,
        log=_suffixed(base.log, t),
        mram=_suffixed(base.mram or _mram_default(base.log), t),
        pcap=_suffixed(base.pcap, t),
        use_env=False,
    )
    if core != 1 and "hardware" not in desc:
        o.card = hardware or DEFAULT_CORE
    if "hardware" in desc:
        hw = desc["hardware"]
        if not isinstance(hw, str) or not hw:
            raise MachineError(f'{where}: hardware must be "ethercat" or "gts:N"')
        o.card = None if hw.strip().lower() == "ethercat" else hw
    if "eni" in desc:
        o.eni = path("eni")
    for key in ("log", "mram", "pcap"):
        if key in desc:
            setattr(o, key, path(key) if desc[key] else "")
    if "machine" in desc:
        o.machine = path("machine")
    elif set(desc) & (_MACHINE_KEYS - {"card"}):
        o.machine = machine_from_dict(desc, where, extra_keys=_KEYS)
    else:  # the same machine; its faults stay with card 0, its tables describe the others
        o.machine = dataclasses.replace(machine, faults=(), cards={}, cores={})
    if explicit is not None:
        for f in ("eni", "machine", "clock", "backend", "iface", "cycle_ms", "log", "bus"):
            v = getattr(explicit, f)
            if v is not None:
                setattr(o, f, v)
        for f in ("mram", "card", "pcap", "bank"):
            v = getattr(explicit, f)
            if v:
                setattr(o, f, v)
    return o


def _mram_default(log: str | None) -> str:
    from ..programs.mram import default_path

    return str(default_path(log))


def _where(card: int, core: int) -> str:
    if card and core != 1:
        return f"card.{card}.core.{core}"
    return f"card.{card}" if card else f"core.{core}"


__all__ = ["CARD_CORES", "DEFAULT_CORE", "MAX_CARDS", "check_card", "description", "options_for"]
