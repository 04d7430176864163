"""The pysoem backend: the same master on a real network interface (SOEM through pysoem).

Selected by ``GTECAT_BACKEND=pysoem`` and ``GTECAT_IFACE``.  :class:`gtecat.master.bus.Master`
drives the bring-up exactly as on the emulated backend; this module maps each
step onto SOEM (``ecx_*`` through pysoem):

* ``open``: ``Master.open(iface)`` with ``manual_state_change`` set, so SOEM
  never changes an AL state on its own and the master's walk decides
  (ETG.1000.6 6.4: INIT -> PREOP -> SAFEOP -> OP).
* ``scan``: ``config_init`` (SII identity of every slave, mailbox sync managers).
* PREOP -> SAFEOP: the master runs each slave's ``PS`` CoE InitCmds (PDO
  assignment 0x1C12/0x1C13, mapping 0x16xx/0x1Axx) before asking for SAFEOP.
  ``config_map`` reads the PDO mapping through CoE, so it must come after the
  InitCmds of *every* slave: the SAFEOP requests are held until the last
  slave asks, then the IO map is built once, its per-slave sizes are checked
  against the ENI (a difference is GT -8) and every slave is asked for SAFEOP.
* SAFEOP -> OP: requested while process data keeps flowing (outputs valid,
  ETG.1000.6 6.4.3), as SOEM's examples do.

Process image: SOEM's IO map holds every slave's outputs then inputs in its
own order; each cycle copies, per slave, the master's logical image area into
``slave.output`` and ``slave.input`` back (:meth:`ProcessImage.to_slave` /
``from_slave``, the same calls the emulated backend makes with its virtual
slaves' buffers).  So ``GT_GetEcatRawData`` offsets are identical on both.
SOEM packs slaves with fewer than 8 bits into shared bytes; :func:`soem_bit_starts`
reproduces that packing so those slaves are read and written bit-exactly.

Mailbox: an SDO waits for the slave's answer on the wire (SOEM's mailbox timeout, set to
the master's 700 ms), with the GIL let go, while the cycles go on in another thread
(:attr:`Backend.mailbox_on_wire`): SOEM sends and takes its process-data and mailbox
frames under their own datagram indexes, so the two interleave.  One transfer at a time
(:attr:`PysoemBackend.mailbox_lock`).  SOEM's outcomes become the abort codes the
emulated bus gives (:data:`gtecat.drives.abort.MAILBOX_FAILURE_CODES`): an abort frame its
code, no answer 05040000h, a mailbox error reply or an answer that is not the SDO's
08000000h.

Working counter: returned as data; a drop starts SOEM's supervision pattern
(acknowledge SAFEOP+ERROR, re-request OP, reconfigure a slave that fell back
to INIT/PREOP with its InitCmds re-applied, re-address a lost slave when it
answers again), rate limited so the cycle keeps running.
"""

from __future__ import annotations

import logging
import os
import sys
import threading
import time
from collections import deque
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from types import ModuleType
from typing import Any

import numpy as np

from gtecat.drives.abort import MailboxFailure, SdoAbort, mailbox_failure
from gtecat.drives.slave import AlState, AlStatusCode, Emergency
from gtecat.eni.layout import Layout
from gtecat.eni.model import Direction, Identity, InitCmd

from ...errors import BusError, ConfigMismatch, NoSlavesError, StateError
from ..bus import SDO_TIMEOUT_MS
from ..image import ProcessImage, Segment
from .base import Backend, FoundSlave

_log = logging.getLogger("gtecat.pysoem")

STATE_MASK = 0x0F  # AL status register 0x0130: state nibble
ERROR_FLAG = 0x10  # AL status 0x0130 bit 4: error indication; AL control: acknowledge
IOMAP_BYTES = 4096  # pysoem's static IO map (EC_IOMAPSIZE)
_SDO_BIG = 1 << 16  # retry size for objects larger than pysoem's 256-byte default buffer
_SII_MBX_PROTO = 0x001C  # SII word: mailbox protocols supported
_PACKET_TOO_SMALL = 3  # SOEM packet error: the data container is too small for the answer
#: GIL switch interval while the bus is open: a user thread polling GT functions in a
#: tight loop (manual example 5-5) otherwise keeps the cycle thread waiting up to 5 ms
SWITCH_INTERVAL_S = 0.0005


def soem_bit_starts(bits: list[int]) -> list[tuple[int, bool] | None]:
    """Start bit of each slave inside its first IO map byte, as SOEM packs them.

    SOEM (``ecx_config_create_output_mappings``) gives a slave with 1..7 bits a
    bit-granular FMMU that continues where the previous bit slave ended; a
    slave with 8 bits or more starts on a fresh byte.  Returns ``None`` for
    byte-oriented or empty slaves, else ``(start_bit, straddles)`` where
    ``straddles`` says the bits run into the next byte.
    """
    pos = 0
    out: list[tuple[int, bool] | None] = []
    for b in bits:
        if b <= 0:
            out.append(None)
        elif b > 7:
            pos = 0
            out.append(None)
        else:
            out.append((pos, pos + b > 8))
            pos = (pos + b) % 8
    return out


def _al_code(code: int) -> AlStatusCode | int:
    try:
        return AlStatusCode(code)
    except ValueError:
        return int(code)


def _code_text(code: int) -> str:
    try:
        return AlStatusCode(code).name.lower().replace("_", " ")
    except ValueError:
        return "vendor specific"


def _state_name(raw: int) -> str:
    try:
        name = AlState(raw & STATE_MASK).name
    except ValueError:
        name = f"0x{raw & STATE_MASK:X}"
    return name + ("+ERROR" if raw & ERROR_FLAG else "")


@dataclass
class _Io:
    """One slave's process data: SOEM slave object <-> master image segment."""

    position: int
    soem: Any
    seg: Segment
    buf: bytearray
    bits: int
    start_bit: int | None  # SOEM bit packing for slaves under 8 bits


@dataclass
class BusStats:
    """What the backend saw on the wire (realtime diagnostics, GTE_GetCycleStats)."""

    cycles: int = 0
    wkc_errors: int = 0
    lost_frames: int = 0
    recoveries: int = 0
    checks: int = 0
    #: send -> receive round trip of the process-data frame, ns (ring buffer)
    rtt_ns: np.ndarray = field(default_factory=lambda: np.zeros(1 << 16, dtype=np.int64))
    rtt_count: int = 0

    def add_rtt(self, ns: int) -> None:
        self.rtt_ns[self.rtt_count & (len(self.rtt_ns) - 1)] = ns
        self.rtt_count += 1

    def rtt_samples(self) -> np.ndarray:
        n = min(self.rtt_count, len(self.rtt_ns))
        return self.rtt_ns[:n]


def _import_pysoem() -> ModuleType:
    try:
        import pysoem
    except ImportError as e:
        raise BusError(
            f"the pysoem backend needs the pysoem package: pip install 'gtecat[pysoem]' ({e})"
        ) from None
    return pysoem


def interfaces() -> list[str]:
    """Network interfaces of this machine (Linux: /sys/class/net)."""
    net = Path("/sys/class/net")
    if net.is_dir():
        return sorted(p.name for p in net.iterdir() if p.name != "lo")
    try:
        return [a.name for a in _import_pysoem().find_adapters()]
    except Exception:
        return []


def has_raw_socket_rights() -> bool:
    """CAP_NET_RAW and CAP_NET_ADMIN in the effective set (root usually has both).

    SOEM opens a raw packet socket (CAP_NET_RAW) and puts the NIC in
    promiscuous mode (CAP_NET_ADMIN); without either, ``open`` fails.
    """
    try:
        for line in Path("/proc/self/status").read_text().splitlines():
            if line.startswith("CapEff:"):
                caps = int(line.split()[1], 16)
                return bool(caps >> 13 & 1 and caps >> 12 & 1)  # NET_RAW 13, NET_ADMIN 12
    except OSError:
        pass
    return hasattr(os, "geteuid") and os.geteuid() == 0


def _link_state(iface: str) -> str | None:
    try:
        return Path(f"/sys/class/net/{iface}/operstate").read_text().strip()
    except OSError:
        return None


class PysoemBackend(Backend):
    """The bus on a network interface, through pysoem (SOEM)."""

    recovers_itself = True  # check_and_recover(): SOEM re-addresses and reconfigures
    mailbox_on_wire = True  # an SDO waits for the slave's answer (module docstring "Mailbox")

    name = "pysoem"

    def __init__(
        self,
        iface: str | None = None,
        *,
        soem: ModuleType | Any = None,
        log: Callable[[str], None] | None = None,
        rx_timeout_us: int | None = None,
        state_timeout_ms: float = 2000.0,
        check_interval_ms: float = 100.0,
        dc: bool | None = None,
        monotonic: Callable[[], float] = time.monotonic,
    ) -> None:
        """Nothing touches the NIC before :meth:`open`.

        ``rx_timeout_us``: how long one cycle waits for its frame (default: 80 %
        of the cycle, env ``GTECAT_RX_TIMEOUT_US``).  ``check_interval_ms``: how
        often a bad working counter triggers a state check/recovery.  ``dc``:
        configure distributed clocks and SYNC0 at the ENI cycle (env
        ``GTECAT_DC=1``; drives that need SYNC0 for OP).
        """
        self.iface = iface
        self._soem_module = soem
        self.log: Callable[[str], None] = log or _log.info
        env_rx = os.environ.get("GTECAT_RX_TIMEOUT_US")
        self.rx_timeout_us = rx_timeout_us or (int(env_rx) if env_rx else None)
        self.state_timeout_ms = state_timeout_ms
        self.check_interval_ms = check_interval_ms
        self.dc = dc if dc is not None else os.environ.get("GTECAT_DC", "") in ("1", "yes", "on")
        self._monotonic = monotonic
        self.stats = BusStats()
        self.soem: Any = None  # pysoem module
        self.master: Any = None  # pysoem.Master
        self.layout: Layout | None = None
        self.image: ProcessImage | None = None
        self.slaves: list[Any] = []  # pysoem CdefSlave, bus order
        #: CoE emergencies pysoem handed over since the last cycle: (position, Emergency)
        self._emcy: deque[tuple[int, Emergency]] = deque()
        self.mapped = False
        self._pending_safeop: set[int] = set()
        self._op: set[int] = set()
        self.operational = False  # every slave reached OP once: WKC supervision on
        self._outs: list[_Io] = []
        self._ins: list[_Io] = []
        self._expected = 0
        self._dt_ns = 1_000_000
        self._bad_cycles = 0
        self._lost: set[int] = set()
        self._notes: dict[int, str] = {}
        self._coe: list[bool] = []
        self._switch_interval: float | None = None
        #: one mailbox transfer at a time (the application's SDOs, which run beside the
        #: cycles, and the InitCmds a recovery in the cycle re-applies)
        self.mailbox_lock = threading.Lock()
        #: slaves whose last transfer failed: their mailbox is emptied again before the next
        self._mailbox_dirty: set[int] = set()

    # --- open / scan --------------------------------------------------------------
    def open(self, layout: Layout, image: ProcessImage) -> None:
        self.layout, self.image = layout, image
        if not self.iface:
            raise BusError(
                "the pysoem backend needs a network interface: set GTECAT_IFACE (or "
                f"GT_Open(iface=...)); interfaces here: {', '.join(interfaces()) or 'none'}"
            )
        need = sum(sl.out_bytes + sl.in_bytes for sl in layout.slaves)  # SOEM packs slaves
        if need > IOMAP_BYTES:
            raise BusError(
                f"the ENI's slaves exchange {need} bytes of process data; pysoem's IO map "
                f"holds {IOMAP_BYTES}"
            )
        self.soem = self._soem_module or _import_pysoem()
        m = self.soem.Master()
        try:
            m.manual_state_change = 1  # the master's walk decides every AL transition
        except AttributeError:
            raise BusError(
                "pysoem is too old (manual state change needs pysoem >= 1.0.5)"
            ) from None
        try:
            m.open(self.iface)
        except ConnectionError as e:
            raise BusError(self._open_failure(self.iface)) from e
        self.master = m
        # the master's mailbox timeout (gtecat.master.bus.SDO_TIMEOUT_MS), in µs
        for attr in ("sdo_read_timeout", "sdo_write_timeout"):
            if hasattr(m, attr):
                setattr(m, attr, SDO_TIMEOUT_MS * 1000)
        self._switch_interval = sys.getswitchinterval()
        if self._switch_interval > SWITCH_INTERVAL_S:
            sys.setswitchinterval(SWITCH_INTERVAL_S)
        self.log(f"Opened {self.iface} (pysoem {getattr(self.soem, '__version__', '?')}).")

    def _open_failure(self, iface: str) -> str:
        known = interfaces()
        if known and iface not in known:
            return (
                f"network interface {iface!r} does not exist; interfaces here: "
                f"{', '.join(known)} (set GTECAT_IFACE)"
            )
        if not has_raw_socket_rights():
            return (
                f"cannot open {iface!r} for raw EtherCAT frames: needs root or the "
                "CAP_NET_RAW and CAP_NET_ADMIN capabilities (see docs/hardware.md)"
            )
        return f"SOEM could not open {iface!r} (is it up? ip link set {iface} up)"

    def scan(self) -> list[FoundSlave]:
        m = self._require()
        n = m.config_init()
        if n is None or n <= 0:
            link = _link_state(self.iface or "")
            hint = f"; link of {self.iface} is {link}" if link and link != "up" else ""
            raise NoSlavesError(
                f"no slave answered the scan on {self.iface}{hint}: check the cable goes to "
                "the first slave's IN port, the slaves are powered, and GTECAT_IFACE names "
                "the EtherCAT NIC"
            )
        self.slaves = list(m.slaves)
        self._coe = [self._has_coe(s) for s in self.slaves]
        self._emcy.clear()
        for i, s in enumerate(self.slaves):
            self._listen_for_emergencies(i, s)
        found = []
        for i, s in enumerate(self.slaves):
            found.append(FoundSlave(i, Identity(int(s.man), int(s.id), int(s.rev)), str(s.name)))
        return found

    def _listen_for_emergencies(self, position: int, s: Any) -> None:
        """A CoE emergency that arrives while SOEM waits for a mailbox answer goes to the
        master log (as the emulated bus's do), not into the SDO call: without a callback
        pysoem raises it from ``sdo_read``/``sdo_write`` and the SDO's own answer is lost."""
        add = getattr(s, "add_emergency_callback", None)
        if add is None:  # an older pysoem: sdo_upload/sdo_download catch it instead
            return
        add(lambda e, pos=position: self._emcy.append((pos, _emergency(e))))

    def emergencies(self) -> list[tuple[int, object]]:
        out = []
        while self._emcy:
            out.append(self._emcy.popleft())
        return out

    @staticmethod
    def _has_coe(s: Any) -> bool:
        """CoE in the slave's SII mailbox protocols (word 0x001C, bit 2; ETG.1000.6 Table 17).

        Read while the master still owns the EEPROM (after ``config_init``), so an
        SDO to a slave without a mailbox fails at once with the reason, as on the
        emulated backend, instead of after a mailbox timeout.
        """
        try:
            return bool(int.from_bytes(s.eeprom_read(_SII_MBX_PROTO)[:2], "little") & 0x04)
        except Exception:
            return True  # cannot tell: let the SDO itself find out

    def _require(self) -> Any:
        if self.master is None:
            raise BusError("the pysoem backend is not open")
        return self.master

    def _slave(self, position: int) -> Any:
        if self.master is None:
            raise BusError("the EtherCAT bus is closed (GT_InitEcatComm opens it)")
        if not 0 <= position < len(self.slaves):
            raise BusError(f"no slave {position}: the bus has {len(self.slaves)} slaves")
        return self.slaves[position]

    def _name(self, position: int) -> str:
        if self.layout is not None and position < len(self.layout.config.slaves):
            return self.layout.config.slaves[position].name
        return str(self.slaves[position].name) if position < len(self.slaves) else "?"

    # --- AL states ------------------------------------------------------------------
    def state(self, position: int) -> tuple[AlState, AlStatusCode]:
        s = self._slave(position)
        self.master.read_state()
        raw = int(s.state)
        st = raw & STATE_MASK
        if st == 0:
            raise BusError(f"slave {position} ({self._name(position)}) does not answer")
        try:
            state = AlState(st)
        except ValueError:
            raise BusError(f"slave {position} reports an invalid AL state 0x{raw:02X}") from None
        return state, _al_code(int(s.al_status))  # type: ignore[return-value]

    def states(self, count: int) -> list[tuple[AlState, AlStatusCode] | None]:
        """Every slave's state from one ``read_state`` (a state of 0: no answer)."""
        if self.master is None:
            return [None] * count
        self.master.read_state()
        out: list[tuple[AlState, AlStatusCode] | None] = []
        for pos in range(count):
            raw = int(self.slaves[pos].state) if pos < len(self.slaves) else 0
            try:
                state = AlState(raw & STATE_MASK) if raw & STATE_MASK else None
            except ValueError:
                state = None
            code = int(self.slaves[pos].al_status) if state is not None else 0
            out.append(None if state is None else (state, _al_code(code)))  # type: ignore[arg-type]
        return out

    def request_state(self, position: int, state: AlState) -> AlStatusCode:
        target = AlState(state)
        self._slave(position)
        if target == AlState.SAFEOP and not self.mapped:
            return self._safeop_after_all_init_cmds(position)
        if target < AlState.SAFEOP:
            self._op.discard(position)
            self.operational = False
            if target == AlState.INIT:
                self._pending_safeop.discard(position)
        code = self._transition(position, target, pump=target == AlState.OP)
        if target == AlState.OP and code == 0:
            self._op.add(position)
            if len(self._op) == len(self.slaves):
                self.operational = True
                self._bad_cycles = 0
        return code  # type: ignore[return-value]

    def _transition(self, position: int, target: AlState, *, pump: bool = False) -> int:
        """Write AL control and wait for the slave (ETG.1000.6 6.4.1)."""
        s = self.slaves[position]
        req = int(target)
        if int(s.state) & ERROR_FLAG:
            req |= ERROR_FLAG  # acknowledge the previous refusal
        s.state = req
        wkc = s.write_state()
        if wkc is not None and wkc <= 0:
            raise BusError(
                f"slave {position} ({self._name(position)}) does not answer "
                f"(AL control write for {target.name} got no reply)"
            )
        deadline = self._monotonic() + self.state_timeout_ms / 1000
        if pump:
            # outputs must keep arriving while the slave checks them (SAFEOP -> OP)
            while True:
                self._pump()
                got = s.state_check(int(target), 1000)
                if got == target or int(s.state) & ERROR_FLAG or self._monotonic() > deadline:
                    break
        else:
            got = s.state_check(int(target), int(self.state_timeout_ms * 1000))
        raw = int(s.state)
        if got == target and (raw & STATE_MASK) == target:
            return 0
        code = int(s.al_status)
        if raw & ERROR_FLAG and code:
            return code
        raise StateError(
            f"slave {position} ({self._name(position)}): no answer to the {target.name} "
            f"request within {self.state_timeout_ms:.0f} ms (AL state {_state_name(raw)}, "
            f"AL status code 0x{code:04X})",
            expected=target,
            actual=raw & STATE_MASK,
            slave=position,
        )

    def _safeop_after_all_init_cmds(self, position: int) -> int:
        """Hold SAFEOP requests until every slave's PS InitCmds ran, then map once."""
        self._pending_safeop.add(position)
        if position != len(self.slaves) - 1 and len(self._pending_safeop) < len(self.slaves):
            return 0
        self._map()
        for p in sorted(self._pending_safeop):
            code = self._transition(p, AlState.SAFEOP)
            if code and p == position:
                self._pending_safeop.clear()
                return code  # the master reports it for this slave
            if code:
                raw = int(self.slaves[p].state)
                msg = (
                    f"slave {p} ({self._name(p)}): PS refused, AL status code "
                    f"0x{code:04X} {_code_text(code)}; stays in {_state_name(raw)}"
                )
                self.log(msg)
                self._pending_safeop.clear()
                raise StateError(msg, expected=AlState.SAFEOP, actual=raw & STATE_MASK, slave=p)
        self._pending_safeop.clear()
        return 0

    # --- IO map -----------------------------------------------------------------------
    def _map(self) -> None:
        """``config_map`` after the PS InitCmds; check SOEM's sizes against the ENI."""
        m, layout, image = self.master, self.layout, self.image
        assert layout is not None and image is not None
        try:
            size = m.config_map()
        except self.soem.ConfigMapError as e:
            errs = "; ".join(_describe_soem_error(x) for x in e.error_list)
            raise StateError(f"reading the PDO mapping of the slaves failed: {errs}") from None
        self.log(f"IO map: {size} bytes.")
        for pos, s in enumerate(self.slaves):
            sl = layout.slaves[pos]
            for what, want, got in (
                ("output", sl.out_bytes, len(s.output)),
                ("input", sl.in_bytes, len(s.input)),
            ):
                if want != got:
                    pdo = "RxPDO" if what == "output" else "TxPDO"
                    raise ConfigMismatch(
                        f"slave {pos} ({sl.name}): the ENI maps {want} {what} bytes, the "
                        f"slave's {pdo} mapping (as SOEM read it) has {got}; "
                        + self._mismatch_hint(pos)
                    )
        segs = {(g.slave, g.direction): g for g in image.segments}
        self._outs, self._ins = [], []
        for direction, attr, target in (
            (Direction.OUT, "out_bits", self._outs),
            (Direction.IN, "in_bits", self._ins),
        ):
            bits = [getattr(layout.slaves[p], attr) for p in range(len(self.slaves))]
            for pos, packed in enumerate(soem_bit_starts(bits)):
                seg = segs.get((pos, direction))
                if seg is None:
                    continue
                if packed is not None and packed[1]:
                    raise BusError(
                        f"slave {pos} ({self._name(pos)}): SOEM packs its {bits[pos]} "
                        f"{'output' if direction == Direction.OUT else 'input'} bits across "
                        "a byte boundary, which pysoem cannot address"
                    )
                target.append(
                    _Io(
                        pos,
                        self.slaves[pos],
                        seg,
                        bytearray(seg.raw_bytes),
                        bits[pos],
                        None if packed is None else packed[0],
                    )
                )
        # ETG.1000.4 LRW: +2 per slave that took outputs, +1 per slave that gave inputs.
        # This SOEM build's own figure undercounts slaves that share a byte (bit
        # packing), so it is only reported.
        self._expected = 2 * len(self._outs) + len(self._ins)
        soem_wkc = int(m.expected_wkc)
        if soem_wkc != self._expected:
            self.log(
                f"Expected working counter {self._expected} (SOEM computes {soem_wkc}, "
                "which does not count bit-packed slaves one by one)."
            )
        if self.dc:
            self._configure_dc()
        for pos, s in enumerate(self.slaves):
            s.setup_func = self._reconfig_hook(pos)
        self.mapped = True

    def _mismatch_hint(self, pos: int) -> str:
        """Why SOEM may see other process data than the ENI (for the -8 reason)."""
        assert self.layout is not None
        cfgs = self.layout.config.slaves
        twin = next((q for q in range(pos) if cfgs[q].identity == cfgs[pos].identity), None)
        if twin is not None and not self._coe[pos]:
            return (
                f"it has the same vendor/product/revision as slave {twin} "
                f"({cfgs[twin].name}), and SOEM describes such slaves from the first one's "
                "SII (on a real bus the same identity is the same device): give it its own "
                "product code in the ENI"
            )
        return (
            "the PDO assignment/mapping InitCmds did not take effect or the slave uses "
            "another mapping"
        )

    def _configure_dc(self) -> None:
        layout = self.layout
        assert layout is not None
        if not self.master.config_dc():
            self.log("GTECAT_DC: no slave supports distributed clocks.")
            return
        cycle = int(layout.config.cycle_time_ns or 1_000_000)
        for s in self.slaves:
            s.dc_sync(True, cycle)
        self.log(f"Distributed clocks: SYNC0 every {cycle} ns.")

    def _reconfig_hook(self, position: int) -> Callable[[Any], None]:
        """SOEM's PREOP->SAFEOP hook during ``reconfig``: re-apply the InitCmds."""

        def hook(_slave: Any) -> None:
            assert self.layout is not None
            for cmd in self.layout.config.slaves[position].init_cmds:
                if not {"IP", "PS"} & set(cmd.transitions):
                    continue
                try:
                    self._run_init_cmd(position, cmd)
                except Exception as e:
                    self.log(
                        f"slave {position} ({self._name(position)}): InitCmd "
                        f"0x{cmd.index:04X}:{cmd.subindex:02X} failed during "
                        f"reconfiguration: {e}"
                    )

        return hook

    def _run_init_cmd(self, position: int, cmd: InitCmd) -> None:
        if cmd.upload:
            self.sdo_upload(position, cmd.index, cmd.subindex, cmd.complete_access)
        else:
            self.sdo_download(position, cmd.index, cmd.subindex, cmd.data, cmd.complete_access)

    # --- cycle ------------------------------------------------------------------------
    def _rx_timeout(self) -> int:
        if self.rx_timeout_us:
            return int(self.rx_timeout_us)
        return max(100, int(self._dt_ns * 0.8 / 1000))

    def _pump(self) -> int:
        """One frame out and back with the IO map as it stands."""
        m = self.master
        m.send_processdata(release_gil=True)
        return int(m.receive_processdata(self._rx_timeout(), release_gil=True))

    def exchange(self, t_ns: int, dt_ns: int) -> int:
        if not self.mapped:
            return 0
        self._dt_ns = dt_ns
        image = self.image
        assert image is not None
        for io in self._outs:
            image.to_slave(io.seg, io.buf)
            if io.start_bit is None:
                io.soem.output = bytes(io.buf)
            else:
                mask = ((1 << io.bits) - 1) << io.start_bit
                cur = io.soem.output[0]
                io.soem.output = bytes([(cur & ~mask) | ((io.buf[0] << io.start_bit) & mask)])
        m = self.master
        t0 = time.perf_counter_ns()
        m.send_processdata(release_gil=True)
        wkc = int(m.receive_processdata(self._rx_timeout(), release_gil=True))
        self.stats.add_rtt(time.perf_counter_ns() - t0)
        for io in self._ins:
            data = io.soem.input
            if io.start_bit is not None:
                data = bytes([(data[0] >> io.start_bit) & ((1 << io.bits) - 1)])
            image.from_slave(io.seg, data)
        self.stats.cycles += 1
        self._supervise(wkc)
        return max(wkc, 0)

    def expected_wkc(self) -> int:
        if self.mapped:
            return self._expected
        layout = self.layout
        if layout is None:
            return 0
        return sum(2 * bool(s.out_bits) + bool(s.in_bits) for s in layout.slaves)

    # --- working counter supervision ----------------------------------------------------
    def _supervise(self, wkc: int) -> None:
        if not self.operational:
            return
        if wkc == self._expected:
            if self._bad_cycles:
                self.log(
                    f"Working counter back to {wkc}/{self._expected} after "
                    f"{self._bad_cycles} bad cycles."
                )
                self.stats.recoveries += 1
                self._bad_cycles = 0
            return
        self.stats.wkc_errors += 1
        if wkc <= 0:
            self.stats.lost_frames += 1
        self._bad_cycles += 1
        every = max(1, round(self.check_interval_ms * 1_000_000 / self._dt_ns))
        if self._bad_cycles % every == 1 or every == 1:
            self.check_and_recover()

    def check_and_recover(self) -> None:
        """SOEM's supervision pattern, one pass: move every slave back towards OP.

        A slave that does not answer is *lost*; once it answers at its position
        again, ``recover`` gives it back its station address (a restarted slave
        has none, even when a broadcast read shows it in INIT), then
        ``reconfig`` walks it INIT -> PREOP (InitCmds re-applied by the hook)
        -> SAFEOP, and the next pass asks for OP.
        """
        self.stats.checks += 1
        self.master.read_state()
        held = getattr(self, "held", {})
        for pos, s in enumerate(self.slaves):
            if pos in held:  # an operator's state request (Master.held)
                continue
            raw = int(s.state)
            st = raw & STATE_MASK
            if pos in self._lost or st == 0:
                if pos not in self._lost:
                    self._lost.add(pos)
                    s.is_lost = True
                    self._note(pos, "lost (no answer)")
                if s.recover(500) <= 0:
                    continue
                self._lost.discard(pos)
                s.is_lost = False
                self._note(pos, "answers again")
                raw, st = int(AlState.INIT), int(AlState.INIT)
            if st == AlState.OP and not raw & ERROR_FLAG:
                self._notes.pop(pos, None)
                continue
            if raw == (AlState.SAFEOP | ERROR_FLAG):
                code = int(s.al_status)
                self._note(
                    pos, f"SAFEOP+ERROR, AL status 0x{code:04X} {_code_text(code)}; acknowledging"
                )
                s.state = int(AlState.SAFEOP) | ERROR_FLAG
                s.write_state()
            elif st == AlState.SAFEOP:
                self._note(pos, "in SAFEOP, requesting OP")
                s.state = int(AlState.OP)
                s.write_state()
            else:
                self._note(pos, f"in {_state_name(raw)}, reconfiguring (InitCmds re-applied)")
                if not s.reconfig(500):
                    self._lost.add(pos)  # no answer at its address: re-address next pass
                    s.is_lost = True

    def _note(self, pos: int, what: str) -> None:
        """Log a recovery step once per slave and condition (not every check)."""
        if self._notes.get(pos) != what:
            self._notes[pos] = what
            self.log(f"slave {pos} ({self._name(pos)}) {what}")

    # --- mailbox ------------------------------------------------------------------------
    def _mailbox_slave(self, position: int, what: str, index: int, subindex: int) -> Any:
        s = self._slave(position)
        if not self._coe[position]:
            raise BusError(f"slave {position} ({self._name(position)}) has no CoE mailbox")
        if (int(s.state) & STATE_MASK) == AlState.INIT:
            raise BusError(
                f"slave {position}: mailbox not available in INIT ({what} "
                f"0x{index:04X}:{subindex:02X})"
            )
        return s

    def _sdo_error(
        self, e: Exception, position: int, what: str, index: int, subindex: int, waited_s: float
    ) -> Exception:
        """SOEM's outcome as the emulated bus gives it (:data:`MAILBOX_FAILURE_CODES`)."""
        soem = self.soem
        where = f"slave {position} ({self._name(position)}): SDO {what}"
        if isinstance(e, soem.SdoError):
            return SdoAbort(int(e.abort_code), index, subindex)
        if isinstance(e, soem.WkcError):
            if waited_s * 1000 < SDO_TIMEOUT_MS * 0.9:
                # SOEM could not even put the request into the slave's mailbox: the slave
                # is gone, as the emulated bus reports one behind a pulled cable
                return BusError(
                    f"{where} 0x{index:04X}:{subindex:02X}: no answer (the slave did not take "
                    f"the request; {waited_s * 1000:.0f} ms)"
                )
            why = f"no answer within the mailbox timeout ({SDO_TIMEOUT_MS} ms)"
            return mailbox_failure(MailboxFailure.NO_ANSWER, index, subindex, f"{where}: {why}")
        if isinstance(e, soem.MailboxError):
            return mailbox_failure(
                MailboxFailure.ERROR_REPLY,
                index,
                subindex,
                f"{where}: mailbox error {e.error_code} ({e.desc})",
            )
        if isinstance(e, soem.PacketError):
            failure = (
                MailboxFailure.TOO_BIG
                if getattr(e, "error_code", None) == _PACKET_TOO_SMALL
                else MailboxFailure.UNEXPECTED
            )
            return mailbox_failure(
                failure, index, subindex, f"{where}: {_describe_soem_error(e, slave=False)}"
            )
        return BusError(f"{where} 0x{index:04X}:{subindex:02X}: {e!r}")

    def _past_emergencies(
        self, position: int, call: Callable[..., Any], *args: Any, **kw: Any
    ) -> Any:
        """``call``, again after an emergency pysoem raised in its place (a pysoem without
        emergency callbacks): the emergency goes to the master log, the SDO is asked again."""
        emergency = getattr(self.soem, "Emergency", None)
        for _ in range(3):
            try:
                return call(*args, **kw)
            except Exception as e:
                if emergency is None or not isinstance(e, emergency):
                    raise
                self._emcy.append((position, _emergency(e)))
        return call(*args, **kw)

    def sdo_upload(
        self, position: int, index: int, subindex: int, complete_access: bool = False
    ) -> bytes:
        s = self._mailbox_slave(position, "upload", index, subindex)
        soem = self.soem
        errors = (soem.SdoError, soem.WkcError, soem.MailboxError, soem.PacketError)
        read = self._nogil(s.sdo_read)
        with self.mailbox_lock:
            if position in self._mailbox_dirty:
                self._forget_soem_errors(position)
            t0 = self._monotonic()
            try:
                try:
                    return bytes(
                        self._past_emergencies(position, read, index, subindex, ca=complete_access)
                    )
                except soem.PacketError as e:
                    if getattr(e, "error_code", None) != _PACKET_TOO_SMALL:
                        raise
                    return bytes(
                        self._past_emergencies(
                            position, read, index, subindex, _SDO_BIG, ca=complete_access
                        )
                    )
            except errors as e:
                waited = self._monotonic() - t0
                self._forget_soem_errors(position)
                self._mailbox_dirty.add(position)
                raise self._sdo_error(e, position, "upload", index, subindex, waited) from None

    def sdo_download(
        self, position: int, index: int, subindex: int, data: bytes, complete_access: bool = False
    ) -> None:
        s = self._mailbox_slave(position, "download", index, subindex)
        soem = self.soem
        errors = (soem.SdoError, soem.WkcError, soem.MailboxError, soem.PacketError)
        write = self._nogil(s.sdo_write)
        with self.mailbox_lock:
            if position in self._mailbox_dirty:
                self._forget_soem_errors(position)
            t0 = self._monotonic()
            try:
                self._past_emergencies(
                    position, write, index, subindex, bytes(data), ca=complete_access
                )
            except errors as e:
                waited = self._monotonic() - t0
                self._forget_soem_errors(position)
                self._mailbox_dirty.add(position)
                raise self._sdo_error(e, position, "download", index, subindex, waited) from None

    def _forget_soem_errors(self, position: int) -> None:
        """Empty the slave's read mailbox and SOEM's error list after a failed transfer.

        SOEM answers a mailbox error reply by reading the mailbox again until its timeout,
        asking the slave to repeat its last message each time the mailbox is empty: the
        same reply comes back every few ms (one error each), and may still wait in the
        mailbox when the timeout ends.  pysoem raises the first error it pops and leaves
        the rest; the next transfer, however healthy, would fail with them (and with the
        reply it reads from the mailbox first).  Done again before the slave's next
        transfer: a late frame of a slow slave may have put the reply back meanwhile."""
        self._mailbox_dirty.discard(position)
        receive = getattr(self.slaves[position], "mbx_receive", None)
        collect = getattr(self.master, "_collect_mailbox_errors", None)
        if receive is None or collect is None:  # an older pysoem (or a stand-in)
            return
        try:
            receive()  # (raises the stale reply it read, if any)
        except Exception as e:
            _log.debug("stale mailbox message: %s", e)
        try:
            left = collect()
        except Exception as e:  # (nothing to forget is worth failing the transfer for)
            _log.debug("pysoem error list: %s", e)
            return
        if left:
            counts: dict[str, int] = {}
            for x in left:
                what = _describe_soem_error(x, slave=False)
                counts[what] = counts.get(what, 0) + 1
            self.log(
                f"slave {position} ({self._name(position)}): after the failed SDO, SOEM also "
                "reported: "
                + "; ".join(f"{w} ({n} times)" if n > 1 else w for w, n in counts.items())
            )

    def _nogil(self, call: Callable[..., Any]) -> Callable[..., Any]:
        """``call`` letting go of the GIL while SOEM waits (pysoem >= 1.1: ``release_gil``),
        so the cycle thread runs during the transfer."""
        if not hasattr(self.master, "always_release_gil"):  # an older pysoem (or a stand-in)
            return call
        return lambda *a, **kw: call(*a, release_gil=True, **kw)

    # --- close ----------------------------------------------------------------------------
    def close(self) -> None:
        m, self.master = self.master, None
        self.mapped = False
        self.operational = False
        self.slaves, self._outs, self._ins = [], [], []
        self._pending_safeop.clear()
        self._op.clear()
        if self._switch_interval is not None:
            sys.setswitchinterval(self._switch_interval)
            self._switch_interval = None
        if m is not None:
            # an SDO another thread is waiting for ends first (by its answer or its timeout):
            # SOEM must not lose its socket under it
            held = self.mailbox_lock.acquire(timeout=2 * SDO_TIMEOUT_MS / 1000)
            try:
                m.close()
            except Exception as e:
                _log.debug("pysoem close: %s", e)
            finally:
                if held:
                    self.mailbox_lock.release()


def _describe_soem_error(e: Any, *, slave: bool = True) -> str:
    """A pysoem exception in words; ``slave``: led by SOEM's slave number (1-based)."""
    who = f"slave {getattr(e, 'slave_pos', '?')}: " if slave else ""
    abort = getattr(e, "abort_code", None)
    if abort is not None:
        return (
            f"{who}0x{getattr(e, 'index', 0):04X}:"
            f"{getattr(e, 'subindex', 0):02X} SDO abort 0x{int(abort):08X} "
            f"{getattr(e, 'desc', '')}"
        ).strip()
    code = getattr(e, "error_code", None)
    if code is None:
        return f"{who}{e}"
    desc = ""
    try:
        desc = str(e.desc)
    except Exception:
        desc = ""
    kind = {"MailboxError": "mailbox error", "PacketError": "packet error"}.get(
        type(e).__name__, "error"
    )
    return f"{who}{kind} {code} {desc}".strip()


def _emergency(e: Any) -> Emergency:
    """pysoem's emergency (error code, register, byte 1, words 2 and 3) as the emulated
    slaves give theirs (ETG.1000.6 5.6.4: 2 + 1 + 5 bytes)."""
    data = bytes([int(e.b1) & 0xFF]) + (int(e.w1) & 0xFFFF).to_bytes(2, "little")
    data += (int(e.w2) & 0xFFFF).to_bytes(2, "little")
    return Emergency(int(e.error_code) & 0xFFFF, int(e.error_reg) & 0xFF, data)
