"""The in-process backend: virtual slaves exchanged by an FMMU in software.

Each cycle copies every slave's output area of the logical image into its
RxPDO buffer, steps the slave, and copies its TxPDO buffer back into the input
area (ETG.1000.4 logical addressing done by the ESC in real life).  The working
counter follows ETG.1000.4 for one LRW: +2 per slave whose outputs were written
(OP), +1 per slave whose inputs were read (SAFEOP and OP).  Mailbox traffic is
real CoE: whole mailbox messages built by :class:`gtecat.drives.coe.SdoClient` and
answered by the slave's own SDO server.  With ``pcap`` (``GTECAT_PCAP``) the
frames a real master would have exchanged are written to a capture
(:class:`gtecat.master.pcap.BusCapture`).
"""

from __future__ import annotations

import ctypes
from array import array
from collections.abc import Callable, Sequence
from itertools import compress
from typing import Any

import numpy as np

from gtecat.drives.coe import advance_counter, next_counter
from gtecat.drives.io_slaves import IoSlave, look_at_fields
from gtecat.drives.machine import MachineDescription
from gtecat.drives.slave import AlState, AlStatusCode, VirtualSlave
from gtecat.eni.cyclic import MAX_DATAGRAM_DATA
from gtecat.eni.layout import Layout
from gtecat.eni.model import Direction

from ...errors import BusError
from ..image import ProcessImage, Segment
from .base import Backend, FoundSlave

#: what :attr:`EmulatedBackend.answer_hook` says became of a cycle's frame
ANSWERED, LOST, PREVIOUS = 0, 1, 2


class EmulatedBackend(Backend):
    name = "emulated"

    def __init__(
        self,
        machine: MachineDescription | None = None,
        slaves: list[VirtualSlave] | None = None,
        hardware: Layout | None = None,
        pcap: str | None = None,
    ) -> None:
        """``hardware``: the layout of the virtual hardware when it differs from the
        master's ENI (to test what a mismatch does); default: the ENI itself."""
        self.machine = machine or MachineDescription()
        self.hardware = hardware
        self.slaves: list[VirtualSlave] = list(slaves) if slaves is not None else []
        self._given = slaves is not None
        self._plan: list[tuple[VirtualSlave, Segment | None, Segment | None]] = []
        self._expected = 0
        self.image: ProcessImage | None = None
        #: positions unplugged by a scenario (GTE_ helpers): no answer, no WKC
        self.unplugged: set[int] = set()
        #: process-data watchdog of the slaves (ESC default 100 ms)
        self.watchdog_ns = 100_000_000
        self._silent_ns: dict[int, int] = {}
        #: the outside changes when a look (:meth:`emergencies`) left every slave's emergency
        #: queue empty, or None
        self._emcy_empty: int | None = None
        #: (the slaves list, its length, its IO slaves): whose field inputs are looked at
        self._io_seen: tuple[Any, int, tuple[IoSlave, ...]] | None = None
        #: ((outside changes, IO slaves), what fields_watch gave): kept while they stand
        self._watch: tuple[tuple[int, Any], Any] | None = None
        self._outs_seen: tuple[Any, Any] | None = None  # (outputs_watch: its marks, its table)
        self._clients: dict[int, object] = {}
        self._claimed: frozenset[int] = frozenset()
        self._run_plan: list[tuple[VirtualSlave, Segment | None, Segment | None]] = []
        #: the plan and its entries by position (:meth:`exchange_one`)
        self._one_plan: tuple[list[Any], dict[int, Any]] | None = None
        self._claimed_wkc = 0
        self._claimed_slaves: tuple[VirtualSlave, ...] = ()  # what steady() asks for OP
        #: (the run plan and image it was made for, its rows): what steady() compares
        self._steady_plan: tuple[Any, Any, list[tuple[Any, ...]]] | None = None
        #: (VirtualSlave.al_changes, the claimed slaves, the steady plan, every slave
        #: steady() asks in OP): the OP check of steady(), kept while no slave changes state
        self._op_seen: tuple[int, Any, Any, bool] = (-1, None, None, False)
        #: the exchanges made and the mailbox requests served: with the slaves' AL and
        #: outside changes, what an IO slave's fixed point (IoSlave.settled) can change by
        self._exchanges = 0
        self._mailbox_ops = 0
        #: (those four and the steady plan) when steady() last found every slave it steps
        #: settled: asked again only once one of them moved (a raw write between runs of
        #: cycles changes the image, which steady() compares every time, not the slaves)
        self._settled_seen: tuple[int, int, int, int, Any] = (-1, -1, -1, -1, None)
        self.capture = None
        self._source = ""  # the file the virtual slaves come from
        #: what the frame of a cycle meets on its way back (gtecat.faults): called with the
        #: working counter, returns (ANSWERED | LOST | PREVIOUS, working counter); None: nothing
        self.answer_hook: Callable[[int], tuple[int, int]] | None = None
        self._prev_answer: tuple[bytes, int] | None = None
        if pcap:
            from ..pcap import BusCapture

            self.capture = BusCapture(pcap)

    def open(self, layout: Layout, image: ProcessImage) -> None:
        from ..factory import build_slaves

        if not self._given:
            self.slaves = build_slaves(self.hardware or layout, self.machine)
        self._source = (self.hardware or layout).config.source
        self.image = image
        self._clients = {}
        self._emcy_empty = None
        segs: dict[tuple[int, Direction], Segment] = {
            (s.slave, s.direction): s for s in image.segments
        }
        self._plan = []
        for slave in self.slaves:
            out = segs.get((slave.position, Direction.OUT))
            inp = segs.get((slave.position, Direction.IN))
            sl = layout.slaves[slave.position] if slave.position < len(layout.slaves) else None
            if sl is not None:
                slave.expected_sizes = (sl.out_bits, sl.in_bits)
            self._plan.append((slave, out, inp))
        # ETG.1000.4 LRW: +2 per slave with outputs, +1 per slave with inputs (fixed per bus)
        self._expected = sum(2 * (o is not None) + (i is not None) for _, o, i in self._plan)
        self.claimed = set()

    @property
    def claimed(self) -> frozenset[int]:
        """Positions whose slaves the controller's axis bank runs (gtecat.controller.bank):
        they answer in OP (working counter) but are neither stepped nor copied here."""
        return self._claimed

    @claimed.setter
    def claimed(self, positions: set[int] | frozenset[int]) -> None:
        self._claimed = claimed = frozenset(positions)
        plan = self._plan
        if getattr(self, "_plan_of", None) is not plan or len(self._plan_pos) != len(plan):
            self._plan_of = plan
            self._plan_pos = [e[0].position for e in plan]
            self._plan_wkc = [2 * (o is not None) + (i is not None) for _, o, i in plan]
            self._wkc_of = dict(zip(self._plan_pos, self._plan_wkc, strict=True))
            self._claimed_memo: dict[frozenset[int], tuple] = {}
        memo = self._claimed_memo.get(claimed)  # (the bank gives back and takes the same few)
        if memo is None:
            inside = list(map(claimed.__contains__, self._plan_pos))
            out = [not c for c in inside]
            memo = (
                list(compress(plan, out)),
                tuple(e[0] for e in compress(plan, inside)),
                sum(compress(self._plan_wkc, inside)),
            )
            # (each holds ~a list entry per slave: a budget of slaves, not of patterns, as
            # the axis bank's own, or a bus of 1,024 drives switched on one by one keeps 256)
            if len(self._claimed_memo) >= max(8, min(256, 16_384 // max(1, len(plan)))):
                self._claimed_memo.clear()
            self._claimed_memo[claimed] = memo
        self._run_plan, self._claimed_slaves, self._claimed_wkc = memo

    def _slave(self, position: int) -> VirtualSlave:
        if position in self.unplugged or not 0 <= position < len(self.slaves):
            raise BusError(f"slave {position} does not answer")
        return self.slaves[position]

    def unplug(self, position: int) -> None:
        """Cut the cable in front of ``position`` (a scenario's comm loss)."""
        self.unplugged.add(position)
        self._silent_ns[position] = 0
        VirtualSlave.outside_changes += 1  # (a controller that found the bus steady looks again)

    def replug(self, position: int) -> None:
        self.unplugged.discard(position)
        self._silent_ns.pop(position, None)
        VirtualSlave.outside_changes += 1

    def scan(self) -> list[FoundSlave]:
        found = []
        for s in self.slaves:
            if s.position in self.unplugged:
                break  # the chain ends at the first missing slave
            found.append(FoundSlave(s.position, s.identity, s.name))
        if self.capture is not None:
            self.capture.scan(len(found))
        return found

    def empty_scan(self) -> str:
        """There is no cable here: the file lists no slaves, or slave 0 was unplugged."""
        if self.slaves and 0 in self.unplugged:
            return (
                "slave 0 is unplugged (a scenario cut the emulated cable in front of it), so "
                "no slave answers the scan: replug it (GTE_ReplugSlave(0))"
            )
        what = "the hardware description" if self.hardware is not None else "the ENI"
        return (
            f"{what} {self._source or '(no file)'} lists no slaves, so the emulated bus is "
            "empty: use the ENI your configuration tool exported for the machine, or add "
            "slaves to it (`gtecat map FILE` shows a file's slaves)"
        )

    def request_state(self, position: int, state: AlState) -> AlStatusCode:
        slave = self._slave(position)
        code = slave.request_state(state)
        if self.capture is not None:
            self.capture.state(
                position, int(state), int(slave.al_state), int(slave.al_status_code), slave.al_error
            )
        return code

    def state(self, position: int) -> tuple[AlState, AlStatusCode]:
        s = self._slave(position)
        return s.al_state, s.al_status_code

    def exchange(self, t_ns: int, dt_ns: int) -> int:
        hook = self.answer_hook
        if hook is None:
            return self._exchange(t_ns, dt_ns)
        image = self.image
        assert image is not None
        before = image.inputs.tobytes()
        wkc = self._exchange(t_ns, dt_ns)
        action, wkc = hook(wkc)
        if action == LOST:  # the answer never came back: the inputs stay the last received
            image.inputs[:] = np.frombuffer(before, np.uint8)
            return 0
        if action == PREVIOUS and self._prev_answer is not None:
            got, wkc = self._prev_answer
            image.inputs[:] = np.frombuffer(got, np.uint8)
            return wkc
        self._prev_answer = (image.inputs.tobytes(), wkc)
        return wkc

    def _exchange(self, t_ns: int, dt_ns: int) -> int:
        image = self.image
        assert image is not None
        self._exchanges += 1
        wkc = self._claimed_wkc  # the bank's slaves, in OP
        unplugged = self.unplugged
        if unplugged and self._claimed:  # (a bank's slave behind a pulled cable: no answer)
            wkc -= sum(self._wkc_of[p] for p in unplugged if p in self._claimed)
        for slave, out, inp in self._run_plan:
            if unplugged and slave.position in unplugged:
                # powered but cut off: it keeps running; its watchdog notices the silence
                silent = self._silent_ns.get(slave.position, 0) + dt_ns
                self._silent_ns[slave.position] = silent
                if silent >= self.watchdog_ns:
                    slave.watchdog_expired()
                slave.step(t_ns, dt_ns)
                continue
            st = slave.al_state
            if out is not None:
                image.to_slave(out, slave.rx)
                if st == _OP:
                    wkc += 2
            slave.step(t_ns, dt_ns)
            if inp is not None and st >= _SAFEOP:
                image.from_slave(inp, slave.tx)
                wkc += 1
        if self.capture is not None:
            self._capture_cycle(t_ns, image, wkc)
        return wkc

    def exchange_one(self, position: int, t_ns: int, dt_ns: int) -> None:
        """Slave ``position``'s part of this cycle's exchange (one the controller's axis bank
        claims, which it steps on its own objects in the bank's cycle: a row opened for a
        call, gtecat.controller.bank): its outputs from the image, its step, its inputs into
        the image, as :meth:`exchange` does it (the working counter counts a claimed slave
        in OP already)."""
        plan = self._one_plan
        if plan is None or plan[0] is not self._plan:
            plan = self._one_plan = (self._plan, {e[0].position: e for e in self._plan})
        slave, out, inp = plan[1][position]
        image = self.image
        assert image is not None
        if out is not None:
            image.to_slave(out, slave.rx)
        st = slave.al_state
        slave.step(t_ns, dt_ns)
        if inp is not None and st >= _SAFEOP:
            image.from_slave(inp, slave.tx)

    def _capture_cycle(self, t_ns: int, image: ProcessImage, wkc: int) -> None:
        """The cycle into the capture, with each answering slave's share of the working
        counter where its bytes lie (what a capture in several frames counts per frame)."""
        assert self.capture is not None
        view = bytes(image.view)
        shares = []
        if len(view) > MAX_DATAGRAM_DATA:
            base = {Direction.OUT: 0, Direction.IN: image.outputs_bytes}
            for slave, out, inp in self._plan:
                if slave.position in self.unplugged:
                    continue
                claimed = slave.position in self._claimed  # the bank's: in OP
                st = slave.al_state
                for seg, add, counted in ((out, 2, st == _OP), (inp, 1, st >= _SAFEOP)):
                    if seg is not None and (claimed or counted):
                        a = base[seg.direction] + seg.logical_bit // 8
                        shares.append((a, a + (seg.logical_bit % 8 + seg.bit_len + 7) // 8, add))
        self.capture.cycle(t_ns, view, image.outputs_bytes, wkc, shares)

    def steady(self) -> bool:
        """An exchange now would change nothing: no hook, capture or cable pulled, and every
        slave it steps (the ones the axis bank does not run) is a plain IO slave at its fixed
        point - the image's outputs are its ``rx``, its step changes nothing, its ``tx`` is in
        the image's inputs (byte-aligned areas; anything else: not steady).  Every slave is in
        OP, the ones the bank runs too: a slave an operator asked to PREOP (``gtecat states -p 2
        PREOP``) is at a fixed point but leaves the working counter short, which only the
        master's cycle sees (it logs the loss and reads the states).  Asked before every run
        of cycles at once: the areas' bytes are worked out once per run plan."""
        if self.answer_hook is not None or self.capture is not None or self.unplugged:
            return False
        look_at_fields(self._io_slaves())  # (a field write not counted: counted now)
        image = self.image
        if image is None:
            return False
        plan = self._steady_plan
        if plan is None or plan[0] is not self._run_plan or plan[1] is not image:
            plan = self._steady_plan = (self._run_plan, image, self._steady_rows(image))
        # every slave in OP: worked out again only after an AL state change of any slave
        seen = self._op_seen
        if (
            seen[0] != VirtualSlave.al_changes
            or seen[1] is not self._claimed_slaves
            or seen[2] is not plan
        ):
            seen = self._op_seen = (
                VirtualSlave.al_changes,
                self._claimed_slaves,
                plan,
                all(s.al_state == _OP for s in self._claimed_slaves)
                and all(row[0].al_state == _OP for row in plan[2]),
            )
        if not seen[3]:
            return False
        if not self._claimed_emcy_empty():
            for s in self._claimed_slaves:  # an emergency the bank's drive queued: the master's
                if s.emergencies:  # cycle fetches it (the bank runs no mailbox)
                    return False
        view = image.view
        marks = (
            VirtualSlave.al_changes,
            VirtualSlave.outside_changes,
            self._exchanges,
            self._mailbox_ops,
            plan,
        )
        seen = self._settled_seen
        known = (
            seen[4] is plan
            and seen[0] == marks[0]
            and seen[1] == marks[1]
            and seen[2] == marks[2]
            and seen[3] == marks[3]
        )
        for slave, o_start, o_bytes, i_start, i_bytes, o_view, i_view in plan[2]:
            if not known and (type(slave).step is not _IO_STEP or not slave.settled()):
                return False
            if o_bytes:
                if o_bytes < 0:
                    return False  # outputs not byte-aligned
                rx = slave.rx
                n = len(rx)
                if n == o_bytes:  # (the usual case: the area's bytes, cut out once)
                    if rx != o_view:
                        return False
                else:
                    n = min(n, o_bytes)
                    if view[o_start : o_start + n] != rx[:n]:
                        return False
            if i_bytes:
                if i_bytes < 0:
                    return False  # inputs not in whole bytes
                tx = slave.tx
                n = len(tx)
                if n == i_bytes:
                    if tx != i_view:
                        return False
                else:
                    n = min(n, i_bytes)
                    if view[i_start : i_start + n] != tx[:n]:
                        return False
        self._settled_seen = marks
        return True

    def _io_slaves(self) -> tuple[IoSlave, ...]:
        slaves = self.slaves
        seen = self._io_seen
        if seen is None or seen[0] is not slaves or seen[1] != len(slaves):
            io = tuple(s for s in slaves if isinstance(s, IoSlave))
            seen = self._io_seen = (slaves, len(slaves), io)
        return seen[2]

    def look_at_fields(self) -> None:
        seen = self._io_seen
        slaves = self.slaves
        if seen is None or seen[0] is not slaves or seen[1] != len(slaves):
            self._io_slaves()
            seen = self._io_seen
        for s in seen[2]:  # type: ignore[index]  # (look_at_fields, in line: asked per run)
            if s._field_inputs != s._fields_seen:
                look_at_fields(seen[2])  # type: ignore[index]
                return

    def fields_watch(self) -> Any:
        """What a compiled check compares (:meth:`Backend.fields_watch`) as ``(address,
        what it needs kept)``, or None: the IO slaves' field inputs and copies of them as
        :meth:`look_at_fields` sees them now.  The addresses hold while the slaves' outside
        changes stay the same (a new buffer, a new length: counted), which a check asks
        first; kept while they and the IO slaves stay the same."""
        io = self._io_slaves()
        watch = self._watch
        if watch is not None and watch[0][0] == VirtualSlave.outside_changes:
            if watch[0][1] is io:
                return watch[1]
        look_at_fields(io)  # (the copies: what it sees)
        bufs = [s._field_inputs for s in io if len(s._field_inputs)]
        got = None
        if bufs:
            copy = bytearray(b"".join(bufs))
            table = array("q", [len(bufs)])
            at = _address(copy)
            for fi in bufs:
                table.extend((_address(fi), at, len(fi)))
                at += len(fi)
            got = (table.buffer_info()[0], table, copy, bufs)
        self._watch = ((VirtualSlave.outside_changes, io), got)
        return got

    def outputs_watch(self) -> Any:
        """The plain IO slaves' outputs (:meth:`Backend.outputs_watch`) where the bus is
        steady now (:meth:`steady`: asked first): a slave whose step is the IO slave's own,
        with no wire, whose byte-aligned output area is as long as its ``rx`` and its field
        outputs.  For it the general cycle's exchange and step do no more with a changed
        output than copy the area to ``rx`` and ``rx`` to the field outputs (in OP; its
        inputs do not read them), which a compiled cycle does as well.  The addresses hold
        while the slaves' AL and outside changes and the run plan stay the same; made again
        when they do not."""
        plan = self._steady_plan
        image = self.image
        if plan is None or image is None or plan[1] is not image:
            return None
        marks = (VirtualSlave.al_changes, VirtualSlave.outside_changes, plan)
        seen = self._outs_seen
        if seen is not None and seen[0] == marks:
            return seen[1]
        base = int(image.buffer.ctypes.data)
        table = array("q", [0])
        keep = []
        for slave, o_start, o_bytes, *_ in plan[2]:
            if (
                o_bytes > 0
                and type(slave).step is _IO_STEP
                and not slave._wires
                and len(slave.rx) == o_bytes
                and len(slave.field_outputs) == o_bytes
            ):
                rx, fo = slave.rx, slave.field_outputs
                table.extend((base + o_start, _address(rx), _address(fo), o_bytes))
                keep.append((slave.rx, slave.field_outputs))
                table[0] += 1
        got = (table.buffer_info()[0], table, keep, image) if table[0] else None
        self._outs_seen = (marks, got)
        return got

    def _steady_rows(self, image: ProcessImage) -> list[tuple[Any, ...]]:
        """Per slave of the run plan: (slave, first output byte, output bytes, first input
        byte, input bytes, the image's output bytes, its input bytes); -1 bytes: an area
        :meth:`steady` cannot compare, 0: none (and no bytes cut out)."""
        rows = []
        view = image.view
        base = image.outputs_bytes
        for slave, out, inp in self._run_plan:
            o_start = o_bytes = i_start = i_bytes = 0
            if out is not None:
                o_start = out.logical_bit >> 3
                o_bytes = out.raw_bytes if out.aligned else -1
            if inp is not None:
                i_start = base + (inp.logical_bit >> 3)
                i_bytes = inp.bit_len >> 3 if inp.aligned and not inp.bit_len & 7 else -1
            o_view = view[o_start : o_start + o_bytes] if o_bytes > 0 else None
            i_view = view[i_start : i_start + i_bytes] if i_bytes > 0 else None
            rows.append((slave, o_start, o_bytes, i_start, i_bytes, o_view, i_view))
        return rows

    def emergencies(self) -> list[tuple[int, object]]:
        """The emergencies the master receives now.  A slave behind a pulled cable cannot
        send one: what it raises stays in its queue (bounded, as its mailbox is) and
        arrives once the cable is back (ETG.1000.6 5.6.4: an emergency is a mailbox
        message the master collects from the slave)."""
        # a slave queues one only through emit_emergency, which counts as an outside change:
        # while nothing changed since a look that left every queue empty, there is none (the
        # bank's slaves are not stepped here, and whichever of them it holds does not matter)
        seen = VirtualSlave.outside_changes  # (before the look: one queued during it counts)
        if self._emcy_empty == seen:
            return []
        out = []
        claimed = self._claimed
        unplugged = self.unplugged
        slaves: Any = self.slaves
        if claimed:
            slaves = (*(e[0] for e in self._run_plan), *self._claimed_slaves)
        for slave in slaves:
            if unplugged and slave.position in unplugged:
                continue
            while slave.emergencies:
                out.append((slave.position, slave.emergencies.popleft()))
        # (one left: behind a pulled cable, it stays queued, and the next look looks again)
        left = unplugged and any(s.emergencies for s in slaves if s.position in unplugged)
        self._emcy_empty = None if left else seen
        if claimed and len(out) > 1:
            out.sort(key=lambda e: e[0])  # (in the order of the bus, as without the bank)
        return out

    def _claimed_emcy_empty(self) -> bool:
        """A look at the emergency queues (:meth:`emergencies`) left them all empty, and nothing
        changed since: the claimed slaves' queues are empty still."""
        return self._emcy_empty == VirtualSlave.outside_changes

    def expected_wkc(self) -> int:
        return self._expected

    # --- mailbox -----------------------------------------------------------------
    def _client(self, position: int):  # -> gtecat.drives.coe.SdoClient
        slave = self._slave(position)
        if not slave.has_mailbox:
            raise BusError(f"slave {position} ({slave.name}) has no CoE mailbox")
        client = self._clients.get(position)
        if client is None:
            from gtecat.drives.coe import SdoClient

            capture = self.capture

            # the slave's mailbox looked up per message: a fault may stand in front of it
            def transfer(request: bytes, slave: VirtualSlave = slave) -> bytes | None:
                answer = slave.mailbox(request)
                if capture is not None:
                    capture.mailbox(position, request, answer)
                return answer

            client = SdoClient(transfer)
            self._clients[position] = client
        return client

    def unanswered(self, position: int | None = None) -> int:
        """The SDO requests sent so far that got no answer (a fault lost it): the master
        waits its mailbox timeout for each (:meth:`gtecat.master.bus.Master.sdo_upload`);
        ``position``: those sent to that slave alone (one SDO reaches one slave's mailbox,
        so the master asks about that one: a bus of many slaves costs it nothing more)."""
        if position is not None:
            client = self._clients.get(position)
            return client.unanswered if client is not None else 0  # type: ignore[attr-defined]
        return sum(c.unanswered for c in self._clients.values())  # type: ignore[attr-defined]

    def close(self) -> None:
        if self.capture is not None:
            self.capture.close()
            self.capture = None

    def sdo_in_process(
        self,
        position: int,
        index: int,
        subindex: int,
        data: bytes | None,
        complete_access: bool = False,
    ) -> bytes | bool | None:
        """An expedited SDO nothing sees (no pcap, no fault's stand-in in front of the
        mailbox, which has no ``sdo_server_only``: its SDOs take the framed path, counted and
        faulted there), served unframed: the server's own read or write, counters and abort;
        None for any other (:meth:`sdo_upload` / :meth:`sdo_download` frame it, or say why
        the slave cannot take it)."""
        self._mailbox_ops += 1  # (steady(): the slave's objects may change)
        if self.capture is not None or position in self.unplugged:
            return None
        if not (
            0 <= position < len(self.slaves) and 0 <= index <= 0xFFFF and 0 <= subindex <= 0xFF
        ):
            return None
        slave = self.slaves[position]
        if not slave.has_mailbox or slave.al_state < AlState.PREOP:
            return None
        if not getattr(slave.mailbox, "sdo_server_only", False):
            return None
        server = slave.sdo  # type: ignore[attr-defined]
        if data is None:
            # (a longer object is a segmented transfer, with more counters: framed)
            if complete_access or not 0 < (server.od.size_of(index, subindex) or 0) <= 4:
                return None
        elif not 0 < len(data) <= 4:
            return None
        client = self._clients.get(position)
        if client is None:
            client = self._client(position)
        client.counter = next_counter(client.counter)
        if data is None:
            return server.upload_in_process(index, subindex)
        server.download_in_process(index, subindex, bytes(data), complete_access, slave.al_state)
        return True

    def sdo_values_in_process(
        self, position: int, items: Sequence[tuple[int, int, int, int]]
    ) -> int:
        """Several expedited downloads of integers to one slave as :meth:`sdo_in_process`
        serves each (the same checks once: nothing sees the frames, the slave's mailbox is its
        SDO server's, up): each one the server's own write, counters and abort, in order (a
        drive's homing parameters: five objects in one call), the values handed over as they
        are (:meth:`SdoServer.download_values_in_process`)."""
        if self.capture is not None or position in self.unplugged:
            return 0
        if not 0 <= position < len(self.slaves):
            return 0
        slave = self.slaves[position]
        state = slave.al_state
        if not slave.has_mailbox or state < _PREOP:
            return 0
        if not getattr(slave.mailbox, "sdo_server_only", False):
            return 0
        client = self._clients.get(position)
        if client is None:
            client = self._client(position)
        server = slave.sdo  # type: ignore[attr-defined]
        served, abort = server.download_values_in_process(items, state)
        if served:  # (each one a request sent and answered)
            self._mailbox_ops += served  # (steady(): the slave's objects may change)
            client.counter = advance_counter(client.counter, served)
        if abort is not None:
            raise abort
        return served

    def sdo_upload(
        self, position: int, index: int, subindex: int, complete_access: bool = False
    ) -> bytes:
        self._mailbox_ops += 1  # (steady(): the slave's objects may change)
        if not complete_access:
            got = self.sdo_in_process(position, index, subindex, None)
            if got is not None:
                return got  # type: ignore[return-value]
        slave = self._slave(position)
        if slave.al_state < AlState.PREOP:
            raise BusError(f"slave {position}: mailbox not available in {slave.al_state.name}")
        return self._client(position).upload(index, subindex, complete_access=complete_access)

    def sdo_download(
        self, position: int, index: int, subindex: int, data: bytes, complete_access: bool = False
    ) -> None:
        self._mailbox_ops += 1  # (steady(): the slave's objects may change)
        if self.sdo_in_process(position, index, subindex, data, complete_access):
            return
        slave = self._slave(position)
        if slave.al_state < AlState.PREOP:
            raise BusError(f"slave {position}: mailbox not available in {slave.al_state.name}")
        client = self._client(position)
        client.download(index, subindex, bytes(data), complete_access=complete_access)

    def uploads_unframed(self, position: int) -> bool:
        """Whether an expedited upload from ``position`` is its SDO server's answer alone:
        nothing sees the frames (no pcap, no fault in front of the mailbox) and the slave's
        mailbox is up, so :meth:`uploads_answered` can stand for uploads not sent."""
        if self.capture is not None or not 0 <= position < len(self.slaves):
            return False
        slave = self.slaves[position]
        return (
            slave.has_mailbox
            and slave.al_state >= AlState.PREOP
            and getattr(slave.mailbox, "sdo_server_only", False)
        )

    def uploads_answered(self, position: int, count: int) -> None:
        """``count`` expedited uploads from ``position`` (:meth:`uploads_unframed`) whose
        answers change nothing but the mailbox: what their exchanges leave behind - both
        sides' counters moved on once per message, the server's transfer state cleared.
        The axis bank runs cycles in which a capture unit polls its drive's touch probe
        status by SDO; at the release the unit counts those reads here."""
        if count <= 0:
            return
        self._mailbox_ops += 1
        client = self._client(position)
        server = self.slaves[position].sdo  # type: ignore[attr-defined]
        server._pending.clear()
        server._upload = server._download = None
        client.counter = advance_counter(client.counter, count)
        server.counter = advance_counter(server.counter, count)


_IO_STEP = IoSlave.step
_OP = AlState.OP  # (looked up once: an enum member costs more than a comparison)
_SAFEOP = AlState.SAFEOP
_PREOP = AlState.PREOP


def _address(buf: bytearray) -> int:
    """Where a bytearray's bytes are now (they stay there while its length does)."""
    view = (ctypes.c_char * len(buf)).from_buffer(buf)
    try:
        return ctypes.addressof(view)
    finally:
        del view  # (no export kept: the buffer may still change its length)
