"""ETG.2100 ENI XML (``EtherCATConfig``) -> :class:`gtecat.eni.model.EniConfig`.

What is read, per ETG.2100 (EtherCAT Network Information) as TwinCAT, acontis
EC-Engineer and Elmo write it:

* ``Config/Slave/Info``: name, addresses, identity (vendor id and product code
  are required);
* ``Slave/ProcessData``: ``Send``/``Recv`` (the slave's bit area in the output /
  input logical image, zero-based or frame-relative, taken as written), the
  sync managers ``SmN`` with their ``Pdo`` assignment lists, and the
  ``RxPdo``/``TxPdo`` descriptions.  Only PDOs assigned to a sync manager (in a
  ``SmN/Pdo`` list or by an ``Sm`` attribute) count; the others are
  alternatives the tool offered.  Where an SM has a list, the list decides
  (an ``Sm`` attribute copied from the ESI onto an unlisted alternative does
  not).  Direction comes from RxPdo (outputs) / TxPdo (inputs), never from
  the SM number (terminals without mailbox put process data on SM0/SM1);
* ``Slave/Mailbox/CoE/InitCmds/InitCmd``: the SDOs the master writes at a
  state transition (``Ccs`` 1 download, 2 upload);
* ``Config/Cyclic/CycleTime`` (microseconds) and ``Config/ProcessImage``
  (``ByteSize`` and the named ``Variable`` offsets).

An entry whose ``ProcessImage`` variable (``<slave>.<pdo>.<entry>``) is found
gets that variable's bit offset as its ``logical_bit``: offsets are never
recomputed when the file states them, and a stated offset that contradicts
the slave's ``Send``/``Recv`` area and mapping order is an error, as are
overlaps, sizes that do not add up, duplicate addresses and entries with
neither a bit length nor a known data type.  A slave with an area but no PDO
descriptions (files without PDO lists) gets entries synthesised from the
variables inside its area; gaps become padding.
"""

from __future__ import annotations

import copy
import re
from dataclasses import dataclass, field, replace
from typing import TypeVar

from .check import check_config
from .datatypes import CIA402_OBJECTS, type_bits
from .errors import EniError
from .limits import (
    AUTO_INC_ADDR,
    BIT_LENGTH,
    BIT_OFFSET,
    CCS,
    ENTRY_BITS,
    ESC_ADDRESS,
    IDENTITY,
    IMAGE_BYTES,
    INDEX,
    PHYS_ADDR,
    SM,
    SM_CONTROL,
    SM_LENGTH,
    SUBINDEX,
    TIMEOUT_MS,
    Limit,
    check_span,
    cycle_ns_from_us,
)
from .model import (
    Direction,
    EniConfig,
    Identity,
    InitCmd,
    MailboxLayout,
    Pdo,
    PdoEntry,
    ProcessDataArea,
    Slave,
    SyncManager,
    Variable,
)
from .numbers import fmt_index, parse_hex_bytes, shown
from .xmltree import Node

_SM_TAG = re.compile(r"^Sm(\d+)$")
_T = TypeVar("_T")
_TRUE = {"1", "true", "yes"}
_XS_BOOLEAN = {"true": True, "1": True, "false": False, "0": False}
_SM_TAG = re.compile(r"Sm(\d+)")
_SM_TYPES = {"outputs": Direction.OUT, "inputs": Direction.IN}
_ADDR_IN_NAME = re.compile(r"(?:0x|#x)([0-9a-fA-F]{4}):(?:0x|#x)?([0-9a-fA-F]{1,2})\b")
_CIA402_BY_NAME = {name.lower(): idx for idx, (name, _t) in CIA402_OBJECTS.items()}


@dataclass
class _Ctx:
    """Where we are, for error messages."""

    source: str
    slave: int | None = None
    slave_name: str | None = None
    #: slave name -> bus positions, to spot names that ProcessImage variables cannot tell apart
    positions_by_name: dict[str, list[int]] = field(default_factory=dict)
    #: equal model values, one object each (the same init commands, identity, sync manager
    #: and mailbox layout slave after slave: a bus of a thousand drives holds one copy)
    seen: dict[object, object] = field(default_factory=dict)
    #: an InitCmd element's content (attributes, children's tags, texts, attributes) -> its model
    init_cmds: dict[tuple[object, ...], InitCmd] = field(default_factory=dict)
    #: (RxPdo/TxPdo node, its order) -> what it was read as: a subtree the tree shares
    #: (:func:`gtecat.eni.xmltree.parse_xml`) is read once; each slave gets its own copy
    pdos: dict[tuple[int, int], _PdoXml] = field(default_factory=dict)
    #: id of a Mailbox node (the tree is alive while it is read) -> its init commands, layout
    mailboxes: dict[int, tuple[tuple[InitCmd, ...], MailboxLayout | None]] = field(
        default_factory=dict
    )

    def shared(self, value: _T) -> _T:
        """``value``, or the equal one this file gave before (the model is immutable)."""
        return self.seen.setdefault(value, value)  # type: ignore[return-value]

    def error(self, message: str, node: Node | None, element: str | None = None) -> EniError:
        return EniError(
            message,
            file=self.source,
            line=node.line if node is not None else None,
            slave=self.slave,
            slave_name=self.slave_name,
            element=element if element is not None else (node.tag if node is not None else None),
        )

    def int_of(
        self,
        node: Node,
        tag: str,
        limit: Limit,
        *,
        required: bool = False,
        default: int | None = None,
        element: str | None = None,
    ) -> int | None:
        """The integer in child ``tag``, checked against ``limit`` (:mod:`gtecat.eni.limits`)."""
        child = node.find(tag)
        if child is None or not child.text.strip():
            if required:
                raise self.error(f"missing <{tag}>", node, element or node.tag)
            return default
        try:
            return limit.parse(child.text, tag)
        except ValueError as exc:
            raise self.error(str(exc), child, element or tag) from None

    def bool_of(self, node: Node, tag: str, element: str) -> bool | None:
        """An xs:boolean child (``true``/``false``/``1``/``0``, blanks around), None if absent."""
        child = node.find(tag)
        if child is None or not child.text.strip():
            return None  # as an empty number: the element says nothing
        text = child.text.strip()
        if text not in _XS_BOOLEAN:
            raise self.error(
                f"<{tag}> is {shown(text)}, not an xs:boolean (true, false, 1, 0)", child, element
            )
        return _XS_BOOLEAN[text]

    def int_attr(self, node: Node, name: str, limit: Limit, element: str) -> int | None:
        """The integer in attribute ``name`` (None when absent or empty), checked."""
        text = node.attrib.get(name, "")
        if not text.strip():
            return None
        try:
            return limit.parse(text, name)
        except ValueError as exc:
            raise self.error(str(exc), node, element) from None


@dataclass
class _PdoXml:
    node: Node
    direction: Direction
    index: int
    name: str
    fixed: bool
    sm_attr: int | None
    entries: tuple[PdoEntry, ...]
    entry_lines: tuple[int, ...]
    doc_order: int


@dataclass
class _Area:
    bit_start: int
    bit_len: int
    node: Node


@dataclass
class _VarIndex:
    """ProcessImage variables by direction and name, consumed as entries claim them."""

    by_name: dict[tuple[Direction, str], list[Variable]] = field(default_factory=dict)
    lines: dict[int, int] = field(default_factory=dict)  # id(variable) -> line

    def claim(self, direction: Direction, names: list[str], want: int | None) -> Variable | None:
        for name in names:
            cands = self.by_name.get((direction, name))
            if not cands:
                continue
            pick = (
                next((v for v in cands if v.bit_offset == want), None) if want is not None else None
            )
            if pick is None:
                pick = cands[0]
            cands.remove(pick)
            return pick
        return None


def _bool(text: str | None) -> bool:
    return (text or "").strip().lower() in _TRUE


def read_xml(root: Node, source: str) -> EniConfig:
    """Build the model from a parsed ``EtherCATConfig`` tree (see module doc)."""
    ctx = _Ctx(source)
    config = root.find("Config")
    if config is None:
        raise ctx.error("no <Config> element in EtherCATConfig", root, "EtherCATConfig")
    master_name = config.findtext("Master/Info/Name") or ""
    cycle_ns = _cycle_time(ctx, config)
    variables, sizes, var_index = _process_image(ctx, config)

    slaves: list[Slave] = []
    for pos, snode in enumerate(config.findall("Slave")):
        name = snode.findtext("Info/Name") or f"Slave {pos}"
        ctx.positions_by_name.setdefault(name, []).append(pos)
    for pos, snode in enumerate(config.findall("Slave")):
        ctx.slave, ctx.slave_name = pos, None
        slaves.append(_slave(ctx, snode, pos, var_index))
    ctx.slave = ctx.slave_name = None
    slaves = _place_unplaced(slaves)

    ends = {d: 0 for d in Direction}
    for s in slaves:
        for d, area in ((Direction.OUT, s.outputs), (Direction.IN, s.inputs)):
            if area is not None:
                ends[d] = max(ends[d], area.bit_start + area.bit_len)
    image_bytes: dict[Direction, int] = {}
    for d in Direction:
        need = (ends[d] + 7) // 8
        stated, node = sizes.get(d, (None, None))
        if stated is not None and stated < need:
            what = "Outputs" if d == Direction.OUT else "Inputs"
            raise ctx.error(
                f"ByteSize {stated} is smaller than the {need} bytes the slaves' "
                f"{'Send' if d == Direction.OUT else 'Recv'} areas need",
                node,
                f"ProcessImage/{what}/ByteSize",
            )
        image_bytes[d] = stated if stated is not None else need

    cfg = EniConfig(
        source=source,
        format="xml",
        slaves=tuple(slaves),
        cycle_time_ns=cycle_ns,
        outputs_bytes=image_bytes[Direction.OUT],
        inputs_bytes=image_bytes[Direction.IN],
        variables=tuple(variables),
        master_name=master_name,
    )
    check_config(cfg)
    return cfg


def _cycle_time(ctx: _Ctx, config: Node) -> int | None:
    """``Cyclic/CycleTime`` (us) in ns; absent or empty is "not given", 0 is refused.

    The legal range is 31.25 us .. 1 s (:data:`gtecat.eni.limits.CYCLE_NS`).
    """
    for cyc in config.findall("Cyclic"):
        node = cyc.find("CycleTime")
        if node is not None and node.text.strip():
            try:
                return cycle_ns_from_us(node.text, "CycleTime")
            except ValueError as exc:
                raise ctx.error(str(exc), node, "Cyclic/CycleTime") from None
    return None


def _process_image(
    ctx: _Ctx, config: Node
) -> tuple[list[Variable], dict[Direction, tuple[int | None, Node | None]], _VarIndex]:
    variables: list[Variable] = []
    sizes: dict[Direction, tuple[int | None, Node | None]] = {}
    index = _VarIndex()
    pi = config.find("ProcessImage")
    if pi is None:
        return variables, sizes, index
    for part in pi.children:
        if part.tag not in ("Inputs", "Outputs"):
            continue
        d = Direction.IN if part.tag == "Inputs" else Direction.OUT
        bs = part.find("ByteSize")
        byte_size = ctx.int_of(
            part, "ByteSize", IMAGE_BYTES, element=f"ProcessImage/{part.tag}/ByteSize"
        )
        sizes[d] = (byte_size, bs)
        for vnode in part.findall("Variable"):
            elem = f"ProcessImage/{part.tag}/Variable"
            name = vnode.findtext("Name") or ""
            size = ctx.int_of(vnode, "BitSize", BIT_LENGTH, required=True, element=elem)
            offs = ctx.int_of(vnode, "BitOffs", BIT_OFFSET, required=True, element=elem)
            assert size is not None and offs is not None
            # no check against ByteSize: TwinCAT lists variables (InfoData) past its image
            try:
                check_span(offs, size, f"variable {name!r}")
            except ValueError as exc:
                raise ctx.error(str(exc), vnode, elem) from None
            var = Variable(name, d, offs, size, vnode.findtext("DataType") or "")
            variables.append(var)
            index.by_name.setdefault((d, name), []).append(var)
            index.lines[id(var)] = vnode.line
    return variables, sizes, index


def _slave(ctx: _Ctx, snode: Node, pos: int, var_index: _VarIndex) -> Slave:
    info = snode.find("Info")
    if info is None:
        raise ctx.error("slave has no <Info>", snode, "Slave")
    name = info.findtext("Name") or f"Slave {pos}"
    ctx.slave_name = name
    vendor = ctx.int_of(info, "VendorId", IDENTITY, required=True, element="Info/VendorId")
    product = ctx.int_of(info, "ProductCode", IDENTITY, required=True, element="Info/ProductCode")
    assert vendor is not None and product is not None
    identity = ctx.shared(
        Identity(
            vendor_id=vendor,
            product_code=product,
            revision_no=ctx.int_of(info, "RevisionNo", IDENTITY, default=0) or 0,
            serial_no=ctx.int_of(info, "SerialNo", IDENTITY, default=0) or 0,
        )
    )
    phys = ctx.int_of(info, "PhysAddr", PHYS_ADDR, default=0) or 0
    # the 16-bit register value: "-1" and "65535" are the same auto-increment address
    auto_inc = (ctx.int_of(info, "AutoIncAddr", AUTO_INC_ADDR, default=0) or 0) & 0xFFFF

    rx: tuple[Pdo, ...] = ()
    tx: tuple[Pdo, ...] = ()
    areas: dict[Direction, ProcessDataArea | None] = {Direction.OUT: None, Direction.IN: None}
    pd = snode.find("ProcessData")
    if pd is not None:
        area_nodes = {Direction.OUT: _area(ctx, pd, "Send"), Direction.IN: _area(ctx, pd, "Recv")}
        assigned = _assigned_pdos(ctx, pd)
        result: dict[Direction, tuple[Pdo, ...]] = {}
        for d in Direction:
            pdos, area = _direction(ctx, d, assigned[d], area_nodes[d], var_index, name)
            result[d] = pdos
            areas[d] = area
        rx, tx = result[Direction.OUT], result[Direction.IN]

    mailbox_node = snode.find("Mailbox")
    init_cmds: tuple[InitCmd, ...] = ()
    layout: MailboxLayout | None = None
    if mailbox_node is not None:
        # one node for the byte-identical mailbox elements of like slaves: read once
        read = ctx.mailboxes.get(id(mailbox_node))
        if read is None:
            read = ctx.mailboxes[id(mailbox_node)] = (
                ctx.shared(
                    tuple(
                        _init_cmd_once(ctx, n) for n in mailbox_node.findall("CoE/InitCmds/InitCmd")
                    )
                ),
                _mailbox_layout(ctx, mailbox_node),
            )
        init_cmds, layout = read
    return Slave(
        position=pos,
        name=name,
        identity=identity,
        phys_addr=phys,
        auto_inc_addr=auto_inc,
        rx_pdos=rx,
        tx_pdos=tx,
        outputs=areas[Direction.OUT],
        inputs=areas[Direction.IN],
        init_cmds=init_cmds,
        mailbox=mailbox_node is not None,
        line=snode.line,
        sync_managers=_sync_managers(ctx, pd) if pd is not None else (),
        mailbox_layout=layout,
        product_revision=info.findtext("ProductRevision") or None,
    )


def _sync_managers(ctx: _Ctx, pd: Node) -> tuple[SyncManager, ...]:
    """``ProcessData/SmN`` elements with a ``Type`` of Outputs or Inputs (others: mailbox)."""
    out = []
    for child in pd.children:
        m = _SM_TAG.fullmatch(child.tag)
        direction = _SM_TYPES.get((child.findtext("Type") or "").strip().lower())
        if m is None or direction is None:
            continue
        elem = f"ProcessData/{child.tag}"
        try:
            number = SM.parse(m.group(1), child.tag)
        except ValueError as exc:
            raise ctx.error(str(exc), child, elem) from None
        start = ctx.int_of(child, "StartAddress", ESC_ADDRESS, element=elem)
        if start is None:
            continue  # no address: the device's default layout stays
        out.append(
            SyncManager(
                number,
                direction,
                start,
                ctx.int_of(child, "ControlByte", SM_CONTROL, default=0, element=elem) or 0,
                bool(ctx.bool_of(child, "Enable", elem)),
            )
        )
    return ctx.shared(tuple(out))


def _mailbox_layout(ctx: _Ctx, mbx: Node) -> MailboxLayout | None:
    """``Mailbox/Send`` and ``Mailbox/Recv`` start and length, when all four are given."""
    values = [
        ctx.int_of(mbx, f"{side}/{tag}", limit, element=f"Mailbox/{side}/{tag}")
        for side in ("Send", "Recv")
        for tag, limit in (("Start", ESC_ADDRESS), ("Length", SM_LENGTH))
    ]
    if None in values:
        return None
    return ctx.shared(MailboxLayout(*values))  # type: ignore[arg-type]


def _area(ctx: _Ctx, pd: Node, tag: str) -> _Area | None:
    found: list[_Area] = []
    for node in pd.findall(tag):
        elem = f"ProcessData/{tag}"
        start = ctx.int_of(node, "BitStart", BIT_OFFSET, required=True, element=elem)
        length = ctx.int_of(node, "BitLength", BIT_LENGTH, required=True, element=elem)
        assert start is not None and length is not None
        try:
            check_span(start, length, tag)
        except ValueError as exc:
            raise ctx.error(str(exc), node, elem) from None
        if length:
            found.append(_Area(start, length, node))
    if not found:
        return None
    found.sort(key=lambda a: a.bit_start)
    merged = found[0]
    for a in found[1:]:
        if a.bit_start != merged.bit_start + merged.bit_len:
            raise ctx.error(
                f"several non-contiguous {tag} areas (bits {merged.bit_start}+{merged.bit_len} "
                f"and {a.bit_start}+{a.bit_len}); one area per direction is supported",
                a.node,
                f"ProcessData/{tag}",
            )
        merged = _Area(merged.bit_start, merged.bit_len + a.bit_len, merged.node)
    return merged


def _assigned_pdos(ctx: _Ctx, pd: Node) -> dict[Direction, list[_PdoXml] | None]:
    """The PDOs assigned to a sync manager, per direction, in SM then list order.

    ``None`` for a direction means "no PDO description to go by" (synthesise).
    """
    described: list[_PdoXml] = []
    read = ctx.pdos
    for order, node in enumerate(c for c in pd.children if c.tag in ("RxPdo", "TxPdo")):
        p = read.get((id(node), order))
        if p is None or p.node is not node:
            p = read[id(node), order] = _pdo(ctx, node, order)
        # a copy: the assignment below sets sm_attr, per slave
        described.append(copy.copy(p))

    sm_lists: list[tuple[int, str, list[tuple[int, Node]]]] = []
    for node in pd.children:
        m = _SM_TAG.match(node.tag)
        if m:
            try:
                sm_no = SM.parse(m.group(1), "sync manager")
            except ValueError as exc:
                raise ctx.error(str(exc), node, "ProcessData/Sm") from None
        elif node.tag == "Sm" and ("No" in node.attrib or "Index" in node.attrib):
            attr = "No" if "No" in node.attrib else "Index"
            no = ctx.int_attr(node, attr, SM, "ProcessData/Sm")
            if no is None:
                raise ctx.error(f"empty {attr} attribute", node, "ProcessData/Sm")
            sm_no = no
        else:
            continue
        kind = (node.findtext("Type") or "").lower()
        listed = []
        for p in node.findall("Pdo"):
            try:
                listed.append((INDEX.parse(p.text, "PDO index"), p))
            except ValueError as exc:
                raise ctx.error(str(exc), p, f"Sm{sm_no}/Pdo") from None
        sm_lists.append((sm_no, kind, listed))

    any_assignment = any(p.sm_attr is not None for p in described) or any(
        listed for _, _, listed in sm_lists
    )
    if not any_assignment:
        # nothing says which PDOs are assigned: _direction takes them only on an exact fit
        unassigned: dict[Direction, list[_PdoXml] | None] = {}
        for d in Direction:
            cands = [p for p in described if p.direction == d]
            unassigned[d] = _Unassigned(cands) if cands else None
        return unassigned

    # (sm, rank in that SM's list, doc order) -> pdo
    placed: dict[int, tuple[int, int, int]] = {}
    missing: dict[Direction, list[tuple[int, int, Node]]] = {d: [] for d in Direction}
    for sm_no, kind, listed in sm_lists:
        for rank, (pdo_index, pnode) in enumerate(listed):
            matches = [p for p in described if p.index == pdo_index]
            if len(matches) > 1:
                want = Direction.OUT if "out" in kind else Direction.IN if "in" in kind else None
                matches = [p for p in matches if p.direction == want] or matches[:1]
            if not matches:
                d = Direction.OUT if "out" in kind else Direction.IN
                missing[d].append((pdo_index, sm_no, pnode))
                continue
            p = matches[0]
            if id(p) not in placed:
                placed[id(p)] = (sm_no, rank, p.doc_order)
    # A sync manager with an SmN/Pdo list is assigned by that list alone: it is what the
    # master writes to 0x1C12/0x1C13 and sizes the SM from.  An ``Sm`` attribute naming such
    # an SM on a PDO the list leaves out is the default SM the ESI gave that alternative
    # (tools that copy RxPdo/TxPdo elements from the ESI keep it), not an assignment.
    listed_sms = {sm_no for sm_no, _kind, listed in sm_lists if listed}
    for p in described:
        if p.sm_attr is not None and id(p) not in placed and p.sm_attr not in listed_sms:
            placed[id(p)] = (p.sm_attr, 1 << 30, p.doc_order)
    by_dir: dict[Direction, list[_PdoXml] | None] = {}
    for d in Direction:
        chosen = sorted(
            (p for p in described if id(p) in placed and p.direction == d),
            key=lambda p: placed[id(p)],
        )
        for p in chosen:
            p.sm_attr = placed[id(p)][0]
        if missing[d] and chosen:
            idx, sm_no, pnode = missing[d][0]
            raise ctx.error(
                f"Sm{sm_no} assigns PDO #x{idx:04X}, which the file does not describe",
                pnode,
                f"Sm{sm_no}/Pdo",
            )
        by_dir[d] = chosen if chosen else None
    return by_dir


class _Unassigned(list):  # type: ignore[type-arg]
    """PDOs of a slave whose file says nothing about assignment (see _direction)."""


def _pdo(ctx: _Ctx, node: Node, order: int) -> _PdoXml:
    direction = Direction.OUT if node.tag == "RxPdo" else Direction.IN
    elem = node.tag
    index = ctx.int_of(node, "Index", INDEX, required=True, element=elem)
    assert index is not None
    elem = f"{node.tag} #x{index:04X}"
    sm_attr = ctx.int_attr(node, "Sm", SM, elem)
    entries: list[PdoEntry] = []
    lines: list[int] = []
    for enode in node.findall("Entry"):
        eidx = ctx.int_of(enode, "Index", INDEX, required=True, element=f"{elem}/Entry")
        assert eidx is not None
        sub = ctx.int_of(enode, "SubIndex", SUBINDEX, default=0, element=f"{elem}/Entry") or 0
        eelem = f"{elem}/Entry {fmt_index(eidx, sub)}"
        dtype = enode.findtext("DataType") or ""
        bits = ctx.int_of(enode, "BitLen", ENTRY_BITS, element=eelem)
        if bits is None:
            bits = type_bits(dtype) if dtype else None
            if bits is None:
                why = f"unknown data type {dtype!r}" if dtype else "no data type"
                raise ctx.error(f"entry has no BitLen and {why}", enode, eelem)
        if eidx == 0:  # a gap: tools may name it ("__unused"), it still maps nothing
            entries.append(PdoEntry(0, 0, bits))
        else:
            entries.append(PdoEntry(eidx, sub, bits, enode.findtext("Name") or "", dtype))
        lines.append(enode.line)
    return _PdoXml(
        node,
        direction,
        index,
        node.findtext("Name") or "",
        _bool(node.attrib.get("Fixed")),
        sm_attr,
        tuple(entries),
        tuple(lines),
        order,
    )


def _direction(
    ctx: _Ctx,
    d: Direction,
    pdos: list[_PdoXml] | None,
    area: _Area | None,
    var_index: _VarIndex,
    slave_name: str,
) -> tuple[tuple[Pdo, ...], ProcessDataArea | None]:
    tag = "Send" if d == Direction.OUT else "Recv"
    if isinstance(pdos, _Unassigned):
        total = sum(e.bit_len for p in pdos for e in p.entries)
        pdos = list(pdos) if area is not None and total == area.bit_len else None
    if not pdos:
        if area is None:
            return (), None
        return _synthesise(ctx, d, area, var_index, slave_name)

    total = sum(e.bit_len for p in pdos for e in p.entries)
    if area is not None and total != area.bit_len and area.bit_len != (total + 7) // 8 * 8:
        raise ctx.error(
            f"the assigned {'RxPdo' if d == Direction.OUT else 'TxPdo'}s map {total} bits "
            f"but {tag}/BitLength is {area.bit_len}",
            area.node,
            f"ProcessData/{tag}",
        )

    # claim ProcessImage variables by name, check them against the area
    result: list[Pdo] = []
    cum = 0
    anchor: tuple[int, int, int] | None = None  # (stated bit, cum, line) fixing an unknown area
    for p in pdos:
        entries = []
        for e, line in zip(p.entries, p.entry_lines, strict=True):
            stated = None
            if not e.is_padding:
                want = area.bit_start + cum if area is not None else None
                names = [f"{slave_name}.{p.name}.{e.name}", f"{slave_name}.{e.name}"]
                var = var_index.claim(d, names, want)
                if var is not None:
                    where = f"{p.node.tag} #x{p.index:04X}/Entry {fmt_index(e.index, e.subindex)}"
                    namesakes = ctx.positions_by_name.get(slave_name, [])
                    if area is None and len(namesakes) > 1:
                        # variables are found by "<slave>.<pdo>.<entry>": with no Send/Recv
                        # to check them against, the namesakes' offsets could be swapped
                        raise EniError(
                            f"slaves {', '.join(map(str, namesakes))} share the name "
                            f"{slave_name!r} and the file gives no {tag} area, so the "
                            f"ProcessImage variable {var.name!r} cannot be told apart; give "
                            "the slaves distinct names or Send/Recv BitStart",
                            file=ctx.source,
                            line=var_index.lines.get(id(var)),
                            slave=ctx.slave,
                            slave_name=ctx.slave_name,
                            element=where,
                        )
                    if var.bit_size != e.bit_len:
                        raise EniError(
                            f"ProcessImage variable {var.name!r} is {var.bit_size} bits but the "
                            f"entry maps {e.bit_len}",
                            file=ctx.source,
                            line=var_index.lines.get(id(var)),
                            slave=ctx.slave,
                            slave_name=ctx.slave_name,
                            element=where,
                        )
                    stated = var.bit_offset
                    if want is not None and stated != want:
                        raise EniError(
                            f"ProcessImage variable {var.name!r} is at bit {stated}, but "
                            f"{tag} BitStart {area.bit_start} and the mapping order put the "
                            f"entry at bit {want}",
                            file=ctx.source,
                            line=var_index.lines.get(id(var)),
                            slave=ctx.slave,
                            slave_name=ctx.slave_name,
                            element=where,
                        )
                    if anchor is None:
                        anchor = (stated, cum, line)
                    elif stated - anchor[0] != cum - anchor[1]:
                        raise EniError(
                            f"ProcessImage variable {var.name!r} at bit {stated} does not follow "
                            "the mapping order of the entries before it",
                            file=ctx.source,
                            line=var_index.lines.get(id(var)),
                            slave=ctx.slave,
                            slave_name=ctx.slave_name,
                            element=where,
                        )
            entries.append(e.at(stated) if stated is not None else e)
            cum += e.bit_len
        result.append(Pdo(p.index, d, tuple(entries), p.name, p.sm_attr, p.fixed))

    out_area: ProcessDataArea | None
    if area is not None:
        out_area = ProcessDataArea(area.bit_start, total)
    elif anchor is not None:
        start = anchor[0] - anchor[1]
        if start < 0:
            raise ctx.error(
                f"ProcessImage variables put the {tag} area before bit 0",
                None,
                f"ProcessData/{tag}",
            )
        out_area = ProcessDataArea(start, total)
    else:
        out_area = None  # placed after the others by _place_unplaced
    if total == 0:
        out_area = None
    return tuple(result), out_area


def _synthesise(
    ctx: _Ctx, d: Direction, area: _Area, var_index: _VarIndex, slave_name: str
) -> tuple[tuple[Pdo, ...], ProcessDataArea]:
    """Entries from the ProcessImage variables inside a slave's area; gaps are padding."""
    tag = "Send" if d == Direction.OUT else "Recv"
    lo, hi = area.bit_start, area.bit_start + area.bit_len
    inside: list[Variable] = []
    for (vd, _name), cands in var_index.by_name.items():
        if vd != d:
            continue
        for v in cands:
            if lo <= v.bit_offset < hi:
                if v.bit_offset + v.bit_size > hi:
                    raise EniError(
                        f"ProcessImage variable {v.name!r} (bits {v.bit_offset}+{v.bit_size}) "
                        f"runs past the slave's {tag} area ({lo}+{area.bit_len})",
                        file=ctx.source,
                        line=var_index.lines.get(id(v)),
                        slave=ctx.slave,
                        slave_name=ctx.slave_name,
                        element="ProcessImage/Variable",
                    )
                inside.append(v)
    inside.sort(key=lambda v: v.bit_offset)
    entries: list[PdoEntry] = []
    used: set[tuple[int, int]] = set()
    cursor = lo
    for v in inside:
        if v.bit_offset < cursor:
            raise EniError(
                f"ProcessImage variable {v.name!r} at bit {v.bit_offset} overlaps the variable "
                "before it",
                file=ctx.source,
                line=var_index.lines.get(id(v)),
                slave=ctx.slave,
                slave_name=ctx.slave_name,
                element="ProcessImage/Variable",
            )
        if v.bit_offset > cursor:
            entries.append(PdoEntry(0, 0, v.bit_offset - cursor))
        index, sub = _index_from_name(v, used)
        short = v.name[len(slave_name) + 1 :] if v.name.startswith(slave_name + ".") else v.name
        entries.append(PdoEntry(index, sub, v.bit_size, short, v.data_type, v.bit_offset))
        cursor = v.bit_offset + v.bit_size
    if cursor < hi:
        entries.append(PdoEntry(0, 0, hi - cursor))
    pdo = Pdo(
        0x1600 if d == Direction.OUT else 0x1A00,
        d,
        tuple(entries),
        "(from ProcessImage)",
        None,
        True,
    )
    return (pdo,), ProcessDataArea(lo, area.bit_len)


def _index_from_name(v: Variable, used: set[tuple[int, int]]) -> tuple[int, int]:
    """An object address a variable's name gives (``...0x6040:00`` or a CiA-402 name)."""
    found: tuple[int, int] | None = None
    m = _ADDR_IN_NAME.search(v.name)
    if m:
        found = (int(m.group(1), 16), int(m.group(2), 16))
    else:
        last = v.name.rsplit(".", 1)[-1].strip().lower()
        idx = _CIA402_BY_NAME.get(last)
        if idx is not None and type_bits(CIA402_OBJECTS[idx][1]) == v.bit_size:
            found = (idx, 0)
    if found is None or found in used or found[0] == 0:
        return 0, 0
    used.add(found)
    return found


def _place_unplaced(slaves: list[Slave]) -> list[Slave]:
    """Give a logical area to slaves whose PDOs the file places nowhere (after the rest)."""
    ends = {Direction.OUT: 0, Direction.IN: 0}
    for s in slaves:
        for d, a in ((Direction.OUT, s.outputs), (Direction.IN, s.inputs)):
            if a is not None:
                ends[d] = max(ends[d], a.bit_start + a.bit_len)
    out = []
    for s in slaves:
        changes: dict[str, ProcessDataArea] = {}
        for d, a, bits, attr in (
            (Direction.OUT, s.outputs, s.out_bits, "outputs"),
            (Direction.IN, s.inputs, s.in_bits, "inputs"),
        ):
            if a is None and bits:
                start = (ends[d] + 7) // 8 * 8
                changes[attr] = ProcessDataArea(start, bits)
                ends[d] = start + bits
        out.append(replace(s, **changes) if changes else s)
    return out


def _init_cmd_once(ctx: _Ctx, node: Node) -> InitCmd:
    """:func:`_init_cmd`, read once per content: the init commands of a bus of like drives are
    the same elements slave after slave (an InitCmd is leaves only; one with more depth, or
    one that is wrong, is read as it stands)."""
    children = node.children
    if any(c.children for c in children):
        return ctx.shared(_init_cmd(ctx, node))
    key = (
        tuple(node.attrib.items()),
        tuple((c.tag, c.text, tuple(c.attrib.items())) for c in children),
    )
    cmd = ctx.init_cmds.get(key)
    if cmd is None:
        cmd = ctx.init_cmds[key] = ctx.shared(_init_cmd(ctx, node))
    return cmd


def _init_cmd(ctx: _Ctx, node: Node) -> InitCmd:
    elem = "Mailbox/CoE/InitCmds/InitCmd"
    transitions = tuple(
        t.text.strip().upper() for t in node.findall("Transition") if t.text.strip()
    )
    if not transitions:
        raise ctx.error("InitCmd without <Transition>", node, elem)
    index = ctx.int_of(node, "Index", INDEX, required=True, element=elem)
    sub = ctx.int_of(node, "SubIndex", SUBINDEX, default=0, element=elem) or 0
    assert index is not None
    ccs = ctx.int_of(node, "Ccs", CCS, default=1, element=elem)
    data_node = node.find("Data")
    data = b""
    if data_node is not None and data_node.text.strip():
        try:
            data = parse_hex_bytes(data_node.text)
        except ValueError as exc:
            raise ctx.error(str(exc), data_node, f"{elem}/Data") from None
    ca = node.attrib.get("CompleteAccess") or node.findtext("CompleteAccess")
    return InitCmd(
        transitions=transitions,
        index=index,
        subindex=sub,
        data=data,
        complete_access=_bool(ca),
        comment=node.findtext("Comment") or "",
        timeout_ms=ctx.int_of(node, "Timeout", TIMEOUT_MS, default=0, element=elem) or 0,
        upload=ccs == 2,
    )
