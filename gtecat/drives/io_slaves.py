"""Virtual EtherCAT IO: digital/analog terminals and a modular coupler (ETG.5001 style).

An IO slave's process data is whatever its PDO mapping says (from the ENI).
The *field side* is what a scenario touches: outputs the master wrote are read
with :meth:`IoSlave.get_output`, inputs are set with :meth:`IoSlave.set_input`,
and :meth:`IoSlave.wire` connects an output bit to an input bit (a wire on the
terminal block), so a raw-data write comes back as an input one cycle later.

A modular coupler maps module ``n``'s inputs at ``0x6000 + 0x10*n`` and its
outputs at ``0x7000 + 0x10*n`` (ETG.5001.1 modular device profile); the
Googol coupler of manual figure 5-4 (IBM337 + DI16/DO16/AI4/AO4) is one.
:meth:`IoSlave.modules` groups the mapped objects that way.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable, Sequence
from dataclasses import dataclass
from typing import Any

from gtecat.eni.bits import get_bits, set_bits
from gtecat.eni.model import Direction, Identity, Pdo

from .pdo_mapping import is_gap
from .slave import AlState, AlStatusCode, VirtualSlave

# the states a cycle compares with, looked up once (an enum member's lookup costs more
# than the comparison)
_OP = AlState.OP
_SAFEOP = AlState.SAFEOP

_SIGNED_TYPES = {"SINT", "INT", "DINT", "LINT", "INT8", "INT16", "INT32", "INT64"}


@dataclass(frozen=True, slots=True)
class IoPoint:
    """One mapped object inside the slave's own rx (OUT) or tx (IN) buffer."""

    direction: Direction
    index: int
    subindex: int
    bit: int  # offset inside rx/tx
    bits: int
    name: str
    signed: bool


def _place(
    layout: Iterable[tuple[Direction, Iterable[tuple[int, int, int, str, bool]]]],
) -> dict[tuple[Direction, int, int], IoPoint]:
    """Field-side points from mapped entries ``(index, sub, bits, name, signed)`` in mapping
    order per direction: each at its bit inside rx/tx; gaps (index 0..7) take room only."""
    points: dict[tuple[Direction, int, int], IoPoint] = {}
    for direction, entries in layout:
        bit = 0
        for index, sub, bits, name, signed in entries:
            if not is_gap(index):
                points.setdefault(
                    (direction, index, sub),
                    IoPoint(direction, index, sub, bit, bits, name, signed),
                )
            bit += bits
    return points


class FieldInputs(bytearray):
    """What an IO slave's terminals see on their inputs.  Written from outside the slave's
    cycle (:meth:`IoSlave.set_input`, a test's ``slave.field_inputs[0] = 0x3C``, a fault),
    each write counts as a change of the bus (:attr:`VirtualSlave.outside_changes`): a
    controller that found the bus at a fixed point looks again.  (The slave's own wires
    count too: a cycle that steps the slave makes the controller look again anyway.)
    A write through the buffer protocol (``memoryview``, ``struct.pack_into``, ctypes'
    ``from_buffer``) cannot be counted: the controller compares the bytes with the ones
    its last look saw instead (:func:`look_at_fields`).  What changes the length counts
    too, so the bytes stay where that look found them while nothing was counted."""

    __slots__ = ()

    # (counted before the write, and where the length may change after it too: a compiled
    # check that finds the count as it armed it reads the bytes where they were then)
    def __setitem__(self, key: Any, value: Any) -> None:
        VirtualSlave.outside_changes += 1
        bytearray.__setitem__(self, key, value)
        if type(key) is slice:
            VirtualSlave.outside_changes += 1


def _counted(name: str) -> Callable[..., Any]:
    way = getattr(bytearray, name)

    def counted(self: FieldInputs, *args: Any) -> Any:
        VirtualSlave.outside_changes += 1
        try:
            return way(self, *args)
        finally:
            VirtualSlave.outside_changes += 1

    counted.__name__ = name
    counted.__doc__ = way.__doc__
    return counted


# (bytearray's in-place operators give back the bytearray itself: counted alike)
for _name in (
    "__delitem__",
    "__iadd__",
    "__imul__",
    "append",
    "extend",
    "insert",
    "pop",
    "remove",
    "clear",
    "reverse",
):
    setattr(FieldInputs, _name, _counted(_name))


def look_at_fields(slaves: Sequence[IoSlave]) -> None:
    """Count a change of the bus (:attr:`VirtualSlave.outside_changes`) where an IO slave's
    field inputs are no longer the bytes the last look saw (a write through the buffer
    protocol, which :class:`FieldInputs` cannot count), and keep them as seen now.  A few
    bytes compared per IO slave: asked before a steady bus is taken as still steady."""
    moved = False
    for s in slaves:
        fi = s._field_inputs
        if fi != s._fields_seen:
            s._fields_seen = bytes(fi)
            moved = True
    if moved:
        VirtualSlave.outside_changes += 1


class IoSlave(VirtualSlave):
    """A generic IO slave driven by its PDO mapping.

    Outputs only reach the field while the slave is in OP (in SAFEOP the
    outputs stay in their safe state: all zero), as ETG.1000.6 requires.
    """

    def __init__(
        self,
        position: int,
        name: str,
        identity: Identity,
        *,
        rx_pdos: Sequence[Pdo] = (),
        tx_pdos: Sequence[Pdo] = (),
    ) -> None:
        self.rx_pdos = tuple(rx_pdos)
        self.tx_pdos = tuple(tx_pdos)
        super().__init__(position, name, identity)
        self.points = _place(
            (
                d,
                [
                    (e.index, e.subindex, e.bit_len, e.name, e.data_type.upper() in _SIGNED_TYPES)
                    for pdo in pdos
                    for e in pdo.entries
                ],
            )
            for d, pdos in ((Direction.OUT, self.rx_pdos), (Direction.IN, self.tx_pdos))
        )
        self.field_inputs = bytearray(len(self.tx))  # what the terminals see on their inputs
        #: input bits a fault holds (a stuck input): bit -> 0 or 1, laid over the field inputs
        #: on their way to ``tx`` (after the wires); the field inputs stay what the field puts
        #: there, so an input let go reads the field's value at once (:meth:`hold_input_bit`)
        self.held: dict[int, int] = {}
        self._held_masks: tuple[bytes, bytes] | None = None
        self.field_outputs = bytearray(len(self.rx))  # what the terminals drive
        self._wires: list[tuple[int, int]] = []  # (output bit, input bit) in rx/tx numbering
        self._wire_plan: list[tuple[int, int, int, int]] | None = None  # see _plan_wires

    def pdo_sizes(self) -> tuple[int, int]:
        return (sum(p.bit_len for p in self.rx_pdos), sum(p.bit_len for p in self.tx_pdos))

    @property
    def field_inputs(self) -> FieldInputs:
        """What the terminals see on their inputs (:class:`FieldInputs`)."""
        return self._field_inputs

    @field_inputs.setter
    def field_inputs(self, value: Any) -> None:
        self._field_inputs = FieldInputs(value)
        self._fields_seen = bytes(self._field_inputs)  # (what :func:`look_at_fields` saw)
        VirtualSlave.outside_changes += 1

    # --- field side -----------------------------------------------------------
    def point(self, direction: Direction, index: int, subindex: int) -> IoPoint:
        try:
            return self.points[(direction, index, subindex)]
        except KeyError:
            kind = "output" if direction == Direction.OUT else "input"
            raise KeyError(
                f"slave {self.position} ({self.name}) maps no {kind} 0x{index:04X}:{subindex:02X}"
            ) from None

    def get_output(self, index: int, subindex: int) -> int:
        """The value the terminal drives for an output object (0 unless in OP)."""
        p = self.point(Direction.OUT, index, subindex)
        return get_bits(self.field_outputs, p.bit, p.bits, signed=p.signed)

    def set_input(self, index: int, subindex: int, value: int) -> None:
        """Set what the terminal reads on an input object (reported from the next cycle)."""
        p = self.point(Direction.IN, index, subindex)
        set_bits(self.field_inputs, p.bit, p.bits, int(value))

    def get_output_bit(self, bit: int) -> bool:
        return bool(get_bits(self.field_outputs, bit, 1))

    def set_input_bit(self, bit: int, on: bool) -> None:
        set_bits(self.field_inputs, bit, 1, int(bool(on)))

    def hold_input_bit(self, bit: int, value: int | None) -> None:
        """Hold input bit ``bit`` at ``value`` whatever the field puts there (a stuck input,
        a broken terminal), or let it go (``value`` None): from the next cycle ``tx`` carries
        the held value, then the field's again.  What the field puts there meanwhile
        (:meth:`set_input_bit`, a wire) is kept in the field inputs underneath."""
        if value is None:
            self.held.pop(int(bit), None)
        else:
            self.held[int(bit)] = int(bool(value))
        self._held_masks = None
        VirtualSlave.outside_changes += 1

    def _inputs(self) -> bytes | bytearray:
        """What ``tx`` carries: the field inputs with the held bits laid over them."""
        fi = self._field_inputs
        if not self.held:
            return fi
        masks = self._held_masks
        if masks is None or len(masks[0]) != len(fi):
            keep, put = bytearray(b"\xff" * len(fi)), bytearray(len(fi))
            for bit, v in self.held.items():
                if 0 <= bit < 8 * len(fi):  # (a bit a new mapping no longer has: none)
                    keep[bit >> 3] &= ~(1 << (bit & 7)) & 0xFF
                    put[bit >> 3] |= v << (bit & 7)
            masks = self._held_masks = (bytes(keep), bytes(put))
        keep, put = masks
        return bytes((b & k) | q for b, k, q in zip(fi, keep, put, strict=True))

    def wire(self, out_bit: int, in_bit: int) -> None:
        """Connect output bit ``out_bit`` (rx numbering) to input bit ``in_bit`` (tx numbering)."""
        if not 0 <= out_bit < len(self.rx) * 8:
            raise ValueError(f"slave {self.position}: no output bit {out_bit}")
        if not 0 <= in_bit < len(self.tx) * 8:
            raise ValueError(f"slave {self.position}: no input bit {in_bit}")
        self._wires.append((out_bit, in_bit))
        self._wire_plan = None
        VirtualSlave.outside_changes += 1

    def wire_objects(
        self, out: tuple[int, int], inp: tuple[int, int], bits: int | None = None
    ) -> None:
        """Wire a whole output object to an input object (bit for bit)."""
        po = self.point(Direction.OUT, *out)
        pi = self.point(Direction.IN, *inp)
        n = min(po.bits, pi.bits) if bits is None else bits
        for k in range(n):
            self.wire(po.bit + k, pi.bit + k)

    def modules(self) -> dict[int, list[IoPoint]]:
        """Mapped objects grouped by ETG.5001 module number (0x6000/0x7000 + 0x10*n)."""
        out: dict[int, list[IoPoint]] = {}
        for p in self.points.values():
            if 0x6000 <= p.index < 0x8000:
                n = (p.index & 0x0FFF) >> 4
                out.setdefault(n, []).append(p)
        return out

    # --- cycle ------------------------------------------------------------------
    def step(self, t_ns: int, dt_ns: int) -> None:
        if self.al_state == _OP:
            self.field_outputs[:] = self.rx
        else:
            self.field_outputs[:] = bytes(len(self.field_outputs))
        if self._wires:
            plan = self._wire_plan
            if plan is None:
                plan = self._wire_plan = self._plan_wires()
            fo, fi = self.field_outputs, self.field_inputs
            for ob, ib, shift, mask in plan:
                v = fo[ob] << shift if shift >= 0 else fo[ob] >> -shift
                fi[ib] = (fi[ib] & ~mask) | (v & mask)
        if self.al_state >= _SAFEOP:
            self.tx[:] = self._inputs()

    def settled(self) -> bool:
        """A :meth:`step` now would change nothing (its outputs reached the field, the wires
        and the field inputs reached ``tx``), given the same ``rx``."""
        if self.emergencies:
            return False
        fo = self.field_outputs
        if self.al_state == _OP:
            if fo != self.rx:
                return False
        elif any(fo):
            return False
        fi = self.field_inputs
        if self._wires:
            plan = self._wire_plan
            if plan is None:
                plan = self._wire_plan = self._plan_wires()
            for ob, ib, shift, mask in plan:
                v = fo[ob] << shift if shift >= 0 else fo[ob] >> -shift
                if (fi[ib] ^ v) & mask:
                    return False
        return self.al_state < _SAFEOP or self.tx == self._inputs()

    def _plan_wires(self) -> list[tuple[int, int, int, int]]:
        """The wires as byte operations ``(out byte, in byte, shift, in mask)``: the wires
        that move bits between the same two bytes by the same shift are one masked copy.
        Every wire reads the field outputs as they stand, so of several wires onto one
        input bit the last one wins (as when they ran one by one)."""
        last = {ib: ob for ob, ib in self._wires}
        groups: dict[tuple[int, int, int], int] = {}
        for ib, ob in last.items():
            key = (ob >> 3, ib >> 3, (ib & 7) - (ob & 7))
            groups[key] = groups.get(key, 0) | 1 << (ib & 7)
        return [(ob, ib, shift, mask) for (ob, ib, shift), mask in groups.items()]


class CoeIoSlave(IoSlave):
    """An IO slave with a CoE mailbox (an ETG.5001 coupler, an analog terminal...).

    Same object dictionary, PDO mapping/assignment objects (1600h-/1A00h-,
    1C12h/1C13h) and SDO server as the CiA-402 drive, so the CoE InitCmds an ENI
    carries for such a slave (acontis clears and re-assigns 1C12h/1C13h) work as
    on the real device.  The field side keeps the point layout of the mapping the
    master finally configured (recomputed at PREOP -> SAFEOP).  Mapped objects
    that the slave does not describe are held as PDO placeholders; their SDO
    upload reads what the process data holds last (outputs: the master's last
    RxPDO, inputs: the last TxPDO), as a real terminal's object does
    (ETG.5001: the mapped 0x6000/0x7000 objects *are* the process data).
    """

    has_mailbox = True

    def __init__(
        self,
        position: int,
        name: str,
        identity: Identity,
        *,
        rx_pdos: Sequence[Pdo] = (),
        tx_pdos: Sequence[Pdo] = (),
        device_type: int = 0x00001389,  # ETG.5001 modular device profile
        mailbox_size: int = 128,
    ) -> None:
        from .od import Access, DataType, ObjectDictionary, add_identity
        from .pdo_mapping import PdoMapping
        from .sdo_server import SdoServer

        self.od = ObjectDictionary()
        self.od.add_var(0x1000, "Device type", DataType.UINT32, Access.RO, default=device_type)
        self.od.add_var(0x1008, "Device name", DataType.VISIBLE_STRING, Access.CONST, default=name)
        add_identity(self.od, identity)
        self.mapping = PdoMapping(self.od, rx_pdos, tx_pdos)
        self.sdo = SdoServer(self.od, mailbox_size=mailbox_size)
        super().__init__(position, name, identity, rx_pdos=rx_pdos, tx_pdos=tx_pdos)
        self._link_process_data()

    def pdo_sizes(self) -> tuple[int, int]:
        return self.mapping.sizes()

    def _link_process_data(self) -> None:
        """Placeholders of mapped objects read (and write) their bits of ``rx``/``tx``.

        Read at SDO time, so the cycle pays nothing; the buffers are looked up on
        every access because a new mapping reallocates them.
        """
        for p in self.points.values():
            var = self.od.find(p.index, p.subindex)
            if var is None or not var.placeholder:
                continue
            if p.direction == Direction.OUT:
                var.getter = lambda p=p: get_bits(self.rx, p.bit, p.bits)
                var.setter = lambda v, p=p: set_bits(self.rx, p.bit, p.bits, int(v))
            else:
                var.getter = lambda p=p: get_bits(self.tx, p.bit, p.bits)

    def mailbox(self, request: bytes) -> bytes | None:
        return self.sdo.handle(request, self.al_state)

    mailbox.sdo_server_only = True  # type: ignore[attr-defined]  (as Cia402Drive.mailbox)

    def on_state_change(self, old: AlState, new: AlState) -> AlStatusCode:
        if old == AlState.PREOP and new == AlState.SAFEOP:
            self._relayout()
        return AlStatusCode.NO_ERROR

    def _relayout(self) -> None:
        """Field-side points from the mapping the master configured."""

        def entries(d: Direction) -> list[tuple[int, int, int, str, bool]]:
            out = []
            for index, sub, bits in self.mapping.entries(d):
                old = self.points.get((d, index, sub))
                out.append((index, sub, bits, old.name if old else "", bool(old and old.signed)))
            return out

        points = _place((d, entries(d)) for d in (Direction.OUT, Direction.IN))
        self.points = points
        rx_bits, tx_bits = self.mapping.sizes()
        self.field_outputs = bytearray((rx_bits + 7) // 8)
        self.field_inputs = bytearray((tx_bits + 7) // 8)
        self._link_process_data()
