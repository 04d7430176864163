"""gtecat.eni.xmltree.parse_xml: the tree the readers walk, and the subtrees they skip."""

from __future__ import annotations

import pytest

from gtecat.eni.errors import EniError
from gtecat.eni.xmltree import parse_xml

DOC = """<?xml version="1.0"?>
<Config>
  <Master><InitCmds><InitCmd><Cmd>7</Cmd></InitCmd></InitCmds><Info><Name>m</Name></Info></Master>
  <Slave>
    <Info><Name>s</Name></Info>
    <Mailbox><CoE><InitCmds><InitCmd><Index>#x6060</Index></InitCmd></InitCmds></CoE></Mailbox>
    <InitCmds><InitCmd><Cmd>2</Cmd><InitCmds/></InitCmd></InitCmds>
    <ProcessData><Send><BitLength>8</BitLength></Send></ProcessData>
  </Slave>
</Config>
"""
SKIP = frozenset({("Master", "InitCmds"), ("Slave", "InitCmds")})


def test_skipped_subtrees_are_not_built_and_the_rest_is() -> None:
    root = parse_xml(DOC, "x.xml", SKIP)
    slave = root.find("Slave")
    assert slave is not None and root.find("Master/InitCmds") is None
    assert [c.tag for c in slave.children] == ["Info", "Mailbox", "ProcessData"]
    assert slave.findtext("Mailbox/CoE/InitCmds/InitCmd/Index") == "#x6060"  # CoE parent
    assert slave.findtext("ProcessData/Send/BitLength") == "8"
    assert root.findtext("Master/Info/Name") == "m"
    full = parse_xml(DOC, "x.xml")
    assert full.findtext("Slave/InitCmds/InitCmd/Cmd") == "2"


def test_a_skipped_subtree_must_still_be_well_formed() -> None:
    broken = DOC.replace("<Cmd>2</Cmd>", "<Cmd>2</Cdm>")
    with pytest.raises(EniError, match=r"malformed XML: mismatched tag") as err:
        parse_xml(broken, "x.xml", SKIP)
    assert err.value.line == 7


# --- subtrees repeated byte for byte, and subtrees fed to expat with no handler -------------

SHARE = frozenset({("Slave", "Mailbox")})
SLAVE = """  <Slave>
    <Info><Name>{name}</Name></Info>
    <InitCmds>{junk}<InitCmd><Cmd>{k}</Cmd></InitCmd></InitCmds>
    <Mailbox><CoE><InitCmds><InitCmd Fixed="1"><Index>#x6060</Index><Data>08</Data></InitCmd>
      </InitCmds></CoE>{tail}</Mailbox>
  </Slave>
"""


def _doc(tails: list[str], junk: str = "") -> str:
    body = "".join(SLAVE.format(name=f"s{k}", k=k, tail=t, junk=junk) for k, t in enumerate(tails))
    return f'<?xml version="1.0"?>\n<Config>\n{body}</Config>\n'


def _same(a, b) -> None:  # type: ignore[no-untyped-def]
    assert (a.tag, a.attrib, a.text.strip(), len(a.children)) == (
        b.tag,
        b.attrib,
        b.text.strip(),
        len(b.children),
    )
    if a.tag == "Slave":
        assert a.line == b.line
    for x, y in zip(a.children, b.children, strict=True):
        _same(x, y)


@pytest.mark.parametrize(
    "junk",
    [
        "",
        "<!-- </InitCmds> -->",
        "<![CDATA[</InitCmds>]]>",
        "<?pi </InitCmds>?>",
        "<InitCmds/>",
        "<InitCmd><InitCmds><InitCmds/></InitCmds></InitCmd>",
        '<InitCmd Comment="a>b"/>',
    ],
)
def test_repeated_and_skipped_subtrees_give_the_tree_read_element_by_element(junk: str) -> None:
    text = _doc(["", "", "<Send>1</Send>", ""], junk)
    # as text, expat's byte positions are not the document's: every element reaches Python
    plain = parse_xml(text, "x.xml", SKIP)
    fast = parse_xml(text.encode(), "x.xml", SKIP, SHARE)
    _same(plain, fast)
    boxes = [s.find("Mailbox") for s in fast.findall("Slave")]
    assert boxes[0] is boxes[1] is boxes[3] and boxes[2] is not boxes[0]
    assert [s.line for s in fast.findall("Slave")] == [
        i + 1 for i, line in enumerate(text.splitlines()) if line == "  <Slave>"
    ]


def test_pieces_of_any_size(monkeypatch: pytest.MonkeyPatch) -> None:
    import gtecat.eni.xmltree as xmltree

    text = _doc(["", "<Send>1</Send>", "", ""], "<!-- x -->").encode()
    whole = parse_xml(text, "x.xml", SKIP, SHARE)
    for size in (1, 7, 64):
        monkeypatch.setattr(xmltree, "_CHUNK", size)
        _same(whole, parse_xml(text, "x.xml", SKIP, SHARE))


def test_a_repeated_subtree_still_must_be_well_formed() -> None:
    text = _doc(["", "", ""]).encode()
    at = text.rindex(b"<Data>08</Data>")
    broken = text[:at] + b"<Data>08</Dat>" + text[at + len(b"<Data>08</Data>") :]
    with pytest.raises(EniError, match="mismatched tag") as err:
        parse_xml(broken, "x.xml", SKIP, SHARE)
    assert err.value.line == broken[:at].count(b"\n") + 1


def test_a_reader_error_is_found_again_without_sharing(monkeypatch: pytest.MonkeyPatch) -> None:
    """Lines inside a shared subtree are its first occurrence's: an ENI the reader refuses
    is read again from a tree with the line of every element."""
    import gtecat.eni.reader as reader
    from gtecat.eni.writer import write_eni
    from tools.gen_axes_eni import axes_config

    text = write_eni(axes_config(3)).encode()
    trees: list[bool] = []

    def refuse(root, source):  # type: ignore[no-untyped-def]
        boxes = [s.find("Mailbox") for s in root.findall("Config/Slave")]
        trees.append(boxes[0] is boxes[2])
        raise EniError("refused", file=source, line=boxes[2].line)

    monkeypatch.setattr(reader, "read_xml", refuse)
    with pytest.raises(EniError) as err:
        reader.parse_eni(text, "x.xml")
    assert trees == [True, False]
    assert err.value.line == text[: text.rindex(b"<Mailbox")].count(b"\n") + 1
