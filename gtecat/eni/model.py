"""The configuration model: what an ENI says about the bus, and nothing that runs.

Frozen, slotted dataclasses (python-canopen keeps its object dictionary
separate from the runtime node the same way).  Both readers (ETG.2100 XML and
Googol's INI ``Gecat.eni``) produce an :class:`EniConfig`; the writer consumes
one.  Offsets here are *as the file states them*; :mod:`gtecat.eni.layout` derives the
GT raw view from them.
"""

from __future__ import annotations

from dataclasses import dataclass, field, fields
from enum import IntEnum
from operator import attrgetter


class Direction(IntEnum):
    """Process data direction, from the master's point of view.

    OUT is an RxPDO (master -> slave, the ENI ``Send`` image); IN is a TxPDO
    (slave -> master, the ``Recv`` image).  Direction comes from RxPdo/TxPdo,
    never from the sync manager number (DESIGN.md).
    """

    OUT = 0
    IN = 1


@dataclass(frozen=True, slots=True)
class Identity:
    vendor_id: int
    product_code: int
    revision_no: int = 0
    serial_no: int = 0


@dataclass(frozen=True, slots=True)
class PdoEntry:
    """One mapped object; ``index == 0`` is a padding (gap) entry."""

    index: int
    subindex: int
    bit_len: int
    name: str = ""
    data_type: str = ""
    #: the entry's bit offset in its direction's logical image when the file
    #: states it (ENI ``ProcessImage`` variables); ``None`` to derive it from
    #: the slave's ``Send``/``Recv`` start and the entries before it.
    logical_bit: int | None = None

    @property
    def is_padding(self) -> bool:
        return self.index == 0

    def at(self, logical_bit: int | None) -> PdoEntry:
        """This entry at ``logical_bit``: ``dataclasses.replace`` costs five times as much,
        and a bus of a thousand drives lays out tens of thousands of entries."""
        return PdoEntry(
            self.index, self.subindex, self.bit_len, self.name, self.data_type, logical_bit
        )


@dataclass(frozen=True, slots=True)
class Pdo:
    """A PDO assigned to a sync manager (unassigned alternatives are not kept)."""

    index: int
    direction: Direction
    entries: tuple[PdoEntry, ...]
    name: str = ""
    sm: int | None = None
    fixed: bool = False

    @property
    def bit_len(self) -> int:
        return sum(e.bit_len for e in self.entries)


@dataclass(frozen=True, slots=True)
class InitCmd:
    """A CoE init command (ETG.2100 ``Mailbox/CoE/InitCmds/InitCmd``).

    ``transitions`` holds ETG.2100 codes such as ``"PS"`` (PREOP -> SAFEOP),
    ``"IP"``, ``"SO"``.  ``data`` is the little-endian payload as written.
    """

    transitions: tuple[str, ...]
    index: int
    subindex: int
    data: bytes
    complete_access: bool = False
    comment: str = ""
    timeout_ms: int = 0
    #: True for an SDO upload check (CCS 2) rather than a download
    upload: bool = False


@dataclass(frozen=True, slots=True)
class ProcessDataArea:
    """A slave's contiguous area in one logical image (ENI ``Send``/``Recv``)."""

    bit_start: int
    bit_len: int


@dataclass(frozen=True, slots=True)
class SyncManager:
    """One ``ProcessData/SmN`` element (ETG.2100): where the device keeps a process-data SM.

    ``direction`` is the element's ``Type`` (``Outputs``/``Inputs``); the wire face puts
    these into the slave's SII so a master that reads the SII (SOEM) finds the device's own
    layout (an EL2008's output SM at 0F00h)."""

    number: int
    direction: Direction
    start: int
    control: int = 0
    enable: bool = False


@dataclass(frozen=True, slots=True)
class MailboxLayout:
    """``Mailbox/Send`` and ``Mailbox/Recv`` (ETG.2100): (start, length) of each direction."""

    out_start: int  #: master -> slave (SM0)
    out_length: int
    in_start: int  #: slave -> master (SM1)
    in_length: int


@dataclass(frozen=True, slots=True)
class Slave:
    """One EtherCAT slave, in bus order (``position`` is 0-based)."""

    position: int
    name: str
    identity: Identity
    phys_addr: int = 0
    auto_inc_addr: int = 0
    rx_pdos: tuple[Pdo, ...] = ()  # assigned outputs, in sync-manager / mapping order
    tx_pdos: tuple[Pdo, ...] = ()  # assigned inputs
    outputs: ProcessDataArea | None = None
    inputs: ProcessDataArea | None = None
    init_cmds: tuple[InitCmd, ...] = ()
    mailbox: bool = False
    #: Googol INI ``type`` (1 servo / 0 IO) and ``nservo`` when the file says so
    servo_hint: bool | None = None
    nservo_hint: int | None = None
    #: line in the source file where this slave starts (for error messages)
    line: int | None = None
    #: what an ETG.2100 file says of the device's wire side (empty for a Googol INI file)
    sync_managers: tuple[SyncManager, ...] = ()
    mailbox_layout: MailboxLayout | None = None
    product_revision: str | None = None  #: ``Info/ProductRevision`` (``EL2008-0000-0018``)

    @property
    def out_bits(self) -> int:
        return sum(p.bit_len for p in self.rx_pdos)

    @property
    def in_bits(self) -> int:
        return sum(p.bit_len for p in self.tx_pdos)


@dataclass(frozen=True, slots=True)
class Variable:
    """An ENI ``ProcessImage`` variable (name, direction, offset as written)."""

    name: str
    direction: Direction
    bit_offset: int
    bit_size: int
    data_type: str = ""


@dataclass(frozen=True, slots=True)
class EniConfig:
    """A whole bus configuration."""

    source: str
    format: str  # "xml" | "googol"
    slaves: tuple[Slave, ...]
    cycle_time_ns: int | None = None
    outputs_bytes: int = 0  # size of the logical output image
    inputs_bytes: int = 0  # size of the logical input image
    variables: tuple[Variable, ...] = field(default=())
    master_name: str = ""


def quick_pickling(cls: type) -> type:
    """A frozen slotted dataclass's state for pickle as one tuple read by a C attribute
    getter; the dataclass default walks ``fields()`` for every object (the ENI cache keeps
    a large bus's model between processes: thousands of objects).  Returns ``cls``."""
    names = tuple(f.name for f in fields(cls))
    get = attrgetter(*names)
    put = object.__setattr__

    if len(names) == 1:

        def getstate(self: object) -> tuple:
            return (get(self),)

    else:

        def getstate(self: object) -> tuple:
            return get(self)  # type: ignore[no-any-return]

    def setstate(self: object, state: tuple) -> None:
        for name, value in zip(names, state, strict=True):
            put(self, name, value)

    cls.__getstate__ = getstate  # type: ignore[attr-defined]
    cls.__setstate__ = setstate  # type: ignore[attr-defined]
    return cls


for _cls in (
    Identity,
    PdoEntry,
    Pdo,
    InitCmd,
    ProcessDataArea,
    SyncManager,
    MailboxLayout,
    Slave,
    Variable,
    EniConfig,
):
    quick_pickling(_cls)
