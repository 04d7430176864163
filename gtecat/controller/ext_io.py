"""Extension IO modules and gLink slaves of a controller: their terminals and their access.

The machine description lists what is plugged in (``[ext.N]``, ``[glink.N]``;
:mod:`gtecat.drives.ext_modules`).  Each module here holds what a wire would show: which inputs
are active, which outputs are on, the voltage on every analog channel, and whether the
module answers on its bus.  A scenario drives the field side (:class:`ExtModule`'s
``set_input`` / ``set_voltage`` / ``online``, or ``GTE_SetExtDi`` / ``GTE_SetExtAdVoltage``
from C) and reads the outputs (``output`` / ``ao_voltage``); the application sees
levels through the ``GT_*ExtIo*`` functions (:mod:`gtecat.gt.ext_io_calls`).

Decisions the vendor leaves open:

* **Levels.**  The registers hold terminal *levels*; ``active_low`` (per module, else the
  family's wiring: GTS ``ExtMdl`` modules active low, GTN cores and gLink active high)
  says which level is "on".  Inputs that a module does not have read the inactive level.
* **Power-on and resets.**  Outputs start off and inputs inactive.  ``GT_ResetExtMdl``
  switches every output of the modules off; ``GT_Reset`` does not touch them (the vendor's
  reset clears the card's own outputs; the modules hang on their own bus).  Closing the
  access (``GT_CloseExtMdl``) leaves the outputs as they are.
* **Analog.**  A channel holds volts; the vendor's raw values map linearly onto the
  module's range: ``unsigned short`` 0..65535 for the GTS ``ExtMdl`` functions, ``short``
  -32768..32767 over +-max(|low|, |high|) for the GTN cores' ``*Value`` functions.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

from gtecat.drives.ext_modules import ExtModuleSpec

from .._attrs import PerObject
from ..errors import ParameterError

#: the families that address modules (their default wiring: active low?)
GTS_EXTMDL, GTN_EXT, GLINK = "gts", "gtn", "glink"
_DEFAULT_ACTIVE_LOW = {GTS_EXTMDL: True, GTN_EXT: False, GLINK: False}


@dataclass(eq=False)
class ExtModule:
    """One module (or gLink slave): the field side and the registers behind the API."""

    number: int
    spec: ExtModuleSpec
    #: input terminals that are active (bit i = input i)
    inputs: int = 0
    #: output terminals that are on (bit i = output i)
    outputs: int = 0
    #: the bits an application wrote beyond the outputs the module has (read back as written)
    _spare_levels: int = 0
    ai: list[float] = field(default_factory=list)
    ao: list[float] = field(default_factory=list)
    #: the module answers on its bus (a scenario unplugs it with ``online = False``)
    online: bool = True

    def __post_init__(self) -> None:
        self.ai = [0.0] * self.spec.ai
        self.ao = [0.0] * self.spec.ao

    # --- the field side ---------------------------------------------------------------
    def set_input(self, index: int, active: bool) -> None:
        """Input ``index`` (from 0) becomes active or inactive."""
        i = _index("input", index, self.spec.di)
        self.inputs = self.inputs | (1 << i) if active else self.inputs & ~(1 << i)

    def output(self, index: int) -> bool:
        """Whether output ``index`` (from 0) is on."""
        return bool(self.outputs >> _index("output", index, self.spec.do) & 1)

    def set_voltage(self, channel: int, volts: float) -> None:
        """The voltage on analog input ``channel`` (from 0), clipped to the module's range."""
        c = _index("analog input", channel, self.spec.ai)
        lo, hi = self.spec.ai_range
        self.ai[c] = min(max(float(volts), lo), hi)

    def ao_voltage(self, channel: int) -> float:
        """The voltage analog output ``channel`` (from 0) drives."""
        return self.ao[_index("analog output", channel, self.spec.ao)]

    # --- levels (what the registers show) -------------------------------------------------
    def active_low(self, family: str) -> bool:
        if self.spec.active_low is not None:
            return self.spec.active_low
        return _DEFAULT_ACTIVE_LOW[family]

    def input_levels(self, family: str, width: int = 32) -> int:
        mask = (1 << width) - 1
        return (~self.inputs if self.active_low(family) else self.inputs) & mask

    def output_levels(self, family: str, width: int = 32) -> int:
        have = (1 << self.spec.do) - 1
        on = self.outputs & have
        levels = (~on & have) if self.active_low(family) else on
        return (levels | (self._spare_levels & ~have)) & ((1 << width) - 1)

    def write_output_levels(self, family: str, levels: int, mask: int = 0xFFFFFFFF) -> None:
        """Outputs under ``mask`` take ``levels``; bits past the module's outputs are kept."""
        have = (1 << self.spec.do) - 1
        on = ~levels if self.active_low(family) else levels
        self.outputs = (self.outputs & ~(mask & have)) | (on & mask & have)
        self._spare_levels = (self._spare_levels & ~mask) | (levels & mask & ~have)

    def all_off(self) -> None:
        self.outputs = 0
        self._spare_levels = 0
        self.ao = [0.0] * self.spec.ao


def _index(what: str, index: int, count: int) -> int:
    i = int(index)
    if not 0 <= i < count:
        have = f"0..{count - 1}" if count else "none"
        raise ParameterError(f"{what} {i} does not exist: the module has {count} ({have})")
    return i


class ExtIo:
    """Every module of one controller and the state of the three access paths."""

    def __init__(self, machine: Any) -> None:
        self.modules = {n: ExtModule(n, s) for n, s in getattr(machine, "ext", {}).items()}
        self.glink = {n: ExtModule(n, s) for n, s in getattr(machine, "glink", {}).items()}
        self.source = getattr(machine, "source", "") or "the machine description"
        #: GTS ExtMdl access: GT_OpenExtMdl, GT_LoadExtConfig, GT_SetExtMdlMode
        self.opened = False
        self.configured = False
        self.config_file = ""
        self.mode = 0
        #: GTN cores: GTN_ExtModuleInit; gLink: GT_GLinkInit
        self.gtn_ready = False
        self.gtn_method = 1
        self.glink_ready = False

    def flat(self) -> list[ExtModule]:
        """The modules in bus order (the GTN cores number their terminals through them)."""
        return [self.modules[n] for n in sorted(self.modules)]


_EXT: PerObject[ExtIo] = PerObject("ext_io")


def ext_io(ctl: Any) -> ExtIo:
    """The extension IO of controller ``ctl`` (made from its machine description on first use)."""
    base = getattr(ctl, "_base", ctl)  # a core view shares its controller's modules
    io = _EXT.get(base)
    if io is None:
        io = _EXT[base] = ExtIo(base.machine)
    return io


__all__ = ["GLINK", "GTN_EXT", "GTS_EXTMDL", "ExtIo", "ExtModule", "ext_io"]
