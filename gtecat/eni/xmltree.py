"""A small, safe XML element tree that remembers the line of every element.

ENI errors must name the line (DESIGN.md "Errors"), which
``xml.etree.ElementTree`` does not keep, and an ENI must never make us read
another file: this parser is expat (the same engine ElementTree uses) with
every document type declaration refused, so no DTD, no internal or external
entity is ever expanded ("billion laughs" and XXE are impossible by
construction).  Namespace prefixes are dropped from tags and attribute names:
ETG.2100 files come with and without them.
"""

from __future__ import annotations

import codecs
import functools
import re
from collections.abc import Iterator
from xml.parsers import expat

from .errors import EniError
from .numbers import shown

#: what an element without attributes or children holds (shared: a tree is read, never
#: changed, and an ENI has a few hundred thousand such elements)
_NO_ATTRS: dict[str, str] = {}
_NO_CHILDREN: tuple[Node, ...] = ()


class Node:
    """One element: local tag name, attributes, children, text and source line (read only)."""

    __slots__ = ("attrib", "children", "line", "tag", "text")

    def __init__(self, tag: str, attrib: dict[str, str], line: int) -> None:
        self.tag = tag
        self.attrib = attrib
        self.children: list[Node] | tuple[Node, ...] = _NO_CHILDREN
        self.text = ""
        self.line = line

    def find(self, tag: str) -> Node | None:
        """First child named ``tag`` (``a/b`` walks down), or None."""
        if "/" not in tag:
            for c in self.children:
                if c.tag == tag:
                    return c
            return None
        node: Node | None = self
        for part in tag.split("/"):
            assert node is not None
            node = next((c for c in node.children if c.tag == part), None)
            if node is None:
                return None
        return node

    def findall(self, tag: str) -> list[Node]:
        """Children named ``tag`` (``a/b`` collects every ``b`` under every ``a``)."""
        *head, last = tag.split("/")
        parents = [self]
        for part in head:
            parents = [c for p in parents for c in p.children if c.tag == part]
        return [c for p in parents for c in p.children if c.tag == last]

    def findtext(self, tag: str) -> str | None:
        """Stripped text of the first child named ``tag``, None when absent."""
        node = self.find(tag)
        return None if node is None else node.text.strip()

    def iter(self) -> Iterator[Node]:
        yield self
        for c in self.children:
            yield from c.iter()

    def __repr__(self) -> str:
        return f"<Node {self.tag} line {self.line}>"


_DECL_ENCODING = re.compile(rb"^\s*<\?xml[^>]*?\bencoding\s*=\s*[\"']([^\"']*)[\"']")
#: what expat decodes itself (XML 1.0 section 4.3.3 requires UTF-8 and UTF-16)
_EXPAT_NATIVE = {"utf_8", "utf_16", "iso8859_1", "latin_1", "ascii"}
#: GB2312 files written on Windows routinely hold GBK characters; GB18030 reads both
_SUPERSET = {"gb2312": "gb18030", "gbk": "gb18030"}
#: byte order marks, longest first (a UTF-32-LE BOM starts like UTF-16-LE's)
_BOMS = (
    (b"\x00\x00\xfe\xff", "utf-32"),
    (b"\xff\xfe\x00\x00", "utf-32"),
    (b"\xef\xbb\xbf", "utf-8-sig"),
    (b"\xff\xfe", "utf-16"),
    (b"\xfe\xff", "utf-16"),
)


def _decode(data: bytes, codec: str, what: str, source: str) -> str:
    try:
        return data.decode(codec)
    except UnicodeDecodeError as exc:
        line = data.count(b"\n", 0, exc.start) + 1
        raise EniError(
            f"byte 0x{data[exc.start]:02X} is not valid {what}", file=source, line=line
        ) from None
    except UnicodeError as exc:  # codecs that refuse without a position (punycode, undefined)
        raise EniError(f"the text is not valid {what}: {exc}", file=source, line=1) from None


def _decoded(data: bytes, source: str) -> bytes | str:
    """Decode a document whose encoding expat cannot handle (``GB2312``, ``Shift_JIS``).

    A byte order mark decides over the declaration (XML 1.0 appendix F).
    Otherwise the declaration decides, and only a text encoding is accepted:
    ``encoding="rot13"`` or ``"base64"`` (Python codecs that are not
    bytes-to-text) and names Python does not know are refused with the name.
    Chinese configuration tools write ``encoding="GB2312"``; expat only knows
    UTF-8/UTF-16/ISO-8859-1/ASCII (and refuses multi-byte codecs through
    pyexpat), so Python's codec decodes it and expat gets text.
    """
    for bom, codec in _BOMS:
        if data.startswith(bom):
            return _decode(data, codec, f"{codec.upper()} (the byte order mark)", source)
    m = _DECL_ENCODING.match(data[:512])
    if m is None:
        return data
    declared = m.group(1).decode("ascii", "replace")
    try:
        info = codecs.lookup(declared)
    except (LookupError, ValueError):  # ValueError: a NUL in the name
        info = None
    if info is None or not getattr(info, "_is_text_encoding", True):
        what = "unknown encoding" if info is None else "not a text encoding:"
        raise EniError(
            f"{what} {shown(declared)} in the XML declaration; the encoding must be a "
            "text encoding such as UTF-8, UTF-16 or GB2312",
            file=source,
            line=1,
        )
    name = info.name.replace("-", "_")
    if name in _EXPAT_NATIVE:  # "UTF-16" without a BOM: expat tells the byte order from "<"
        return data
    return _decode(
        data,
        _SUPERSET.get(name, name),
        f"{shown(declared, quote=False)} (the declared encoding)",
        source,
    )


def _cuts(raw: bytes, pairs: frozenset[tuple[str, str]]) -> list[int]:
    """Where to end the pieces fed to expat: just after each start tag that may open a
    skipped or shared subtree (``pairs``' elements, without a namespace prefix), so that the
    handler that meets it can let the rest of the subtree pass with no handler at all (a
    ``>`` in an attribute value only places the cut early: the subtree then passes with its
    end tags, as one with a prefix does)."""
    out = []
    for name in {name for _, name in pairs if name.isascii()}:
        opening = b"<" + name.encode()
        n = len(opening)
        at = raw.find(opening)
        while at >= 0:
            if raw[at + n : at + n + 1] in (b">", b" ", b"\t", b"\r", b"\n"):
                gt = raw.find(b">", at + n)
                if gt > 0:
                    out.append(gt + 1)
            at = raw.find(opening, at + n)
    out.sort()
    return out


@functools.lru_cache(maxsize=64)
def _tag_patterns(tag: str) -> tuple[re.Pattern[bytes], re.Pattern[bytes]]:
    """The end tag and the start tag of an element named ``tag`` (ASCII), as bytes."""
    name = re.escape(tag.encode("ascii"))
    return re.compile(rb"</" + name + rb"[\s>]"), re.compile(rb"<" + name + rb"[\s/>]")


def _end_tag(raw: bytes, tag: str, at: int) -> int:
    """Where the end tag of the element whose start tag is at ``at`` begins, or -1 where the
    bytes do not tell it for certain.

    The first ``</tag`` after ``at`` is that end tag when nothing between is a comment, a
    CDATA section or a processing instruction (``<!``, ``<?``: the only places where ``<``
    may stand outside markup) and no element of the same name starts in between (an
    element closed by ``/>`` has no end tag: then one of the same name follows, or none).
    Whether the document is well formed is expat's to say: it still reads every byte."""
    if not tag.isascii():
        return -1
    end, start = _tag_patterns(tag)
    m = end.search(raw, at)
    if m is None:
        return -1
    stop = m.start()
    if raw.find(b"<!", at, stop) >= 0 or raw.find(b"<?", at, stop) >= 0:
        return -1
    return -1 if start.search(raw, at + 1, stop) else stop


def _add(parent: Node, node: Node) -> None:
    if parent.children:
        parent.children.append(node)  # type: ignore[union-attr]
    else:
        parent.children = [node]


def _local(name: str) -> str:
    return name.rpartition(":")[2]


class _Refused(Exception):
    pass


#: bytes handed to expat at a time: it then holds one such piece, not a copy of the document
_CHUNK = 1 << 18


def parse_xml(
    data: bytes | str,
    source: str,
    skip: frozenset[tuple[str, str]] = frozenset(),
    share: frozenset[tuple[str, str]] = frozenset(),
) -> Node:
    """Parse a whole document; any error becomes an :class:`EniError` with its line.

    ``skip``: (parent, element) local names whose subtrees are checked by expat but not
    built, for the parts a reader never looks at (an ENI's register InitCmds are most of
    its elements): inside one, only a depth counter runs, and no text is delivered.

    ``share``: (parent, element) local names whose subtree, when its bytes (start tag to
    end tag) are those of one built before, is that same node: expat still checks it, but
    only its end tags reach Python (a bus of like drives repeats each drive's mailbox
    element byte for byte).  The lines inside a shared subtree are those of its first
    occurrence: a reader that finds an error reads the document again without sharing.
    Only for a document given as bytes that expat decodes itself (its byte positions are
    those of ``data``).

    An element's ``text`` is its character data; an element with children keeps the
    first piece only when the others are blank (the indentation between its children
    would otherwise make one long string per parent)."""
    if isinstance(data, bytes):
        data = _decoded(data, source)
    parser = expat.ParserCreate()
    parser.SetParamEntityParsing(expat.XML_PARAM_ENTITY_PARSING_NEVER)
    parser.buffer_text = True
    stack: list[Node] = []
    root: list[Node] = []
    local: dict[str, str] = {}  # qualified name -> local name
    seen: dict[str, str] = {}  # short texts, one object each
    depth = 0  # inside a skipped subtree
    #: the document's bytes where expat reads them as they are (not UTF-16 or UTF-32)
    raw = data if isinstance(data, bytes) and b"\x00" not in data[:4] else None
    #: a shared subtree's bytes -> its node; the bytes' first occurrence, until it ends
    shared: dict[bytes, Node] = {}
    opened: dict[int, tuple[Node, int, bytes]] = {}  # id(node) -> (node, start, end tag)
    until = 0  # inside a skipped or shared subtree: the position of its end tag
    fed = 0  # where the piece expat reads now ends
    blind = 0  # the subtree's end tag, when expat reads up to it with no handler at all

    def passing(stop: int) -> None:
        """Let the subtree until ``stop`` (its end tag) pass: where it goes on beyond the piece
        expat reads now, the rest of it is fed with no handler at all, otherwise only end
        tags reach Python until its own."""
        nonlocal until, blind
        until = stop
        parser.StartElementHandler = parser.CharacterDataHandler = None  # type: ignore[assignment]
        if stop >= fed:
            parser.EndElementHandler = None  # type: ignore[assignment]
            blind = stop
        else:
            parser.EndElementHandler = until_end

    # (the elements' names first: a set lookup of the name the parser gives, no pair made)
    skip_names = frozenset(name for _, name in skip)
    share_names = frozenset(name for _, name in share)

    def start(tag: str, attrs: dict[str, str]) -> None:
        nonlocal depth
        name = local.get(tag)
        if name is None:
            name = local[tag] = _local(tag)
        parent = stack[-1] if stack else None
        if name in skip_names and parent is not None and (parent.tag, name) in skip:
            stop = _end_tag(raw, tag, parser.CurrentByteIndex) if raw is not None else -1
            if stop < 0:
                depth = 1
                parser.StartElementHandler, parser.EndElementHandler = skipping
                parser.CharacterDataHandler = None  # type: ignore[assignment]
            else:
                passing(stop)
            return
        pending = None
        if (
            name in share_names
            and raw is not None
            and parent is not None
            and (parent.tag, name) in share
        ):
            at = parser.CurrentByteIndex
            stop = _end_tag(raw, tag, at)
            if stop > 0:
                span = raw[at:stop]
                same = shared.get(span)
                if same is not None:  # its bytes and so its tree
                    _add(parent, same)
                    passing(stop)
                    return
                pending = (at, span)
        attrib = {_local(k): v for k, v in attrs.items()} if attrs else _NO_ATTRS
        node = Node(name, attrib, parser.CurrentLineNumber)
        if parent is None:
            root.append(node)
        else:
            _add(parent, node)
        stack.append(node)
        if pending is not None:
            opened[id(node)] = (node, *pending)

    def end(tag: str) -> None:
        node = stack.pop()
        if node.children:  # read only from here on: a tuple is smaller than a list
            node.children = tuple(node.children)
        if opened:
            first = opened.pop(id(node), None)
            if first is not None:
                shared.setdefault(first[2], node)

    def until_end(tag: str) -> None:
        if parser.CurrentByteIndex == until:
            parser.StartElementHandler, parser.EndElementHandler, parser.CharacterDataHandler = (
                building
            )

    def skip_start(tag: str, attrs: dict[str, str]) -> None:
        nonlocal depth
        depth += 1

    def skip_end(tag: str) -> None:
        nonlocal depth
        depth -= 1
        if not depth:
            parser.StartElementHandler, parser.EndElementHandler, parser.CharacterDataHandler = (
                building
            )

    def chars(data: str) -> None:
        if stack:
            node = stack[-1]
            text = node.text
            if not text:  # one string for each text a file repeats (names, types, indents)
                node.text = seen.setdefault(data, data) if len(data) <= 64 else data
            elif not (data.isspace() and text.isspace()):
                node.text = text + data

    def refuse_doctype(*_args: object) -> None:
        raise _Refused(
            "DOCTYPE declarations are not accepted in an ENI (no DTD, no entities are resolved)"
        )

    def refuse_entity(*_args: object) -> None:
        raise _Refused("entity declarations and references are not accepted in an ENI")

    building = [start, end, chars]
    skipping = [skip_start, skip_end]
    parser.StartElementHandler = start
    parser.EndElementHandler = end
    parser.CharacterDataHandler = chars
    parser.StartDoctypeDeclHandler = refuse_doctype
    parser.EntityDeclHandler = refuse_entity
    parser.ExternalEntityRefHandler = refuse_entity  # type: ignore[assignment]
    parser.UnparsedEntityDeclHandler = refuse_entity
    try:
        if raw is not None:
            view = memoryview(raw)
            cuts = _cuts(raw, skip | share)
            k, pos, end = 0, 0, len(raw)
            while pos < end:
                if blind > pos:  # a subtree's rest: no handler at all
                    fed = blind
                else:
                    while k < len(cuts) and cuts[k] <= pos:
                        k += 1
                    fed = min(cuts[k] if k < len(cuts) else end, pos + _CHUNK)
                parser.Parse(view[pos:fed], False)
                if blind == fed:  # from its end tag on: end tags, until its own
                    blind = 0
                    parser.EndElementHandler = until_end
                pos = fed
            parser.Parse(b"", True)
        elif isinstance(data, bytes) and len(data) > _CHUNK:
            view = memoryview(data)
            for at in range(0, len(data), _CHUNK):
                parser.Parse(view[at : at + _CHUNK], False)
            parser.Parse(b"", True)
        else:
            parser.Parse(data, True)
    except _Refused as exc:
        raise EniError(str(exc), file=source, line=parser.CurrentLineNumber) from None
    except expat.ExpatError as exc:
        msg = expat.errors.messages.get(exc.code, str(exc)) if exc.code else str(exc)
        raise EniError(f"malformed XML: {msg}", file=source, line=exc.lineno) from None
    except (ValueError, LookupError) as exc:  # an encoding pyexpat cannot use
        raise EniError(f"cannot decode the XML: {shown(str(exc))}", file=source, line=1) from None
    finally:
        # the handlers and the parser refer to each other: without this the cycle (and the
        # whole tree through ``root``) would wait for the cyclic collector
        parser.StartElementHandler = parser.EndElementHandler = None  # type: ignore[assignment]
        parser.CharacterDataHandler = None  # type: ignore[assignment]
        # and the handlers refer to each other through these lists (start and skip_end
        # swap them): emptying them frees the parser and its buffers now
        building.clear()
        skipping.clear()
    if not root:
        raise EniError("empty XML document", file=source)
    return root[0]
