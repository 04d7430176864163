"""The controller's general-purpose terminals: ``MC_GPI`` inputs, ``MC_GPO`` / ``MC_CLEAR`` outputs.

A GTS card has 16 general-purpose inputs and 16 outputs of its own (and one enable and
one alarm-clear output per axis).  Nothing on the machine side drives the inputs: a
scenario sets them (``GTE_SetGpi``); the outputs are registers a test reads back
(``GT_GetDo``).  The per-axis inputs (limits, home, alarm, arrive) are not stored here:
``GT_GetDi`` reads them from each axis (:mod:`gtecat.gt.io_calls`).  The registers exist on
both personalities (card and EtherCAT core) and survive ``GT_Reset`` as wired terminals do,
except the outputs, which ``GT_Reset`` switches off.
"""

from __future__ import annotations

from typing import Any

from .._attrs import PerObject
from ..errors import ParameterError

#: general-purpose inputs and outputs (MC_GPI / MC_GPO 1..16)
GPIO_COUNT = 16
_MASK = (1 << GPIO_COUNT) - 1


class DigitalIo:
    """The terminal registers of one controller (bit i = terminal i + 1)."""

    __slots__ = ("clear", "gpi", "gpo")

    def __init__(self) -> None:
        self.gpi = 0
        self.gpo = 0
        self.clear = 0

    def set_gpi(self, index: int, active: bool) -> None:
        if not 1 <= index <= GPIO_COUNT:
            raise ParameterError(f"gpi {index} out of range 1..{GPIO_COUNT}")
        bit = 1 << (index - 1)
        self.gpi = self.gpi | bit if active else self.gpi & ~bit

    def gpi_level(self, index: int) -> bool:
        return bool(self.gpi >> (index - 1) & 1)

    def set_gpo(self, value: int) -> None:
        self.gpo = int(value) & _MASK

    def reset(self) -> None:
        """GT_Reset: outputs off; input levels are the field's."""
        self.gpo = 0
        self.clear = 0


_IO: PerObject[DigitalIo] = PerObject("digital_io")


def digital_io(ctl: Any) -> DigitalIo:
    """The registers of controller ``ctl`` (made on first use, reset by GT_Reset)."""
    io = _IO.get(ctl)
    if io is None:
        io = _IO[ctl] = DigitalIo()
        ctl.on_reset.append(lambda c: io.reset())
    return io


__all__ = ["GPIO_COUNT", "DigitalIo", "digital_io"]
