"""The backend seam: the only place that knows where the slaves are.

The master (:mod:`gtecat.master.bus`) talks to a :class:`Backend`; the emulated
backend has the virtual slaves in-process, the pysoem backend has a NIC.  A
cycle returns what happened (the working counter is data, as in ethercrab's
``TxRxResponse``); the master decides what a bad WKC means.
"""

from __future__ import annotations

from abc import ABC, abstractmethod
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

from gtecat.drives.slave import AlState, AlStatusCode
from gtecat.eni.errors import GtecatError
from gtecat.eni.layout import Layout
from gtecat.eni.model import Identity

from ..image import ProcessImage


@dataclass(frozen=True, slots=True)
class FoundSlave:
    """What a bus scan reports for one position."""

    position: int
    identity: Identity
    name: str = ""


class Backend(ABC):
    name = "abstract"
    #: the backend brings lost slaves back itself (SOEM's recover/reconfig); otherwise the
    #: master re-walks them (:meth:`gtecat.master.bus.Master.recover`)
    recovers_itself = False
    #: the mailbox waits for slaves on a wire (pysoem): an SDO takes the slave's answer time
    #: on the wall clock, a lost answer the mailbox timeout; the master keeps the cycles
    #: running meanwhile (:attr:`gtecat.master.bus.Master.mailbox_transfer`)
    mailbox_on_wire = False

    @abstractmethod
    def open(self, layout: Layout, image: ProcessImage) -> None:
        """Attach to the bus described by ``layout``; ``image`` is the master's image."""

    @abstractmethod
    def scan(self) -> list[FoundSlave]:
        """The slaves present, in bus order."""

    def empty_scan(self) -> str:
        """Why a scan found no slave, and what to do (GT_InitEcatComm -10's reason)."""
        return "no slave answered the scan; check the cabling / interface"

    @abstractmethod
    def request_state(self, position: int, state: AlState) -> AlStatusCode:
        """Ask one slave for an AL state; the code the slave answered (0 = done)."""

    @abstractmethod
    def state(self, position: int) -> tuple[AlState, AlStatusCode]:
        """A slave's current AL state and status code."""

    def states(self, count: int) -> list[tuple[AlState, AlStatusCode] | None]:
        """AL state and status code of slaves ``0 .. count-1``; None for one that does not
        answer.  Backends that read every state in one go (SOEM's ``read_state``) override it."""
        out: list[tuple[AlState, AlStatusCode] | None] = []
        for pos in range(count):
            try:
                out.append(self.state(pos))
            except GtecatError:
                out.append(None)
        return out

    @abstractmethod
    def exchange(self, t_ns: int, dt_ns: int) -> int:
        """One process-data cycle: outputs out, inputs in; returns the working counter."""

    def steady(self) -> bool:
        """An exchange now would change nothing but the time (the controller may then run
        many cycles at once, :meth:`gtecat.master.bus.Master.steady`); False unless the
        backend can tell."""
        return False

    def look_at_fields(self) -> None:
        """Count what the field changed without it being counted (an emulated IO slave's
        field inputs written through the buffer protocol) as a change of the bus: asked
        before a bus found steady is taken as steady still.  Nothing here."""
        return None

    def fields_watch(self) -> Any:
        """What a compiled check compares to find the field inputs as the last look saw
        them (:meth:`look_at_fields`), as ``(address, what it needs kept)``: at the address
        a count, then per buffer its address, the address of its copy and its length.
        None: nothing to compare."""
        return None

    def outputs_watch(self) -> Any:
        """The outputs a compiled cycle may take to the field itself, as ``(address, what it
        needs kept)``: at the address a count, then per slave the address of its output
        area in the process image, of its ``rx``, of its field outputs, and the bytes.
        None: none (every change of an output takes the general cycle)."""
        return None

    @abstractmethod
    def expected_wkc(self) -> int:
        """The working counter of a healthy cycle with every slave in OP."""

    @abstractmethod
    def sdo_upload(
        self, position: int, index: int, subindex: int, complete_access: bool = False
    ) -> bytes:
        """CoE SDO upload; raises :class:`gtecat.drives.abort.SdoAbort`."""

    @abstractmethod
    def sdo_download(
        self, position: int, index: int, subindex: int, data: bytes, complete_access: bool = False
    ) -> None:
        """CoE SDO download; raises :class:`gtecat.drives.abort.SdoAbort`."""

    def sdo_in_process(
        self,
        position: int,
        index: int,
        subindex: int,
        data: bytes | None,
        complete_access: bool = False,
    ) -> bytes | bool | None:
        """An expedited SDO served in this process with nothing between master and slave:
        ``data`` None an upload (its bytes), else a download (True); None when this one
        takes the backend's :meth:`sdo_upload` / :meth:`sdo_download` (the only way unless
        the backend serves its slaves itself).  What it leaves behind - the object, both
        sides' counters, an abort raised - is what those leave, and it is never unanswered,
        so the master skips its count of unanswered requests
        (:meth:`gtecat.master.bus.Master.sdo_upload`)."""
        return None

    def sdo_values_in_process(
        self, position: int, items: Sequence[tuple[int, int, int, int]]
    ) -> int:
        """Expedited downloads ``(index, subindex, value, size)`` to one slave, in order, each
        served as :meth:`sdo_in_process` serves the value's ``size`` little-endian bytes (two's
        complement when negative): how many of the first it served (0: none, the caller sends
        them one by one); an abort is raised where one fails, after the ones before it."""
        return 0

    def emergencies(self) -> list[tuple[int, object]]:
        """CoE emergencies received since the last call: ``(position, Emergency)``."""
        return []

    def close(self) -> None:  # noqa: B027 - optional hook
        """Release the bus."""
