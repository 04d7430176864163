"""EtherCAT bits behind the controller's terminals: ``GT_RelateEcatSlaveToMcGpoBit`` and
``GT_GetEcatAxisDOBit`` (vendor GTN header; field code maps a drive's 60FEh bit 16 or an IO
slave's output bit to a general-purpose output, then drives it with ``GT_SetDoBit(MC_GPO)``).

* ``GT_RelateEcatSlaveToMcGpoBit(gpo, ecatIndex, ecatType, bitOffset, pdoOffset)``:
  general-purpose output ``gpo`` (1..16, the controller's outputs) drives, every cycle from
  now on, ``ecatType`` 0: bit ``bitOffset`` (0..7) of byte ``pdoOffset`` of IO slave
  ``ecatIndex``'s output region (as ``GT_EcatIOBitWriteOutput`` addresses it); ``ecatType``
  1: bit ``bitOffset`` (0..31) of 60FEh:01 of axis ``ecatIndex + 1``.  The output's state
  (``GT_SetDo`` / ``GT_SetDoBit`` / ``GT_GetDo`` of ``MC_GPO``) is the bit: 1 = set.  A new
  relation for the same output replaces the old one; the outputs keep their relations
  until ``GT_TerminateEcatComm``.  Anything the bus does not have returns 7 at the call.
* ``GT_GetEcatAxisDOBit(axis, bitIndex, pValue)``: bit ``bitIndex`` (from 0) of the 60FEh:01
  the controller sends the drive (as ``GT_GetEcatAxisDO``): 0 or 1.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

from ..controller.core import Controller
from ..controller.digital_io import GPIO_COUNT, digital_io
from ..errors import ParameterError
from ._core import check_range, gt_function, store_bytes
from .axis_calls import bus_axis, reachable
from .bus_calls import _region

_DO = 0x60FE


@dataclass(frozen=True, slots=True)
class _Relation:
    kind: int
    index: int
    bit: int
    byte: int


class _GpoRelations:
    """Copies the mapped general-purpose outputs onto their EtherCAT bits before each exchange."""

    def __init__(self, ctl: Controller) -> None:
        self.ctl = ctl
        self.map: dict[int, _Relation] = {}

    def __call__(self, t: int, dt: int) -> None:
        gpo = digital_io(self.ctl).gpo
        for n, rel in self.map.items():
            _write(self.ctl, rel, bool(gpo >> (n - 1) & 1))


def _write(ctl: Controller, rel: _Relation, on: bool) -> None:
    if rel.kind == 0:
        image, raw = _region(ctl, rel.index, rel.byte, 1, write=True)
        cur = image.read_raw(raw, 1)[0]
        new = cur | (1 << rel.bit) if on else cur & ~(1 << rel.bit)
        if new != cur:
            image.write_raw(raw, bytes([new & 0xFF]))
        return
    io = ctl.axes[rel.index + 1].io
    cur = int(io.read(_DO, 1)) & 0xFFFFFFFF
    new = cur | (1 << rel.bit) if on else cur & ~(1 << rel.bit)
    if new != cur:
        io.write(_DO, new, 1)


def _relations(ctl: Controller) -> _GpoRelations:
    for f in ctl.pre_cycle:
        if isinstance(f, _GpoRelations) and f.ctl is ctl:
            return f
    r = _GpoRelations(ctl)
    ctl.pre_cycle.append(r)
    return r


@gt_function
def GT_RelateEcatSlaveToMcGpoBit(
    ctl: Controller, gpo: int, ecatIndex: int, ecatType: int, bitOffset: int, pdoOffset: int
) -> int:
    """Output ``gpo`` drives an EtherCAT bit from now on (the module docstring)."""
    n = int(gpo)
    if n > GPIO_COUNT:
        raise ParameterError(f"gpo={n}: the controller has general-purpose outputs 1..{GPIO_COUNT}")
    kind = int(ecatType)
    if kind == 0:
        rel = _Relation(
            0, int(ecatIndex), check_range("bitOffset", bitOffset, 0, 7), int(pdoOffset)
        )
        image, _ = _region(ctl, rel.index, rel.byte, 1, write=True)  # 7: no such byte
        outputs = image.layout.slaves[rel.index].out_bytes
        if rel.byte >= outputs:
            raise ParameterError(
                f"pdoOffset={rel.byte}: slave {rel.index} has {outputs} output byte(s)"
            )
    else:
        axis = int(ecatIndex) + 1
        ax = bus_axis(ctl, axis)
        if ax.io.get(_DO, 1) is None:
            raise ParameterError(f"ecatIndex={ecatIndex}: axis {axis} does not map 60FEh:01")
        rel = _Relation(1, axis - 1, check_range("bitOffset", bitOffset, 0, 31), 0)
    relations = _relations(ctl)
    relations.map[n] = rel
    _write(ctl, rel, bool(digital_io(ctl).gpo >> (n - 1) & 1))
    return 0


@gt_function
def GT_GetEcatAxisDOBit(ctl: Controller, axis: int, bitIndex: int, pValue: Any) -> int:
    """Bit ``bitIndex`` of the 60FEh:01 sent to the drive of ``axis``."""
    ax = bus_axis(ctl, axis)
    reachable(ax, _DO)
    value = int(ax.io.read(_DO, 1)) & 0xFFFFFFFF
    store_bytes(pValue, bytes([value >> int(bitIndex) & 1]))
    return 0
