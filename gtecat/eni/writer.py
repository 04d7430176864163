"""Write an :class:`EniConfig` as ETG.2100 ENI XML (``EtherCATConfig``).

The file holds what :mod:`gtecat.eni.xml_reader` reads, in the element order of the
ETG.2100 schema, so ``read(write(cfg)) == cfg`` for every configuration the
topology builder makes (source and lines aside):

* ``Config/Master/Info``;
* per slave ``Info`` (name, addresses, identity), ``ProcessData`` with
  ``Send``/``Recv`` (bit areas in the zero-based logical images), one ``SmN``
  per sync manager with its ``Pdo`` assignment list, the assigned
  ``TxPdo``/``RxPdo`` with their entries (``Sm`` attribute set), and
  ``Mailbox/CoE/InitCmds`` for slaves with a mailbox;
* per slave ``InitCmds``: the register commands a master that replays the file
  word for word (TwinCAT, acontis EC-Master) runs per transition - state
  requests and checks, identity, station address, SMs, FMMUs
  (:mod:`gtecat.eni.register_cmds`) - and the master's ``BeforeSlave`` commands in
  ``Config/Master/InitCmds``; the readers ignore them (they follow from the rest);
* ``Cyclic`` (cycle time in microseconds; an LWR of the output image and an LRD of the input
  image, at separate logical addresses: :func:`gtecat.eni.register_cmds.logical_bases`);
* ``ProcessImage`` with ``ByteSize`` and one ``Variable`` per mapped entry.
"""

from __future__ import annotations

import os
import xml.etree.ElementTree as ET
from collections.abc import Iterable
from pathlib import Path

from .model import Direction, EniConfig, InitCmd, Pdo, Slave, Variable
from .register_cmds import (
    MAILBOX,
    SM_DEFAULT,
    Command,
    RegisterCmd,
    has_mailbox,
    logical_bases,
    master_cmds,
    slave_cmds,
    sm_maps,
    sm_of,
)


def _hex(v: int, width: int = 4) -> str:
    return f"#x{v:0{width}x}"


def _sub(parent: ET.Element, tag: str, text: object | None = None, **attrib: str) -> ET.Element:
    el = ET.SubElement(parent, tag, attrib)
    if text is not None:
        el.text = str(text)
    return el


def _slave_variables(cfg: EniConfig) -> list[Variable]:
    """The ProcessImage variables to write: the model's own, else one per stated entry."""
    if cfg.variables:
        return list(cfg.variables)
    out: list[Variable] = []
    for d in (Direction.IN, Direction.OUT):
        for s in cfg.slaves:
            for p in s.rx_pdos if d == Direction.OUT else s.tx_pdos:
                for e in p.entries:
                    if not e.is_padding and e.logical_bit is not None:
                        out.append(
                            Variable(
                                f"{s.name}.{p.name}.{e.name}",
                                d,
                                e.logical_bit,
                                e.bit_len,
                                e.data_type,
                            )
                        )
    return out


def _pdo_xml(parent: ET.Element, p: Pdo, sm: int) -> None:
    el = _sub(
        parent,
        "RxPdo" if p.direction == Direction.OUT else "TxPdo",
        Fixed="1" if p.fixed else "0",
        Sm=str(sm),
    )
    _sub(el, "Index", _hex(p.index))
    _sub(el, "Name", p.name)
    for e in p.entries:
        ent = _sub(el, "Entry")
        _sub(ent, "Index", _hex(e.index))
        if not e.is_padding or e.subindex:
            _sub(ent, "SubIndex", e.subindex)
        _sub(ent, "BitLen", e.bit_len)
        if e.name:
            _sub(ent, "Name", e.name)
        if e.data_type:
            _sub(ent, "DataType", e.data_type)


def _process_data(parent: ET.Element, s: Slave) -> None:
    pd = _sub(parent, "ProcessData")
    for tag, area in (("Send", s.outputs), ("Recv", s.inputs)):
        if area is not None:
            a = _sub(pd, tag)
            _sub(a, "BitStart", area.bit_start)
            _sub(a, "BitLength", area.bit_len)
    for m in sm_maps(s):
        smel = _sub(pd, f"Sm{m.number}")
        _sub(smel, "Type", "Outputs" if m.direction == Direction.OUT else "Inputs")
        _sub(smel, "DefaultSize", m.length)
        start, control = SM_DEFAULT[m.direction]
        _sub(smel, "StartAddress", _hex(start))
        _sub(smel, "ControlByte", _hex(control, 2))
        _sub(smel, "Enable", 1)
        for p in m.pdos:
            _sub(smel, "Pdo", _hex(p.index))
    for p in s.tx_pdos:
        _pdo_xml(pd, p, sm_of(p))
    for p in s.rx_pdos:
        _pdo_xml(pd, p, sm_of(p))


def _init_cmd(parent: ET.Element, c: InitCmd) -> None:
    attrs = {"Fixed": "1"}
    if c.complete_access:
        attrs["CompleteAccess"] = "1"
    el = _sub(parent, "InitCmd", **attrs)
    for t in c.transitions:
        _sub(el, "Transition", t)
    if c.comment:
        _sub(el, "Comment", c.comment)
    _sub(el, "Timeout", c.timeout_ms)
    _sub(el, "Ccs", 2 if c.upload else 1)
    _sub(el, "Index", _hex(c.index))
    _sub(el, "SubIndex", c.subindex)
    if c.data:
        _sub(el, "Data", c.data.hex())


def _mailbox(parent: ET.Element, s: Slave) -> None:
    mb = _sub(parent, "Mailbox", DataLinkLayer="true")
    for tag, (start, length) in zip(("Send", "Recv"), MAILBOX, strict=True):
        el = _sub(mb, tag)
        _sub(el, "Start", _hex(start))
        _sub(el, "Length", length)
    _sub(mb, "Protocol", "CoE")
    coe = _sub(mb, "CoE")
    if s.init_cmds:
        cmds = _sub(coe, "InitCmds")
        for c in s.init_cmds:
            _init_cmd(cmds, c)


def _register_cmds(parent: ET.Element, cmds: Iterable[RegisterCmd]) -> None:
    """``InitCmds`` in the element order of ETG.2100 ``EcatCmdType``."""
    el = _sub(parent, "InitCmds")
    for c in cmds:
        ic = _sub(el, "InitCmd")
        for t in c.transitions:
            _sub(ic, "Transition", t)
        if c.before_slave:
            _sub(ic, "BeforeSlave", "true")
        _sub(ic, "Comment", c.comment)
        if c.cycle:
            _sub(ic, "Requires", "cycle")
        _sub(ic, "Cmd", int(c.cmd))
        _sub(ic, "Adp", c.adp)
        _sub(ic, "Ado", c.ado)  # decimal, as TwinCAT and EC-Engineer write Cmd/Adp/Ado
        if isinstance(c.data, int):
            _sub(ic, "DataLength", c.data)
        else:
            _sub(ic, "Data", c.data.hex())
        if c.cnt is not None:
            _sub(ic, "Cnt", c.cnt)
        _sub(ic, "Retries", c.retries)
        if c.timeout_ms is not None:
            _sub(ic, "Timeout", c.timeout_ms)
        if c.validate is not None:
            v = _sub(ic, "Validate")
            _sub(v, "Data", c.validate.data.hex())
            if c.validate.mask is not None:
                _sub(v, "DataMask", c.validate.mask.hex())
            _sub(v, "Timeout", c.validate.timeout_ms)


def _wkc(slaves: Iterable[Slave], direction: Direction) -> int:
    """Expected working counter of the LWR (outputs) or LRD (inputs): +1 per slave that
    takes or gives data in that direction (ETG.1000.4 5.4)."""
    return sum(1 for s in slaves if (s.outputs if direction == Direction.OUT else s.inputs))


def to_xml(cfg: EniConfig) -> ET.Element:
    root = ET.Element(
        "EtherCATConfig",
        {
            "Version": "1.3",
            "xmlns:xsi": "http://www.w3.org/2001/XMLSchema-instance",
            "xsi:noNamespaceSchemaLocation": "EtherCATConfig.xsd",
        },
    )
    config = _sub(root, "Config")
    master = _sub(config, "Master")
    info = _sub(master, "Info")
    _sub(info, "Name", cfg.master_name or "gtecat")
    _sub(info, "Destination", "ffffffffffff")
    _sub(info, "Source", "000000000000")
    _sub(info, "EtherType", "a488")
    if cfg.slaves:
        _register_cmds(master, master_cmds(len(cfg.slaves)))
    bases = logical_bases(cfg.outputs_bytes)
    for s in cfg.slaves:
        sel = _sub(config, "Slave")
        si = _sub(sel, "Info")
        _sub(si, "Name", s.name)
        _sub(si, "PhysAddr", s.phys_addr)
        _sub(si, "AutoIncAddr", s.auto_inc_addr)
        _sub(si, "VendorId", _hex(s.identity.vendor_id, 8))
        _sub(si, "ProductCode", _hex(s.identity.product_code, 8))
        _sub(si, "RevisionNo", _hex(s.identity.revision_no, 8))
        _sub(si, "SerialNo", s.identity.serial_no)
        if s.rx_pdos or s.tx_pdos or s.outputs or s.inputs:
            _process_data(sel, s)
        if has_mailbox(s):
            _mailbox(sel, s)
        _register_cmds(sel, slave_cmds(s, bases))
    if cfg.cycle_time_ns is not None:
        cyc = _sub(config, "Cyclic")
        us = cfg.cycle_time_ns / 1000
        _sub(cyc, "CycleTime", int(us) if us == int(us) else us)
        frame = _sub(cyc, "Frame")
        for direction, command, size, comment in (
            (Direction.OUT, Command.LWR, cfg.outputs_bytes, "outputs"),
            (Direction.IN, Command.LRD, cfg.inputs_bytes, "inputs"),
        ):
            if not size:
                continue
            cmd = _sub(frame, "Cmd")
            _sub(cmd, "State", "SAFEOP")
            _sub(cmd, "State", "OP")
            _sub(cmd, "Comment", f"process data {comment}")
            _sub(cmd, "Cmd", int(command))
            _sub(cmd, "Addr", bases[direction])
            _sub(cmd, "DataLength", size)
            _sub(cmd, "Cnt", _wkc(cfg.slaves, direction))
            _sub(cmd, "InputOffs", 0)
            _sub(cmd, "OutputOffs", 0)
    pi = _sub(config, "ProcessImage")
    variables = _slave_variables(cfg)
    for tag, d, size in (
        ("Inputs", Direction.IN, cfg.inputs_bytes),
        ("Outputs", Direction.OUT, cfg.outputs_bytes),
    ):
        part = _sub(pi, tag)
        _sub(part, "ByteSize", size)
        for v in variables:
            if v.direction != d:
                continue
            ve = _sub(part, "Variable")
            _sub(ve, "Name", v.name)
            if v.data_type:
                _sub(ve, "DataType", v.data_type)
            _sub(ve, "BitSize", v.bit_size)
            _sub(ve, "BitOffs", v.bit_offset)
    return root


def write_eni(cfg: EniConfig) -> str:
    """The ENI XML text of ``cfg`` (UTF-8 declared, two-space indented)."""
    root = to_xml(cfg)
    ET.indent(root, space="  ")
    body = ET.tostring(root, encoding="unicode")
    return '<?xml version="1.0" encoding="utf-8"?>\n<!-- written by gtecat -->\n' + body + "\n"


def write_eni_file(cfg: EniConfig, path: str | os.PathLike[str]) -> None:
    Path(path).write_text(write_eni(cfg), encoding="utf-8")
