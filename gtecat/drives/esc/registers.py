"""One EtherCAT slave controller (ESC): its register space and what the registers do.

The physical memory of an ESC is 64 KiB: registers below 1000h (ETG.1000.4
Table 31), process RAM above.  A master reads and writes it with datagrams;
:meth:`Esc.read` and :meth:`Esc.write` are those accesses, returning whether
the ESC accepted them (the working counter counts accepted accesses only).

What the registers do, and where it is specified:

* 0000h-0008h type, revision, build, FMMU/SM counts, RAM size, ports, features
  (DC supported, 64 bit) - read only.
* 0010h configured station address (FP addressing), 0012h alias (from SII word 4,
  used for FP addressing when DL control 0103h bit 0 is set).
* 0100h DL control, 0110h DL status (link/loop/communication per port, set from
  the slave's place in the chain so a master sees the topology; ETG.1000.4 Table 34).
* 0120h AL control -> 0130h AL status / 0134h AL status code (ETG.1000.4 Table 35,
  ETG.1000.6 6.4): the request goes to :meth:`VirtualSlave.request_state`; a
  pending error (status bit 4) must be acknowledged (control bit 4) before a
  request for the same or a higher state is taken; lower states are always taken.
  A slave with a mailbox has firmware, which checks valid mailbox SMs for
  INIT -> PREOP (16h) and process data SM lengths against the current mapping
  for PREOP -> SAFEOP (1Dh outputs, 1Eh inputs); a bare ESC without one checks
  nothing (device emulation: AL status follows AL control).
* 0200h/0210h ECAT event mask/request (AL status change, SM mailbox full), OR-ed
  into every datagram's IRQ field.
* 0300h-0313h error counters (any write clears them).
* 0400h watchdog divider, 0420h SM watchdog time, 0440h SM watchdog status.
* 0500h-050Fh SII EEPROM interface (ETG.1000.4 Table 48): read (8 bytes per
  command, status bit 6), write (needs the write-enable bit), reload, NOP clears
  errors; the busy bit (15) stays set for ``eeprom_busy_ns`` after a command.
* 0600h+ FMMUs (ETG.1000.4 Table 57), 16 bytes each: logical <-> physical, bit
  granular, read and/or write.
* 0800h+ sync managers (ETG.1000.4 Table 59), 8 bytes each: mailbox mode (one
  buffer; a write to a full write-mailbox and a read of an empty read-mailbox are
  refused; the access to the last byte completes/frees it; repeat request via the
  activate register bit 1, acknowledged in PDI control bit 1) and buffered mode
  (process data; the write of the last byte hands the outputs to the slave).
  The firmware behind the mailbox (ETG.1000.4 5.5, as the ETG slave stack does
  it): a message whose non-zero counter equals the previous message's is a
  repeat - a master resending a frame whose answer came late - and is not
  executed again (the answer it already got stays; a lost answer is served
  again through the SM1 repeat request); the counter memory is cleared when the
  mailbox starts (INIT).  Answers of several messages (SDO Information
  fragments) go out one by one as the master reads them; CoE emergencies the
  slave raises (``slave.emergencies``) are queued as CoE service 1 messages
  from PREOP on; FoE is answered by :mod:`gtecat.drives.foe` (reads of the files in
  ``esc.foe.files``, "not found" otherwise, writes refused: no firmware update).
* 0900h-0935h DC: receive times latched by a write to 0900h, 64-bit system time at
  0910h (a write there is the drift compensation: the local copy locks onto
  it), offset 0920h, delay 0928h, difference 092Ch; SYNC0/SYNC1: once activated (0981h)
  with a cycle (09A0h), 0990h/0998h read the next pulse's system time and 098Eh/098Fh say
  a pulse came (no PDI side acts on the pulses).

Sync managers are deactivated by the slave's side (PDI control bit 0) in the
states where the slave does not serve them: mailboxes in INIT, inputs below
SAFEOP, outputs below OP - the same working counter rule as the in-process
backend (+1 inputs from SAFEOP, +2 outputs in OP).
"""

from __future__ import annotations

import logging
import struct
import time
from collections import deque
from collections.abc import Callable

from gtecat.eni.bits import get_bits, set_bits
from gtecat.eni.ethercat import EepromStatus, Reg

from ..coe import CoeService, MailboxError, MailboxType, build_coe, mailbox_error
from ..foe import FoeServer
from ..slave import AlState, AlStatusCode, VirtualSlave

log = logging.getLogger(__name__)

REGISTER_SPACE = 0x1000
SM_FLOOR = 0x0F00  #: the lowest address an SM buffer may start at (digital I/O, 0F00h)
MEMORY_SIZE = 0x10000
N_FMMU = 8
N_SM = 8
#: forwarding + processing delay of one slave, for the DC receive times
HOP_NS = 800

_U16 = struct.Struct("<H")
_U32 = struct.Struct("<I")
_U64 = struct.Struct("<Q")
_I64 = struct.Struct("<q")
_FMMU = struct.Struct("<IHBBHBBB3x")
_SM = struct.Struct("<HHBBBB")


# --- which register bytes a master may write, and with which bits ----------------------------
_WMASK = bytearray(REGISTER_SPACE)


def _rw(start: int, n: int, mask: int = 0xFF) -> None:
    for a in range(start, start + n):
        _WMASK[a] = mask


_rw(Reg.STATION_ADDRESS, 2)
_rw(Reg.DL_CONTROL, 4)
_rw(0x0108, 2)  # physical read/write offset
_rw(Reg.AL_CONTROL, 2)
_rw(0x0138, 2)  # RUN/ERR LED override
_rw(Reg.EVENT_MASK, 2)
_rw(Reg.RX_ERROR, 0x14)  # error counters (a write clears them)
_rw(Reg.WD_DIVIDER, 2)
_rw(Reg.WD_TIME_PDI, 2)
_rw(Reg.WD_TIME_PD, 2)
_rw(Reg.WD_COUNTER_PD, 2)  # a write clears them
_rw(Reg.EEPROM_CONFIG, 1, 0x03)
_rw(Reg.EEPROM_CONTROL, 1, 0x01)  # write enable
_rw(Reg.EEPROM_CONTROL + 1, 1, 0x07)  # command
_rw(Reg.EEPROM_ADDRESS, 4)
_rw(Reg.EEPROM_DATA, 8)
_rw(Reg.FMMU0, 16 * 16)
for _n in range(16):
    _rw(Reg.SM0 + 8 * _n, 5)  # start, length, control
    _rw(Reg.SM0 + 8 * _n + 6, 1, 0xC3)  # activate: enable, repeat, latch events
_rw(Reg.DC_SYSTEM_OFFSET, 12)  # offset + delay
_rw(Reg.DC_SPEED_COUNT, 2)
_rw(Reg.DC_FILTER_DEPTH, 2)
_rw(Reg.DC_CYCLIC_CONTROL, 2)
_rw(Reg.DC_START_TIME, 8)
_rw(Reg.DC_SYNC0_CYCLE, 8)
_rw(0x09A8, 2)  # latch control
_rw(0x0F00, 4)  # digital outputs
_rw(0x0F10, 8)  # general purpose outputs
_WMASK_BYTES = bytes(_WMASK)

# SM control bits (ETG.1000.4 Table 59)
SM_MODE_MAILBOX = 0x02
SM_DIR_WRITE = 0x04  # ECAT writes, PDI reads
SM_WATCHDOG = 0x40
SM_STATUS_MAILBOX_FULL = 0x08
SM_STATUS_IRQ_WRITE = 0x01
SM_STATUS_IRQ_READ = 0x02
SM_ACT_ENABLE = 0x01
SM_ACT_REPEAT = 0x02
SM_PDI_DEACTIVATE = 0x01
SM_PDI_REPEAT_ACK = 0x02

EVENT_AL_STATUS = 0x0008


class SyncManager:
    """One enabled sync manager (decoded from 0800h + 8n)."""

    __slots__ = (
        "ecat_writes",
        "end",
        "full",
        "length",
        "mailbox",
        "num",
        "pdi_off",
        "start",
        "status_addr",
        "watchdog",
    )

    def __init__(self, num: int, start: int, length: int, control: int) -> None:
        self.num = num
        self.status_addr = Reg.SM0 + 8 * num + 5
        self.start = start
        self.length = length
        self.end = start + length
        self.mailbox = (control & 0x03) == SM_MODE_MAILBOX
        self.ecat_writes = (control & 0x0C) == SM_DIR_WRITE
        self.watchdog = bool(control & SM_WATCHDOG)
        self.full = False
        self.pdi_off = False


class Fmmu:
    """One active FMMU (decoded from 0600h + 16n)."""

    __slots__ = ("aligned", "lbit0", "lbit1", "lend", "lstart", "pbit0", "pstart", "read", "write")

    def __init__(
        self, lstart: int, length: int, lsb: int, leb: int, pstart: int, psb: int, ftype: int
    ) -> None:
        self.lstart = lstart
        self.lend = lstart + length  # exclusive, in bytes
        self.lbit0 = lstart * 8 + (lsb & 7)
        self.lbit1 = (lstart + length - 1) * 8 + (leb & 7) + 1  # exclusive, in bits
        self.pstart = pstart
        self.pbit0 = pstart * 8 + (psb & 7)
        self.read = bool(ftype & 1)
        self.write = bool(ftype & 2)
        self.aligned = (lsb & 7) == 0 and (leb & 7) == 7 and (psb & 7) == 0


class LogicalPlan:
    """One ESC's part of a logical datagram, as byte copies (:meth:`Esc.logical_plan`).

    The chain runs it inline: ``writes`` (datagram offset, end, physical start,
    end) into ``mem``, then ``done`` (the SMs whose last byte was written, with the
    ESC's handler), then ``reads`` back into the datagram; ``wkc`` is the increment.
    """

    __slots__ = ("done", "esc", "mem", "reads", "wkc", "writes")

    def __init__(
        self,
        esc: Esc,
        writes: tuple[tuple[int, int, int, int], ...],
        done: tuple[SyncManager, ...],
        reads: tuple[tuple[int, int, int, int], ...],
        wkc: int,
    ) -> None:
        self.esc = esc
        self.mem = esc.mem
        self.writes = writes
        self.done = tuple((esc._buffer_written, sm) for sm in done)
        self.reads = reads
        self.wkc = wkc

    def run(self, data: memoryview) -> int:
        """Writes first, then reads, like :meth:`Esc.logical`; the WKC increment."""
        mem = self.mem
        for f0, f1, p0, p1 in self.writes:
            mem[p0:p1] = data[f0:f1]
        for handler, sm in self.done:
            handler(sm)
        for f0, f1, p0, p1 in self.reads:
            data[f0:f1] = mem[p0:p1]
        return self.wkc


class FrameTime:
    """When the frame being processed reached the first slave (host monotonic ns)."""

    __slots__ = ("t_ns",)

    def __init__(self, t_ns: int = 0) -> None:
        self.t_ns = t_ns


def _noop(*_: object) -> None:
    return None


class Esc:
    """The register space and firmware of one virtual slave."""

    def __init__(
        self,
        slave: VirtualSlave,
        sii: bytes,
        *,
        position: int = 0,
        chain_length: int = 1,
        clock: Callable[[], int] = time.monotonic_ns,
        frame_time: FrameTime | None = None,
        watchdog_trips: bool = False,
        eeprom_busy_ns: int = 20_000,
    ) -> None:
        self.slave = slave
        self.sii = bytearray(sii)
        self.position = position
        self.chain_length = chain_length
        self.clock = clock
        self.ft = frame_time or FrameTime(clock())
        self.watchdog_trips = watchdog_trips
        self.eeprom_busy_ns = eeprom_busy_ns
        self.mem = bytearray(MEMORY_SIZE)
        self.sms: list[SyncManager] = []
        #: lowest address any enabled SM covers (SMs may sit in register space: an
        #: EL2008's output SM is the digital output register 0F00h)
        self._sm_floor = REGISTER_SPACE
        self.fmmus: list[Fmmu] = []
        self.outputs_sm: SyncManager | None = None
        self.inputs_sm: SyncManager | None = None
        self.mbx_out_sm: SyncManager | None = None  # master -> slave (SM0)
        self.mbx_in_sm: SyncManager | None = None  # slave -> master (SM1)
        self._sm_keys: list[tuple[int, ...]] = [()] * N_SM
        self._mbx_queue: deque[bytes] = deque()
        self._mbx_last: bytes = b""  #: the message the SM1 buffer holds (or held last)
        #: the message the master read last: what a repeat request puts back
        self._mbx_read: bytes = b""
        self._mbx_cnt = 0
        self._mbx_in_pending = False
        #: counter of the last mailbox message taken (0: none since the mailbox started)
        self._mbx_write_counter = 0
        #: the slave may have further messages of its last answer (``mailbox_next``)
        self._mbx_more = False
        #: FoE of the firmware: files offered for reading, writes (firmware updates) refused
        self.foe = FoeServer(
            mailbox_size=int(getattr(getattr(slave, "sdo", None), "mailbox_size", 128))
        )
        #: mailbox messages not executed because they repeated the previous counter
        self.mailbox_repeats = 0
        #: answers and emergencies dropped because the queue was full
        self.mailbox_overflows = 0
        self._eeprom_busy_until = 0
        self._dc_base = (position + 1) * 123_456_789
        self._dc_correction = 0
        #: the start time the master wrote (0990h reads back the next SYNC0 pulse once active)
        self._sync_start = 0
        self._wd_last = 0
        self._wd_expired = False
        self._id_request = False
        self._state_seen = slave.al_state
        self._op = slave.al_state == AlState.OP
        self._outputs_since_op = False
        #: set by the chain: the station address / FMMUs changed, PDI work is pending
        self.on_station_change: Callable[[Esc], None] = _noop
        self.on_fmmu_change: Callable[[Esc], None] = _noop
        #: the slave side wrote an input SM (:meth:`load_inputs`): snapshots are stale
        self.on_inputs: Callable[[Esc], None] = _noop
        #: the unmasked event requests changed: the chain keeps their OR for the IRQ field
        self.on_irq_change: Callable[[Esc], None] = _noop
        self._irq = 0
        #: SM configuration or PDI (de)activation changed: compiled datagram plans are stale
        self.on_sm_change: Callable[[Esc], None] = _noop
        #: the system time's constants changed (offset, delay, a drift correction that moved
        #: the clock): the chain's compiled DC datagrams are stale
        self.on_dc_change: Callable[[Esc], None] = _noop
        self.on_pending: Callable[[Esc], None] = _noop
        self.errors = 0
        self._reset_registers()

    # --- power-on register values ------------------------------------------------------------
    def _reset_registers(self) -> None:
        m = self.mem
        m[Reg.TYPE] = 0x11
        m[Reg.REVISION] = 0x00
        _U16.pack_into(m, Reg.BUILD, 0x0003)
        m[Reg.FMMU_COUNT] = N_FMMU
        m[Reg.SM_COUNT] = N_SM
        m[Reg.RAM_SIZE] = 8
        m[Reg.PORT_DESCRIPTOR] = 0x0F  # ports 0 and 1: MII
        _U16.pack_into(m, Reg.FEATURES, 0x000C)  # DC supported, 64-bit DC
        _U32.pack_into(m, Reg.DL_CONTROL, 0x00000001)
        _U16.pack_into(m, Reg.AL_CONTROL, int(AlState.INIT))
        m[Reg.PDI_CONTROL] = self.sii[0] if self.sii else 0x05
        m[Reg.ESC_CONFIG] = self.sii[1] if len(self.sii) > 1 else 0x00
        _U16.pack_into(m, Reg.WD_DIVIDER, 0x09C2)  # 100 us
        _U16.pack_into(m, Reg.WD_TIME_PDI, 1000)
        _U16.pack_into(m, Reg.WD_TIME_PD, 1000)  # 100 ms
        _U16.pack_into(m, Reg.WD_STATUS_PD, 0x0001)
        status = EepromStatus.READ_8_BYTES
        if len(self.sii) > 2048:
            status |= EepromStatus.TWO_ADDRESS_BYTES
        _U16.pack_into(m, Reg.EEPROM_CONTROL, status)
        _U16.pack_into(m, Reg.DC_SPEED_COUNT, 0x1000)
        _U16.pack_into(m, Reg.DC_FILTER_DEPTH, 0x0C00)
        self._load_alias()
        self.set_topology(self.position, self.chain_length)
        self.sync_al()
        self.mem[0x0210] = 0  # power-on is no AL status event
        self._irq_update()

    def _load_alias(self) -> None:
        if len(self.sii) >= 10:
            self.mem[Reg.STATION_ALIAS : Reg.STATION_ALIAS + 2] = self.sii[8:10]

    def set_topology(self, position: int, chain_length: int) -> None:
        """DL status for a slave in a line: port 0 towards the master, port 1 onwards."""
        self.position, self.chain_length = position, chain_length
        last = position >= chain_length - 1
        status = 0x0001 | 0x0002  # PDI operational (EEPROM loaded), PDI watchdog fine
        status |= 0x0010 | 0x0200  # port 0: link, loop open, communication
        if last:
            status |= 0x0400  # port 1 loop closed
        else:
            status |= 0x0020 | 0x0800  # port 1: link, loop open, communication
        status |= 0x1000 | 0x4000  # ports 2 and 3 closed
        _U16.pack_into(self.mem, Reg.DL_STATUS, status)

    # --- properties a master sees ----------------------------------------------------------------
    @property
    def station_address(self) -> int:
        return _U16.unpack_from(self.mem, Reg.STATION_ADDRESS)[0]

    @property
    def station_alias(self) -> int:
        return _U16.unpack_from(self.mem, Reg.STATION_ALIAS)[0]

    @property
    def alias_enabled(self) -> bool:
        return bool(self.mem[Reg.DL_ALIAS] & 0x01)

    @property
    def event_irq(self) -> int:
        """Event request bits the master unmasked (what goes into the IRQ field)."""
        return self._irq

    def _irq_update(self) -> None:
        """Event request (0210h) or mask (0200h) changed: the chain ORs the new value."""
        m = self.mem
        irq = (m[0x0210] | m[0x0211] << 8) & (m[0x0200] | m[0x0201] << 8)
        if irq != self._irq:
            self._irq = irq
            self.on_irq_change(self)

    def peek(self, addr: int, n: int) -> bytes:
        """Raw memory, no side effects (tests, tools)."""
        return bytes(self.mem[addr : addr + n])

    # --- ECAT accesses -------------------------------------------------------------------------
    def read(self, addr: int, n: int) -> bytes | None:
        """An ECAT read of ``n`` bytes; ``None`` when the ESC refuses it (no WKC)."""
        end = addr + n
        if end > MEMORY_SIZE or addr < 0:
            return None
        if end > self._sm_floor:
            hit = None
            for sm in self.sms:
                if sm.start < end and addr < sm.end:
                    if sm.pdi_off:
                        return None
                    if sm.mailbox and (sm.ecat_writes or not sm.full):
                        return None
                    if hit is None:
                        hit = [sm]
                    else:
                        hit.append(sm)
            if hit:
                data = bytes(self.mem[addr:end]) if addr >= REGISTER_SPACE else None
                if data is None:
                    data = self._reg_read(addr, end)
                for sm in hit:
                    if sm.mailbox and addr < sm.end <= end:
                        self._mailbox_read_done(sm)
                return data
            if addr >= REGISTER_SPACE:
                return bytes(self.mem[addr:end])
        return self._reg_read(addr, end)

    def _reg_read(self, addr: int, end: int) -> bytes:
        if addr < 0x0918 and end > 0x0910:
            _U64.pack_into(self.mem, Reg.DC_SYSTEM_TIME, self.system_time())
        if addr < 0x09A0 and end > 0x098E:
            self._sync_pulses()
        if addr < 0x0504 and end > 0x0502:
            self._eeprom_poll()
        data = bytes(self.mem[addr:end])
        if addr < 0x0132 and end > 0x0130 and self.mem[0x0210] & EVENT_AL_STATUS:
            self.mem[0x0210] &= ~EVENT_AL_STATUS & 0xFF  # reading AL status acknowledges the event
            self._irq_update()
        return data

    def write(self, addr: int, data: bytes | bytearray | memoryview) -> bool:
        """An ECAT write; ``False`` when the ESC refuses it (no WKC)."""
        n = len(data)
        end = addr + n
        if end > MEMORY_SIZE or addr < 0:
            return False
        if end > self._sm_floor:
            hit = None
            for sm in self.sms:
                if sm.start < end and addr < sm.end:
                    if sm.pdi_off or not sm.ecat_writes:
                        return False
                    if sm.mailbox and sm.full:
                        return False
                    if hit is None:
                        hit = [sm]
                    else:
                        hit.append(sm)
            if addr >= REGISTER_SPACE:
                self.mem[addr:end] = data
            elif end <= REGISTER_SPACE:
                self._reg_write(addr, bytes(data))
            else:
                self._reg_write(addr, bytes(data[: REGISTER_SPACE - addr]))
                self.mem[REGISTER_SPACE:end] = data[REGISTER_SPACE - addr :]
            if hit:
                for sm in hit:
                    if addr < sm.end <= end:
                        self._buffer_written(sm)
            return True
        self._reg_write(addr, bytes(data))
        return True

    # --- registers ----------------------------------------------------------------------------
    def _reg_write(self, addr: int, data: bytes) -> None:
        end = addr + len(data)
        m = self.mem
        mask = _WMASK_BYTES[addr:end]
        if mask == b"\xff" * len(data):
            m[addr:end] = data
        else:
            for i, b in enumerate(data):
                k = mask[i]
                if k:
                    a = addr + i
                    m[a] = (m[a] & ~k) | (b & k)
        # side effects, in register order
        if addr < 0x0012 and end > 0x0010:
            self.on_station_change(self)
        if addr < 0x0202 and end > 0x0200:
            self._irq_update()
        if addr < 0x0104 and end > 0x0103:
            self.on_station_change(self)  # alias enable changed FP matching
        if addr < 0x0122 and end > 0x0120:
            self._al_control()
        if addr < 0x0314 and end > 0x0300:
            m[0x0300:0x0314] = bytes(0x14)
        if addr < 0x0444 and end > 0x0442:
            m[0x0442:0x0444] = b"\x00\x00"
        if addr < 0x0501 and end > 0x0500 and m[0x0500] & 0x02:
            m[0x0501] = 0  # force ECAT access: the PDI loses the EEPROM
        if addr < 0x0504 and end > 0x0502:
            self._eeprom_command()
        if addr < 0x0700 and end > 0x0600:
            self._decode_fmmus()
        if addr < 0x0880 and end > 0x0800:
            self._decode_sms()
        if addr < 0x0904 and end > 0x0900:
            self._latch_receive_times()
        if addr < 0x0918 and end > 0x0910:
            self._system_time_written(addr, data)
        if addr < 0x0928 and end > 0x0920:
            self._dc_correction = 0  # a new offset: the control loop starts over
        if addr < 0x092C and end > 0x0920:
            self.on_dc_change(self)
        if addr < 0x0998 and end > 0x0990:
            self._sync_start = _U64.unpack_from(m, Reg.DC_START_TIME)[0]

    # --- AL state machine ----------------------------------------------------------------------
    def _al_control(self) -> None:
        value = _U16.unpack_from(self.mem, Reg.AL_CONTROL)[0]
        target = value & 0x0F
        ack = bool(value & 0x10)
        slave = self.slave
        current = slave.al_state
        if slave.al_error and not ack and target >= current:
            return  # an error must be acknowledged first (ETG.1000.6 6.4.1)
        self._id_request = bool(value & 0x20)
        if ack and slave.al_error and target == current:
            slave.al_error = False
            slave.al_status_code = AlStatusCode.NO_ERROR
        code = self._firmware_check(current, target)
        if code:
            slave.al_error = True
            slave.al_status_code = code
        elif target != current or slave.al_error:
            try:
                slave.request_state(target)  # type: ignore[arg-type]
            except Exception:  # a slave bug must not take the chain down
                log.exception("slave %d (%s): request_state(%d)", self.position, slave.name, target)
                self.errors += 1
                slave.al_error = True
                slave.al_status_code = AlStatusCode.UNSPECIFIED_ERROR
        self.sync_al()

    def _firmware_check(self, current: AlState, target: int) -> AlStatusCode:
        """What a slave's firmware checks before it takes a transition.

        Only a slave with a microcontroller behind its ESC has firmware; that is a
        slave with a mailbox.  A bare ESC (an EL1xxx/EL2xxx terminal: digital I/O
        PDI, device emulation) takes every state the master requests and checks no
        SM layout: TwinCAT writes an EL2008's output SM only at SAFEOP -> OP.
        """
        if not self.slave.has_mailbox:
            return AlStatusCode.NO_ERROR
        if current == AlState.INIT and target == AlState.PREOP and self.slave.has_mailbox:
            out, inp = self.mbx_out_sm, self.mbx_in_sm
            if out is None or inp is None or out.length < 8 or inp.length < 8:
                return AlStatusCode.INVALID_MAILBOX_CONFIGURATION
            if out.start < inp.end and inp.start < out.end:
                return AlStatusCode.INVALID_MAILBOX_CONFIGURATION
        if current == AlState.PREOP and target == AlState.SAFEOP:
            # the buffers the data path uses (first enabled process-data SM per direction);
            # a stale extra SM a master left enabled (SOEM clears only SM0-3) is not counted
            rx_bits, tx_bits = self.slave.pdo_sizes()
            out_len = self.outputs_sm.length if self.outputs_sm is not None else 0
            in_len = self.inputs_sm.length if self.inputs_sm is not None else 0
            if out_len != (rx_bits + 7) // 8:
                return AlStatusCode.INVALID_OUTPUT_CONFIGURATION
            if in_len != (tx_bits + 7) // 8:
                return AlStatusCode.INVALID_INPUT_CONFIGURATION
        return AlStatusCode.NO_ERROR

    def sync_al(self) -> None:
        """Mirror the slave's AL state into 0130h/0134h and follow a state change."""
        slave = self.slave
        state = slave.al_state
        if state != self._state_seen:
            self._enter_state(self._state_seen, state)
            self._state_seen = state
        self._op = state == AlState.OP
        status = int(state) | (0x10 if slave.al_error else 0)
        code = int(slave.al_status_code)
        if self._id_request and not slave.al_error:
            status |= 0x20
            code = self.station_alias
        m = self.mem
        if m[Reg.AL_STATUS] != status or _U16.unpack_from(m, Reg.AL_STATUS_CODE)[0] != code:
            m[Reg.AL_STATUS] = status
            _U16.pack_into(m, Reg.AL_STATUS_CODE, code)
            m[0x0210] |= EVENT_AL_STATUS
            self._irq_update()

    def _enter_state(self, old: AlState, new: AlState) -> None:
        if new == AlState.INIT:
            self._mbx_queue.clear()
            self._mbx_read = b""
            self._mbx_in_pending = False
            self._mbx_more = False
            self._mbx_write_counter = 0
            for sm in self.sms:
                if sm.mailbox:
                    self._set_full(sm, False)
        if new != AlState.OP:
            self._outputs_since_op = False
            self.slave.outputs_valid = False
        self._apply_pdi_sm_state()
        if new >= AlState.SAFEOP:
            self.load_inputs()

    def _apply_pdi_sm_state(self) -> None:
        state = self.slave.al_state
        for sm in self.sms:
            if sm.mailbox:
                off = state == AlState.INIT
            elif sm.ecat_writes:
                off = state != AlState.OP
            else:
                off = state not in (AlState.SAFEOP, AlState.OP)
            sm.pdi_off = off
            a = Reg.SM0 + 8 * sm.num + 7
            self.mem[a] = (self.mem[a] & ~SM_PDI_DEACTIVATE) | (SM_PDI_DEACTIVATE if off else 0)
        self.on_sm_change(self)

    # --- sync managers -------------------------------------------------------------------------
    def _decode_sms(self) -> None:
        m = self.mem
        old = {sm.num: sm for sm in self.sms}
        sms: list[SyncManager] = []
        for n in range(N_SM):
            start, length, control, _status, activate, _pdi = _SM.unpack_from(m, Reg.SM0 + 8 * n)
            key = (start, length, control, activate & SM_ACT_ENABLE)
            prev = old.get(n)
            pdi = Reg.SM0 + 8 * n + 7
            # an SM buffer lies at the digital I/O registers (0F00h, TwinCAT's EL2008) or in
            # the process memory (1000h on): one that would cover the configuration
            # registers, or run past the memory, is not activated, so a master that wrote
            # one cannot lock itself (or the next master) out of the FMMU and SM registers
            usable = SM_FLOOR <= start and start + length <= MEMORY_SIZE
            if activate & SM_ACT_ENABLE and length and usable:
                if prev is not None and self._sm_keys[n] == key:
                    sm = prev
                    if sm.mailbox and not sm.ecat_writes:
                        ack = m[pdi] & SM_PDI_REPEAT_ACK
                        if bool(activate & SM_ACT_REPEAT) != bool(ack):
                            self._repeat(sm, activate & SM_ACT_REPEAT)
                else:
                    sm = SyncManager(n, start, length, control)
                    m[Reg.SM0 + 8 * n + 5] = 0  # fresh buffer: empty
                    # a new configuration starts with the repeat handshake in step
                    m[pdi] = (m[pdi] & ~SM_PDI_REPEAT_ACK) | (activate & SM_ACT_REPEAT)
                sms.append(sm)
            else:
                m[Reg.SM0 + 8 * n + 5] = 0
            self._sm_keys[n] = key
        self.sms = sms
        self._sm_floor = min([REGISTER_SPACE, *(sm.start for sm in sms)])
        self.outputs_sm = next((s for s in sms if not s.mailbox and s.ecat_writes), None)
        self.inputs_sm = next((s for s in sms if not s.mailbox and not s.ecat_writes), None)
        mbx_out = next((s for s in sms if s.mailbox and s.ecat_writes), None)
        if mbx_out is not self.mbx_out_sm:
            self._mbx_write_counter = 0  # a mailbox set up anew starts a new counter sequence
        self.mbx_out_sm = mbx_out
        self.mbx_in_sm = next((s for s in sms if s.mailbox and not s.ecat_writes), None)
        self._apply_pdi_sm_state()
        if self.slave.al_state >= AlState.SAFEOP:
            self.load_inputs()

    def _set_full(self, sm: SyncManager, full: bool) -> None:
        sm.full = full
        a = sm.status_addr
        irq = SM_STATUS_IRQ_WRITE if sm.ecat_writes else SM_STATUS_IRQ_READ
        if full:
            self.mem[a] |= SM_STATUS_MAILBOX_FULL | irq
        else:
            self.mem[a] &= ~(SM_STATUS_MAILBOX_FULL | irq) & 0xFF
        bit = 1 << (4 + sm.num)  # ECAT event request mirrors the SM interrupt
        req = _U16.unpack_from(self.mem, Reg.EVENT_REQUEST)[0]
        _U16.pack_into(self.mem, Reg.EVENT_REQUEST, (req | bit) if full else (req & ~bit))
        self._irq_update()

    def _repeat(self, sm: SyncManager, repeat_bit: int) -> None:
        """Mailbox repeat request: put back the message the master read last (its answer was
        lost), with its own counter, and acknowledge (ETG.1000.4 5.6).  A newer message
        already waiting unread in the buffer (the next fragment, say) goes back to the front
        of the queue and follows once the repeated one is read."""
        last = self._mbx_read or self._mbx_last
        if last:
            newer = self._mbx_last
            if sm.full and newer and newer is not last:
                self._mbx_queue.appendleft(newer)
            self._write_mailbox(sm, last)
        a = Reg.SM0 + 8 * sm.num + 7
        self.mem[a] = (self.mem[a] & ~SM_PDI_REPEAT_ACK) | (SM_PDI_REPEAT_ACK if repeat_bit else 0)

    def _mailbox_read_done(self, sm: SyncManager) -> None:
        self._mbx_read = self._mbx_last
        self._set_full(sm, False)
        if self._mbx_queue or self._mbx_more:
            self.on_pending(self)

    def _buffer_written(self, sm: SyncManager) -> None:
        if sm.mailbox:
            self._set_full(sm, True)
            self._mbx_in_pending = True
            self.on_pending(self)
            return
        # buffered outputs: the slave gets them now
        rx = self.slave.rx
        n = sm.length if sm.length <= len(rx) else len(rx)
        mem = self.mem
        rx[:n] = mem[sm.start : sm.start + n]
        mem[sm.status_addr] |= SM_STATUS_IRQ_WRITE
        self._wd_last = self.ft.t_ns
        if self._wd_expired:
            self._wd_expired = False
            mem[Reg.WD_STATUS_PD] |= 0x01
        if self._op:
            self._outputs_since_op = True
            self.slave.outputs_valid = True

    def load_inputs(self) -> None:
        """The slave's TxPDO bytes into the inputs buffer (after each step)."""
        sm = self.inputs_sm
        if sm is not None:
            tx = self.slave.tx
            n = min(len(tx), sm.length)
            self.mem[sm.start : sm.start + n] = tx[:n]
            self.on_inputs(self)

    # --- mailbox (the slave's side of SM0/SM1) -------------------------------------------------
    def service(self) -> None:
        """PDI work after a frame: take a mailbox request, hand out the next answer.

        A slave without a mailbox (an EL2008, an EK1100) is an ESC with no microcontroller:
        the master may configure SM0/SM1 as mailbox buffers, the ESC keeps them as it keeps
        any SM, but nobody on the PDI side reads SM0 or writes SM1, so a request stays in
        SM0 (the next write finds it full: WKC 0) and no answer ever comes."""
        if not self.slave.has_mailbox:
            self._mbx_in_pending = False
            return
        sm = self.mbx_out_sm
        if self._mbx_in_pending and sm is not None and sm.full:
            self._mbx_in_pending = False
            msg = bytes(self.mem[sm.start : sm.end])
            self._set_full(sm, False)
            self._take(msg)
        elif self._mbx_in_pending:
            self._mbx_in_pending = False
        out = self.mbx_in_sm
        if out is None or out.full or out.pdi_off:
            return
        if not self._mbx_queue and self._mbx_more:
            try:
                more = self.slave.mailbox_next()
            except Exception:
                log.exception("slave %d (%s): mailbox_next failed", self.position, self.slave.name)
                self.errors += 1
                more = None
            if more:
                self._mbx_queue.append(bytes(more))
            else:
                self._mbx_more = False
        if self._mbx_queue:
            self._put_mailbox(out, self._mbx_queue.popleft())

    #: answers and emergencies a slave may have waiting for the master
    MAILBOX_QUEUE_LIMIT = 64

    def _queue(self, message: bytes) -> None:
        if len(self._mbx_queue) >= self.MAILBOX_QUEUE_LIMIT:
            self.mailbox_overflows += 1
            if self.mailbox_overflows <= 5:
                log.warning(
                    "slave %d (%s): mailbox queue full, message dropped",
                    self.position,
                    self.slave.name,
                )
            return
        self._mbx_queue.append(message)

    def _take(self, msg: bytes) -> None:
        """A mailbox message the master wrote: run it unless it repeats the last one."""
        counter = (msg[5] >> 4) & 0x07 if len(msg) >= 6 else 0
        if counter and counter == self._mbx_write_counter:
            self.mailbox_repeats += 1
            log.info(
                "slave %d (%s): mailbox message with counter %d repeated, not executed again",
                self.position,
                self.slave.name,
                counter,
            )
            return
        self._mbx_write_counter = counter
        self._handle(msg)

    def _handle(self, msg: bytes) -> None:
        length = _U16.unpack_from(msg, 0)[0]
        mtype = msg[5] & 0x0F
        if length + 6 > len(msg):
            self._queue(mailbox_error(MailboxError.INVALID_SIZE))
            return
        if mtype == MailboxType.FOE and getattr(self.slave, "foe", None) is None:
            answer = self.foe.handle(msg[: 6 + length])  # the firmware's FoE (gtecat.drives.foe)
            if answer:
                self._queue(answer)
            return
        try:
            answer = self.slave.mailbox(msg[: 6 + length])
        except Exception:  # the SDO server answers aborts itself; anything else is a bug
            log.exception("slave %d (%s): mailbox handler failed", self.position, self.slave.name)
            self.errors += 1
            answer = mailbox_error(MailboxError.SYNTAX)
        if answer is None and mtype != MailboxType.COE:
            answer = mailbox_error(MailboxError.UNSUPPORTED_PROTOCOL)
        if answer:
            self._queue(bytes(answer))
            self._mbx_more = True

    def collect_emergencies(self) -> None:
        """The slave's pending CoE emergencies into the send queue (ETG.1000.6 5.6.4)."""
        slave = self.slave
        pending = slave.emergencies
        if not pending:
            return
        if (
            not slave.has_mailbox
            or slave.al_state < AlState.PREOP
            or slave.al_state == AlState.BOOT
        ):
            pending.clear()  # no mailbox to carry them: a real slave loses them too
            return
        while pending:
            emcy = pending.popleft()
            body = struct.pack("<HB", emcy.code & 0xFFFF, emcy.register & 0xFF) + bytes(
                emcy.data[:5]
            ).ljust(5, b"\0")
            self._queue(build_coe(CoeService.EMERGENCY, body, counter=0))
        self.on_pending(self)

    def _put_mailbox(self, sm: SyncManager, answer: bytes) -> None:
        if len(answer) > sm.length:
            log.error(
                "slave %d (%s): mailbox answer of %d bytes exceeds SM%d (%d bytes)",
                self.position,
                self.slave.name,
                len(answer),
                sm.num,
                sm.length,
            )
            self.errors += 1
            answer = mailbox_error(MailboxError.NO_MORE_MEMORY)
        if answer is not self._mbx_last:
            self._mbx_cnt = self._mbx_cnt % 7 + 1  # link-layer counter 1..7 (0 is reserved)
            buf = bytearray(answer)
            if len(buf) >= 6:
                buf[5] = (buf[5] & 0x8F) | (self._mbx_cnt << 4)
            answer = bytes(buf)
        self._write_mailbox(sm, answer)

    def _write_mailbox(self, sm: SyncManager, answer: bytes) -> None:
        """``answer`` (its link-layer counter stamped) into the SM1 buffer, which is then full."""
        self.mem[sm.start : sm.end] = answer + bytes(sm.length - len(answer))
        self._mbx_last = answer
        self._set_full(sm, True)

    # --- FMMUs ---------------------------------------------------------------------------------
    def _decode_fmmus(self) -> None:
        fmmus = []
        for n in range(N_FMMU):
            ls, length, lsb, leb, ps, psb, ftype, act = _FMMU.unpack_from(
                self.mem, Reg.FMMU0 + 16 * n
            )
            if act & 1 and length and ftype & 3:
                fmmus.append(Fmmu(ls, length, lsb, leb, ps, psb, ftype))
        self.fmmus = fmmus
        self.on_fmmu_change(self)

    def logical(self, command: int, laddr: int, data: bytearray | memoryview) -> int:
        """LRD (10) / LWR (11) / LRW (12) through this ESC's FMMUs; the WKC increment.

        Writes happen before reads, so a slave whose inputs overlay its outputs
        (SOEM's overlapped map) takes the outputs, then puts its inputs.
        """
        n = len(data)
        lend = laddr + n
        wrote = read = False
        if command != 10:
            for f in self.fmmus:
                if f.write and f.lstart < lend and laddr < f.lend:
                    wrote |= self._fmmu_write(f, laddr, data)
        if command != 11:
            for f in self.fmmus:
                if f.read and f.lstart < lend and laddr < f.lend:
                    read |= self._fmmu_read(f, laddr, data)
        return (1 if read else 0) + ((2 if command == 12 else 1) if wrote else 0)

    def logical_plan(self, command: int, laddr: int, n: int) -> LogicalPlan | None:
        """:meth:`logical` for one datagram shape, as plain copies (None: not plain).

        A master sends the same cyclic datagram every cycle; when every FMMU it
        hits here is byte aligned and lands wholly in an active buffered SM of the
        right direction, or in plain process RAM, :meth:`logical` reduces to byte
        copies and the SMs whose last byte is written.  The chain keeps the plan
        until an FMMU, an SM or the AL state changes.
        """
        lend = laddr + n
        writes: list[tuple[int, int, int, int]] = []
        reads: list[tuple[int, int, int, int]] = []
        done: list[SyncManager] = []
        for f in self.fmmus:
            if not (f.lstart < lend and laddr < f.lend):
                continue
            if not f.aligned:
                return None
            lo, hi = max(f.lstart, laddr), min(f.lend, lend)
            p0 = f.pstart + (lo - f.lstart)
            p1 = p0 + (hi - lo)
            if p0 < REGISTER_SPACE or p1 > MEMORY_SIZE:
                return None
            sms = [sm for sm in self.sms if sm.start < p1 and p0 < sm.end]
            if len(sms) > 1 or any(sm.mailbox or sm.pdi_off for sm in sms):
                return None
            sm = sms[0] if sms else None
            if sm is not None and (sm.start > p0 or sm.end < p1):
                return None
            if f.write and command != 10:
                if sm is not None and not sm.ecat_writes:
                    return None
                writes.append((lo - laddr, hi - laddr, p0, p1))
                if sm is not None and p0 < sm.end <= p1:
                    done.append(sm)
            if f.read and command != 11:
                if sm is not None and sm.ecat_writes:
                    return None  # an FMMU reading an output SM: refused, the general path
                reads.append((lo - laddr, hi - laddr, p0, p1))
        wkc = (1 if reads else 0) + ((2 if command == 12 else 1) if writes else 0)
        return LogicalPlan(self, tuple(writes), tuple(done), tuple(reads), wkc)

    def _fmmu_write(self, f: Fmmu, laddr: int, data: bytearray | memoryview) -> bool:
        if f.aligned:
            lo = max(f.lstart, laddr)
            hi = min(f.lend, laddr + len(data))
            return self.write(f.pstart + (lo - f.lstart), data[lo - laddr : hi - laddr])
        b0 = max(f.lbit0, laddr * 8)
        b1 = min(f.lbit1, (laddr + len(data)) * 8)
        if b0 >= b1:
            return False
        nbits = b1 - b0
        value = get_bits(data, b0 - laddr * 8, nbits)
        p0 = f.pbit0 + (b0 - f.lbit0)
        first, last = p0 >> 3, (p0 + nbits - 1) >> 3
        raw = bytearray(self.mem[first : last + 1])
        set_bits(raw, p0 - first * 8, nbits, value)
        return self.write(first, raw)

    def _fmmu_read(self, f: Fmmu, laddr: int, data: bytearray | memoryview) -> bool:
        if f.aligned:
            lo = max(f.lstart, laddr)
            hi = min(f.lend, laddr + len(data))
            got = self.read(f.pstart + (lo - f.lstart), hi - lo)
            if got is None:
                return False
            data[lo - laddr : hi - laddr] = got
            return True
        b0 = max(f.lbit0, laddr * 8)
        b1 = min(f.lbit1, (laddr + len(data)) * 8)
        if b0 >= b1:
            return False
        nbits = b1 - b0
        p0 = f.pbit0 + (b0 - f.lbit0)
        first, last = p0 >> 3, (p0 + nbits - 1) >> 3
        got = self.read(first, last - first + 1)
        if got is None:
            return False
        set_bits(data, b0 - laddr * 8, nbits, get_bits(got, p0 - first * 8, nbits))
        return True

    # --- SII EEPROM ----------------------------------------------------------------------------
    def _eeprom_poll(self) -> None:
        if self.mem[0x0503] & 0x80 and self.clock() >= self._eeprom_busy_until:
            self.mem[0x0503] &= 0x7F

    def _eeprom_command(self) -> None:
        m = self.mem
        ctl = _U16.unpack_from(m, Reg.EEPROM_CONTROL)[0]
        self._eeprom_poll()
        if m[0x0503] & 0x80:  # a command while busy is ignored
            _U16.pack_into(m, Reg.EEPROM_CONTROL, ctl & ~(EepromStatus.CMD_MASK | 1) | 0x8000)
            return
        cmd = ctl & EepromStatus.CMD_MASK
        status = ctl & ~(EepromStatus.CMD_MASK | EepromStatus.WRITE_ENABLE)
        if cmd == 0:
            status &= ~EepromStatus.ERROR_MASK  # NOP clears the error bits
            _U16.pack_into(m, Reg.EEPROM_CONTROL, status)
            return
        word = _U32.unpack_from(m, Reg.EEPROM_ADDRESS)[0]
        status &= ~EepromStatus.ERROR_MASK
        if cmd == EepromStatus.CMD_READ:
            chunk = bytes(self.sii[2 * word : 2 * word + 8])
            m[Reg.EEPROM_DATA : Reg.EEPROM_DATA + 8] = chunk + b"\xff" * (8 - len(chunk))
        elif cmd == EepromStatus.CMD_WRITE:
            if not ctl & EepromStatus.WRITE_ENABLE:
                status |= EepromStatus.WRITE_ENABLE_ERROR
            elif 2 * word + 2 > 0x20000:
                status |= EepromStatus.ACK_ERROR
            else:
                if len(self.sii) < 2 * word + 2:
                    self.sii += b"\xff" * (2 * word + 2 - len(self.sii))
                self.sii[2 * word : 2 * word + 2] = m[Reg.EEPROM_DATA : Reg.EEPROM_DATA + 2]
        elif cmd == EepromStatus.CMD_RELOAD:
            self._load_alias()
        else:
            status |= EepromStatus.ACK_ERROR  # more than one command bit
        if self.eeprom_busy_ns > 0:
            status |= EepromStatus.BUSY
            self._eeprom_busy_until = self.clock() + self.eeprom_busy_ns
        _U16.pack_into(m, Reg.EEPROM_CONTROL, status)

    # --- distributed clocks --------------------------------------------------------------------
    def _arrival(self) -> int:
        """Host time at which the current frame reaches this ESC's port 0."""
        return self.ft.t_ns + self.position * HOP_NS

    def system_time(self, t_abs: int | None = None) -> int:
        """Local time + offset (0920h) + what the drift compensation learned, 64 bit."""
        t = self._arrival() if t_abs is None else t_abs
        offset = _I64.unpack_from(self.mem, Reg.DC_SYSTEM_OFFSET)[0]
        return (t + self._dc_base + offset + self._dc_correction) & 0xFFFFFFFFFFFFFFFF

    def _latch_receive_times(self) -> None:
        t0 = self._arrival() + self._dc_base
        m = self.mem
        _U32.pack_into(m, Reg.DC_RECEIVE_TIME0, t0 & 0xFFFFFFFF)
        if self.position < self.chain_length - 1:
            back = 2 * (self.chain_length - 1 - self.position) * HOP_NS
            _U32.pack_into(m, Reg.DC_RECEIVE_TIME1, (t0 + back) & 0xFFFFFFFF)
        else:
            _U32.pack_into(m, Reg.DC_RECEIVE_TIME1, 0)
        m[0x0908:0x0910] = bytes(8)
        _U64.pack_into(m, Reg.DC_RECEIVE_TIME_PU, t0 & 0xFFFFFFFFFFFFFFFF)

    def _system_time_written(self, addr: int, data: bytes) -> None:
        lo = max(addr, 0x0910)
        hi = min(addr + len(data), 0x0918)
        if lo != 0x0910:
            return
        nbits = 8 * (hi - lo)
        received = int.from_bytes(data[lo - addr : hi - addr], "little")
        delay = _U32.unpack_from(self.mem, Reg.DC_SYSTEM_DELAY)[0]
        mask = (1 << nbits) - 1
        diff = (received + delay - self.system_time()) & mask
        if diff >> (nbits - 1):
            diff -= 1 << nbits
        mag = min(abs(diff), 0x7FFFFFFF)
        _U32.pack_into(self.mem, Reg.DC_SYSTEM_DIFF, mag | (0x80000000 if diff > 0 else 0))
        if diff:
            self._dc_correction += diff  # the control loop locks at once
            self.on_dc_change(self)

    def system_time_constant(self) -> int:
        """``system_time() - frame time``: what this ESC adds to the frame's arrival time
        (its place in the line, its local clock's base, offset 0920h and the correction),
        constant until :attr:`on_dc_change` says otherwise."""
        offset = _I64.unpack_from(self.mem, Reg.DC_SYSTEM_OFFSET)[0]
        return self.position * HOP_NS + self._dc_base + offset + self._dc_correction

    def _sync_pulses(self) -> None:
        """SYNC0/SYNC1 as the master reads them (ET1100 datasheet, 0980h-09A7h): once cyclic
        operation and SYNC0 are activated (0981h bits 0 and 1) with a cycle (09A0h), 0990h
        reads the system time of the next SYNC0 pulse (start time + k cycles), 098Eh bit 0
        says a pulse came; with SYNC1 (bit 2) 0998h reads the next SYNC1 pulse, 09A4h after
        its SYNC0 pulse (0: with it).  Inactive, 0990h reads back the start time written."""
        m = self.mem
        act = m[Reg.DC_ACTIVATION]
        cycle0 = _U32.unpack_from(m, Reg.DC_SYNC0_CYCLE)[0]
        start = self._sync_start
        if act & 0x03 != 0x03 or not cycle0:
            _U64.pack_into(m, Reg.DC_START_TIME, start)
            m[0x098E] = 0
            return
        now = self.system_time()
        if now <= start:
            next0, pulsed = start, False
        else:
            next0, pulsed = start + -(-(now - start) // cycle0) * cycle0, True
        _U64.pack_into(m, Reg.DC_START_TIME, next0 & 0xFFFFFFFFFFFFFFFF)
        m[0x098E] = 0x01 if pulsed else 0
        if act & 0x04:
            cycle1 = _U32.unpack_from(m, Reg.DC_SYNC1_CYCLE)[0] % cycle0
            next1 = (
                next0 - cycle0 + cycle1
                if pulsed and next0 - cycle0 + cycle1 > now
                else (next0 + cycle1)
            )
            _U64.pack_into(m, 0x0998, next1 & 0xFFFFFFFFFFFFFFFF)
            m[0x098F] = 0x01 if pulsed else 0

    # --- watchdog ------------------------------------------------------------------------------
    def watchdog_ns(self) -> int:
        m = self.mem
        divider = _U16.unpack_from(m, Reg.WD_DIVIDER)[0]
        units = _U16.unpack_from(m, Reg.WD_TIME_PD)[0]
        return units * (divider + 2) * 40

    def check_watchdog(self, now: int) -> bool:
        """Process data watchdog (0420h): True when it expired just now."""
        sm = self.outputs_sm
        if (
            sm is None
            or not sm.watchdog
            or self._wd_expired
            or self.slave.al_state != AlState.OP
            or not self._outputs_since_op
        ):
            return False
        limit = self.watchdog_ns()
        if not limit or now - self._wd_last <= limit:
            return False
        self._wd_expired = True
        self.mem[Reg.WD_STATUS_PD] &= 0xFE
        self.mem[Reg.WD_COUNTER_PD] = min(self.mem[Reg.WD_COUNTER_PD] + 1, 0xFF)
        if self.watchdog_trips:
            self.slave.watchdog_expired()  # SAFEOP + error 001Bh; a drive faults
            self.sync_al()
        return True
