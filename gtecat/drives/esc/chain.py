"""A line of ESCs processing EtherCAT frames, the way the frame travels a real chain.

:meth:`Chain.process` takes a received Ethernet frame (in a ``bytearray``,
changed in place) and does what each slave's ESC does as the frame passes:

* addressing (ETG.1000.4 5.4): auto-increment (APxx, ARMW: each slave increments
  ADP, the one that sees 0 is addressed; the returned ADP is the sent one plus
  the number of slaves), configured station address or alias (FPxx, FRMW),
  broadcast (Bxx: every slave; reads OR their data into the datagram; ADP is
  incremented like APxx), logical (LRD/LWR/LRW through each slave's FMMUs);
* working counters (ETG.1000.4 5.4, per command): +1 per successful read, +1 per
  successful write, +3 for a read-write slave that did both (+1 read, +2 write;
  LRW likewise per slave: +1 if any read FMMU, +2 if any write FMMU took part);
  ARMW/FRMW: +1 for the addressed slave's read, +1 per other slave's write;
  NOP and unknown commands: data and WKC untouched;
* each slave ORs its unmasked ECAT event requests into the IRQ field, and the
  frame leaves with the locally administered bit set in its source address, as
  a real first ESC returns it.

Frames are checked whole before anything happens (:func:`~.frames.walk`); a
malformed or truncated frame is dropped and counted, never half-processed.
Datagrams are processed one after the other, each through the whole line (real
ESCs interleave them slave by slave; the difference only shows for frames whose
datagrams depend on each other across slaves, which masters do not send).

The slave side runs between frames: :meth:`service` hands mailbox requests to
the slaves and their answers back to SM1; :meth:`step` runs one cycle of every
slave and refreshes the input buffers; :meth:`poll` checks the watchdogs.
"""

from __future__ import annotations

import logging
import struct
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass

from gtecat.eni.ethercat import Command

from ..slave import VirtualSlave
from .frames import walk
from .registers import Esc, FrameTime, LogicalPlan
from .sii import SiiInfo, build_sii, sii_info_for

log = logging.getLogger(__name__)

_U16 = struct.Struct("<H")
_U32 = struct.Struct("<I")

_AP = frozenset({Command.APRD, Command.APWR, Command.APRW})
_FP = frozenset({Command.FPRD, Command.FPWR, Command.FPRW})
_B = frozenset({Command.BRD, Command.BWR, Command.BRW})
_L = frozenset({Command.LRD, Command.LWR, Command.LRW})
# APRD/FPRD/BRD = 1 (read), APWR/FPWR/BWR = 2 (write), APRW/FPRW/BRW = 3 (both)
_KIND = {
    Command.APRD: 1,
    Command.FPRD: 1,
    Command.BRD: 1,
    Command.APWR: 2,
    Command.FPWR: 2,
    Command.BWR: 2,
    Command.APRW: 3,
    Command.FPRW: 3,
    Command.BRW: 3,
}


@dataclass(slots=True)
class ChainStats:
    """What the chain saw (the runner prints these)."""

    frames: int = 0  # processed and answered
    datagrams: int = 0
    process_data_frames: int = 0  # frames in which an FMMU took part
    dropped: int = 0  # malformed EtherCAT frames (dropped, not answered)
    ignored: int = 0  # not EtherCAT at all
    errors: int = 0  # internal errors while processing (frame dropped)
    slave_errors: int = 0  # exceptions out of a slave's step

    def as_dict(self) -> dict[str, int]:
        return {k: getattr(self, k) for k in self.__slots__}  # type: ignore[attr-defined]


class _Fast:
    """A cyclic logical datagram answered from a snapshot, its writes applied after the send.

    Eligible when every ESC's part is a :class:`LogicalPlan`, every read comes from
    a buffered input SM (whose memory only the slave side changes, at
    :meth:`Esc.load_inputs`), reads do not overlap in the datagram, and no ESC
    writes bytes an earlier ESC's read put into the datagram.  Then the answer
    is: keep the datagram's output bytes, put the input snapshot in, add the
    WKC - a few slice copies whatever the number of slaves - and the outputs
    reach the ESCs (SM buffers, watchdog, the slaves' ``rx``) in
    :meth:`Chain.flush`, before anything else looks at them.
    """

    __slots__ = ("parts", "runs", "sources", "w0", "w1", "wkc")

    def __init__(self, parts: list[LogicalPlan], wkc: int) -> None:
        self.parts = parts
        self.wkc = wkc
        writes = [(f0, f1) for part in parts for f0, f1, _p0, _p1 in part.writes]
        self.w0 = min((f0 for f0, _ in writes), default=0)
        self.w1 = max((f1 for _, f1 in writes), default=0)
        reads = sorted(
            (f0, f1, part.mem, p0, p1) for part in parts for f0, f1, p0, p1 in part.reads
        )
        runs: list[list] = []  # [f0, f1, [(mem, p0, p1), ...]]
        for f0, f1, mem, p0, p1 in reads:
            if runs and runs[-1][1] == f0:
                runs[-1][1] = f1
                runs[-1][2].append((mem, p0, p1))
            else:
                runs.append([f0, f1, [(mem, p0, p1)]])
        self.sources = [(f0, f1, tuple(src)) for f0, f1, src in runs]
        self.runs: list[tuple[int, int, bytes]] = []
        self.refresh()

    def refresh(self) -> None:
        self.runs = [
            (f0, f1, b"".join(mem[p0:p1] for mem, p0, p1 in src)) for f0, f1, src in self.sources
        ]

    @staticmethod
    def eligible(parts: list[LogicalPlan | Esc]) -> bool:
        if not parts or any(type(p) is not LogicalPlan for p in parts):
            return False
        read_so_far: list[tuple[int, int]] = []
        for part in parts:
            assert isinstance(part, LogicalPlan)
            for f0, f1, _p0, _p1 in part.writes:
                if any(r0 < f1 and f0 < r1 for r0, r1 in read_so_far):
                    return False
            for f0, f1, p0, p1 in part.reads:
                if any(r0 < f1 and f0 < r1 for r0, r1 in read_so_far):
                    return False  # two reads of one byte: the general path's order decides
                sms = [sm for sm in part.esc.sms if sm.start <= p0 and p1 <= sm.end]
                if not sms or sms[0].ecat_writes or sms[0].mailbox:
                    return False  # plain RAM: a master's write may change it in between
                read_so_far.append((f0, f1))
        return True

    def apply(self, saved: bytes | bytearray) -> None:
        """The kept output bytes into the ESCs (writes, then the SMs they complete)."""
        w0 = self.w0
        for part in self.parts:
            mem = part.mem
            for f0, f1, p0, p1 in part.writes:
                mem[p0:p1] = saved[f0 - w0 : f1 - w0]
            for handler, sm in part.done:
                handler(sm)


class _DcPlan:
    """A datagram of the system time (0910h, 4 or 8 bytes) answered without the register path.

    The master's drift compensation sends it every cycle beside the LRW: ARMW/FRMW (the
    reference clock reads, every other slave writes what passes by), BRD (every slave's time
    ORed), APRD/FPRD (one slave's time).  Every emulated clock runs on the host's clock, so a
    slave's system time is the frame's arrival time plus a constant of its own
    (:meth:`Esc.system_time_constant`), and the difference a write makes (0910h written =
    reference time + delay - own time) does not depend on when the frame comes: once one
    pass through the registers moved no clock, every further one would not either.  So the
    plan runs the register path until a pass changes nothing, then answers from the
    constants: the reader's time (or the OR of all) into the datagram, the working counter
    of the pass - until an offset, a delay or a correction changes (:attr:`Esc.on_dc_change`).
    Writers ahead of the reader take the master's own bytes, which change every cycle: that
    shape stays on the register path.
    """

    __slots__ = (
        "adp_inc",
        "brd",
        "cmd",
        "consts",
        "gen",
        "mask",
        "nbytes",
        "readers",
        "stable",
        "wkc",
    )

    def __init__(self, cmd: int, readers: list[Esc], stable: bool, nbytes: int, count: int) -> None:
        self.cmd = cmd
        self.brd = cmd == Command.BRD
        #: what the line adds to the address field (auto-increment and broadcast commands)
        self.adp_inc = count if cmd in (Command.ARMW, Command.BRD, Command.APRD) else 0
        self.readers = readers
        #: no slave writes ahead of the reader: the plan may lock
        self.stable = stable
        self.nbytes = nbytes
        self.mask = (1 << (8 * nbytes)) - 1
        self.gen = -1  #: the chain's DC generation the constants belong to (-1: not locked)
        self.consts: tuple[int, ...] = ()
        self.wkc = 0


class Chain:
    """Virtual slaves behind ESCs, in bus order."""

    def __init__(
        self,
        slaves: Sequence[VirtualSlave],
        *,
        sii: Sequence[SiiInfo | bytes] | None = None,
        clock: Callable[[], int] = time.monotonic_ns,
        watchdog_trips: bool = False,
        eeprom_busy_ns: int = 20_000,
        mailbox_size: int = 128,
    ) -> None:
        self.clock = clock
        self.ft = FrameTime(clock())
        n = len(slaves)
        if sii is not None and len(sii) != n:
            raise ValueError(f"{len(sii)} SII descriptions for {n} slaves")
        self.sii_info: list[SiiInfo | None] = []
        self.escs: list[Esc] = []
        for i, slave in enumerate(slaves):
            desc = sii[i] if sii is not None else sii_info_for(slave, mailbox_size=mailbox_size)
            if isinstance(desc, bytes | bytearray):
                raw, info = bytes(desc), None
            else:
                raw, info = build_sii(desc), desc
            esc = Esc(
                slave,
                raw,
                position=i,
                chain_length=n,
                clock=clock,
                frame_time=self.ft,
                watchdog_trips=watchdog_trips,
                eeprom_busy_ns=eeprom_busy_ns,
            )
            esc.on_station_change = self._stations_changed
            esc.on_fmmu_change = self._fmmus_changed
            esc.on_sm_change = self._sms_changed
            esc.on_irq_change = self._irq_changed
            esc.on_inputs = self._inputs_loaded
            esc.on_pending = self._add_pending
            esc.on_dc_change = self._dc_changed
            self.escs.append(esc)
            self.sii_info.append(info)
        self.stats = ChainStats()
        #: True when the last frame carried process data (an FMMU took part)
        self.process_data = False
        self._stations: dict[int, list[Esc]] | None = None
        self._lmap: list[tuple[int, int, Esc]] | None = None
        #: compiled logical datagrams: (cmd, address, length) -> per-ESC copy plans, or
        #: None for a shape that takes the general path
        self._plans: dict[tuple[int, int, int], list[LogicalPlan | Esc]] = {}
        self._fast: dict[tuple[int, int, int], _Fast | None] = {}
        #: answers given from snapshots whose output bytes still go to the ESCs:
        #: (plan, a copy of the output bytes, frame time), applied by :meth:`flush`
        self._deferred: list[tuple[_Fast, bytearray, int]] = []
        #: an input SM changed since the snapshots were taken
        self._inputs_changed = False
        self._pending: list[Esc] = []
        #: OR of every ESC's unmasked event requests (what each datagram's IRQ field gets)
        self._irq = 0
        #: the last frame that was one fast-path datagram: (frame length, bytes 12..17
        #: = EtherType, frame header, command, bytes 18..24 = address and length, its
        #: plan, where its working counter is)
        self._cyclic: tuple[int, bytes, bytes, _Fast, int] | None = None
        self._cyclic_seen: tuple[bytes, bytes, _Fast, int] | None = None
        #: datagrams of the system time: (cmd, adp, ado, length) -> plan (None: not one)
        self._dc_plans: dict[tuple[int, int, int, int], _DcPlan | None] = {}
        #: counts changes of any ESC's system-time constants (locked DC plans compare it)
        self._dc_gen = 0
        #: the last frame of several datagrams that were all compiled (fast logical ones, DC
        #: plans): (frame length, each datagram's (offset, command, address and length bytes),
        #: their plans, EtherType and frame header)
        self._multi: (
            tuple[int, tuple[tuple[int, int, bytes], ...], tuple[tuple, ...], bytes] | None
        ) = None
        self._multi_seen: list[tuple] | None = None
        #: ESCs behind an open link (:meth:`cut_after`): powered, stepped, out of the frames
        self.cut: list[Esc] = []

    @property
    def slaves(self) -> list[VirtualSlave]:
        return [e.slave for e in (*self.escs, *self.cut)]

    def cut_after(self, position: int) -> None:
        """The link behind ``position`` opens: the frame turns back there (the ESC closes
        its port), so the slaves after it vanish from every datagram; they keep running
        and their watchdogs see the silence.  ``-1`` cuts in front of the first slave."""
        self.mend()
        keep = max(0, position + 1)
        if keep >= len(self.escs):
            return
        if self._deferred:
            self.flush()
        self.escs, self.cut = self.escs[:keep], self.escs[keep:]
        self._line_changed()

    def mend(self) -> None:
        """Close the link again (the slaves behind it answer from the next frame on)."""
        if self.cut:
            if self._deferred:
                self.flush()
            self.escs, self.cut = [*self.escs, *self.cut], []
            self._line_changed()

    def _line_changed(self) -> None:
        self._stations = None
        self._lmap = None
        self._dc_plans.clear()  # the datagrams of the system time reach other ESCs now
        self._dc_gen += 1
        self._forget_plans()
        self._irq_changed(self.escs[0] if self.escs else None)  # type: ignore[arg-type]

    def __len__(self) -> int:
        return len(self.escs)

    # --- bookkeeping the ESCs report ---------------------------------------------------------
    def _stations_changed(self, _esc: Esc) -> None:
        self._stations = None
        self._dc_plans.clear()
        self._multi = None

    def _dc_changed(self, _esc: Esc) -> None:
        self._dc_gen += 1

    def _fmmus_changed(self, _esc: Esc) -> None:
        self._lmap = None
        self._forget_plans()

    def _irq_changed(self, _esc: Esc) -> None:
        irq = 0
        for esc in self.escs:
            irq |= esc.event_irq
        self._irq = irq

    def _sms_changed(self, _esc: Esc) -> None:
        if self._plans:
            self._forget_plans()

    def _forget_plans(self) -> None:
        if self._deferred:
            self.flush()
        self._plans.clear()
        self._fast.clear()
        self._cyclic = None
        self._multi = None

    def _inputs_loaded(self, _esc: Esc) -> None:
        self._inputs_changed = True

    def refresh_snapshots(self) -> None:
        """Input snapshots of the cyclic datagrams after the slaves' inputs changed."""
        self._inputs_changed = False
        for fast in self._fast.values():
            if fast is not None:
                fast.refresh()

    def flush(self) -> None:
        """Outputs of answered datagrams into the ESCs (and the slaves' ``rx``)."""
        deferred, self._deferred = self._deferred, []
        if not deferred:
            return
        ft = self.ft
        now = ft.t_ns
        try:
            for fast, saved, t_ns in deferred:
                ft.t_ns = t_ns
                fast.apply(saved)
        finally:
            ft.t_ns = now

    def _add_pending(self, esc: Esc) -> None:
        if esc not in self._pending:
            self._pending.append(esc)

    def _station_map(self) -> dict[int, list[Esc]]:
        stations: dict[int, list[Esc]] = {}
        for esc in self.escs:
            stations.setdefault(esc.station_address, []).append(esc)
            if esc.alias_enabled and esc.station_alias != esc.station_address:
                stations.setdefault(esc.station_alias, []).append(esc)
        self._stations = stations
        return stations

    def _logical_map(self) -> list[tuple[int, int, Esc]]:
        lmap = [(f.lstart, f.lend, esc) for esc in self.escs for f in esc.fmmus]
        self._lmap = lmap
        return lmap

    # --- the frame -----------------------------------------------------------------------------
    def process(self, buf: bytearray, n: int | None = None, t_ns: int | None = None) -> bool:
        """Process one received Ethernet frame in place; ``True`` = send it back.

        ``n`` is the frame length when ``buf`` is a larger receive buffer;
        ``t_ns`` the time the frame arrived (default: the chain's clock).
        """
        if n is None:
            n = len(buf)
        cyclic = self._cyclic
        if (
            cyclic is not None
            and n == cyclic[0]
            and buf[12:17] == cyclic[1]
            and buf[18:24] == cyclic[2]
            and not self._deferred
        ):
            # the cyclic frame again (one logical datagram, same command, address and
            # length, nothing deferred): what _datagrams does for it, without the walk
            return self._cyclic_answer(
                buf, cyclic[3], cyclic[4], self.clock() if t_ns is None else t_ns
            )
        multi = self._multi
        if multi is not None and n == multi[0] and buf[12:16] == multi[3] and not self._deferred:
            for off, cmd, want in multi[1]:
                if buf[off] != cmd or buf[off + 2 : off + 8] != want:
                    break
            else:  # the same frame of compiled datagrams again: no walk, no dispatch
                return self._multi_answer(buf, multi[2], self.clock() if t_ns is None else t_ns)
        offsets = walk(buf, n)
        if offsets is None:
            if n >= 14 and buf[12:14] != b"\x88\xa4":
                self.stats.ignored += 1
            else:
                self.stats.dropped += 1
            return False
        self.ft.t_ns = self.clock() if t_ns is None else t_ns
        self.process_data = False
        self._cyclic_seen = None
        checks = frame_header = None
        if len(offsets) > 1 and not self._deferred:
            # what a frame must repeat to be this one: EtherType and frame header, and each
            # datagram's command, address and length (as the master sent them)
            checks = [(off, buf[off], bytes(buf[off + 2 : off + 8])) for off in offsets]
            frame_header = bytes(buf[12:16])
            self._multi_seen = []
        else:
            self._multi_seen = None
        try:
            self._datagrams(buf, offsets)
        except Exception:  # never let one frame take the chain down
            log.exception("internal error while processing a frame; dropped")
            self.stats.errors += 1
            return False
        seen = self._cyclic_seen
        if seen is not None:  # one fast datagram: the next frame like it skips the walk
            self._cyclic = (n, *seen)
        ops = self._multi_seen
        if ops is not None and checks is not None and len(ops) == len(offsets):
            # every datagram was compiled
            self._multi = (n, tuple(checks), tuple(ops), frame_header)
        buf[6] |= 0x02  # the source address comes back locally administered
        self.stats.frames += 1
        self.stats.datagrams += len(offsets)
        if self.process_data:
            self.stats.process_data_frames += 1
        return True

    def _cyclic_answer(self, buf: bytearray, fast: _Fast, wkc_at: int, t_ns: int) -> bool:
        self.ft.t_ns = t_ns
        if self._inputs_changed:
            self.refresh_snapshots()
        irq = self._irq
        if irq:
            _U16.pack_into(buf, 24, _U16.unpack_from(buf, 24)[0] | irq)
        d0 = 26  # Ethernet 14 + EtherCAT header 2 + datagram header 10
        self._deferred.append((fast, buf[d0 + fast.w0 : d0 + fast.w1], t_ns))
        for f0, f1, snap in fast.runs:
            buf[d0 + f0 : d0 + f1] = snap
        wkc = fast.wkc
        if wkc:
            _U16.pack_into(buf, wkc_at, (_U16.unpack_from(buf, wkc_at)[0] + wkc) & 0xFFFF)
        self.process_data = True
        buf[6] |= 0x02
        stats = self.stats
        stats.frames += 1
        stats.datagrams += 1
        stats.process_data_frames += 1
        return True

    def _multi_answer(self, buf: bytearray, ops: tuple[tuple, ...], t_ns: int) -> bool:
        """:meth:`_datagrams` for a frame :attr:`_multi` describes: each datagram by its plan."""
        self.ft.t_ns = t_ns
        irq = self._irq
        u16_unpack, u16_pack = _U16.unpack_from, _U16.pack_into
        deferred = self._deferred
        pd = False
        for fast, dc, off, d0, d1 in ops:
            if irq:
                u16_pack(buf, off + 8, u16_unpack(buf, off + 8)[0] | irq)
            if fast is not None:
                if self._inputs_changed:
                    self.refresh_snapshots()
                deferred.append((fast, buf[d0 + fast.w0 : d0 + fast.w1], t_ns))
                for f0, f1, snap in fast.runs:
                    buf[d0 + f0 : d0 + f1] = snap
                pd = True
                wkc = fast.wkc
                if wkc:
                    u16_pack(buf, d1, (u16_unpack(buf, d1)[0] + wkc) & 0xFFFF)
            elif dc.gen != self._dc_gen:
                self._dc_datagram(dc, buf, off, d0, d1, t_ns)  # not locked (any more)
            else:  # _dc_datagram's locked path, inline
                consts = dc.consts
                if dc.brd:
                    value = int.from_bytes(buf[d0:d1], "little")
                    for c in consts:
                        value |= t_ns + c
                    buf[d0:d1] = (value & dc.mask).to_bytes(dc.nbytes, "little")
                elif consts:
                    buf[d0:d1] = ((t_ns + consts[0]) & dc.mask).to_bytes(dc.nbytes, "little")
                if dc.adp_inc:
                    u16_pack(buf, off + 2, (u16_unpack(buf, off + 2)[0] + dc.adp_inc) & 0xFFFF)
                wkc = dc.wkc
                if wkc:
                    u16_pack(buf, d1, (u16_unpack(buf, d1)[0] + wkc) & 0xFFFF)
        self.process_data = pd
        buf[6] |= 0x02
        stats = self.stats
        stats.frames += 1
        stats.datagrams += len(ops)
        if pd:
            stats.process_data_frames += 1
        return True

    def exchange(self, frame: bytes) -> bytes | None:
        """Process a copy of ``frame``; the answer, or ``None`` when it was dropped."""
        buf = bytearray(frame)
        answered = self.process(buf)
        self.flush()
        return bytes(buf) if answered else None

    def _datagrams(self, buf: bytearray, offsets: list[int]) -> None:
        escs = self.escs
        count = len(escs)
        irq = self._irq
        u16_unpack, u16_pack = _U16.unpack_from, _U16.pack_into
        ft_ns = self.ft.t_ns
        for off in offsets:
            cmd = buf[off]
            dlen = u16_unpack(buf, off + 6)[0] & 0x07FF
            d0 = off + 10
            d1 = d0 + dlen
            if irq:
                u16_pack(buf, off + 8, u16_unpack(buf, off + 8)[0] | irq)
            wkc = 0
            if cmd not in _L and _dc_only(buf, off, dlen):
                # the system time (0910h): a compiled plan where the datagram is one
                dkey = (cmd, u16_unpack(buf, off + 2)[0], u16_unpack(buf, off + 4)[0], dlen)
                dc = self._dc_plans.get(dkey, False)
                if dc is False:
                    dc = self._dc_plan(*dkey)
                if dc is not None:
                    self._dc_datagram(dc, buf, off, d0, d1, ft_ns)
                    if self._multi_seen is not None:
                        self._multi_seen.append((None, dc, off, d0, d1))
                    continue
            elif self._deferred and cmd not in _L:
                self.flush()  # a register access sees the outputs answered before it
            if cmd in _L:
                laddr = _U32.unpack_from(buf, off + 2)[0]
                key = (cmd, laddr, dlen)
                fast = self._fast.get(key, False)
                if fast:
                    if len(offsets) == 1 and not self._deferred:
                        self._cyclic_seen = (bytes(buf[12:17]), bytes(buf[18:24]), fast, d1)
                    if self._multi_seen is not None:
                        self._multi_seen.append((fast, None, off, d0, d1))
                    if self._inputs_changed:
                        self.refresh_snapshots()
                    self._deferred.append((fast, buf[d0 + fast.w0 : d0 + fast.w1], ft_ns))
                    for f0, f1, snap in fast.runs:
                        buf[d0 + f0 : d0 + f1] = snap
                    self.process_data = True
                    wkc = fast.wkc
                    if wkc:
                        u16_pack(buf, d1, (u16_unpack(buf, d1)[0] + wkc) & 0xFFFF)
                    continue
                if self._deferred:
                    self.flush()
                plan = self._plans.get(key, False)
                if plan is False:
                    plan = self._compile(cmd, laddr, dlen)
                if plan:
                    self.process_data = True
                    with memoryview(buf) as mv:
                        data = mv[d0:d1]
                        for part in plan:
                            if part.__class__ is LogicalPlan:  # inline LogicalPlan.run
                                mem = part.mem  # type: ignore[union-attr]
                                for f0, f1, p0, p1 in part.writes:  # type: ignore[union-attr]
                                    mem[p0:p1] = data[f0:f1]
                                for handler, sm in part.done:  # type: ignore[union-attr]
                                    handler(sm)
                                for f0, f1, p0, p1 in part.reads:  # type: ignore[union-attr]
                                    data[f0:f1] = mem[p0:p1]
                                wkc += part.wkc  # type: ignore[union-attr]
                            else:
                                wkc += part.logical(cmd, laddr, data)  # type: ignore[union-attr]
                        data.release()
            elif cmd in _FP:
                adp, ado = _U16.unpack_from(buf, off + 2)[0], u16_unpack(buf, off + 4)[0]
                stations = self._stations if self._stations is not None else self._station_map()
                for esc in tuple(stations.get(adp, ())):
                    wkc += _physical(_KIND[cmd], esc, ado, buf, d0, d1)
            elif cmd in _AP:
                adp, ado = u16_unpack(buf, off + 2)[0], u16_unpack(buf, off + 4)[0]
                pos = (-adp) & 0xFFFF
                if pos < count:
                    wkc += _physical(_KIND[cmd], escs[pos], ado, buf, d0, d1)
                u16_pack(buf, off + 2, (adp + count) & 0xFFFF)
            elif cmd in _B:
                adp, ado = u16_unpack(buf, off + 2)[0], u16_unpack(buf, off + 4)[0]
                wkc += _broadcast(_KIND[cmd], escs, ado, buf, d0, d1)
                u16_pack(buf, off + 2, (adp + count) & 0xFFFF)
            elif cmd == Command.ARMW or cmd == Command.FRMW:
                adp, ado = u16_unpack(buf, off + 2)[0], u16_unpack(buf, off + 4)[0]
                if cmd == Command.ARMW:
                    pos = (-adp) & 0xFFFF
                    reader = escs[pos] if pos < count else None
                    u16_pack(buf, off + 2, (adp + count) & 0xFFFF)
                else:
                    stations = self._stations if self._stations is not None else self._station_map()
                    found = stations.get(adp)
                    reader = found[0] if found else None
                wkc += _read_multiple_write(reader, escs, ado, buf, d0, d1)
            else:
                continue  # NOP or unknown: data and WKC pass untouched
            if wkc:
                u16_pack(buf, d1, (u16_unpack(buf, d1)[0] + wkc) & 0xFFFF)

    def _dc_plan(self, cmd: int, adp: int, ado: int, dlen: int) -> _DcPlan | None:
        """The plan of a system-time datagram (:class:`_DcPlan`), or None for another one."""
        plan: _DcPlan | None = None
        escs = self.escs
        count = len(escs)
        if ado == 0x0910 and dlen in (4, 8):
            if cmd == Command.BRD:
                plan = _DcPlan(cmd, list(escs), True, dlen, count)
            elif cmd in (Command.ARMW, Command.APRD):
                pos = (-adp) & 0xFFFF
                readers = [escs[pos]] if pos < count else []
                plan = _DcPlan(cmd, readers, cmd == Command.APRD or pos == 0, dlen, count)
            elif cmd in (Command.FRMW, Command.FPRD):
                stations = self._stations if self._stations is not None else self._station_map()
                found = stations.get(adp, [])
                # one reader that no other slave precedes (FPRD: one slave, anywhere); an
                # address two slaves answer to stays with the register path
                stable = len(found) == 1 and (cmd == Command.FPRD or found[0] is escs[0])
                if len(found) <= 1 or cmd == Command.FRMW:
                    plan = _DcPlan(cmd, found[:1], stable, dlen, len(escs))
        if len(self._dc_plans) > 256:  # a master that sends ever new shapes: keep it bounded
            self._dc_plans.clear()
            self._multi = None
        self._dc_plans[(cmd, adp, ado, dlen)] = plan
        return plan

    def _dc_datagram(
        self, plan: _DcPlan, buf: bytearray, off: int, d0: int, d1: int, t_ns: int
    ) -> None:
        """Run a :class:`_DcPlan`: from its constants when locked, else the register path."""
        cmd = plan.cmd
        if plan.gen == self._dc_gen:
            mask = plan.mask
            if cmd == Command.BRD:
                value = int.from_bytes(buf[d0:d1], "little")  # ORed into what the frame carries
                for c in plan.consts:
                    value |= (t_ns + c) & mask
            elif plan.consts:
                value = (t_ns + plan.consts[0]) & mask
            else:
                value = -1
            if value >= 0:
                buf[d0:d1] = value.to_bytes(plan.nbytes, "little")
            wkc = plan.wkc
        else:
            gen = self._dc_gen
            escs = self.escs
            ado = _U16.unpack_from(buf, off + 4)[0]
            if cmd == Command.BRD:
                wkc = _broadcast(1, escs, ado, buf, d0, d1)
            elif cmd == Command.ARMW or cmd == Command.FRMW:
                reader = plan.readers[0] if plan.readers else None
                wkc = _read_multiple_write(reader, escs, ado, buf, d0, d1)
            else:
                wkc = _physical(1, plan.readers[0], ado, buf, d0, d1) if plan.readers else 0
            if plan.stable and gen == self._dc_gen:  # the pass moved no clock: lock
                plan.gen = gen
                plan.consts = tuple(e.system_time_constant() for e in plan.readers)
                plan.wkc = wkc
        if plan.adp_inc:
            adp = _U16.unpack_from(buf, off + 2)[0]
            _U16.pack_into(buf, off + 2, (adp + plan.adp_inc) & 0xFFFF)
        if wkc:
            _U16.pack_into(buf, d1, (_U16.unpack_from(buf, d1)[0] + wkc) & 0xFFFF)

    def _compile(self, cmd: int, laddr: int, dlen: int) -> list[LogicalPlan | Esc]:
        """The ESCs a logical datagram hits, each as a copy plan where it can be one."""
        lmap = self._lmap if self._lmap is not None else self._logical_map()
        lend = laddr + dlen
        hit: list[Esc] = []
        for ls, le, esc in lmap:
            if ls < lend and laddr < le and (not hit or hit[-1] is not esc):
                hit.append(esc)
        parts: list[LogicalPlan | Esc] = []
        for esc in hit:
            plan = esc.logical_plan(cmd, laddr, dlen)
            parts.append(esc if plan is None else plan)
        if len(self._plans) > 256:  # a master that sends ever new shapes: keep it bounded
            self._forget_plans()
        key = (cmd, laddr, dlen)
        self._plans[key] = parts
        if _Fast.eligible(parts):
            self._fast[key] = _Fast(parts, sum(p.wkc for p in parts))  # type: ignore[misc]
        else:
            self._fast[key] = None
        return parts

    # --- the slaves' side ----------------------------------------------------------------------
    def service(self) -> None:
        """Mailbox work the last frames left (requests to slaves, answers to SM1)."""
        if self._deferred:
            self.flush()
        while self._pending:
            esc = self._pending.pop(0)
            esc.service()

    def step(self, t_ns: int, dt_ns: int, between: Callable[[], object] | None = None) -> None:
        """One cycle of every slave: outputs are in ``rx``; refresh the input buffers.

        ``between`` runs after each slave's step: the serve loop answers a frame that
        arrived meanwhile instead of letting it wait for the whole chain (a frame
        answered from the snapshots sees the previous cycle's inputs of every slave).
        """
        if self._deferred:
            self.flush()
        for esc in self.escs if not self.cut else (*self.escs, *self.cut):
            slave = esc.slave
            try:
                slave.step(t_ns, dt_ns)
            except Exception:
                self.stats.slave_errors += 1
                if self.stats.slave_errors <= 10:
                    log.exception("slave %d (%s): step failed", esc.position, slave.name)
            esc.load_inputs()
            esc.sync_al()
            if slave.emergencies:
                esc.collect_emergencies()
            if between is not None:
                between()
        if self._inputs_changed:
            self.refresh_snapshots()  # here, so the next frame's answer need not

    def poll(self, now_ns: int | None = None) -> None:
        """Watchdogs, and slave state changes made outside a step."""
        now = self.clock() if now_ns is None else now_ns
        if self._deferred:
            self.flush()
        for esc in self.escs if not self.cut else (*self.escs, *self.cut):
            esc.check_watchdog(now)
            esc.sync_al()
            if esc.slave.emergencies:
                esc.collect_emergencies()


def _dc_only(buf: bytearray, off: int, dlen: int) -> bool:
    """A datagram that touches only the distributed-clock registers (0900h-09FFh: port
    times, system time, offset, delay, SYNC): the outputs a logical datagram left to be
    applied cannot change what it reads or writes, so it need not wait for them. The DC
    frame of a master (LRW + ARMW/FRMW of 0910h) stays on the fast path."""
    ado = _U16.unpack_from(buf, off + 4)[0]
    return 0x0900 <= ado and ado + dlen <= 0x0A00


def _physical(kind: int, esc: Esc, ado: int, buf: bytearray, d0: int, d1: int) -> int:
    """APxx/FPxx at one slave; the WKC increment."""
    if kind == 1:
        got = esc.read(ado, d1 - d0)
        if got is None:
            return 0
        buf[d0:d1] = got
        return 1
    if kind == 2:
        return 1 if esc.write(ado, bytes(buf[d0:d1])) else 0
    incoming = bytes(buf[d0:d1])
    got = esc.read(ado, d1 - d0)
    wrote = esc.write(ado, incoming)
    if got is not None:
        buf[d0:d1] = got
    return (1 if got is not None else 0) + (2 if wrote else 0)


def _broadcast(kind: int, escs: list[Esc], ado: int, buf: bytearray, d0: int, d1: int) -> int:
    """BRD/BWR/BRW: every slave; reads OR into what the frame carries on."""
    n = d1 - d0
    cur = int.from_bytes(buf[d0:d1], "little")
    wkc = 0
    for esc in escs:
        if kind & 1:
            got = esc.read(ado, n)
            if kind & 2 and esc.write(ado, cur.to_bytes(n, "little")):
                wkc += 2
            if got is not None:
                cur |= int.from_bytes(got, "little")
                wkc += 1
        elif esc.write(ado, bytes(buf[d0:d1])):
            wkc += 1
    if kind & 1:
        buf[d0:d1] = cur.to_bytes(n, "little")
    return wkc


def _read_multiple_write(
    reader: Esc | None, escs: list[Esc], ado: int, buf: bytearray, d0: int, d1: int
) -> int:
    """ARMW/FRMW: the addressed slave reads, every other slave writes what passes by."""
    wkc = 0
    for esc in escs:
        if esc is reader:
            got = esc.read(ado, d1 - d0)
            if got is not None:
                buf[d0:d1] = got
                wkc += 1
        elif esc.write(ado, bytes(buf[d0:d1])):
            wkc += 1
    return wkc
