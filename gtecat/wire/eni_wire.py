"""What an ETG.2100 ENI says about the slaves' wire side, for their SII on ``gtecat serve``.

The configuration model (:mod:`gtecat.eni.model`) keeps what the process image needs.
A slave on the wire must also look like the real device to a master that reads
its SII rather than the ENI (SOEM, KickCAT, ebpfcat): the sync managers where
the device has them (an EL2008's output SM is the digital output register
0F00h, an EL1809's inputs are SM0, an EL4002's SM3 sits at 1180h), the mailbox
where the ENI puts it, and the product it is.  This module reads those facts
from the ENI's ``ProcessData/SmN`` (ETG.2100: ``Type``, ``StartAddress``,
``ControlByte``, ``Enable``), ``Mailbox/Send|Recv`` (``Start``, ``Length``) and
``Info/ProductRevision``, and :func:`sii_for` applies them to the SII the slave
would otherwise get (:func:`gtecat.drives.esc.sii.sii_info_for`).

A Googol INI file states none of it: its slaves keep the default layout.
"""

from __future__ import annotations

import dataclasses
import re
from dataclasses import dataclass
from pathlib import Path

from gtecat.drives.esc.sii import (
    SM_CONTROL_MBX_IN,
    SM_CONTROL_MBX_OUT,
    SiiInfo,
    SmConfig,
    SmType,
    sii_info_for,
)
from gtecat.drives.slave import VirtualSlave
from gtecat.eni.model import Direction
from gtecat.eni.numbers import parse_int
from gtecat.eni.reader import detect_format
from gtecat.eni.xmltree import Node, parse_xml

_SM_TYPES = {"outputs": SmType.OUTPUTS, "inputs": SmType.INPUTS}


@dataclass(frozen=True, slots=True)
class EniSm:
    """One ``ProcessData/SmN`` element."""

    number: int
    type: SmType
    start: int
    control: int
    enable: bool


@dataclass(frozen=True, slots=True)
class SlaveWire:
    """The wire facts the ENI states for one slave (None where it states nothing)."""

    name: str
    product: str
    sms: tuple[EniSm, ...] = ()
    mailbox_out: tuple[int, int] | None = None  # (start, length), master -> slave
    mailbox_in: tuple[int, int] | None = None


def product_name(name: str, product_revision: str | None) -> str:
    """What the device calls itself in 1008h: ``EL2008`` for ``EL2008-0000-0018`` or
    ``Term 2 (EL2008)``, else the ENI's name of the slave."""
    if product_revision:
        return product_revision.split("-")[0].strip() or name
    found = re.search(r"\(([^()]+)\)\s*$", name)
    return found.group(1).strip() if found else name


def _int(node: Node, tag: str) -> int | None:
    text = node.findtext(tag)
    return None if text is None or not text else parse_int(text)


def _slave(node: Node) -> SlaveWire:
    name = node.findtext("Info/Name") or ""
    sms = []
    pd = node.find("ProcessData")
    for child in pd.children if pd is not None else ():
        m = re.fullmatch(r"Sm(\d+)", child.tag)
        kind = _SM_TYPES.get((child.findtext("Type") or "").lower())
        start = _int(child, "StartAddress")
        if m is None or kind is None or start is None:
            continue
        sms.append(
            EniSm(
                int(m.group(1)),
                kind,
                start,
                _int(child, "ControlByte") or 0,
                bool(_int(child, "Enable") or 0),
            )
        )
    mbx = node.find("Mailbox")
    out = inp = None
    if mbx is not None:
        s0, l0 = _int(mbx, "Send/Start"), _int(mbx, "Send/Length")
        s1, l1 = _int(mbx, "Recv/Start"), _int(mbx, "Recv/Length")
        if None not in (s0, l0, s1, l1):
            out, inp = (s0, l0), (s1, l1)
    return SlaveWire(
        name,
        product_name(name, node.findtext("Info/ProductRevision")),
        tuple(sms),
        out,  # type: ignore[arg-type]
        inp,  # type: ignore[arg-type]
    )


def read_wire(path: str | Path) -> list[SlaveWire] | None:
    """Per slave in bus order, what the ENI says; None for a file that is not ETG.2100 XML."""
    data = Path(path).read_bytes()
    if detect_format(data) != "xml":
        return None
    root = parse_xml(data, str(path))
    return [_slave(s) for s in root.findall("Config/Slave")]


def _sm_length(slave: VirtualSlave, sm: EniSm, sms: tuple[EniSm, ...]) -> int:
    """Bytes of one process-data SM: the PDOs assigned to it, else the whole direction."""
    direction = Direction.OUT if sm.type == SmType.OUTPUTS else Direction.IN
    pdos = getattr(slave, "rx_pdos" if direction == Direction.OUT else "tx_pdos", ()) or ()
    rx_bits, tx_bits = slave.pdo_sizes()
    total = rx_bits if direction == Direction.OUT else tx_bits
    same = [s for s in sms if s.type == sm.type and s.enable]
    if len(same) > 1 and any(p.sm is not None for p in pdos):
        total = sum(p.bit_len for p in pdos if p.sm == sm.number)
    elif same and same[0] is not sm:
        total = 0  # one direction, one buffer: the first enabled SM of the type carries it
    return (total + 7) // 8 if sm.enable else 0


def sii_for(slave: VirtualSlave, wire: SlaveWire | None) -> SiiInfo:
    """The slave's SII with the SM layout, mailbox and name the ENI states.

    Also makes the slave's SDO server segment to the ENI's mailbox size and its
    1008h name the product.
    """
    sdo = getattr(slave, "sdo", None)
    if wire is not None and wire.mailbox_out and wire.mailbox_in and sdo is not None:
        sdo.mailbox_size = min(wire.mailbox_out[1], wire.mailbox_in[1])
    if wire is not None:
        od = getattr(slave, "od", None)
        name = od.find(0x1008, 0) if od is not None else None
        if name is not None and name.getter is None:
            name.value = wire.product
    info = sii_info_for(slave)
    if wire is None or not (wire.sms or wire.mailbox_out):
        return info
    by_number: dict[int, SmConfig] = {}
    if info.has_mailbox:
        out = wire.mailbox_out or info.rx_mailbox
        inp = wire.mailbox_in or info.tx_mailbox
        by_number[0] = SmConfig(out[0], out[1], SM_CONTROL_MBX_OUT, 1, SmType.MAILBOX_OUT)
        by_number[1] = SmConfig(inp[0], inp[1], SM_CONTROL_MBX_IN, 1, SmType.MAILBOX_IN)
    if wire.sms:
        for sm in wire.sms:
            by_number[sm.number] = SmConfig(
                sm.start, _sm_length(slave, sm, wire.sms), sm.control, int(sm.enable), sm.type
            )
    else:  # the ENI places the mailbox only: process data SMs as the default puts them
        for sm in info.sync_managers:
            if sm.type in (SmType.OUTPUTS, SmType.INPUTS):
                by_number[max(by_number, default=-1) + 1] = sm
    unused = SmConfig(0, 0, 0, 0, SmType.UNUSED)
    layout = tuple(by_number.get(n, unused) for n in range(max(by_number) + 1))
    return dataclasses.replace(
        info,
        sync_managers=layout,
        rx_mailbox=(by_number[0].start, by_number[0].length) if info.has_mailbox else (0, 0),
        tx_mailbox=(by_number[1].start, by_number[1].length) if info.has_mailbox else (0, 0),
    )
