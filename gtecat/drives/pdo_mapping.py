"""PDO mapping (1600h-/1A00h-) and assignment (1C12h/1C13h) objects, and the process-data codec.

The objects live in the object dictionary (CiA 301 7.5.2.35-36, ETG.1000.6
5.6.7.4): a mapping object's subindex n holds ``index << 16 | subindex << 8 |
bit length``; an assignment object's subindex n holds a mapping object's
index.  Both are writable only in INIT/PREOP, and only in the order ETG.1000.6
prescribes: SI0 := 0, entries, SI0 := n (an entry written while SI0 != 0 is
refused with 0x06010003).  Complete access is supported for all of them.

:meth:`PdoMapping.compile` turns the *current* assignment into a
:class:`PdoCodec`: one precompiled ``struct`` format for the byte-aligned
entries of each direction, :mod:`gtecat.eni.bits` for sub-byte ones.  The drive
recompiles at PREOP -> SAFEOP, so the layout on the bus is always what the
master configured.
"""

from __future__ import annotations

import functools
import logging
import struct
from collections.abc import Callable, Iterable, Sequence
from dataclasses import dataclass
from functools import partial
from typing import Any

from gtecat.drives.abort import SdoAbort, SdoAbortCode
from gtecat.drives.od import (
    PREOP_ONLY,
    Access,
    DataType,
    ObjectCode,
    ObjectDictionary,
    PdoDir,
    SlotVariable,
    Variable,
)
from gtecat.eni.bits import get_bits, set_bits
from gtecat.eni.model import Direction, Pdo

log = logging.getLogger(__name__)

RX_ASSIGN = 0x1C12
TX_ASSIGN = 0x1C13
RX_MAP_RANGE = range(0x1600, 0x1800)
TX_MAP_RANGE = range(0x1A00, 0x1C00)
#: object ranges whose unknown members a PDO mapping may name (manufacturer, profiles)
PLACEHOLDER_RANGE = range(0x2000, 0xA000)


def pack_entry(index: int, subindex: int, bits: int) -> int:
    """A mapping entry value: index in bits 31..16, subindex 15..8, bit length 7..0."""
    return (index << 16) | (subindex << 8) | bits


def unpack_entry(value: int) -> tuple[int, int, int]:
    return value >> 16, (value >> 8) & 0xFF, value & 0xFF


def is_gap(index: int) -> bool:
    """Padding entries: index 0 (ETG) or a CiA 301 dummy data-type index 0x0001-0x0007."""
    return index <= 0x0007


@functools.cache
def _names(head: str, n: int) -> tuple[str, ...]:
    """``head 1`` .. ``head n``: one set of entry names for every drive's objects."""
    return tuple(f"{head} {k + 1}" for k in range(n))


class _SlotEntries:
    """Makes a mapping or assignment object's entries as they are looked at: the one entry
    a read or write names (a bus's start-up writes four or five of a mapping's seventeen,
    two of an assignment's nine), all of them when the whole object is (those made before
    among them: an entry, once made, is the object's for good)."""

    __slots__ = ("access", "assign", "cap", "index", "made", "owner", "put", "slots")

    def __init__(
        self,
        owner: PdoMapping,
        index: int,
        slots: _Slots,
        cap: int,
        access: Access,
        *,
        assign: bool = False,
    ) -> None:
        self.owner, self.index, self.slots, self.cap, self.access = owner, index, slots, cap, access
        self.assign = assign
        self.made: dict[int, Variable] | None = None
        #: (k, value) -> the write of entry k+1, shared by the entries
        self.put: Callable[[int, Any], None] | None = None

    def __call__(self) -> list[Variable]:
        return [self.one(k) for k in range(self.cap + 1)]  # type: ignore[misc]

    def one(self, subindex: int) -> Variable | None:
        """Entry ``subindex`` (None: the object has none)."""
        if not 0 <= subindex <= self.cap:
            return None
        made = self.made
        if made is None:
            made = self.made = {}
        var = made.get(subindex)
        if var is None:
            var = made[subindex] = self.owner._slot_entry(self, subindex)
        return var


@dataclass(slots=True)
class _Slots:
    """Values behind one mapping or assignment object."""

    count: int
    values: list[int]
    fixed: bool = False


def _sm_types() -> list[Variable]:
    """1C00h's entries (made when the object is first looked at: a bus's start-up never
    does), as :meth:`ObjectDictionary.add_record` makes them: the count, then SM0..SM3's
    communication types (mailbox out, mailbox in, outputs, inputs)."""
    types = [
        Variable(0x1C00, k + 1, f"SM{k} type", DataType.UINT8, Access.RO, default=t)
        for k, t in enumerate((1, 2, 3, 4))
    ]
    count = Variable(0x1C00, 0, "Number of entries", DataType.UINT8, Access.RO, default=4)
    return [count, *types]


class PdoMapping:
    """Mapping and assignment objects of one slave, and the compiler of its codec.

    ``strict`` refuses what a real device would (unknown objects 0x06040041,
    wrong bit length 0x06040043, unknown PDOs in an assignment 0x06090030).
    Lenient mode (the default of the virtual drive) accepts what an ENI made
    for some real drive configures: unknown objects become placeholders,
    unknown PDO indices get an empty mapping object, odd bit lengths are
    packed as written.  Objects the device knows to be unmappable are refused
    in both modes.
    """

    def __init__(
        self,
        od: ObjectDictionary,
        rx_pdos: Sequence[Pdo] = (),
        tx_pdos: Sequence[Pdo] = (),
        *,
        spare_rx: Iterable[int] = (0x1600, 0x1601, 0x1602, 0x1603),
        spare_tx: Iterable[int] = (0x1A00, 0x1A01, 0x1A02, 0x1A03),
        max_entries: int = 16,
        max_assigned: int = 8,
        max_bytes: int = 256,
        strict: bool = False,
    ) -> None:
        self.od = od
        self.strict = strict
        self.max_entries = max_entries
        self.max_bytes = max_bytes
        od.allow_placeholders = not strict
        self._maps: dict[int, _Slots] = {}
        #: the last codec compiled and what it was compiled from (:meth:`compile`)
        self._compiled: tuple[tuple, PdoCodec] | None = None
        self._assign: dict[int, _Slots] = {
            RX_ASSIGN: _Slots(0, [0] * max_assigned),
            TX_ASSIGN: _Slots(0, [0] * max_assigned),
        }
        for pdos, assign, direction in (
            (rx_pdos, RX_ASSIGN, PdoDir.RX),
            (tx_pdos, TX_ASSIGN, PdoDir.TX),
        ):
            slots = self._assign[assign]
            if len(pdos) > len(slots.values):
                slots.values += [0] * (len(pdos) - len(slots.values))
            for k, pdo in enumerate(pdos):
                self._initial_pdo(pdo, direction)
                slots.values[k] = pdo.index
            slots.count = len(pdos)
        for idx in spare_rx:
            if idx not in self._maps:
                self._add_map(idx, [], fixed=False)
        for idx in spare_tx:
            if idx not in self._maps:
                self._add_map(idx, [], fixed=False)
        self._add_assign_object(RX_ASSIGN, "RxPDO assign")
        self._add_assign_object(TX_ASSIGN, "TxPDO assign")
        if 0x1C00 not in od:
            od.add_lazy_record(
                0x1C00, "Sync manager communication type", _sm_types, code=ObjectCode.ARRAY
            )

    # --- construction ------------------------------------------------------------
    def _initial_pdo(self, pdo: Pdo, direction: PdoDir) -> None:
        """A PDO as the ENI lists it: always accepted (the ENI describes this very device)."""
        values = []
        for e in pdo.entries:
            values.append(pack_entry(e.index, e.subindex, e.bit_len))
            if is_gap(e.index):
                continue
            var = self.od.find(e.index, e.subindex)
            if var is None:
                log.info(
                    "ENI maps 0x%04X:%02X which the virtual drive lacks: placeholder",
                    e.index,
                    e.subindex,
                )
                self.od.placeholder(e.index, e.subindex, e.bit_len, direction)
                continue
            if not var.pdo & direction:
                log.info(
                    "ENI maps 0x%04X:%02X to a %s: accepted", e.index, e.subindex, direction.name
                )
                var.pdo |= direction
            if var.pdo_bits != e.bit_len:
                log.info(
                    "ENI maps 0x%04X:%02X with %d bits (type has %d): packed as written",
                    e.index,
                    e.subindex,
                    e.bit_len,
                    var.pdo_bits,
                )
        if pdo.index in self._maps:
            raise ValueError(f"PDO 0x{pdo.index:04X} listed twice")
        self._add_map(pdo.index, values, fixed=pdo.fixed)

    def _add_map(self, index: int, values: list[int], *, fixed: bool) -> _Slots:
        cap = max(self.max_entries, len(values))
        slots = _Slots(len(values), values + [0] * (cap - len(values)), fixed)
        self._maps[index] = slots
        direction = PdoDir.RX if index in RX_MAP_RANGE else PdoDir.TX
        access = Access.RO if fixed else Access.RW
        name = ("RxPDO" if direction is PdoDir.RX else "TxPDO") + f" mapping 0x{index:04X}"
        self.od.add_lazy_record(index, name, _SlotEntries(self, index, slots, cap, access))
        return slots

    def _add_assign_object(self, index: int, name: str) -> None:
        slots = self._assign[index]
        entries = _SlotEntries(self, index, slots, len(slots.values), Access.RW, assign=True)
        self.od.add_lazy_record(index, name, entries, code=ObjectCode.ARRAY)

    def _slot_entry(self, e: _SlotEntries, k: int) -> Variable:
        """Entry ``k`` of a mapping or assignment object (:class:`_SlotEntries`): subindex 0
        the count, then the mapped objects or assigned PDOs, written in PREOP only."""
        index, slots = e.index, e.slots
        if k == 0:
            return Variable(
                index,
                0,
                "Number of assigned PDOs" if e.assign else "Number of mapped objects",
                DataType.UINT8,
                e.access,
                high=e.cap,
                write_states=PREOP_ONLY,
                getter=partial(getattr, slots, "count"),
                setter=partial(self._set_assign_count if e.assign else self._set_map_count, index),
            )
        put = e.put
        if put is None:
            put = e.put = partial(
                self._set_assign_entry if e.assign else self._set_map_entry, index
            )
        return SlotVariable(
            slots.values,
            k - 1,
            put,
            index,
            _names("Assigned PDO" if e.assign else "Mapped object", e.cap)[k - 1],
            DataType.UINT16 if e.assign else DataType.UINT32,
            e.access,
            write_states=PREOP_ONLY,
        )

    # --- setters behind the objects -----------------------------------------------
    def _direction_of(self, pdo_index: int) -> PdoDir:
        return PdoDir.RX if pdo_index in RX_MAP_RANGE else PdoDir.TX

    def _set_map_entry(self, index: int, k: int, value: int) -> None:
        slots = self._maps[index]
        if slots.count != 0:
            raise SdoAbort(
                SdoAbortCode.SUBINDEX_CANNOT_BE_WRITTEN,
                index,
                k + 1,
                "set subindex 0 to 0 before changing the mapping",
            )
        if value != 0:
            self._check_entry(index, k + 1, value, self._direction_of(index))
        slots.values[k] = value

    def _check_entry(self, pdo: int, sub: int, value: int, direction: PdoDir) -> None:
        obj_index, obj_sub, bits = unpack_entry(value)
        if bits == 0:
            raise SdoAbort(
                SdoAbortCode.PARAMETER_INCOMPATIBILITY, pdo, sub, "mapping entry with bit length 0"
            )
        if is_gap(obj_index):
            return
        var = self.od.find(obj_index, obj_sub)
        if var is None:
            if self.strict or obj_index not in PLACEHOLDER_RANGE:
                raise SdoAbort(
                    SdoAbortCode.OBJECT_CANNOT_BE_MAPPED,
                    pdo,
                    sub,
                    f"0x{obj_index:04X}:{obj_sub:02X} does not exist",
                )
            log.info("mapping names unknown 0x%04X:%02X: placeholder", obj_index, obj_sub)
            self.od.placeholder(obj_index, obj_sub, bits, direction)
            return
        if var.info.is_string or not var.pdo & direction:
            raise SdoAbort(
                SdoAbortCode.OBJECT_CANNOT_BE_MAPPED,
                pdo,
                sub,
                f"0x{obj_index:04X}:{obj_sub:02X} is not {direction.name}-mappable",
            )
        if bits != var.pdo_bits and (self.strict or bits > 64):
            raise SdoAbort(
                SdoAbortCode.PARAMETER_INCOMPATIBILITY,
                pdo,
                sub,
                f"0x{obj_index:04X}:{obj_sub:02X} has {var.pdo_bits} bits, not {bits}",
            )

    def _set_map_count(self, index: int, count: int) -> None:
        slots = self._maps[index]
        bits = 0
        for v in slots.values[:count]:
            if v == 0:
                raise SdoAbort(
                    SdoAbortCode.PARAMETER_INCOMPATIBILITY,
                    index,
                    0,
                    "an entry below the new count is empty",
                )
            bits += v & 0xFF
        if bits > self.max_bytes * 8:
            raise SdoAbort(
                SdoAbortCode.PDO_LENGTH_EXCEEDED,
                index,
                0,
                f"{bits} bits exceed {self.max_bytes} bytes",
            )
        slots.count = count

    def _set_assign_entry(self, index: int, k: int, value: int) -> None:
        slots = self._assign[index]
        if slots.count != 0:
            raise SdoAbort(
                SdoAbortCode.SUBINDEX_CANNOT_BE_WRITTEN,
                index,
                k + 1,
                "set subindex 0 to 0 before changing the assignment",
            )
        if value != 0:
            wanted = RX_MAP_RANGE if index == RX_ASSIGN else TX_MAP_RANGE
            if value not in wanted:
                raise SdoAbort(
                    SdoAbortCode.VALUE_RANGE_EXCEEDED,
                    index,
                    k + 1,
                    f"0x{value:04X} is not a {'Rx' if index == RX_ASSIGN else 'Tx'}PDO",
                )
            if value not in self._maps:
                if self.strict:
                    raise SdoAbort(
                        SdoAbortCode.VALUE_RANGE_EXCEEDED, index, k + 1, f"no PDO 0x{value:04X}"
                    )
                log.info("assignment names unknown PDO 0x%04X: empty mapping object", value)
                self._add_map(value, [], fixed=False)
        slots.values[k] = value

    def _set_assign_count(self, index: int, count: int) -> None:
        slots = self._assign[index]
        bits = 0
        for v in slots.values[:count]:
            if v == 0:
                raise SdoAbort(
                    SdoAbortCode.PARAMETER_INCOMPATIBILITY,
                    index,
                    0,
                    "an entry below the new count is empty",
                )
            bits += self.pdo_bits(v)
        if bits > self.max_bytes * 8:
            raise SdoAbort(
                SdoAbortCode.PDO_LENGTH_EXCEEDED,
                index,
                0,
                f"{bits} bits exceed {self.max_bytes} bytes",
            )
        slots.count = count

    # --- queries -------------------------------------------------------------------
    def pdo_bits(self, pdo_index: int) -> int:
        slots = self._maps[pdo_index]
        return sum(v & 0xFF for v in slots.values[: slots.count])

    def assigned(self, direction: Direction) -> list[int]:
        slots = self._assign[RX_ASSIGN if direction is Direction.OUT else TX_ASSIGN]
        return list(slots.values[: slots.count])

    def entries(self, direction: Direction) -> list[tuple[int, int, int]]:
        """(index, subindex, bits) of every mapped entry in process-data order."""
        out = []
        for pdo in self.assigned(direction):
            slots = self._maps[pdo]
            out.extend(unpack_entry(v) for v in slots.values[: slots.count])
        return out

    def sizes(self) -> tuple[int, int]:
        """(RxPDO bits, TxPDO bits) of the current assignment."""
        rx = sum(self.pdo_bits(p) for p in self.assigned(Direction.OUT))
        tx = sum(self.pdo_bits(p) for p in self.assigned(Direction.IN))
        return rx, tx

    def mapped_objects(self, direction: Direction) -> set[tuple[int, int]]:
        return {(i, s) for i, s, _ in self.entries(direction) if not is_gap(i)}

    def compile(self) -> PdoCodec:
        """The codec of the current mapping.  The one compiled last is given again when the
        mapping still names the same entries, each the same object of the same type (a
        codec is immutable): a bus's start-up compiles each drive's mapping at construction
        and again at PREOP->SAFEOP, most often unchanged by its InitCmds."""
        rx = []
        off = 0
        for i, s, n in self.entries(Direction.OUT):
            if not is_gap(i):
                rx.append((off, n, self.od.variable(i, s)))
            off += n
        rx_bits = off
        tx = []
        off = 0
        for i, s, n in self.entries(Direction.IN):
            if not is_gap(i):
                tx.append((off, n, self.od.variable(i, s)))
            off += n
        key = (rx_bits, off, _traits(rx), _traits(tx))
        last = self._compiled
        if last is not None and last[0] == key:
            return last[1]
        codec = PdoCodec(rx, rx_bits, tx, off)
        self._compiled = (key, codec)
        return codec


# --- the codec --------------------------------------------------------------------------
_STRUCT_BITS = {8, 16, 32, 64}


def _fast(off: int, bits: int, var: Variable) -> str | None:
    """The struct code for an entry that can be packed as a whole aligned field."""
    if off & 7 or bits not in _STRUCT_BITS or var.info.is_string:
        return None
    if var.info.size * 8 != bits or var.data_type is DataType.BOOL:
        return None
    return var.info.fmt


def _fit(value: Any, bits: int, signed: bool, fmt: str) -> Any:
    """Bring a getter's value into what the field can hold (wrap like the C types do)."""
    if fmt == "f":
        return float(value)
    v = int(value) & ((1 << bits) - 1)
    if signed and v >> (bits - 1):
        v -= 1 << bits
    return v


class PdoCodec:
    """Decode ``rx`` into object writes and encode ``tx`` from object reads.

    Built by :meth:`PdoMapping.compile`; immutable, so a cycle needs no checks.
    """

    __slots__ = (
        "_rx_fields",
        "_rx_setters",
        "_rx_slow",
        "_rx_struct",
        "_tx_fields",
        "_tx_getters",
        "_tx_slow",
        "_tx_struct",
        "rx_bits",
        "rx_bytes",
        "rx_vars",
        "tx_bits",
        "tx_bytes",
        "tx_vars",
    )

    def __init__(
        self,
        rx: list[tuple[int, int, Variable]],
        rx_bits: int,
        tx: list[tuple[int, int, Variable]],
        tx_bits: int,
    ) -> None:
        self.rx_bits, self.tx_bits = rx_bits, tx_bits
        self.rx_bytes, self.tx_bytes = (rx_bits + 7) // 8, (tx_bits + 7) // 8
        self.rx_vars = [v for _, _, v in rx]
        self.tx_vars = [v for _, _, v in tx]
        self._rx_struct, rx_fast, self._rx_slow = self._split(rx)
        self._tx_struct, tx_fast, self._tx_slow = self._split(tx)
        self._rx_setters = tuple(_setter(v) for _, _, v in rx_fast)
        self._rx_fields = tuple(rx_fast)
        self._tx_getters = tuple(_getter(v) for _, _, v in tx_fast)
        self._tx_fields = tuple(tx_fast)

    @staticmethod
    def _split(
        entries: list[tuple[int, int, Variable]],
    ) -> tuple[struct.Struct, list[tuple[int, int, Variable]], tuple]:
        fast: list[tuple[int, int, Variable]] = []
        slow = []
        fmt = "<"
        pos = 0  # byte position the format has reached
        for off, bits, var in entries:
            code = _fast(off, bits, var)
            if code is None:
                real = var.info.fmt == "f"
                slow.append((off, bits, var.info.signed, real, _setter(var), _getter(var)))
                continue
            gap = off // 8 - pos
            if gap:
                fmt += f"{gap}x"
            fmt += code
            pos = off // 8 + bits // 8
            fast.append((off, bits, var))
        return struct.Struct(fmt), fast, tuple(slow)

    def decode(self, buf: Any) -> None:
        """Write every mapped RxPDO entry from ``buf`` (the slave's ``rx``)."""
        if self._rx_setters:
            for setter, value in zip(
                self._rx_setters, self._rx_struct.unpack_from(buf), strict=True
            ):
                setter(value)
        for off, bits, signed, real, setter, _ in self._rx_slow:
            raw = get_bits(buf, off, bits, signed=signed and not real)
            if real:  # a REAL32 off the byte grid: reinterpret the 32 bits
                raw = struct.unpack("<f", (raw & 0xFFFFFFFF).to_bytes(4, "little"))[0]
            setter(raw)

    def encode(self, buf: Any) -> None:
        """Fill every mapped TxPDO entry of ``buf`` (the slave's ``tx``)."""
        if self._tx_getters:
            values = [g() for g in self._tx_getters]
            try:
                self._tx_struct.pack_into(buf, 0, *values)
            except struct.error:
                fitted = [
                    _fit(v, bits, var.info.signed, var.info.fmt)
                    for v, (_, bits, var) in zip(values, self._tx_fields, strict=True)
                ]
                self._tx_struct.pack_into(buf, 0, *fitted)
        for off, bits, _, real, _, getter in self._tx_slow:
            value = getter()
            if real:
                value = int.from_bytes(struct.pack("<f", float(value)), "little")
            set_bits(buf, off, bits, int(value) & ((1 << bits) - 1))


def _traits(entries: list[tuple[int, int, Variable]]) -> tuple:
    """What a codec's fields are made of, in one tuple: each entry's place, object and type,
    and a plain entry's own getter and setter (another entry kind answers them from what it
    was made with, fixed for its life)."""
    out: list[Any] = []
    for off, bits, var in entries:
        out += (off, bits, var, var.data_type)
        if type(var) is Variable:
            out += (var.getter, var.setter)
    return tuple(out)


def _setter(var: Variable) -> Callable[[Any], None]:
    if var.setter is not None:
        return var.setter

    def store(value: Any, var: Variable = var) -> None:
        var.value = value

    return store


def _getter(var: Variable) -> Callable[[], Any]:
    if var.getter is not None:
        return var.getter
    return lambda var=var: var.value
