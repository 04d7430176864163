"""Replay an ETG.2100 ENI the way TwinCAT does: its InitCmds word for word, per transition.

Read here with :mod:`xml.etree.ElementTree`, not with ``eni/`` (the replay must not
share a reader with the product): ``Config/Master/InitCmds``,
``Config/Slave/InitCmds`` (register commands: ``Cmd``, ``Adp``, ``Ado``,
``Data`` or ``DataLength``, ``Cnt`` the expected working counter, ``Retries``,
``Timeout``, ``Validate`` with ``Data``/``DataMask``/``Timeout``,
``BeforeSlave``), ``Config/Slave/Mailbox/CoE/InitCmds`` (SDO downloads and
uploads: ``Ccs``, ``Index``, ``SubIndex``, ``Data``, ``CompleteAccess``) and
``Config/Cyclic/Frame/Cmd``.

Per transition (IP, PS, SO) the master's ``BeforeSlave`` commands run first,
then each slave's commands in document order - its CoE commands go just before
the command that requests the transition's target state when the slave already
has a mailbox (PS, SO), after the whole list for IP (the mailbox starts in
PREOP) - then the master's other commands.  A command with ``Cnt`` is repeated
(``Retries``, within ``Timeout``) until the working counter matches; a
``Validate`` read is repeated until the masked data matches or its timeout
passes.  Between SAFEOP and OP, and in OP, the cyclic frames run - each ``Frame`` one
Ethernet frame of its ``Cmd`` datagrams, refused when no Ethernet frame could carry it - and
their working counters are checked against ``Cnt``.

Nothing is made up: a slave whose InitCmds do not request a transition's target
state is a failure (a replaying master would leave it where it is).
"""

from __future__ import annotations

import time
import xml.etree.ElementTree as ET
from dataclasses import dataclass, field
from pathlib import Path

from tests.gtecat.wire.rawmaster import FrameTooLong, NoAnswer, RawMaster, SdoAbortSeen

APWR, FPWR, BWR = 2, 5, 8  # ETG.1000.4 Table 9
_TARGET = {"I": 1, "P": 2, "B": 3, "S": 4, "O": 8}


def _int(text: str | None, default: int = 0) -> int:
    if text is None or not text.strip():
        return default
    t = text.strip()
    if t.lower().startswith("#x"):
        return int(t[2:], 16)
    return int(t, 0)


@dataclass
class RegCmd:
    transitions: tuple[str, ...]
    comment: str
    cmd: int
    adp: int
    ado: int
    data: bytes
    cnt: int | None = None
    retries: int = 0
    timeout_ms: int = 0
    validate: tuple[bytes, bytes | None, int] | None = None
    before_slave: bool = False


@dataclass
class CoeCmd:
    transitions: tuple[str, ...]
    comment: str
    upload: bool
    index: int
    subindex: int
    data: bytes
    complete_access: bool = False
    timeout_ms: int = 0


@dataclass
class SlaveCfg:
    name: str
    phys_addr: int
    position: int
    reg: list[RegCmd] = field(default_factory=list)
    coe: list[CoeCmd] = field(default_factory=list)
    mailbox: tuple[int, int, int, int] | None = None


@dataclass
class CyclicCmd:
    states: tuple[str, ...]
    cmd: int
    adp: int
    ado: int
    length: int
    cnt: int | None


@dataclass
class Eni:
    path: Path
    master: list[RegCmd]
    slaves: list[SlaveCfg]
    cyclic: list[list[CyclicCmd]]  #: per ``Frame``, its commands


def _reg(node: ET.Element) -> RegCmd:
    data_text = node.findtext("Data")
    data = bytes.fromhex(data_text) if data_text else bytes(_int(node.findtext("DataLength")))
    v = node.find("Validate")
    validate = None
    if v is not None:
        mask = v.findtext("DataMask")
        validate = (
            bytes.fromhex(v.findtext("Data") or ""),
            bytes.fromhex(mask) if mask else None,
            _int(v.findtext("Timeout")),
        )
    cnt = node.findtext("Cnt")
    return RegCmd(
        tuple(t.text or "" for t in node.findall("Transition")),
        node.findtext("Comment") or "",
        _int(node.findtext("Cmd")),
        _int(node.findtext("Adp")),
        _int(node.findtext("Ado")),
        data,
        _int(cnt) if cnt is not None else None,
        _int(node.findtext("Retries")),
        _int(node.findtext("Timeout")),
        validate,
        (node.findtext("BeforeSlave") or "").lower() in ("true", "1"),
    )


def _coe(node: ET.Element) -> CoeCmd:
    return CoeCmd(
        tuple(t.text or "" for t in node.findall("Transition")),
        node.findtext("Comment") or "",
        _int(node.findtext("Ccs"), 1) == 2,
        _int(node.findtext("Index")),
        _int(node.findtext("SubIndex")),
        bytes.fromhex(node.findtext("Data") or ""),
        (node.get("CompleteAccess") or "").lower() in ("1", "true"),
        _int(node.findtext("Timeout")),
    )


def parse(path: Path) -> Eni:
    root = ET.parse(path).getroot()
    config = root.find("Config")
    assert config is not None, f"{path}: no Config"
    master = [_reg(n) for n in config.findall("Master/InitCmds/InitCmd")]
    slaves = []
    for pos, s in enumerate(config.findall("Slave")):
        mbx = s.find("Mailbox")
        box = None
        if mbx is not None and mbx.find("Send/Start") is not None:
            box = (
                _int(mbx.findtext("Send/Start")),
                _int(mbx.findtext("Send/Length")),
                _int(mbx.findtext("Recv/Start")),
                _int(mbx.findtext("Recv/Length")),
            )
        slaves.append(
            SlaveCfg(
                s.findtext("Info/Name") or f"slave {pos}",
                _int(s.findtext("Info/PhysAddr"), 1001 + pos),
                pos,
                [_reg(n) for n in s.findall("InitCmds/InitCmd")],
                [_coe(n) for n in s.findall("Mailbox/CoE/InitCmds/InitCmd")],
                box,
            )
        )
    cyclic = [[_cyclic(c) for c in f.findall("Cmd")] for f in config.findall("Cyclic/Frame")]
    return Eni(path, master, slaves, cyclic)


def _cyclic(c: ET.Element) -> CyclicCmd:
    addr = c.findtext("Addr")
    a = _int(addr) if addr is not None else None
    cnt = c.findtext("Cnt")
    return CyclicCmd(
        tuple(t.text or "" for t in c.findall("State")),
        _int(c.findtext("Cmd")),
        (a & 0xFFFF) if a is not None else _int(c.findtext("Adp")),
        (a >> 16) if a is not None else _int(c.findtext("Ado")),
        _int(c.findtext("DataLength")),
        _int(cnt) if cnt is not None else None,
    )


# --- the replay ----------------------------------------------------------------------------------
class Replay:
    def __init__(self, master: RawMaster, eni: Eni) -> None:
        self.m = master
        self.eni = eni
        self.failures: list[str] = []
        self.commands = 0
        self.sdos = 0
        self.cyclic_frames = 0

    def fail(self, what: str) -> None:
        self.failures.append(what)

    def run(self, cycles: int = 100) -> list[str]:
        for tr in ("IP", "PS"):
            self.transition(tr)
        self.cyclic("SAFEOP", 5)
        self.transition("SO")
        self.cyclic("OP", cycles)
        return self.failures

    def transition(self, tr: str) -> None:
        target = _TARGET[tr[1]]
        for c in self.eni.master:
            if tr in c.transitions and c.before_slave:
                self.register(c, "master")
        for s in self.eni.slaves:
            cmds = [c for c in s.reg if tr in c.transitions]
            if tr == "IP":
                self.m.mbx_counter[s.phys_addr] = 0  # the mailbox starts anew
            split = next(
                (
                    k
                    for k, c in enumerate(cmds)
                    if c.ado == 0x0120
                    and c.cmd in (APWR, FPWR, BWR)
                    and c.data[:1]
                    and c.data[0] & 0x0F == target
                ),
                None,
            )
            if split is None:
                self.fail(f"{s.name}: no {tr} InitCmd requests state {target}")
                continue
            coe = [c for c in s.coe if tr in c.transitions]
            if tr[0] in "PSO":
                for c in cmds[:split]:
                    self.register(c, s.name)
                for c in coe:
                    self.sdo(s, c)
                for c in cmds[split:]:
                    self.register(c, s.name)
            else:
                for c in cmds:
                    self.register(c, s.name)
                for c in coe:
                    self.sdo(s, c)
        for c in self.eni.master:
            if tr in c.transitions and not c.before_slave:
                self.register(c, "master")

    def register(self, c: RegCmd, who: str) -> None:
        self.commands += 1
        deadline = time.monotonic() + max(c.timeout_ms, 200) / 1000
        attempts = 0
        while True:
            attempts += 1
            try:
                got = self.m.transact(c.cmd, c.adp, c.ado, c.data)
            except NoAnswer:
                self.fail(f"{who}: {c.comment!r}: no answer")
                return
            if c.cnt is None or got.wkc == c.cnt:
                break
            if attempts > c.retries and time.monotonic() > deadline:
                self.fail(f"{who}: {c.comment!r}: working counter {got.wkc}, {c.cnt} expected")
                return
            time.sleep(0.001)
        if c.validate is None:
            return
        want, mask, timeout_ms = c.validate
        end = time.monotonic() + max(timeout_ms, 100) / 1000

        def masked(data: bytes) -> bytes:
            m = mask if mask is not None else b"\xff" * len(want)
            return bytes(a & b for a, b in zip(data, m, strict=False))

        while masked(got.data) != masked(want):
            if time.monotonic() > end:
                self.fail(
                    f"{who}: {c.comment!r}: read {got.data.hex()}, {want.hex()} expected"
                    f" (mask {mask.hex() if mask else 'none'})"
                )
                return
            time.sleep(0.001)
            got = self.m.transact(c.cmd, c.adp, c.ado, c.data)

    def sdo(self, s: SlaveCfg, c: CoeCmd) -> None:
        self.sdos += 1
        if s.mailbox is None:
            self.fail(f"{s.name}: {c.comment!r}: CoE InitCmd for a slave without mailbox")
            return
        try:
            if c.upload:
                got = self.m.sdo_upload(s.phys_addr, s.mailbox, c.index, c.subindex)
                if c.data and got[: len(c.data)] != c.data:
                    self.fail(f"{s.name}: {c.comment!r}: uploaded {got.hex()}, {c.data.hex()}")
            else:
                self.m.sdo_download(
                    s.phys_addr, s.mailbox, c.index, c.subindex, c.data, c.complete_access
                )
        except SdoAbortSeen as err:
            self.fail(f"{s.name}: {c.comment!r} 0x{c.index:04X}:{c.subindex:02X}: {err}")
        except NoAnswer as err:
            self.fail(f"{s.name}: {c.comment!r}: {err}")

    def cyclic(self, state: str, cycles: int) -> None:
        """Each ``Frame`` as one Ethernet frame, its commands as its datagrams, every cycle."""
        frames = [[c for c in f if state in c.states] for f in self.eni.cyclic]
        frames = [f for f in frames if f]
        for n in range(cycles):
            for k, f in enumerate(frames):
                try:
                    got = self.m.transact_frame([(c.cmd, c.adp, c.ado, bytes(c.length)) for c in f])
                except FrameTooLong as err:
                    self.fail(f"frame {k}: {err}")
                    return
                self.cyclic_frames += 1
                for c, r in zip(f, got, strict=True):
                    if state == "OP" and c.cnt is not None and r.wkc != c.cnt:
                        self.fail(f"cycle {n} frame {k}: cmd {c.cmd} wkc {r.wkc}, {c.cnt} expected")
                        return

    def states(self) -> list[tuple[int, int]]:
        return [self.m.state(s.phys_addr) for s in self.eni.slaves]
