"""What every virtual slave is to a master: process data buffers, AL state, mailbox, a step.

The same object serves the in-process backend (the master copies its logical
image to and from ``rx``/``tx`` the way FMMUs would) and the wire-level ESC
model (which puts ``rx``/``tx`` behind sync managers 2/3 and ``mailbox``
behind SM0/SM1).  Subclasses: the CiA-402 drive and the IO slaves.

``rx`` holds the slave's RxPDO bytes (outputs of the master) packed in mapping
order, LSB first, rounded up to whole bytes; ``tx`` the TxPDO bytes.  That is
exactly the slave's region of the GT raw image (manual 5.2.2.4).
"""

from __future__ import annotations

from collections import deque
from dataclasses import dataclass
from enum import IntEnum

from gtecat.eni.ethercat import AlState
from gtecat.eni.model import Identity


class AlStatusCode(IntEnum):
    """AL status codes (ETG.1000.6 Table 11, register 0x0134)."""

    NO_ERROR = 0x0000
    UNSPECIFIED_ERROR = 0x0001
    NO_MEMORY = 0x0002
    INVALID_REQUESTED_STATE_CHANGE = 0x0011
    UNKNOWN_REQUESTED_STATE = 0x0012
    BOOTSTRAP_NOT_SUPPORTED = 0x0013
    NO_VALID_FIRMWARE = 0x0014
    INVALID_MAILBOX_CONFIGURATION = 0x0016
    INVALID_SYNC_MANAGER_CONFIGURATION = 0x0017
    NO_VALID_INPUTS = 0x0018
    NO_VALID_OUTPUTS = 0x0019
    SYNCHRONIZATION_ERROR = 0x001A
    SYNC_MANAGER_WATCHDOG = 0x001B
    INVALID_SYNC_MANAGER_TYPES = 0x001C
    INVALID_OUTPUT_CONFIGURATION = 0x001D
    INVALID_INPUT_CONFIGURATION = 0x001E
    INVALID_WATCHDOG_CONFIGURATION = 0x001F
    SLAVE_NEEDS_COLD_START = 0x0020
    SLAVE_NEEDS_INIT = 0x0021
    SLAVE_NEEDS_PREOP = 0x0022
    SLAVE_NEEDS_SAFEOP = 0x0023
    INVALID_PROCESS_DATA_MAPPING = 0x0024
    INCONSISTENT_SETTINGS = 0x0025
    FREERUN_NOT_SUPPORTED = 0x0026
    SYNCMODE_NOT_SUPPORTED = 0x0027
    FREERUN_NEEDS_3BUFFER_MODE = 0x0028
    BACKGROUND_WATCHDOG = 0x0029
    NO_VALID_INPUTS_AND_OUTPUTS = 0x002A
    FATAL_SYNC_ERROR = 0x002B
    NO_SYNC_ERROR = 0x002C
    INVALID_DC_SYNC_CONFIGURATION = 0x0030
    INVALID_DC_LATCH_CONFIGURATION = 0x0031
    PLL_ERROR = 0x0032
    DC_SYNC_IO_ERROR = 0x0033
    DC_SYNC_TIMEOUT_ERROR = 0x0034
    DC_INVALID_SYNC_CYCLE_TIME = 0x0035
    MBX_AOE = 0x0041
    MBX_EOE = 0x0042
    MBX_COE = 0x0043
    MBX_FOE = 0x0044
    MBX_SOE = 0x0045
    MBX_VOE = 0x004F


# Legal AL transitions a slave accepts (ETG.1000.6 Table 9): from -> allowed targets.
_ALLOWED: dict[AlState, frozenset[AlState]] = {
    AlState.INIT: frozenset({AlState.INIT, AlState.PREOP, AlState.BOOT}),
    AlState.PREOP: frozenset({AlState.INIT, AlState.PREOP, AlState.SAFEOP}),
    AlState.BOOT: frozenset({AlState.INIT, AlState.BOOT}),
    AlState.SAFEOP: frozenset({AlState.INIT, AlState.PREOP, AlState.SAFEOP, AlState.OP}),
    AlState.OP: frozenset({AlState.INIT, AlState.PREOP, AlState.SAFEOP, AlState.OP}),
}


@dataclass(frozen=True, slots=True)
class Emergency:
    """A CoE emergency (ETG.1000.6 5.6.4, CiA 301 7.2.7): error code, register, 5 data bytes."""

    code: int
    register: int
    data: bytes = bytes(5)


class VirtualSlave:
    """Base of every virtual slave.

    Subclasses override :meth:`step` (the device's cycle), and may override
    :meth:`mailbox` (CoE; default: no mailbox), :meth:`on_state_change` (a
    veto or work at a transition, e.g. PDO mapping checks at PREOP -> SAFEOP)
    and :meth:`pdo_sizes` (the current RxPDO/TxPDO bit lengths).
    """

    has_mailbox = False
    #: counts the AL state changes of every slave: a reader that worked out something from
    #: the states (``EmulatedBackend.steady``: every claimed slave in OP) keeps it while the
    #: count stays the same.  Every write of ``al_state`` goes through :meth:`enter_state`.
    al_changes = 0
    #: counts the changes made to a slave from outside its cycle (an IO slave's field inputs
    #: and wires, an emergency queued): a reader that found the bus at a fixed point (the
    #: controller's runs of cycles at once) keeps that while this count stays
    outside_changes = 0
    #: the AL state (INIT at power-on); written only by :meth:`enter_state`
    al_state: AlState

    def enter_state(self, state: AlState) -> None:
        """Set :attr:`al_state` (nothing else: the caller does the transition's work) and
        count the change in :attr:`al_changes`."""
        self.al_state = state
        VirtualSlave.al_changes += 1

    def __init__(self, position: int, name: str, identity: Identity) -> None:
        self.position = position
        self.name = name
        self.identity = identity
        self.enter_state(AlState.INIT)
        self.al_status_code = AlStatusCode.NO_ERROR
        self.al_error = False
        rx_bits, tx_bits = self.pdo_sizes()
        self.rx = bytearray((rx_bits + 7) // 8)
        self.tx = bytearray((tx_bits + 7) // 8)
        #: the outputs are valid (master in OP, sync-manager watchdog fed)
        self.outputs_valid = False
        #: set by the master to what the ENI expects, checked at PREOP -> SAFEOP
        self.expected_sizes: tuple[int, int] | None = None
        #: emergencies not yet fetched by the master (bounded like a mailbox queue)
        self.emergencies: deque[Emergency] = deque(maxlen=32)

    def emit_emergency(self, code: int, register: int, data: bytes = bytes(5)) -> None:
        """Queue a CoE emergency; the master fetches it (and logs it like IgH does)."""
        self.emergencies.append(Emergency(code, register, bytes(data[:5]).ljust(5, b"\0")))
        VirtualSlave.outside_changes += 1

    # --- hooks -------------------------------------------------------------
    def pdo_sizes(self) -> tuple[int, int]:
        """(RxPDO bits, TxPDO bits) of the current mapping."""
        return 0, 0

    def mailbox(self, request: bytes) -> bytes | None:
        """Handle one whole mailbox message (6-byte mailbox header + service data, ETG.1000.6
        Table 29) and return the whole response, or None when there is nothing to answer."""
        return None

    def mailbox_next(self) -> bytes | None:
        """The next message of an answer that takes several (SDO Information fragments).

        Asked for each time the master has read the previous message; None when the
        answer is complete.  The default serves the slave's SDO server, if it has one.
        """
        next_message = getattr(getattr(self, "sdo", None), "next_message", None)
        return next_message() if next_message is not None else None

    def on_state_change(self, old: AlState, new: AlState) -> AlStatusCode:
        """Called before a transition is accepted; a non-zero code refuses it."""
        return AlStatusCode.NO_ERROR

    def step(self, t_ns: int, dt_ns: int) -> None:
        """One bus cycle: ``rx`` has the newest outputs; fill ``tx``."""

    # --- AL state machine ------------------------------------------------------
    def request_state(self, target: AlState) -> AlStatusCode:
        """Handle a write to AL control (0x0120): move or refuse with an AL status code.

        A refused transition leaves the slave in its state with the error flag
        set (ETG.1000.6 6.4.1); a request for the current or a lower state with
        the error acknowledged clears the flag.
        """
        try:
            target = AlState(target)
        except ValueError:
            return self._refuse(AlStatusCode.UNKNOWN_REQUESTED_STATE)
        if target in (AlState.NONE,):
            return self._refuse(AlStatusCode.UNKNOWN_REQUESTED_STATE)
        if target == AlState.BOOT:
            return self._refuse(AlStatusCode.BOOTSTRAP_NOT_SUPPORTED)
        if target not in _ALLOWED[self.al_state]:
            return self._refuse(AlStatusCode.INVALID_REQUESTED_STATE_CHANGE)
        old = self.al_state
        if target == AlState.SAFEOP and old == AlState.PREOP:
            code = self._check_process_data()
            if code:
                return self._refuse(code)
        code = self.on_state_change(old, target)
        if code:
            return self._refuse(code)
        self.enter_state(target)
        self.al_error = False
        self.al_status_code = AlStatusCode.NO_ERROR
        if target < AlState.SAFEOP or target == AlState.BOOT:
            self.outputs_valid = False
        return AlStatusCode.NO_ERROR

    def _check_process_data(self) -> AlStatusCode:
        rx_bits, tx_bits = self.pdo_sizes()
        if len(self.rx) != (rx_bits + 7) // 8:
            self.rx = bytearray((rx_bits + 7) // 8)
        if len(self.tx) != (tx_bits + 7) // 8:
            self.tx = bytearray((tx_bits + 7) // 8)
        if self.expected_sizes is not None:
            exp_rx, exp_tx = self.expected_sizes
            if exp_rx != rx_bits:
                return AlStatusCode.INVALID_OUTPUT_CONFIGURATION
            if exp_tx != tx_bits:
                return AlStatusCode.INVALID_INPUT_CONFIGURATION
        return AlStatusCode.NO_ERROR

    def watchdog_expired(self) -> None:
        """The process-data (SM) watchdog ran out: no outputs for its time (ETG.1000.4 6.3).

        The slave leaves OP for SAFEOP with the error flag and AL status code 0x001B,
        as ESCs do when the master stops sending (a cable pulled).
        """
        if self.al_state == AlState.OP:
            old = self.al_state
            self.on_state_change(old, AlState.SAFEOP)
            self.enter_state(AlState.SAFEOP)
            self.outputs_valid = False
            self._refuse(AlStatusCode.SYNC_MANAGER_WATCHDOG)

    def _refuse(self, code: AlStatusCode) -> AlStatusCode:
        self.al_error = True
        self.al_status_code = code
        return code
