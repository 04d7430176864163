"""A typed CANopen-over-EtherCAT object dictionary (CiA 301 7.4, ETG.1000.6 5.6.1).

Objects are variables (one value at subindex 0), arrays or records (subindex 0
holds the number of entries).  Each entry knows its CiA data type, its access
right, whether it may be mapped to an RxPDO/TxPDO, its value range and the AL
states in which it may be written (PDO mapping and assignment only in PREOP).

Values live either in the entry itself or, through ``getter``/``setter`` hooks,
in plain Python attributes of the drive; the cycle then reads and writes those
attributes directly and the dictionary is only the SDO face of them.

:meth:`ObjectDictionary.upload` and :meth:`ObjectDictionary.download` take and
return the little-endian bytes of the wire and raise
:class:`~gtecat.drives.abort.SdoAbort` with the CiA 301 code for every refusal.
"""

from __future__ import annotations

import struct
from collections.abc import Callable, Iterable, Iterator
from dataclasses import dataclass
from enum import IntEnum, IntFlag
from functools import partial
from typing import Any

from gtecat.drives.abort import SdoAbort, SdoAbortCode
from gtecat.drives.slave import AlState


class DataType(IntEnum):
    """CiA 301 static data types (Table 44); the value is the data type index."""

    BOOL = 0x0001
    INT8 = 0x0002
    INT16 = 0x0003
    INT32 = 0x0004
    UINT8 = 0x0005
    UINT16 = 0x0006
    UINT32 = 0x0007
    REAL32 = 0x0008
    VISIBLE_STRING = 0x0009
    OCTET_STRING = 0x000A
    INT64 = 0x0015
    UINT64 = 0x001B


@dataclass(frozen=True, slots=True)
class TypeInfo:
    size: int  # bytes on the SDO wire (0 = variable length)
    pdo_bits: int  # bit length when mapped (BOOL maps as one bit)
    fmt: str  # struct code, "" for strings
    signed: bool
    low: int | float | None
    high: int | float | None

    @property
    def is_string(self) -> bool:
        return self.size == 0


def _int_info(size: int, fmt: str, signed: bool) -> TypeInfo:
    bits = size * 8
    if signed:
        return TypeInfo(size, bits, fmt, True, -(1 << (bits - 1)), (1 << (bits - 1)) - 1)
    return TypeInfo(size, bits, fmt, False, 0, (1 << bits) - 1)


TYPE_INFO: dict[DataType, TypeInfo] = {
    DataType.BOOL: TypeInfo(1, 1, "B", False, 0, 1),
    DataType.INT8: _int_info(1, "b", True),
    DataType.INT16: _int_info(2, "h", True),
    DataType.INT32: _int_info(4, "i", True),
    DataType.INT64: _int_info(8, "q", True),
    DataType.UINT8: _int_info(1, "B", False),
    DataType.UINT16: _int_info(2, "H", False),
    DataType.UINT32: _int_info(4, "I", False),
    DataType.UINT64: _int_info(8, "Q", False),
    DataType.REAL32: TypeInfo(4, 32, "f", True, None, None),
    DataType.VISIBLE_STRING: TypeInfo(0, 0, "", False, None, None),
    DataType.OCTET_STRING: TypeInfo(0, 0, "", False, None, None),
}


class Access(IntEnum):
    """Access right of an entry (ETG.2000 ``Access``; CONST reads like RO)."""

    RO = 1
    WO = 2
    RW = 3
    CONST = 4

    @property
    def readable(self) -> bool:
        return self is not Access.WO

    @property
    def writable(self) -> bool:
        return self in _WRITABLE


#: the access rights an SDO download may write (a set: a member's lookup on its class costs
#: more than the test, and a download tests it every time)
_WRITABLE = frozenset({Access.WO, Access.RW})


class PdoDir(IntFlag):
    """Where an entry may be mapped: RX = RxPDO (master outputs), TX = TxPDO (inputs)."""

    NONE = 0
    RX = 1
    TX = 2


class ObjectCode(IntEnum):
    """CiA 301 object codes (Table 42)."""

    VAR = 7
    ARRAY = 8
    RECORD = 9


class ObjectAccess(IntFlag):
    """Access word of a Get Entry Description response (ETG.1000.6 5.6.3.6.2)."""

    READ_PREOP = 0x0001
    READ_SAFEOP = 0x0002
    READ_OP = 0x0004
    WRITE_PREOP = 0x0008
    WRITE_SAFEOP = 0x0010
    WRITE_OP = 0x0020
    RXPDO_MAPPABLE = 0x0040
    TXPDO_MAPPABLE = 0x0080
    BACKUP = 0x0100
    SETTINGS = 0x0200


_READ_ALL = ObjectAccess.READ_PREOP | ObjectAccess.READ_SAFEOP | ObjectAccess.READ_OP
_WRITE_IN = {
    AlState.INIT: ObjectAccess.WRITE_PREOP,
    AlState.PREOP: ObjectAccess.WRITE_PREOP,
    AlState.SAFEOP: ObjectAccess.WRITE_SAFEOP,
    AlState.OP: ObjectAccess.WRITE_OP,
}
#: data type index of the standard records (CiA 301 Table 44, ETG.1000.6 Table 64)
PDO_MAPPING_TYPE = 0x0021
IDENTITY_TYPE = 0x0023


#: AL states in which PDO mapping (16xx/1Axx) and assignment (1C12/1C13) may be written.
#: INIT is included because masters write them before the slave reports PREOP (ETG.2100 IP
#: init commands); a slave in SAFEOP/OP refuses with 0x08000022.
PREOP_ONLY = frozenset({AlState.INIT, AlState.PREOP})


#: a data type's value when an entry gives none: empty bytes, 0.0 or 0
_DEFAULT_VALUE: dict[DataType, Any] = {
    t: b"" if info.is_string else (0.0 if info.fmt == "f" else 0) for t, info in TYPE_INFO.items()
}
#: an integer type's size in bytes and range: the values its bytes decode to
#: (:meth:`ObjectDictionary.download_value` takes a value of that size in that range as it is)
_INT_RANGE: dict[DataType, tuple[int, int, int]] = {
    t: (info.size, info.low, info.high)  # type: ignore[misc]
    for t, info in TYPE_INFO.items()
    if info.size and info.fmt != "f"
}


def _interned_x(x: dict[str, Any]) -> dict[str, Any]:
    """The one dict of these extras (never changed after): entries with the same extras (the
    same object of drive after drive) share one."""
    try:
        shared = tuple(sorted((k, type(v).__name__, v) for k, v in x.items()))
        if len(_XS) >= 4096:
            _XS.clear()
        return _XS.setdefault(shared, x)
    except TypeError:  # an unhashable value: its own dict
        return x


class Variable:
    """One entry (index, subindex) of the dictionary."""

    __slots__ = (
        "_x",
        "access",
        "data_type",
        "getter",
        "index",
        "name",
        "pdo",
        "setter",
        "subindex",
        "value",
        "write_states",
    )

    def __init__(
        self,
        index: int,
        subindex: int,
        name: str,
        data_type: DataType,
        access: Access = Access.RW,
        *,
        pdo: PdoDir = PdoDir.NONE,
        default: Any = None,
        low: int | float | None = None,
        high: int | float | None = None,
        allowed: Iterable[int] | None = None,
        write_states: frozenset[AlState] | None = None,
        getter: Callable[[], Any] | None = None,
        setter: Callable[[Any], None] | None = None,
        max_size: int = 0,
        pdo_bits: int | None = None,
    ) -> None:
        self.index = index
        self.subindex = subindex
        self.name = name
        if type(data_type) is not DataType:
            data_type = DataType(data_type)
        self.data_type = data_type
        self.access = access
        self.pdo = pdo
        #: what few entries have (a range, allowed values, a string's size, a placeholder
        #: mark): None or a dict of them, so that the hundreds of entries of a drive without
        #: them stay small (:attr:`low` and the others read it)
        x: dict[str, Any] | None = None
        if low is not None or high is not None or allowed is not None:
            x = {}
            if low is not None:
                x["low"] = low
            if high is not None:
                x["high"] = high
            if allowed is not None:
                x["allowed"] = _shared(frozenset(allowed))
            x = _interned_x(x)
        self._x = x
        self.write_states = write_states
        # (AttrVariable and SlotVariable answer getter/setter themselves: nothing to store)
        plain = type(self) is Variable
        if plain or getter is not None:
            self.getter = getter
        if plain or setter is not None:
            self.setter = setter
        if max_size and TYPE_INFO[data_type].is_string:
            self.max_size = max_size
        if pdo_bits is not None and pdo_bits != TYPE_INFO[data_type].pdo_bits:
            self.pdo_bits = pdo_bits
        self.value = _DEFAULT_VALUE[data_type] if default is None else default

    @property
    def info(self) -> TypeInfo:
        """The data type's sizes and format."""
        return TYPE_INFO[self.data_type]

    @property
    def pdo_bits(self) -> int:
        """Bit length when mapped: the type's, unless a placeholder was sized by a mapping."""
        x = self._x
        if x is not None and "pdo_bits" in x:
            return x["pdo_bits"]  # type: ignore[no-any-return]
        return TYPE_INFO[self.data_type].pdo_bits

    @pdo_bits.setter
    def pdo_bits(self, value: int) -> None:
        self._set_x("pdo_bits", value)

    def __repr__(self) -> str:
        return (
            f"<Variable 0x{self.index:04X}:{self.subindex:02X} {self.name} {self.data_type.name}>"
        )

    def _get_x(self, key: str, default: Any = None) -> Any:
        x = self._x
        return default if x is None else x.get(key, default)

    def _set_x(self, key: str, value: Any) -> None:
        # a new dict each time, never changed after: entries with the same extras (the
        # same object of drive after drive) share one
        x = dict(self._x) if self._x else {}
        x[key] = value
        self._x = _interned_x(x)

    low = property(lambda self: self._get_x("low"), lambda self, v: self._set_x("low", v))
    high = property(lambda self: self._get_x("high"), lambda self, v: self._set_x("high", v))
    allowed = property(
        lambda self: self._get_x("allowed"), lambda self, v: self._set_x("allowed", v)
    )
    #: created only because a PDO mapping names it (see ObjectDictionary.placeholder)
    placeholder = property(
        lambda self: self._get_x("placeholder", False),
        lambda self, v: self._set_x("placeholder", v),
    )

    @property
    def max_size(self) -> int:
        """Bytes a value may have: a string's given size, else the type's."""
        x = self._x
        if x is not None and "max_size" in x:
            return x["max_size"]
        return 0 if self.info.is_string else self.info.size

    @max_size.setter
    def max_size(self, value: int) -> None:
        self._set_x("max_size", value)

    # --- values -------------------------------------------------------------
    def get(self) -> Any:
        return self.getter() if self.getter is not None else self.value

    def set(self, value: Any) -> None:
        """Store a value that already passed :meth:`check` (no range check here)."""
        if self.setter is not None:
            self.setter(value)
        else:
            self.value = value

    def check(self, value: Any) -> None:
        """Raise SdoAbort when ``value`` is outside this entry's range or allowed set."""
        x = self._x
        if x is None:  # no range, no allowed set (most entries)
            return
        allowed = x.get("allowed")
        if allowed is not None and value not in allowed:
            raise SdoAbort(
                SdoAbortCode.VALUE_RANGE_EXCEEDED,
                self.index,
                self.subindex,
                f"{value} is not one of {sorted(allowed)}",
            )
        high = x.get("high")
        if high is not None and value > high:
            raise SdoAbort(
                SdoAbortCode.VALUE_TOO_HIGH, self.index, self.subindex, f"{value} > {high}"
            )
        low = x.get("low")
        if low is not None and value < low:
            raise SdoAbort(
                SdoAbortCode.VALUE_TOO_LOW, self.index, self.subindex, f"{value} < {low}"
            )

    # --- bytes --------------------------------------------------------------
    def encode(self, value: Any) -> bytes:
        info = self.info
        if info.is_string:
            raw = value.encode("latin-1") if isinstance(value, str) else bytes(value)
            return raw
        if info.fmt == "f":
            return struct.pack("<f", float(value))
        v = int(value)
        mask = (1 << (info.size * 8)) - 1
        return (v & mask).to_bytes(info.size, "little")

    def decode(self, data: bytes) -> Any:
        """Bytes of an SDO download -> value, with the CiA 301 length checks."""
        info = self.info
        if info.is_string:
            if self.max_size and len(data) > self.max_size:
                raise SdoAbort(
                    SdoAbortCode.LENGTH_TOO_HIGH,
                    self.index,
                    self.subindex,
                    f"{len(data)} bytes, at most {self.max_size}",
                )
            if self.data_type is DataType.VISIBLE_STRING:
                return bytes(data).rstrip(b"\x00").decode("latin-1")
            return bytes(data)
        if len(data) > info.size:
            raise SdoAbort(
                SdoAbortCode.LENGTH_TOO_HIGH,
                self.index,
                self.subindex,
                f"{len(data)} bytes for a {self.data_type.name} of {info.size}",
            )
        if len(data) < info.size:
            raise SdoAbort(
                SdoAbortCode.LENGTH_TOO_LOW,
                self.index,
                self.subindex,
                f"{len(data)} bytes for a {self.data_type.name} of {info.size}",
            )
        if info.fmt == "f":
            return struct.unpack("<f", data)[0]
        value = int.from_bytes(data, "little", signed=info.signed)
        if self.data_type is DataType.BOOL and value > 1:
            raise SdoAbort(
                SdoAbortCode.VALUE_RANGE_EXCEEDED, self.index, self.subindex, "BOOL must be 0 or 1"
            )
        return value

    @property
    def sdo_size(self) -> int:
        """Bytes this entry takes on the wire now (strings: their current length)."""
        if self.info.is_string:
            return len(self.encode(self.get()))
        return self.info.size

    @property
    def bit_length(self) -> int:
        """Bits of the entry, as SDO Information describes it (strings: their room)."""
        if self.info.is_string:
            return 8 * max(self.max_size, self.sdo_size)
        return (
            self.pdo_bits
            if self.data_type is DataType.BOOL or self.placeholder
            else (8 * self.info.size)
        )

    @property
    def object_access(self) -> ObjectAccess:
        """Read/write rights per AL state and PDO mappability (ETG.1000.6 5.6.3.6.2)."""
        bits = _READ_ALL if self.access.readable else ObjectAccess(0)
        if self.access.writable:
            if self.write_states is None:
                bits |= ObjectAccess.WRITE_PREOP | ObjectAccess.WRITE_SAFEOP | ObjectAccess.WRITE_OP
            else:
                for state in self.write_states:
                    bits |= _WRITE_IN.get(state, ObjectAccess(0))
        if self.pdo & PdoDir.RX:
            bits |= ObjectAccess.RXPDO_MAPPABLE
        if self.pdo & PdoDir.TX:
            bits |= ObjectAccess.TXPDO_MAPPABLE
        return bits


def _shared(values: frozenset[int]) -> frozenset[int]:
    """One frozenset per content for every dictionary (the same allowed values of the same
    objects, drive after drive)."""
    if len(_SHARED) >= 1024:
        _SHARED.clear()
    return _SHARED.setdefault(values, values)


_SHARED: dict[frozenset[int], frozenset[int]] = {}
#: the rare attributes of entries (range, allowed values, sizes), one dict per content
_XS: dict[tuple[tuple[str, str, Any], ...], dict[str, Any]] = {}


def _only_none(self: Variable, value: object) -> None:
    if value is not None:
        raise TypeError(f"{type(self).__name__} {self!r}: its value has a fixed home")


class AttrVariable(Variable):
    """An entry whose value is the attribute ``attr`` of ``owner`` (a drive's own state).

    The same as ``Variable(..., getter=partial(getattr, owner, attr), setter=partial(setattr,
    owner, attr))``, but the two callables are made only when asked for: a drive holds a
    hundred such entries, and hundreds of drives a bus."""

    __slots__ = ("_attr", "_owner")

    def __init__(
        self,
        owner: object,
        attr: str,
        index: int,
        subindex: int,
        name: str,
        data_type: DataType,
        access: Access = Access.RW,
        **kw: Any,
    ) -> None:
        self._owner, self._attr = owner, attr
        super().__init__(index, subindex, name, data_type, access, **kw)

    getter = property(lambda self: partial(getattr, self._owner, self._attr), _only_none)
    setter = property(lambda self: partial(setattr, self._owner, self._attr), _only_none)

    def get(self) -> Any:
        return getattr(self._owner, self._attr)

    def set(self, value: Any) -> None:
        setattr(self._owner, self._attr, value)


def item_at(owner: object, attr: str, j: int) -> Any:
    """``getattr(owner, attr)[j]``: the value of an entry kept in an owner's list."""
    return getattr(owner, attr)[j]


class ItemVariable(Variable):
    """A read-only entry whose value is ``getattr(owner, attr)[j]`` (a touch probe's latched
    values and counters, an analog input): the same as ``Variable(...,
    getter=partial(getattr-and-index))`` without the callable and its arguments made for
    each entry of each drive (the getter is made only when asked for)."""

    __slots__ = ("_attr", "_j", "_owner")

    def __init__(
        self,
        owner: object,
        attr: str,
        j: int,
        index: int,
        subindex: int,
        name: str,
        data_type: DataType,
        access: Access = Access.RO,
        **kw: Any,
    ) -> None:
        self._owner, self._attr, self._j = owner, attr, j
        super().__init__(index, subindex, name, data_type, access, **kw)

    getter = property(lambda self: partial(item_at, self._owner, self._attr, self._j), _only_none)
    #: (no setter: a write keeps :attr:`value`, which the getter hides, as a plain entry's)
    setter = property(lambda self: None, _only_none)

    def get(self) -> Any:
        return getattr(self._owner, self._attr)[self._j]


class SlotVariable(Variable):
    """An entry whose value is ``values[k]`` of a list its owner keeps (a PDO mapping's or
    assignment's entry); a write goes through ``put(k, value)``, one callable shared by the
    object's entries (no closures per entry)."""

    __slots__ = ("_k", "_put", "_values")

    def __init__(
        self,
        values: list[Any],
        k: int,
        put: Callable[[int, Any], None],
        index: int,
        name: str,
        data_type: DataType,
        access: Access = Access.RW,
        **kw: Any,
    ) -> None:
        self._values, self._k, self._put = values, k, put
        super().__init__(index, k + 1, name, data_type, access, **kw)

    getter = property(lambda self: partial(self._values.__getitem__, self._k), _only_none)
    setter = property(lambda self: partial(self._put, self._k), _only_none)

    def get(self) -> Any:
        return self._values[self._k]

    def set(self, value: Any) -> None:
        self._put(self._k, value)


class OdObject:
    """One index: a VAR (only subindex 0) or an ARRAY/RECORD (subindex 0 = count)."""

    __slots__ = ("_make", "_subs", "code", "index", "name")

    def __init__(
        self,
        index: int,
        name: str,
        code: ObjectCode = ObjectCode.VAR,
        make: Callable[[], Iterable[Variable]] | Variable | tuple[Variable, ...] | None = None,
    ) -> None:
        self.index = index
        self.name = name
        self.code = code
        #: ``make``: the entries are made when first looked at (a drive's spare PDO mappings
        #: are 50 entries nobody reads on most buses); a Variable or a tuple of them: the
        #: entries, put in a dict when first looked at (most of a drive's objects never are:
        #: its own code holds the entries)
        self._subs: dict[int, Variable] | None = None if make is not None else {}
        self._make = make

    @property
    def subs(self) -> dict[int, Variable]:
        """Subindex -> entry."""
        subs = self._subs
        if subs is None:
            make, self._make = self._make, None
            if isinstance(make, Variable):
                subs = self._subs = {make.subindex: make}
            elif isinstance(make, tuple):
                subs = self._subs = {v.subindex: v for v in make}
            else:
                assert make is not None
                subs = self._subs = {v.subindex: v for v in make()}
        return subs

    def sub(self, subindex: int) -> Variable | None:
        """``subs.get(subindex)`` without making the dict of entries given as a Variable or a
        tuple (an object whose one entry a download writes: a drive homing's parameters)."""
        subs = self._subs
        if subs is not None:
            return subs.get(subindex)
        make = self._make
        if isinstance(make, Variable):
            return make if make.subindex == subindex else None
        if isinstance(make, tuple):
            for var in reversed(make):  # (the last of a subindex, as in the dict)
                if var.subindex == subindex:
                    return var
            return None
        one = getattr(make, "one", None)
        if one is not None:  # (a maker of single entries: a PDO mapping's or assignment's)
            return one(subindex)  # type: ignore[no-any-return]
        return self.subs.get(subindex)

    def __repr__(self) -> str:
        return (
            f"<OdObject 0x{self.index:04X} {self.name} {self.code.name} subs={sorted(self.subs)}>"
        )

    def add(self, var: Variable) -> Variable:
        self.subs[var.subindex] = var
        return var

    def entries(self) -> list[Variable]:
        """Subindex 1.. in order (the part complete access carries after SI0)."""
        return [self.subs[k] for k in sorted(self.subs) if k != 0]

    @property
    def max_subindex(self) -> int:
        """Highest subindex (what SI0 counts for an array or record; 0 for a variable)."""
        if self.code is ObjectCode.VAR:
            return 0
        return max(self.subs, default=0)

    @property
    def data_type(self) -> int:
        """Data type index of the object (Get Object Description).

        A variable's own type, an array's element type, the standard record types for
        1018h and the PDO mappings, and for another record the type of its first entry.
        """
        if self.code is ObjectCode.VAR:
            var = self.subs.get(0)
            return int(var.data_type) if var is not None else 0
        if self.index == 0x1018:
            return IDENTITY_TYPE
        if 0x1600 <= self.index < 0x1800 or 0x1A00 <= self.index < 0x1C00:
            return PDO_MAPPING_TYPE
        entries = self.entries()
        if entries:
            return int(entries[0].data_type)
        return int(DataType.UINT8)


class AttrSpec:
    """What an :class:`AttrObject`'s entry is made of, the owner aside: one for the same
    object of every drive channel (:func:`attr_spec`)."""

    __slots__ = ("access", "attr", "data_type", "name", "pdo")

    def __init__(
        self, attr: str, name: str, data_type: DataType, access: Access, pdo: PdoDir
    ) -> None:
        self.attr, self.name, self.data_type, self.access, self.pdo = (
            attr,
            name,
            data_type,
            access,
            pdo,
        )


def attr_spec(attr: str, name: str, data_type: DataType, access: Access, pdo: PdoDir) -> AttrSpec:
    """The one :class:`AttrSpec` of these."""
    key = (attr, name, data_type, access, pdo)
    spec = _ATTR_SPECS.get(key)
    if spec is None:
        if len(_ATTR_SPECS) >= 4096:
            _ATTR_SPECS.clear()
        spec = _ATTR_SPECS[key] = AttrSpec(attr, name, data_type, access, pdo)
    return spec


_ATTR_SPECS: dict[tuple[str, str, DataType, Access, PdoDir], AttrSpec] = {}


class AttrObject(OdObject):
    """A VAR object whose one entry is ``AttrVariable(owner, spec.attr, index, 0, ...)``,
    made when the object is first looked at: most of a drive channel's forty such objects
    never are during a bus's life (the drive's own code reads its attributes), and a bus
    has hundreds of channels.  Once made, the entry is the object's for good (a write to
    it is the owner's attribute: one drive's never shows in another's)."""

    __slots__ = ("_owner",)

    def __init__(self, owner: object, index: int, spec: AttrSpec) -> None:
        super().__init__(index, spec.name, ObjectCode.VAR, spec)  # type: ignore[arg-type]
        self._owner = owner

    @property
    def subs(self) -> dict[int, Variable]:
        """Subindex -> entry (the entry made now if it was not yet)."""
        subs = self._subs
        if subs is None:
            spec: AttrSpec = self._make  # type: ignore[assignment]
            var = AttrVariable(
                self._owner,
                spec.attr,
                self.index,
                0,
                spec.name,
                spec.data_type,
                spec.access,
                pdo=spec.pdo,
            )
            self._make = None
            subs = self._subs = {0: var}
        return subs


class ObjectDictionary:
    """All objects of one slave, with SDO upload/download semantics."""

    def __init__(self) -> None:
        self.objects: dict[int, OdObject] = {}
        #: optional veto run before every SDO download of an entry (e.g. 0x06010006 policy)
        self.download_guard: Callable[[Variable, AlState], None] | None = None
        #: whether PDO mappings may name objects we lack (they become placeholders)
        self.allow_placeholders = False

    # --- building ----------------------------------------------------------
    def add_object(self, obj: OdObject) -> OdObject:
        if obj.index in self.objects:
            raise ValueError(f"object 0x{obj.index:04X} defined twice")
        self.objects[obj.index] = obj
        return obj

    def add_var(
        self, index: int, name: str, data_type: DataType, access: Access = Access.RW, **kw: Any
    ) -> Variable:
        return self.add_entry(Variable(index, 0, name, data_type, access, **kw))

    def add_entry(self, var: Variable) -> Variable:
        """A VAR object holding ``var`` (subindex 0), named as it is."""
        self.add_object(OdObject(var.index, var.name, ObjectCode.VAR, var))
        return var

    def add_record(
        self,
        index: int,
        name: str,
        entries: Iterable[Variable],
        *,
        code: ObjectCode = ObjectCode.RECORD,
        sub0: Variable | None = None,
    ) -> OdObject:
        """A record/array; subindex 0 is a read-only count of the entries unless given."""
        entries = list(entries)
        if sub0 is None:
            n = max((e.subindex for e in entries), default=0)
            sub0 = Variable(index, 0, "Number of entries", DataType.UINT8, Access.RO, default=n)
        # the entries in a tuple until the object is first looked at (then in a dict)
        return self.add_object(OdObject(index, name, code, (sub0, *entries)))

    def add_lazy_record(
        self,
        index: int,
        name: str,
        make: Callable[[], Iterable[Variable]],
        *,
        code: ObjectCode = ObjectCode.RECORD,
    ) -> OdObject:
        """A record/array whose entries (subindex 0 included) ``make`` returns when the
        object is first looked at."""
        return self.add_object(OdObject(index, name, code, make))

    def placeholder(self, index: int, subindex: int, bits: int, direction: PdoDir) -> Variable:
        """An entry a PDO mapping names but this device does not implement.

        Tolerated so that an ENI made for a real drive with vendor objects still
        brings the virtual drive up: the entry holds whatever the master writes
        (RxPDO) or reads as 0 (TxPDO).
        """
        dt = {1: DataType.BOOL, 8: DataType.UINT8, 16: DataType.UINT16, 64: DataType.UINT64}.get(
            bits, DataType.UINT32
        )
        access = Access.RW if direction & PdoDir.RX else Access.RO
        var = Variable(
            index,
            subindex,
            f"placeholder 0x{index:04X}:{subindex:02X}",
            dt,
            access,
            pdo=direction,
            pdo_bits=bits,
        )
        var.placeholder = True
        obj = self.objects.get(index)
        if obj is None:
            code = ObjectCode.VAR if subindex == 0 else ObjectCode.RECORD
            obj = self.add_object(OdObject(index, var.name, code))
            if subindex:
                obj.add(
                    Variable(
                        index, 0, "Number of entries", DataType.UINT8, Access.RO, default=subindex
                    )
                )
        elif 0 in obj.subs and subindex > 0 and obj.subs[0].getter is None:
            obj.subs[0].value = max(int(obj.subs[0].value), subindex)
        return obj.add(var)

    # --- lookup ------------------------------------------------------------
    def __contains__(self, index: object) -> bool:
        return index in self.objects

    def __iter__(self) -> Iterator[OdObject]:
        return iter(self.objects.values())

    def obj(self, index: int, subindex: int = 0) -> OdObject:
        try:
            return self.objects[index]
        except KeyError:
            raise SdoAbort(SdoAbortCode.OBJECT_DOES_NOT_EXIST, index, subindex) from None

    def variable(self, index: int, subindex: int) -> Variable:
        var = self.obj(index, subindex).sub(subindex)
        if var is None:
            raise SdoAbort(SdoAbortCode.SUBINDEX_DOES_NOT_EXIST, index, subindex)
        return var

    def find(self, index: int, subindex: int) -> Variable | None:
        obj = self.objects.get(index)
        return None if obj is None else obj.sub(subindex)

    def size_of(self, index: int, subindex: int) -> int | None:
        """Wire size of an entry, for expedited downloads that do not state their size."""
        var = self.find(index, subindex)
        if var is None or var.info.is_string:
            return None
        return var.info.size

    # --- SDO upload ----------------------------------------------------------
    def upload(self, index: int, subindex: int, complete_access: bool = False) -> bytes:
        obj = self.obj(index, subindex)
        if complete_access and obj.code is not ObjectCode.VAR:
            return self._upload_complete(obj, subindex)
        var = obj.sub(subindex)  # (self.variable, with the object already found)
        if var is None:
            raise SdoAbort(SdoAbortCode.SUBINDEX_DOES_NOT_EXIST, index, subindex)
        if not var.access.readable:
            raise SdoAbort(SdoAbortCode.READ_OF_WRITE_ONLY, index, subindex)
        return var.encode(var.get())

    def _upload_complete(self, obj: OdObject, subindex: int) -> bytes:
        """ETG.1000.6 5.6.2.1.2: all entries back to back; SI0 as 8 bits plus 8 padding bits."""
        if subindex > 1:
            raise SdoAbort(
                SdoAbortCode.SUBINDEX_CANNOT_BE_WRITTEN,
                obj.index,
                subindex,
                "complete access starts at subindex 0 or 1",
            )
        entries = obj.entries()
        if any(e.info.is_string for e in entries):
            raise SdoAbort(SdoAbortCode.COMPLETE_ACCESS_NOT_SUPPORTED, obj.index, subindex)
        out = bytearray()
        if subindex == 0:
            out += bytes((int(obj.subs[0].get()) & 0xFF, 0))
        for e in entries:
            if not e.access.readable:
                raise SdoAbort(SdoAbortCode.READ_OF_WRITE_ONLY, obj.index, e.subindex)
            out += e.encode(e.get())
        return bytes(out)

    # --- SDO download --------------------------------------------------------
    def download(
        self,
        index: int,
        subindex: int,
        data: bytes,
        complete_access: bool = False,
        al_state: AlState = AlState.PREOP,
    ) -> None:
        obj = self.obj(index, subindex)
        if complete_access and obj.code is not ObjectCode.VAR:
            self._download_complete(obj, subindex, bytes(data), al_state)
            return
        var = obj.sub(subindex)  # (self.variable, with the object already found)
        if var is None:
            raise SdoAbort(SdoAbortCode.SUBINDEX_DOES_NOT_EXIST, index, subindex)
        self._write(var, bytes(data), al_state)

    def download_value(
        self, index: int, subindex: int, value: int, size: int, al_state: AlState = AlState.PREOP
    ) -> None:
        """:meth:`download` of the integer ``value`` as a master sends it: its ``size``
        little-endian bytes (two's complement when negative; the value fits them).  An
        integer entry of that size whose range holds the value takes it as it is, which is
        what decoding those bytes gives back; any other entry (another size, a value it reads
        otherwise, a REAL32 or a string) and a missing one take the bytes.  The same checks,
        aborts and write either way, without the bytes made and parsed for each of an
        in-process master's expedited downloads (a drive homing's five parameters)."""
        obj = self.objects.get(index)
        if obj is not None:
            var = obj.sub(subindex)
            if var is not None:
                kind = _INT_RANGE.get(var.data_type)
                if kind is not None and kind[0] == size and kind[1] <= value <= kind[2]:
                    self._write(var, None, al_state, value)
                    return
        data = value.to_bytes(size, "little", signed=value < 0)
        self.download(index, subindex, data, False, al_state)

    def _write(
        self, var: Variable, data: bytes | None, al_state: AlState, value: Any = None
    ) -> None:
        """Write one entry from the bytes of a download (``data`` None: ``value`` is what
        :meth:`Variable.decode` gives for them, :meth:`download_value`)."""
        if var.access not in _WRITABLE:
            raise SdoAbort(SdoAbortCode.WRITE_OF_READ_ONLY, var.index, var.subindex)
        states = var.write_states
        if states is not None and al_state not in states:
            raise SdoAbort(
                SdoAbortCode.CANNOT_TRANSFER_DEVICE_STATE,
                var.index,
                var.subindex,
                f"not writable in {al_state.name}",
            )
        guard = self.download_guard
        if guard is not None:
            guard(var, al_state)
        if data is not None:
            value = var.decode(data)
        if var._x is not None:  # (a range or allowed values: Variable.check)
            var.check(value)
        try:
            var.set(value)
        except SdoAbort as err:
            if (err.index, err.subindex) == (var.index, var.subindex):
                raise
            raise SdoAbort(err.code, var.index, var.subindex, err.detail) from None

    def _download_complete(
        self, obj: OdObject, subindex: int, data: bytes, al_state: AlState
    ) -> None:
        """Complete access write: SI0 (8 bits + 8 padding) then the entries in order.

        Written in the order ETG.1000.6 prescribes for mapping objects: SI0 := 0,
        the entries, then SI0 := n, so each entry's own checks apply.
        """
        if subindex > 1:
            raise SdoAbort(
                SdoAbortCode.SUBINDEX_CANNOT_BE_WRITTEN,
                obj.index,
                subindex,
                "complete access starts at subindex 0 or 1",
            )
        entries = obj.entries()
        if any(e.info.is_string for e in entries):
            raise SdoAbort(SdoAbortCode.COMPLETE_ACCESS_NOT_SUPPORTED, obj.index, subindex)
        sub0 = obj.subs[0]
        pos = 0
        count: int | None = None
        if subindex == 0:
            if len(data) < 1:
                raise SdoAbort(SdoAbortCode.LENGTH_TOO_LOW, obj.index, 0)
            count = data[0]
            pos = 2 if len(data) >= 2 else 1
        values: list[tuple[Variable, bytes]] = []
        for e in entries:
            if pos >= len(data):
                break
            size = e.info.size
            if pos + size > len(data):
                raise SdoAbort(
                    SdoAbortCode.LENGTH_MISMATCH, obj.index, e.subindex, "data ends inside an entry"
                )
            values.append((e, data[pos : pos + size]))
            pos += size
        if pos < len(data):
            raise SdoAbort(
                SdoAbortCode.LENGTH_TOO_HIGH,
                obj.index,
                subindex,
                f"{len(data) - pos} bytes beyond the last entry",
            )
        if count is not None and count > len(values):
            raise SdoAbort(
                SdoAbortCode.LENGTH_TOO_LOW,
                obj.index,
                0,
                f"SI0 = {count} but only {len(values)} entries sent",
            )
        sub0_writable = count is not None and sub0.access.writable
        if count is not None and not sub0_writable:
            if count != int(sub0.get()):
                raise SdoAbort(SdoAbortCode.WRITE_OF_READ_ONLY, obj.index, 0)
        if sub0_writable:
            self._write(sub0, sub0.encode(0), al_state)
        for e, raw in values:
            if e.access.writable:
                self._write(e, raw, al_state)
            elif raw != e.encode(e.get()):
                raise SdoAbort(SdoAbortCode.WRITE_OF_READ_ONLY, obj.index, e.subindex)
        if sub0_writable:
            assert count is not None
            self._write(sub0, sub0.encode(count), al_state)


def add_identity(od: ObjectDictionary, identity: Any) -> OdObject:
    """1018h identity (CiA 301 7.5.2.26): vendor id, product code, revision, serial number."""
    return od.add_record(
        0x1018,
        "Identity",
        [
            Variable(0x1018, k, name, DataType.UINT32, Access.RO, default=value)
            for k, name, value in (
                (1, "Vendor ID", identity.vendor_id),
                (2, "Product code", identity.product_code),
                (3, "Revision number", identity.revision_no),
                (4, "Serial number", identity.serial_no),
            )
        ],
    )
