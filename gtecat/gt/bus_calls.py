"""GT bus calls: open/close, EtherCAT bring-up, raw PDO data, EtherCAT IO, SDO, clock, version.

Manual chapter 5 (5.2.2.1 communication, 5.2.2.4 PDO raw data, 5.2.2.5
EtherCAT IO, examples 5-1, 5-4, 5-5) and chapter 13 entries 7, 11-14, 33, 44,
45, 56, 78-80, 84, 96, 104, 129, 136.

Decisions where the manual is silent:

* ``GT_InitEcatComm`` reads the ENI, scans, compares and brings the slaves to
  SAFEOP before it returns (so -8/-9/-10 come back from it, as the manual
  lists); OP follows a few cycles later, so ``GT_IsEcatReady`` first reports 0
  and the manual's polling loop (example 5-5) is meaningful.
* ``GT_IsEcatReady`` returns 1 (with ``*pStatus = 0``) while no
  ``GT_InitEcatComm`` is in effect: before any, after one that failed (the
  reason repeats the init's code and reason: -8/-9/-10 and why) and after
  ``GT_TerminateEcatComm``.  Entry 80 lists no such case, but a status of 0
  means "not yet", and the README's polling loop (``while GT_IsEcatReady(&s)
  == 0 && s != 1``) would wait forever for a bus that will never come; a
  non-zero return ends it with the reason.  (Example 5-5's C loop, ``while
  (status != 1 || rtn != 0)``, spins on any non-zero return, as it would on the
  vendor's controller: it does not check GT_InitEcatComm's result.)  While an
  initialised bus is not (or no longer) fully up - OP not yet reached, a slave
  lost and being recovered - it returns 0 with status 0, as before: that state
  passes.
* ``GT_StartEcatComm`` returns 1 until the bus is ready; ``GT_AxisOn`` (and so
  every motion, :mod:`gtecat.gt.axis_calls`) returns 1 until it succeeded (entry 129).
* Raw data and EtherCAT IO before ``GT_InitEcatComm`` return 1 ("check the
  EtherCAT communication", manual entries 44/104); out-of-range offsets or
  sizes return 7 and change nothing.
* After a comm loss (:attr:`Master.offline <gtecat.master.bus.Master.offline>`:
  a slave that stopped answering, or fell below OP, while the bus should be in
  OP) ``GT_GetEcatRawData`` / ``GT_SetEcatRawData`` whose bytes touch that
  slave's region, and ``GT_EcatIOReadInput`` / ``GT_EcatIOWriteOutput`` /
  ``GT_EcatIOBitWriteOutput`` on that slave, return 1 naming the slave (entries
  11/12: "check the slave is connected", 44/104: "check the EtherCAT
  communication") and change nothing: the bytes there are the last ones received,
  not the slave's.  Checked after the range (7 first).  Other slaves' bytes work.
* ``GT_EcatIOReadInput`` may read any byte of the slave's region (outputs then
  inputs, manual 5.2.2.5); ``GT_EcatIOWriteOutput`` only its output bytes.
"""

from __future__ import annotations

import ctypes
from typing import Any

from gtecat.drives.abort import SdoAbort
from gtecat.drives.slave import AlState

from .. import __version__
from ..controller import clock_options
from ..controller.cards import options_for
from ..controller.core import Controller, Options
from ..errors import BusError, CommandError, ParameterError
from . import _core
from ._core import (
    SESSION,
    check_range,
    fail,
    gt_function,
    load_bytes,
    store,
    store_bytes,
)
from .fast import wait_yield


class TSlaveInfo(ctypes.Structure):
    """What ``GT_GetEcatSlaveInfo`` reports for one slave.

    The vendor header's layout is not public; this is ours, documented here:
    bus position, identity (ETG.1000.6 0x1018 / ESI), AL state (1 INIT, 2 PREOP,
    4 SAFEOP, 8 OP), the GT axes it carries, and its GT raw region.
    """

    _fields_ = [
        ("position", ctypes.c_short),
        ("vendorId", ctypes.c_uint32),
        ("productCode", ctypes.c_uint32),
        ("revisionNo", ctypes.c_uint32),
        ("serialNo", ctypes.c_uint32),
        ("state", ctypes.c_short),
        ("axisCount", ctypes.c_short),
        ("firstAxis", ctypes.c_short),
        ("outputBytes", ctypes.c_ushort),
        ("inputBytes", ctypes.c_ushort),
        ("pdoOffset", ctypes.c_ushort),
        ("name", ctypes.c_char * 64),
    ]


# --- controller ----------
@gt_function
def GT_Open(
    channel: int = 0,
    param: int = 1,
    *,
    eni: str | None = None,
    machine: Any = None,
    clock: str | None = None,
    backend: str | None = None,
    iface: str | None = None,
    cycle_ms: float | None = None,
    call_latency_us: float = 50.0,
    log: str | None = None,
    bus: str | None = None,
    op_delay_cycles: int = 10,
    mram: str | None = None,
    card: str | None = None,
    pcap: str | None = None,
    bank: str | None = None,
) -> int:
    """Open the (emulated) controller: the current card (``GT_SetCardNo``; card 0 unless
    one was chosen).  ``channel`` and ``param`` do not choose it (the manual: how the
    host reaches the controller, and reserved); another card is described as
    :mod:`gtecat.controller.cards` says.  Keyword options override ``GTECAT_*``.

    ``bank="auto" | "on" | "off"`` (GTECAT_BANK): the vectorised axis bank
    (:mod:`gtecat.controller.bank`; results are the same either way, only faster).

    ``pcap="bus.pcap"`` (GTECAT_PCAP) writes the frames the emulated bus stands for.

    ``card="gts:4"`` (GTECAT_CARD) opens a GTS pulse card with 4 axes instead of an
    EtherCAT master (:mod:`gtecat.controller.card`).

    ``cycle_ms`` (0.03125..1000, the cycles an ENI may give; None: the ENI's, else 1 ms)
    and ``call_latency_us`` (0 or 0.001..1000000) are checked here, before anything opens:
    a bad one returns 7 naming it, its value and its range
    (:mod:`gtecat.controller.clock_options`)."""
    card_kind, card = card, SESSION.card
    if 1 in SESSION.controllers:
        fail(
            _core.CMD_OPEN,
            (f"card {card} is" if card else "the controller is")
            + " already open (GT_Open called twice; call GT_Close first)",
        )
    explicit = Options(  # (the clock options come from these keywords alone: checked here)
        eni=eni,
        machine=machine,
        clock=clock,
        backend=backend,
        iface=iface,
        cycle_ms=cycle_ms,
        call_latency_us=call_latency_us,
        log=log,
        bus=bus,
        op_delay_cycles=op_delay_cycles,
        mram=mram,
        card=card_kind,
        pcap=pcap,
        bank=bank,
    )
    explicit = clock_options.check(explicit)
    if card == 0 or SESSION.base_options is None:
        opts = SESSION.base_options = explicit.resolved()
        if card:
            opts = options_for(opts, card, 1)
    else:  # another card: the first card's options, its description, this call's keywords
        opts = options_for(SESSION.base_options, card, 1, explicit)
    ctl = Controller(opts)
    SESSION.controllers[1] = ctl
    SESSION.time.join(ctl.clock)
    from ..inspect import enabled

    if enabled():  # (off: nothing published, the endpoint's module not even loaded)
        from ..inspect.endpoint import publish  # gtecat ps / the bus verbs / gtecat panel see it

        publish(ctl)
    return 0


@gt_function
def GT_Close() -> int:
    """Close the current card (every core of it); the other cards keep running."""
    import sys

    endpoints = sys.modules.get("gtecat.inspect.endpoint")  # (not loaded: none published)
    for ctl in SESSION.close_card():
        if endpoints is not None:
            endpoints.unpublish(ctl)
        ctl.close()
    return 0


@gt_function
def GT_Reset(ctl: Controller) -> int:
    """Reset the controller: clock from 0, axis resources to their defaults (table 4-4)."""
    ctl.reset_clock()
    for hook in getattr(ctl, "on_reset", []):
        hook(ctl)
    return 0


@gt_function
def GT_GetClock(ctl: Controller, pClock: Any, pLoop: Any = None) -> int:
    """Controller milliseconds since ``GT_Reset`` (manual 11.4); pLoop = cycles run."""
    store(pClock, ctl.clock_ms() & 0xFFFFFFFF)
    store(pLoop, ctl.clock.cycles & 0xFFFFFFFF)
    return 0


@gt_function
def GT_GetVersion(ctl: Controller, pVersion: Any) -> int:
    """The firmware version in table 11-3's form ``aaa bbbbbb ccc dddddd`` (entry 78).

    Firmware 1 is gtecat's version (0.1.0 -> ``010``) and build date, firmware 2 the same
    (the emulator is one piece).  Two ways to receive it, as real client code does: a
    caller's buffer (entry 78's ``char *pVersion``), or the address of a ``char *``
    (example 11-1's ``ADR(pVersion)`` / the vendor header's ``char **``): it is set to a
    NUL-terminated string that stays valid for the life of the process.
    """
    if pVersion.elem is ctypes.c_char_p and pVersion.nbytes >= ctypes.sizeof(ctypes.c_void_p):
        ctypes.c_void_p.from_address(pVersion.addr).value = ctypes.addressof(_VERSION_TEXT)
        return 0
    store_bytes(pVersion, _VERSION_TEXT.raw)
    return 0


def _version_text() -> bytes:
    digits = "".join(f"{int(p) % 10}" for p in [*__version__.split("."), "0", "0"][:3])
    fw = f"{digits} {RELEASE_DATE}"
    return f"{fw} {fw}".encode()


#: build date of this release, yymmdd (table 11-3)
RELEASE_DATE = "261201"
_VERSION_TEXT = ctypes.create_string_buffer(_version_text())


# --- EtherCAT bring-up ------------------------------------------------------------------------
@gt_function
def GT_InitEcatComm(ctl: Controller) -> int:
    """0 ok; -8 slaves differ from the ENI; -9 no ENI; -10 no slave found (entry 79).

    A failure is kept (``Controller.init_error``): GT_IsEcatReady then returns 1 with it.
    """
    ctl.init_ecat()
    return 0


@gt_function
def GT_StartEcatComm(ctl: Controller) -> int:
    ctl.start_ecat()
    return 0


@gt_function
def GT_TerminateEcatComm(ctl: Controller) -> int:
    ctl.terminate_ecat()
    return 0


@gt_function
def GT_IsEcatReady(ctl: Controller, pStatus: Any) -> int:
    """*pStatus = 1 once every slave is in OP with a good working counter (entry 80).

    1 (status 0) while no GT_InitEcatComm is in effect (module docstring).
    """
    e = ctl.init_error
    if e is not None:  # the last init failed (a bus of an earlier one may still run)
        store(pStatus, 0)
        raise CommandError(
            f"GT_InitEcatComm failed ({_core.code_for(e)}: {e}); the bus will not "
            "come up: fix the cause and call GT_InitEcatComm again"
        )
    store(pStatus, 1 if ctl.ready else 0)
    m = ctl.master
    if m is None or not m.opened:
        raise CommandError(
            "EtherCAT communication is not initialised: call GT_InitEcatComm first"
            + (" (it was terminated by GT_TerminateEcatComm)" if m is not None else "")
        )
    return 0


@gt_function
def GT_GetEcatSlaves(ctl: Controller, pSlaveCnt: Any, pIoSlaveCnt: Any = None) -> int:
    """The slaves online (entry 45: "在线的 EtherCAT 从站数目").  One pointer (manual): all of
    them.  Two (vendor header): the motion slaves online, the IO slaves online - the same
    count split, so both forms follow a link loss alike (a slave behind a cut is in neither).

    The count is the master's, as its last cycle left it (the states it read then), not a
    read of the bus of its own: a cable pulled since shows from the first cycle after the
    cut on, in the very cycle GT_IsEcatReady, the axes' alarm bits and the reads of the
    slaves behind it show it (a real controller's master counts the slaves in its cycle)."""
    m = ctl.master
    motion = io = 0
    if m is not None:
        for slave, state in zip(m.layout.slaves, m.states, strict=False):
            if state != AlState.NONE:
                if slave.channels:
                    motion += 1
                else:
                    io += 1
    if pIoSlaveCnt is None:
        store(pSlaveCnt, motion + io)
    else:
        store(pSlaveCnt, motion)
        store(pIoSlaveCnt, io)
    return 0


@gt_function
def GT_GetMcEcatAxisNum(ctl: Controller, pNum: Any) -> int:
    store(pNum, len(ctl.layout.axes) if ctl.layout is not None else 0)
    return 0


@gt_function
def GT_GetEcatPdoLength(ctl: Controller, pLength: Any) -> int:
    """Total length in bytes of the GT raw PDO image (outputs + inputs of every slave)."""
    m = ctl.require_master()
    store(pLength, m.image.size)
    return 0


@gt_function
def GT_GetEcatSlaveInfo(ctl: Controller, slave: int, pInfo: Any) -> int:
    m = ctl.require_master()
    slave = check_range("slave", slave, 0, len(m.layout.slaves) - 1)
    sl = m.layout.slaves[slave]
    cfg = m.layout.config.slaves[slave]
    state = m.refresh_states()[slave]
    info = TSlaveInfo(
        position=slave,
        vendorId=cfg.identity.vendor_id,
        productCode=cfg.identity.product_code,
        revisionNo=cfg.identity.revision_no,
        serialNo=cfg.identity.serial_no,
        state=int(state),
        axisCount=len(sl.axes),
        firstAxis=sl.axes[0] if sl.axes else 0,
        outputBytes=sl.out_bytes,
        inputBytes=sl.in_bytes,
        pdoOffset=sl.gt_offset,
        name=cfg.name.encode("utf-8", "replace")[:63],
    )
    store_bytes(pInfo, bytes(info))
    return 0


# --- raw PDO data (5.2.2.4) ----------
def _image(ctl: Controller):
    m = ctl.master
    if m is None or not m.opened:
        raise CommandError(
            "EtherCAT communication is not established (call GT_InitEcatComm "
            "and wait for GT_IsEcatReady)"
        )
    return m.image


def _require_online(ctl: Controller, slaves: Any, what: str) -> None:
    """1 naming the first of ``slaves`` the master has found offline (comm loss)."""
    m = ctl.master
    offline = m.offline if m is not None else {}
    if not offline:
        return
    for pos in slaves:
        reason = offline.get(pos)
        if reason:
            raise CommandError(
                f"{reason}: {what} (the bytes there are the last received); check the "
                "slave, its cable and the EtherCAT communication"
            )


def _raw_slaves(image: Any, offset: int, size: int) -> list[int]:
    """Slaves whose GT raw region shares a byte with ``[offset, offset + size)``."""
    end = offset + size
    return [
        sl.position
        for sl in image.layout.slaves
        if sl.gt_size and sl.gt_offset < end and offset < sl.gt_offset + sl.gt_size
    ]


def _touches_inputs(image: Any, offset: int, size: int) -> bool:
    end = offset + size
    return any(
        sl.in_bytes and sl.gt_offset + sl.out_bytes < end and offset < sl.gt_offset + sl.gt_size
        for sl in image.layout.slaves
    )


@gt_function
def GT_GetEcatRawData(ctl: Controller, offset: int, size: int, pValue: Any) -> int:
    image = _image(ctl)
    offset, size = int(offset), int(size)
    data = image.read_raw(offset, size)
    _require_online(ctl, _raw_slaves(image, offset, size), "its process data is not exchanged")
    store_bytes(pValue, data)
    return 0


@gt_function
def GT_SetEcatRawData(ctl: Controller, offset: int, size: int, pValue: Any) -> int:
    image = _image(ctl)
    offset, size = int(offset), int(size)
    image.check_range(offset, size)
    touched = _raw_slaves(image, offset, size)
    if not _touches_inputs(image, offset, size):  # else write_raw refuses it (7 first)
        _require_online(ctl, touched, "its outputs would not arrive")
    image.write_raw(offset, load_bytes(pValue, size))
    return 0


# --- EtherCAT IO (5.2.2.5) ----------
def _region(
    ctl: Controller, slave: int, offset: int, size: int, write: bool = False
) -> tuple[Any, int]:
    image = _image(ctl)
    slaves = image.layout.slaves
    slave = check_range("slave", slave, 0, len(slaves) - 1)
    sl = slaves[slave]
    if offset < 0 or size < 0 or offset + size > sl.gt_size:
        raise ParameterError(
            f"slave {slave} ({sl.name}): offset={offset} size={size} outside its "
            f"{sl.gt_size}-byte region ({sl.out_bytes} output + {sl.in_bytes} input bytes)"
        )
    if not (write and offset + size > sl.out_bytes):  # input bytes: write_raw says 7
        _require_online(ctl, (slave,), "its process data is not exchanged")
    return image, sl.gt_offset + offset


@gt_function
def GT_EcatIOReadInput(
    ctl: Controller, slave: int, offset: int, nSize: int, pValue: Any, *more: Any
) -> int:
    """Entry 11.  The 5-argument spelling of the manual's 5.2.2.5 text,
    ``GT_EcatIOReadInput(core, slave, offset, nSize, pValue)``, is accepted too."""
    slave, offset, nSize, pValue = _io_args(slave, offset, nSize, pValue, more)
    image, raw = _region(ctl, slave, offset, nSize)
    store_bytes(pValue, image.read_raw(raw, nSize))
    return 0


@gt_function
def GT_EcatIOWriteOutput(
    ctl: Controller, slave: int, offset: int, nSize: int, pValue: Any, *more: Any
) -> int:
    """Entry 12; the 5-argument spelling with the core first is accepted as for ReadInput."""
    slave, offset, nSize, pValue = _io_args(slave, offset, nSize, pValue, more)
    image, raw = _region(ctl, slave, offset, nSize, write=True)
    image.write_raw(raw, load_bytes(pValue, nSize))
    return 0


def _io_args(a: Any, b: Any, c: Any, d: Any, more: tuple) -> tuple[int, int, int, Any]:
    """(slave, offset, size, buffer) from the 4-argument prototype or the 5-argument text form."""
    if not more:
        return int(a), int(b), int(c), d
    if len(more) > 1:
        raise ParameterError(f"{4 + len(more)} arguments; the prototype takes 4 (or core + 4)")
    check_range("core", a, 1, 1)
    return int(b), int(c), int(d), more[0]


@gt_function
def GT_EcatIOBitWriteOutput(ctl: Controller, slave: int, offset: int, bit: int, value: int) -> int:
    """Set one output bit: byte ``offset`` of the slave's region, ``bit`` 0..7 (vendor header)."""
    bit = check_range("bit", bit, 0, 7)
    image, raw = _region(ctl, int(slave), int(offset), 1, write=True)
    cur = image.read_raw(raw, 1)[0]
    new = (cur | (1 << bit)) if value else (cur & ~(1 << bit))
    image.write_raw(raw, bytes([new & 0xFF]))
    return 0


@gt_function
def GT_EcatIOSynch(ctl: Controller) -> int:
    """Wait until the outputs written so far have been exchanged with the slaves.

    The vendor header has it without documentation; here it runs the clock to
    the end of the next bus cycle (virtual clocks) so the outputs are on the
    bus and inputs read afterwards are fresh.
    """
    _image(ctl)
    ctl.clock.advance_ns(ctl.clock.cycle_ns)
    return 0


# --- SDO (entries 13, 14) ----------
@gt_function
def GT_EcatSDODownload(
    ctl: Controller,
    slave_position: int,
    index: int,
    subindex: int,
    pData: Any,
    data_size: int,
    pAbort_code: Any = None,
) -> int:
    m = ctl.require_master()
    check_range("index", index, 0, 0xFFFF)
    check_range("subindex", subindex, 0, 0xFF)
    data = load_bytes(pData, check_range("data_size", data_size, 0, 1 << 20))
    store(pAbort_code, 0)
    try:
        m.sdo_download(int(slave_position), int(index), int(subindex), data)
    except SdoAbort as e:
        store(pAbort_code, int(e.code))
        raise
    return 0


@gt_function
def GT_EcatSDOUpload(
    ctl: Controller,
    slave_position: int,
    index: int,
    subindex: int,
    pTarget: Any,
    target_size: int,
    pResult_size: Any = None,
    pAbort_code: Any = None,
) -> int:
    m = ctl.require_master()
    check_range("index", index, 0, 0xFFFF)
    check_range("subindex", subindex, 0, 0xFF)
    target_size = check_range("target_size", target_size, 0, 1 << 20)
    store(pAbort_code, 0)
    try:
        data = m.sdo_upload(int(slave_position), int(index), int(subindex))
    except SdoAbort as e:
        store(pAbort_code, int(e.code))
        raise
    if len(data) > target_size:
        store(pResult_size, len(data))
        raise ParameterError(
            f"0x{index:04X}:{subindex:02X} holds {len(data)} bytes, target_size is {target_size}"
        )
    store_bytes(pTarget, data)
    store(pResult_size, len(data))
    return 0


# --- emulator-only helpers ----------
@gt_function
def GTE_Wait(ctl: Controller, ms: float) -> int:
    """Let ``ms`` of controller time pass, in any clock mode (virtual time runs, or the
    realtime clock sleeps), so one script runs unchanged in every mode.

    While a panel or verb is attached to the controller's inspection endpoint, a wait in
    virtual time ends with a yield (``time.sleep(0)``, no waiting): a script that runs
    quick lockstep waits back to back would otherwise keep the interpreter from the
    endpoint's threads, and the panel would get no answer until the script ends.  With
    nobody attached there is no yield: on a busy machine one hands the CPU to another
    process for a scheduler slice."""
    ctl.wait_ms(float(ms))
    wait_yield(ctl)
    return 0


def GTE_GetLastError() -> str:
    """Why the most recent GT call returned non-zero, as ``NAME returned CODE: reason``.

    "" when that call returned 0: every call that succeeds clears it (per call, like the
    return code itself), so read it right after the call that failed.
    """
    e = _core.last_error()
    return "" if e is None else f"{e.function} returned {e.code}: {e.reason}"


@gt_function
def GTE_UnplugSlave(ctl: Controller, slave: int) -> int:
    """Emulated bus: pull the cable in front of ``slave`` (it and the slaves behind it
    stop answering; their process-data watchdogs run out after 100 ms)."""
    backend = _emulated(ctl)
    slave = check_range("slave", slave, 0, len(backend.slaves) - 1)
    for pos in range(slave, len(backend.slaves)):
        backend.unplug(pos)
    return 0


@gt_function
def GTE_ReplugSlave(ctl: Controller, slave: int) -> int:
    """Emulated bus: plug the cable back; the master recovers the slaves to OP."""
    backend = _emulated(ctl)
    slave = check_range("slave", slave, 0, len(backend.slaves) - 1)
    for pos in range(slave, len(backend.slaves)):
        backend.replug(pos)
    return 0


def _emulated(ctl: Controller):
    from ..master.backends.emulated import EmulatedBackend

    backend = ctl.backend
    if not isinstance(backend, EmulatedBackend):
        raise CommandError("only the emulated bus can unplug slaves (GT_InitEcatComm first)")
    return backend


def GTE_GetCycleStats(core: int = 1) -> dict:
    """Cycle period, jitter (p50/p99/max), overruns and working-counter errors so far."""
    from ..master.backends.cycle_stats import cycle_stats

    return cycle_stats(SESSION.controller(core))


def GTE_Controller(core: int = 1) -> Controller:
    """The open controller (the Pythonic API) for scenarios and tests."""
    return SESSION.controller(core)


def GTE_Slave(slave: int, core: int = 1):
    """The virtual slave at ``slave`` (emulated backend): its field side for scenarios."""
    ctl = SESSION.controller(core)
    from ..master.backends.emulated import EmulatedBackend

    backend = ctl.backend
    if not isinstance(backend, EmulatedBackend):
        raise BusError(
            "no emulated bus is open (GT_InitEcatComm first; virtual slaves exist "
            "only on the emulated backend)"
        )
    try:
        return backend.slaves[slave]
    except IndexError:
        raise ParameterError(f"no slave {slave}") from None


GT_EcatSDOupload = GT_EcatSDOUpload  # the manual's prototype spells it so
GTN_EcatSDOupload = _core.REGISTRY["GTN_EcatSDOUpload"]
