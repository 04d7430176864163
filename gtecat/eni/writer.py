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
  image, at separate logical addresses: :func:`gtecat.eni.register_cmds.logical_bases`), in
  one ``Frame``, or cut into several where they would not fit one Ethernet frame (1,498
  bytes of EtherCAT: :mod:`gtecat.eni.cyclic`);
* ``ProcessImage`` with ``ByteSize`` and one ``Variable`` per mapped entry.

The text is written while it is made, element by element, laid out as
``xml.etree.ElementTree.indent`` lays out a tree (two spaces a level, ``<Tag />`` for an
empty element): a bus of 64 535 drives is 1.3 GB of XML, which no tree of it should have to
hold, so the writer keeps only the names of the elements still open.
"""

from __future__ import annotations

import os
import stat
from collections.abc import Callable, Iterable
from io import StringIO
from pathlib import Path
from typing import Protocol

from .cyclic import cyclic_frames
from .model import Direction, EniConfig, InitCmd, Pdo, Slave, Variable
from .register_cmds import (
    KIND,
    MAILBOX,
    SM_DEFAULT,
    RegisterCmd,
    has_mailbox,
    logical_bases,
    master_cmds,
    slave_cmds,
    sm_maps,
    sm_of,
)

HEADER = '<?xml version="1.0" encoding="utf-8"?>\n<!-- written by gtecat -->\n'
_ROOT_ATTRS = {
    "Version": "1.3",
    "xmlns:xsi": "http://www.w3.org/2001/XMLSchema-instance",
    "xsi:noNamespaceSchemaLocation": "EtherCATConfig.xsd",
}


class TextSink(Protocol):
    def write(self, text: str, /) -> object: ...


def _hex(v: int, width: int = 4) -> str:
    return f"#x{v:0{width}x}"


def _text(value: object) -> str:
    """Character data escaped as XML 1.0 section 2.4 requires (ElementTree's escaping)."""
    text = str(value)
    if "&" in text:
        text = text.replace("&", "&amp;")
    if "<" in text:
        text = text.replace("<", "&lt;")
    if ">" in text:
        text = text.replace(">", "&gt;")
    return text


def _attr(value: str) -> str:
    """An attribute value escaped for double quotes (ElementTree's escaping, white space kept)."""
    text = _text(value)
    for c, ref in (('"', "&quot;"), ("\r", "&#13;"), ("\n", "&#10;"), ("\t", "&#09;")):
        if c in text:
            text = text.replace(c, ref)
    return text


#: the line break and indentation before an element at each depth
_INDENT = ["\n" + "  " * k for k in range(16)]


class XmlOut:
    """Indented XML written as it is made: ``open``/``close`` an element with children,
    ``leaf`` one with only text.  Text collects in a list that :meth:`flush` hands to
    ``write`` (the writer flushes after each slave and every few hundred variables)."""

    __slots__ = ("_buf", "_indent", "_open", "_pending", "_write")

    def __init__(self, write: Callable[[str], object]) -> None:
        self._write = write
        self._buf: list[str] = []
        self._open: list[str] = []
        self._indent = _INDENT[0]  # before a child of the innermost open element
        self._pending = False  # the last start tag still lacks its ">" (no child yet)

    def open(self, tag: str, **attrib: str) -> None:
        buf = self._buf
        if self._pending:
            buf.append(">")
        attrs = "".join(f' {k}="{_attr(v)}"' for k, v in attrib.items()) if attrib else ""
        buf.append(f"{self._indent if self._open else ''}<{tag}{attrs}")
        self._open.append(tag)
        self._indent = _INDENT[len(self._open)]
        self._pending = True

    def leaf(self, tag: str, text: object = None) -> None:
        """An element holding ``text`` only (``<Tag />`` for none); an ``int`` as it is,
        anything else as its escaped ``str``. (A few hundred of these make a slave.)"""
        buf = self._buf
        if self._pending:
            buf.append(">")
            self._pending = False
        if text is None or text == "":
            buf.append(f"{self._indent}<{tag} />")
        elif type(text) is int:
            buf.append(f"{self._indent}<{tag}>{text}</{tag}>")
        else:
            buf.append(f"{self._indent}<{tag}>{_text(text)}</{tag}>")

    def close(self) -> None:
        tag = self._open.pop()
        self._indent = _INDENT[len(self._open)]
        if self._pending:
            self._buf.append(" />")
            self._pending = False
        else:
            self._buf.append(f"{self._indent}</{tag}>")

    def flush(self) -> None:
        if self._buf:
            self._write("".join(self._buf))
            self._buf.clear()


def _slave_variables(cfg: EniConfig) -> Iterable[Variable]:
    """The ProcessImage variables to write: the model's own, else one per stated entry."""
    if cfg.variables:
        return cfg.variables
    return _entry_variables(cfg)


def _entry_variables(cfg: EniConfig) -> Iterable[Variable]:
    for d in (Direction.IN, Direction.OUT):
        for s in cfg.slaves:
            for p in s.rx_pdos if d == Direction.OUT else s.tx_pdos:
                for e in p.entries:
                    if not e.is_padding and e.logical_bit is not None:
                        yield Variable(
                            f"{s.name}.{p.name}.{e.name}", d, e.logical_bit, e.bit_len, e.data_type
                        )


def _pdo_xml(x: XmlOut, p: Pdo, sm: int) -> None:
    x.open(
        "RxPdo" if p.direction == Direction.OUT else "TxPdo",
        Fixed="1" if p.fixed else "0",
        Sm=str(sm),
    )
    x.leaf("Index", _hex(p.index))
    x.leaf("Name", p.name)
    for e in p.entries:
        x.open("Entry")
        x.leaf("Index", _hex(e.index))
        if not e.is_padding or e.subindex:
            x.leaf("SubIndex", e.subindex)
        x.leaf("BitLen", e.bit_len)
        if e.name:
            x.leaf("Name", e.name)
        if e.data_type:
            x.leaf("DataType", e.data_type)
        x.close()
    x.close()


def _process_data(x: XmlOut, s: Slave) -> None:
    x.open("ProcessData")
    for tag, area in (("Send", s.outputs), ("Recv", s.inputs)):
        if area is not None:
            x.open(tag)
            x.leaf("BitStart", area.bit_start)
            x.leaf("BitLength", area.bit_len)
            x.close()
    for m in sm_maps(s):
        x.open(f"Sm{m.number}")
        x.leaf("Type", "Outputs" if m.direction == Direction.OUT else "Inputs")
        x.leaf("DefaultSize", m.length)
        start, control = SM_DEFAULT[m.direction]
        x.leaf("StartAddress", _hex(start))
        x.leaf("ControlByte", _hex(control, 2))
        x.leaf("Enable", 1)
        for p in m.pdos:
            x.leaf("Pdo", _hex(p.index))
        x.close()
    for p in s.tx_pdos:
        _pdo_xml(x, p, sm_of(p))
    for p in s.rx_pdos:
        _pdo_xml(x, p, sm_of(p))
    x.close()


def _init_cmd(x: XmlOut, c: InitCmd) -> None:
    if c.complete_access:
        x.open("InitCmd", Fixed="1", CompleteAccess="1")
    else:
        x.open("InitCmd", Fixed="1")
    for t in c.transitions:
        x.leaf("Transition", t)
    if c.comment:
        x.leaf("Comment", c.comment)
    x.leaf("Timeout", c.timeout_ms)
    x.leaf("Ccs", 2 if c.upload else 1)
    x.leaf("Index", _hex(c.index))
    x.leaf("SubIndex", c.subindex)
    if c.data:
        x.leaf("Data", c.data.hex())
    x.close()


def _mailbox(x: XmlOut, s: Slave) -> None:
    x.open("Mailbox", DataLinkLayer="true")
    for tag, (start, length) in zip(("Send", "Recv"), MAILBOX, strict=True):
        x.open(tag)
        x.leaf("Start", _hex(start))
        x.leaf("Length", length)
        x.close()
    x.leaf("Protocol", "CoE")
    x.open("CoE")
    if s.init_cmds:
        x.open("InitCmds")
        for c in s.init_cmds:
            _init_cmd(x, c)
        x.close()
    x.close()
    x.close()


def _register_cmds(x: XmlOut, cmds: Iterable[RegisterCmd]) -> None:
    """``InitCmds`` in the element order of ETG.2100 ``EcatCmdType``."""
    x.open("InitCmds")
    for c in cmds:
        x.open("InitCmd")
        for t in c.transitions:
            x.leaf("Transition", t)
        if c.before_slave:
            x.leaf("BeforeSlave", "true")
        x.leaf("Comment", c.comment)
        if c.cycle:
            x.leaf("Requires", "cycle")
        x.leaf("Cmd", int(c.cmd))
        x.leaf("Adp", c.adp)
        x.leaf("Ado", c.ado)  # decimal, as TwinCAT and EC-Engineer write Cmd/Adp/Ado
        if isinstance(c.data, int):
            x.leaf("DataLength", c.data)
        else:
            x.leaf("Data", c.data.hex())
        if c.cnt is not None:
            x.leaf("Cnt", c.cnt)
        x.leaf("Retries", c.retries)
        if c.timeout_ms is not None:
            x.leaf("Timeout", c.timeout_ms)
        if c.validate is not None:
            x.open("Validate")
            x.leaf("Data", c.validate.data.hex())
            if c.validate.mask is not None:
                x.leaf("DataMask", c.validate.mask.hex())
            x.leaf("Timeout", c.validate.timeout_ms)
            x.close()
        x.close()
    x.close()


def _slave(x: XmlOut, s: Slave, bases: dict[Direction, int]) -> None:
    x.open("Slave")
    x.open("Info")
    x.leaf("Name", s.name)
    x.leaf("PhysAddr", s.phys_addr)
    x.leaf("AutoIncAddr", s.auto_inc_addr)
    x.leaf("VendorId", _hex(s.identity.vendor_id, 8))
    x.leaf("ProductCode", _hex(s.identity.product_code, 8))
    x.leaf("RevisionNo", _hex(s.identity.revision_no, 8))
    x.leaf("SerialNo", s.identity.serial_no)
    x.close()
    if s.rx_pdos or s.tx_pdos or s.outputs or s.inputs:
        _process_data(x, s)
    if has_mailbox(s):
        _mailbox(x, s)
    _register_cmds(x, slave_cmds(s, bases))
    x.close()


def _cyclic(x: XmlOut, cfg: EniConfig, bases: dict[Direction, int]) -> None:
    assert cfg.cycle_time_ns is not None
    x.open("Cyclic")
    us = cfg.cycle_time_ns / 1000
    x.leaf("CycleTime", int(us) if us == int(us) else us)
    size = {Direction.OUT: cfg.outputs_bytes, Direction.IN: cfg.inputs_bytes}
    for frame in cyclic_frames(cfg, bases) or [[]]:  # (no process data: an empty Frame)
        x.open("Frame")
        for c in frame:
            kind = KIND[c.direction]
            x.open("Cmd")
            x.leaf("State", "SAFEOP")
            x.leaf("State", "OP")
            if c.length == size[c.direction]:
                x.leaf("Comment", f"process data {kind}")
            else:
                last = c.offset + c.length - 1
                x.leaf("Comment", f"process data {kind} {c.offset}..{last}")
            x.leaf("Cmd", int(c.command))
            x.leaf("Addr", c.address)
            x.leaf("DataLength", c.length)
            x.leaf("Cnt", c.wkc)
            x.leaf("InputOffs", c.offset)
            x.leaf("OutputOffs", c.offset)
            x.close()
        x.close()
    x.close()


#: ProcessImage variables written between two flushes
_VARIABLES_PER_FLUSH = 128


def _process_image(x: XmlOut, cfg: EniConfig) -> None:
    x.open("ProcessImage")
    for tag, d, size in (
        ("Inputs", Direction.IN, cfg.inputs_bytes),
        ("Outputs", Direction.OUT, cfg.outputs_bytes),
    ):
        x.open(tag)
        x.leaf("ByteSize", size)
        k = 0
        for v in _slave_variables(cfg):
            if v.direction != d:
                continue
            x.open("Variable")
            x.leaf("Name", v.name)
            if v.data_type:
                x.leaf("DataType", v.data_type)
            x.leaf("BitSize", v.bit_size)
            x.leaf("BitOffs", v.bit_offset)
            x.close()
            k += 1
            if k % _VARIABLES_PER_FLUSH == 0:
                x.flush()
        x.close()
    x.close()


def write_eni_to(cfg: EniConfig, out: TextSink) -> None:
    """Write the ENI XML text of ``cfg`` to ``out`` (a text file or stream), one slave at a
    time: what the writer holds besides ``cfg`` does not grow with the bus."""
    out.write(HEADER)
    x = XmlOut(out.write)
    x.open("EtherCATConfig", **_ROOT_ATTRS)
    x.open("Config")
    x.open("Master")
    x.open("Info")
    x.leaf("Name", cfg.master_name or "gtecat")
    x.leaf("Destination", "ffffffffffff")
    x.leaf("Source", "000000000000")
    x.leaf("EtherType", "a488")
    x.close()
    if cfg.slaves:
        _register_cmds(x, master_cmds(len(cfg.slaves)))
    x.close()
    bases = logical_bases(cfg.outputs_bytes)
    for s in cfg.slaves:
        _slave(x, s, bases)
        x.flush()
    if cfg.cycle_time_ns is not None:
        _cyclic(x, cfg, bases)
    _process_image(x, cfg)
    x.close()
    x.close()
    x.flush()
    out.write("\n")


def write_eni(cfg: EniConfig) -> str:
    """The ENI XML text of ``cfg`` (UTF-8 declared, two-space indented)."""
    out = StringIO()
    write_eni_to(cfg, out)
    return out.getvalue()


def write_eni_file(cfg: EniConfig, path: str | os.PathLike[str]) -> None:
    """Write ``cfg`` to ``path`` as it is made; a regular file left half-written by an error
    is removed (a cut ENI is never well-formed XML, and no reader should meet one)."""
    p = Path(path)
    with p.open("w", encoding="utf-8") as f:
        try:
            write_eni_to(cfg, f)
        except BaseException:
            if stat.S_ISREG(os.fstat(f.fileno()).st_mode):
                p.unlink(missing_ok=True)
            raise
