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
passes.  Between SAFEOP and OP, and in OP, the cyclic frames run and their
working counters are checked against ``Cnt``.

An ENI written by gtecat has no register InitCmds; for those the replay
synthesises the commands TwinCAT generates for such a slave (state requests
and checks, EEPROM identity checks, station address, SMs and FMMUs from
``Mailbox``, ``ProcessData/SmN`` and ``Send``/``Recv``).
"""

from __future__ import annotations

import struct
import time
import xml.etree.ElementTree as ET
from dataclasses import dataclass, field
from pathlib import Path

from tests.gtecat.wire.rawmaster import NoAnswer, RawMaster, SdoAbortSeen

APWR, APRD, FPWR, FPRD, BRD, BWR = 2, 1, 5, 4, 7, 8
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
    cyclic: list[CyclicCmd]
    synthesised: bool = False


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
    cyclic = []
    for c in config.findall("Cyclic/Frame/Cmd"):
        addr = c.findtext("Addr")
        a = _int(addr) if addr is not None else None
        cnt = c.findtext("Cnt")
        cyclic.append(
            CyclicCmd(
                tuple(t.text or "" for t in c.findall("State")),
                _int(c.findtext("Cmd")),
                (a & 0xFFFF) if a is not None else _int(c.findtext("Adp")),
                (a >> 16) if a is not None else _int(c.findtext("Ado")),
                _int(c.findtext("DataLength")),
                _int(cnt) if cnt is not None else None,
            )
        )
    eni = Eni(path, master, slaves, cyclic)
    if not any(s.reg for s in slaves):
        _synthesise(eni, root)
    return eni


# --- what TwinCAT generates for a slave, for ENIs that carry no register InitCmds --------------
def _synthesise(eni: Eni, root: ET.Element) -> None:
    eni.synthesised = True
    config = root.find("Config")
    assert config is not None
    base = next((c.adp | c.ado << 16 for c in eni.cyclic if c.cmd in (10, 11, 12)), 0x10000000)
    for cfg, node in zip(eni.slaves, config.findall("Slave"), strict=True):
        pos, phys = cfg.position, cfg.phys_addr
        adp = (-pos) & 0xFFFF
        vendor = _int(node.findtext("Info/VendorId"))
        product = _int(node.findtext("Info/ProductCode"))

        def state(
            tr: str, st: int, addr_cmd: tuple[int, int], adp: int = adp, phys: int = phys
        ) -> list[RegCmd]:
            wr, rd = addr_cmd
            a = adp if wr == APWR else phys
            return [
                RegCmd((tr,), f"set device state {st}", wr, a, 0x0120, struct.pack("<H", st), 1, 3),
                RegCmd(
                    (tr,),
                    f"check device state {st}",
                    rd,
                    a,
                    0x0130,
                    bytes(2),
                    1,
                    3,
                    validate=(struct.pack("<H", st), b"\x1f\x00", 3000),
                ),
            ]

        cmds = state("IP", 1, (APWR, APRD))
        cmds += [
            RegCmd(("IP",), "assign EEPROM to ECAT", APWR, adp, 0x0500, b"\x00", 1),
            RegCmd(("IP",), "read vendor id", APWR, adp, 0x0502, bytes.fromhex("000108000000"), 1),
            RegCmd(
                ("IP",),
                "check vendor id",
                APRD,
                adp,
                0x0508,
                bytes(4),
                1,
                validate=(struct.pack("<I", vendor), None, 100),
            ),
            RegCmd(("IP",), "read product", APWR, adp, 0x0502, bytes.fromhex("00010a000000"), 1),
            RegCmd(
                ("IP",),
                "check product code",
                APRD,
                adp,
                0x0508,
                bytes(4),
                1,
                validate=(struct.pack("<I", product), None, 100),
            ),
            RegCmd(("IP",), "set physical address", APWR, adp, 0x0010, struct.pack("<H", phys), 1),
        ]
        if cfg.mailbox:
            s0, l0, s1, l1 = cfg.mailbox
            sm = struct.pack("<HHBBBB", s0, l0, 0x26, 0, 1, 0) + struct.pack(
                "<HHBBBB", s1, l1, 0x22, 0, 1, 0
            )
            cmds.append(RegCmd(("IP",), "set sm 0/1 (mailbox)", FPWR, phys, 0x0800, sm, 1))
        cmds += state("IP", 2, (FPWR, FPRD))
        pd = node.find("ProcessData")
        fmmu = 0
        for direction, tag in ((True, "Send"), (False, "Recv")):
            area = pd.find(tag) if pd is not None else None
            if area is None:
                continue
            bit_start, bits = _int(area.findtext("BitStart")), _int(area.findtext("BitLength"))
            if not bits:
                continue
            kind = "Outputs" if direction else "Inputs"
            sms = [c for c in (pd or []) if c.tag.startswith("Sm") and c.findtext("Type") == kind]
            if not sms:
                continue
            number = int(sms[0].tag[2:])
            start = _int(sms[0].findtext("StartAddress"))
            control = _int(sms[0].findtext("ControlByte"))
            nbytes = (bits + 7) // 8
            cmds.append(
                RegCmd(
                    ("PS",),
                    f"set sm {number} ({kind.lower()})",
                    FPWR,
                    phys,
                    0x0800 + 8 * number,
                    struct.pack("<HHBBBB", start, nbytes, control, 0, 1, 0),
                    1,
                )
            )
            lbit = bit_start % 8
            lbytes = (lbit + bits + 7) // 8
            logical = base + bit_start // 8
            cmds.append(
                RegCmd(
                    ("PS",),
                    f"set fmmu {fmmu} ({kind.lower()})",
                    FPWR,
                    phys,
                    0x0600 + 16 * fmmu,
                    struct.pack(
                        "<IHBBHBBB3x",
                        logical,
                        lbytes,
                        lbit,
                        (lbit + bits - 1) % 8,
                        start,
                        0,
                        2 if direction else 1,
                        1,
                    ),
                    1,
                )
            )
            fmmu += 1
        cmds += state("PS", 4, (FPWR, FPRD))
        cmds += state("SO", 8, (FPWR, FPRD))
        cfg.reg = cmds


# --- the replay ----------------------------------------------------------------------------------
class Replay:
    def __init__(self, master: RawMaster, eni: Eni) -> None:
        self.m = master
        self.eni = eni
        self.failures: list[str] = []
        self.commands = 0
        self.sdos = 0

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
                len(cmds),
            )
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
        cmds = [c for c in self.eni.cyclic if state in c.states]
        for n in range(cycles):
            for c in cmds:
                got = self.m.transact(c.cmd, c.adp, c.ado, bytes(c.length))
                if state == "OP" and c.cnt is not None and got.wkc != c.cnt:
                    self.fail(f"cycle {n}: cmd {c.cmd} wkc {got.wkc}, {c.cnt} expected")
                    return

    def states(self) -> list[tuple[int, int]]:
        return [self.m.state(s.phys_addr) for s in self.eni.slaves]
