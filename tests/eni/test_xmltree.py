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
