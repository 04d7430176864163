"""The register InitCmds of an ENI: what a master that replays the file writes to bring a bus up.

TwinCAT and acontis EC-Master run an ENI word for word: per state transition
(ETG.2100 ``Transition``: ``IP`` INIT -> PREOP, ``PS``, ``SO``, back ``PI``
...) the master's ``BeforeSlave`` commands, then each slave's
``Config/Slave/InitCmds`` in document order, its CoE InitCmds before the
command that requests the target state.  Without register commands such a
master never leaves INIT, so :mod:`gtecat.eni.writer` writes the set TwinCAT
generates for a slave of this kind (compare
``shared/fixtures/eni/twincat_ek1100_el2008_el4002_el1809.xml``):

* back to INIT (``PI``, ``BI``, ``SI``, ``OI``): request INIT, check it;
* ``IP``: request and check INIT, assign the SII EEPROM to ECAT, read its vendor
  id and product code (words 0008h, 000Ah) and check them, set the station
  address by auto-increment address, for a slave with a mailbox set SM0/SM1 to
  the ENI's ``Mailbox`` areas, request and check PREOP;
* ``PS``: the process-data SMs (lengths from the assigned PDOs), one FMMU per SM
  mapping it onto the slave's ``Send``/``Recv`` bits of the image the cyclic frame
  addresses (outputs and inputs in separate logical ranges), request and check SAFEOP;
* ``SO``: request and check OP; ``OS`` and ``SP``/``OP`` back likewise.

A slave with a mailbox gets the error acknowledge bit with its INIT and PREOP
requests (as TwinCAT writes them): its firmware may have refused a transition.
The station address and mailbox SMs are written in ``IP`` only; the PS commands
rewrite every process-data SM and FMMU on each way up, so no clearing is needed
on the way down beyond the master's ``clear fmmu``.
"""

from __future__ import annotations

import struct
from dataclasses import dataclass

from construct import Const, Int8ul, Int16ul, Int32ul, Padding, Struct

from .ethercat import AlState, Command, EepromStatus, Reg
from .model import Direction, Pdo, Slave

#: logical address of the output image's first byte (the cyclic frame's LWR)
LOGICAL_BASE = 0x10000000
#: the input image starts at the next multiple of this after the outputs (the cyclic LRD)
INPUTS_ALIGN = 0x800


def logical_bases(outputs_bytes: int) -> dict[Direction, int]:
    """Where each image lies in the logical address space: outputs at LOGICAL_BASE, inputs
    after them.  The images are zero-based and laid out independently (``Send``/``Recv``
    BitStart), so one LRW over both would let a slave read the inputs an earlier slave put
    into the frame as its outputs; apart, an LWR and an LRD carry them (as TwinCAT does)."""
    gap = -(-outputs_bytes // INPUTS_ALIGN) * INPUTS_ALIGN
    return {Direction.OUT: LOGICAL_BASE, Direction.IN: LOGICAL_BASE + gap}


#: mailbox areas (start, length) master -> slave (SM0) and slave -> master (SM1)
MAILBOX = ((0x1000, 128), (0x1080, 128))
#: process-data SM defaults per direction: start address, control byte
SM_DEFAULT = {
    Direction.OUT: (0x1100, 0x64),  # buffered, ECAT writes, PDI interrupt, watchdog
    Direction.IN: (0x1400, 0x20),  # buffered, ECAT reads, PDI interrupt
}
# SM control bytes of the mailboxes (ETG.1000.4 Table 59): mailbox mode, direction, PDI interrupt
_MBX_CONTROL = (0x26, 0x22)


AL_ACK = 0x10  # AL control bit 4: error acknowledge
AL_STATUS_MASK = 0x1F  # state and error bit: the state must be reached without error
AL_STATE_MASK = 0x0F  # state only (the way down tolerates a pending error)
SII_VENDOR_ID, SII_PRODUCT_CODE = 0x0008, 0x000A  # SII word addresses (ETG.1000.6 Table 16)

#: one sync manager (ETG.1000.4 Table 59); status and PDI control are the slave's
SmRegister = Struct(
    "start" / Int16ul,
    "length" / Int16ul,
    "control" / Int8ul,
    "status" / Const(0, Int8ul),
    "activate" / Const(1, Int8ul),
    "pdi_control" / Const(0, Int8ul),
)
#: one FMMU (ETG.1000.4 Table 57); type 1 reads (inputs), 2 writes (outputs)
FmmuRegister = Struct(
    "logical_start" / Int32ul,
    "length" / Int16ul,
    "logical_start_bit" / Int8ul,
    "logical_stop_bit" / Int8ul,
    "physical_start" / Int16ul,
    "physical_start_bit" / Const(0, Int8ul),
    "type" / Int8ul,
    "activate" / Const(1, Int8ul),
    Padding(3),
)
_FMMU_TYPE = {Direction.OUT: 2, Direction.IN: 1}
#: what each direction's image holds, in comments
KIND = {Direction.OUT: "outputs", Direction.IN: "inputs"}


@dataclass(frozen=True, slots=True)
class Validate:
    """Repeat the read until ``data`` matches under ``mask`` (all bits without one)."""

    data: bytes
    mask: bytes | None
    timeout_ms: int


@dataclass(frozen=True, slots=True)
class RegisterCmd:
    """One ETG.2100 register InitCmd (``Config/Master`` or ``Config/Slave/InitCmds/InitCmd``).

    ``data`` is the payload, or for a command that carries only zeros its length
    (written as ``DataLength``); ``cnt`` the working counter to wait for.
    """

    transitions: tuple[str, ...]
    comment: str
    cmd: Command
    adp: int
    ado: int
    data: bytes | int
    cnt: int | None = None
    retries: int = 3
    timeout_ms: int | None = None
    validate: Validate | None = None
    #: ``Requires`` = ``cycle``: the master sends it in a cycle of its own (state
    #: changes, and EEPROM data read a cycle after the read command)
    cycle: bool = False
    before_slave: bool = False


@dataclass(frozen=True, slots=True)
class SmMap:
    """One process-data SM: its assigned PDOs and the logical bits its FMMU maps."""

    number: int
    direction: Direction
    pdos: tuple[Pdo, ...]
    logical_bit: int | None  # first bit in the direction's image; None: the slave has no area

    @property
    def bits(self) -> int:
        return sum(p.bit_len for p in self.pdos)

    @property
    def length(self) -> int:
        """SM length in bytes (ETG.1000.4 Table 59)."""
        return (self.bits + 7) // 8


def _u16(v: int) -> bytes:
    return struct.pack("<H", v)


def sm_of(p: Pdo) -> int:
    """The SM a PDO is assigned to: as stated, else SM2 outputs / SM3 inputs (ETG.2000)."""
    if p.sm is not None:
        return p.sm
    return 2 if p.direction == Direction.OUT else 3


def sm_maps(s: Slave) -> list[SmMap]:
    """The slave's process-data SMs in number order (its ``ProcessData/SmN``); within a
    direction the SMs follow each other in the slave's ``Send``/``Recv`` bits."""
    by_sm: dict[int, list[Pdo]] = {}
    for p in (*s.rx_pdos, *s.tx_pdos):
        by_sm.setdefault(sm_of(p), []).append(p)
    bit = {
        Direction.OUT: s.outputs.bit_start if s.outputs is not None else None,
        Direction.IN: s.inputs.bit_start if s.inputs is not None else None,
    }
    out = []
    for n in sorted(by_sm):
        d = by_sm[n][0].direction
        m = SmMap(n, d, tuple(by_sm[n]), bit[d])
        out.append(m)
        if m.logical_bit is not None:
            bit[d] = m.logical_bit + m.bits
    return out


def has_mailbox(s: Slave) -> bool:
    """Whether the writer gives the slave a ``Mailbox`` element (and so SM0/SM1)."""
    return s.mailbox or bool(s.init_cmds)


def _request(
    tr: tuple[str, ...],
    state: AlState,
    cmd: Command,
    adp: int,
    *,
    ack: int = 0,
    cnt: int | None = None,
    retries: int = 3,
    timeout_ms: int,
) -> RegisterCmd:
    data = _u16(state | ack)
    comment = f"set device state to {state.name}"
    return RegisterCmd(
        tr, comment, cmd, adp, Reg.AL_CONTROL, data, cnt, retries, timeout_ms, cycle=True
    )


def _check(
    tr: tuple[str, ...],
    state: AlState,
    cmd: Command,
    adp: int,
    *,
    mask: int,
    timeout_ms: int,
    cnt: int | None = None,
) -> RegisterCmd:
    """Read AL status until it shows ``state`` (2 bytes by position, 6 with the status code
    by station address, as TwinCAT reads them)."""
    n = 2 if cmd == Command.APRD else 6
    want = Validate(bytes([state]) + bytes(n - 1), bytes([mask]) + bytes(n - 1), timeout_ms)
    comment = f"check device state for {state.name}"
    return RegisterCmd(
        tr, comment, cmd, adp, Reg.AL_STATUS, bytes(n), cnt, validate=want, cycle=True
    )


def _identity(adp: int, word: int, value: int, what: str) -> list[RegisterCmd]:
    """Read one SII double word and check it (ETG.1000.4 Table 48: command, then data)."""
    return [
        RegisterCmd(
            ("IP",),
            f"check {what}",
            Command.APWR,
            adp,
            Reg.EEPROM_CONTROL,
            struct.pack("<HI", EepromStatus.CMD_READ, word),
            cnt=1,
        ),
        RegisterCmd(
            ("IP",),
            f"check {what}",
            Command.APRD,
            adp,
            Reg.EEPROM_DATA,
            bytes(4),
            cnt=1,
            validate=Validate(struct.pack("<I", value), None, 100),
            cycle=True,
        ),
    ]


def slave_cmds(s: Slave, bases: dict[Direction, int]) -> list[RegisterCmd]:
    """The register InitCmds of one slave, in document order; ``bases``: where each image
    starts in the logical address space (:func:`logical_bases`)."""
    ap = (-s.position) & 0xFFFF  # auto-increment (position) address: 0, -1, -2, ...
    fp = s.phys_addr
    mbx = has_mailbox(s)
    ack = AL_ACK if mbx else 0
    down = ("PI", "BI", "SI", "OI")
    ip, ps = ("IP",), ("PS",)
    cmds = [
        _request(down, AlState.INIT, Command.APWR, ap, ack=ack, timeout_ms=5000),
        _check(down, AlState.INIT, Command.APRD, ap, mask=AL_STATE_MASK, timeout_ms=5000),
        _request(ip, AlState.INIT, Command.APWR, ap, ack=ack, cnt=1, timeout_ms=3000),
        _check(ip, AlState.INIT, Command.APRD, ap, mask=AL_STATE_MASK, timeout_ms=3000, cnt=1),
        RegisterCmd(ip, "assign EEPROM to ECAT", Command.APWR, ap, Reg.EEPROM_CONFIG, b"\0", cnt=1),
        *_identity(ap, SII_VENDOR_ID, s.identity.vendor_id, "vendor id"),
        *_identity(ap, SII_PRODUCT_CODE, s.identity.product_code, "product code"),
        RegisterCmd(
            ip, "set physical address", Command.APWR, ap, Reg.STATION_ADDRESS, _u16(fp), cnt=1
        ),
    ]
    if mbx:
        for n, ((start, length), control) in enumerate(zip(MAILBOX, _MBX_CONTROL, strict=True)):
            data = SmRegister.build({"start": start, "length": length, "control": control})
            what = f"set sm {n} (mailbox {('out', 'in')[n]})"
            cmds.append(RegisterCmd(ip, what, Command.FPWR, fp, Reg.SM0 + 8 * n, data, cnt=1))
    cmds += [
        _request(ip, AlState.PREOP, Command.FPWR, fp, ack=ack, cnt=1, retries=300, timeout_ms=3000),
        _check(ip, AlState.PREOP, Command.FPRD, fp, mask=AL_STATUS_MASK, timeout_ms=3000, cnt=1),
    ]
    maps = [m for m in sm_maps(s) if m.length]
    for m in maps:
        start, control = SM_DEFAULT[m.direction]
        data = SmRegister.build({"start": start, "length": m.length, "control": control})
        what = f"set sm {m.number} ({KIND[m.direction]})"
        cmds.append(RegisterCmd(ps, what, Command.FPWR, fp, Reg.SM0 + 8 * m.number, data, cnt=1))
    mapped = sorted((m for m in maps if m.logical_bit is not None), key=lambda m: m.direction)
    for k, m in enumerate(mapped):
        what = f"set fmmu {k} ({KIND[m.direction]})"
        data = fmmu_bytes(m, bases[m.direction])
        cmds.append(RegisterCmd(ps, what, Command.FPWR, fp, Reg.FMMU0 + 16 * k, data, cnt=1))
    up, down_mask = AL_STATUS_MASK, AL_STATE_MASK  # up: without error; down: the state only
    cmds += [
        _request(ps, AlState.SAFEOP, Command.FPWR, fp, cnt=1, timeout_ms=10000),
        _check(ps, AlState.SAFEOP, Command.FPRD, fp, mask=up, timeout_ms=10000, cnt=1),
        _request(("SO",), AlState.OP, Command.FPWR, fp, cnt=1, timeout_ms=10000),
        _check(("SO",), AlState.OP, Command.FPRD, fp, mask=up, timeout_ms=10000, cnt=1),
        _request(("OS",), AlState.SAFEOP, Command.FPWR, fp, timeout_ms=200),
        _check(("OS",), AlState.SAFEOP, Command.FPRD, fp, mask=down_mask, timeout_ms=200),
        _request(("SP", "OP"), AlState.PREOP, Command.FPWR, fp, retries=300, timeout_ms=200),
        _check(("SP", "OP"), AlState.PREOP, Command.FPRD, fp, mask=down_mask, timeout_ms=5000),
    ]
    return cmds


def fmmu_bytes(m: SmMap, logical_base: int = LOGICAL_BASE) -> bytes:
    """The FMMU mapping SM ``m`` bit for bit onto its logical bits (the SM starts at bit 0);
    ``logical_base``: the logical address of its direction's image."""
    assert m.logical_bit is not None
    first = m.logical_bit % 8
    return FmmuRegister.build(
        {
            "logical_start": logical_base + m.logical_bit // 8,
            "length": (first + m.bits + 7) // 8,
            "logical_start_bit": first,
            "logical_stop_bit": (first + m.bits - 1) % 8,
            "physical_start": SM_DEFAULT[m.direction][0],
            "type": _FMMU_TYPE[m.direction],
        }
    )


def master_cmds(n_slaves: int) -> list[RegisterCmd]:
    """The master's ``BeforeSlave`` commands: the bus has the slaves the ENI lists, and no
    FMMU or SM a previous master left behind is active (TwinCAT writes the same)."""
    return [
        RegisterCmd(
            ("IP",),
            "read slave count",
            Command.BRD,
            0,
            Reg.AL_STATUS,
            bytes(2),
            n_slaves,
            cycle=True,
            before_slave=True,
        ),
        RegisterCmd(
            ("IP", "PI", "BI", "SI", "OI"),
            "clear fmmu",
            Command.BWR,
            0,
            Reg.FMMU0,
            256,
            cycle=True,
            before_slave=True,
        ),
        RegisterCmd(
            ("IP",), "clear sm", Command.BWR, 0, Reg.SM0, 256, cycle=True, before_slave=True
        ),
    ]
