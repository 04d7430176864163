"""Inconsistent or hostile configuration files raise EniError naming file, line, slave, element."""

from __future__ import annotations

from pathlib import Path

import pytest

from gtecat.eni.errors import EniError
from gtecat.eni.reader import parse_eni, read_eni

from .snippets import (
    area,
    eni,
    entry,
    image,
    line_of,
    pdo,
    process_data,
    servo_slave,
    slave,
    variable,
)


def _raises(text: str, source: str = "bad.eni") -> EniError:
    with pytest.raises(EniError) as info:
        parse_eni(text, source)
    err = info.value
    assert err.file == source
    assert str(err).startswith(source)
    return err


def test_overlapping_send_areas() -> None:
    text = eni(servo_slave("A", phys=1001) + servo_slave("B", start_out=32, start_in=80, phys=1002))
    err = _raises(text)
    assert err.slave == 1 and err.slave_name == "B"
    assert err.line == line_of(text, "<Slave>", 1)
    assert "overlap" in err.message and "slave 0 (A)" in err.message


def test_overlapping_variables_in_a_file_without_pdo_lists() -> None:
    body = process_data(area("Send", 0, 32))
    outs = variable("S.a", 0, 16) + variable("S.b", 8, 16)
    text = eni(slave("S", body), image("", outs))
    err = _raises(text)
    assert err.line == line_of(text, "<Variable><Name>S.b")
    assert "overlaps" in err.message and err.slave == 0


def test_sizes_that_do_not_add_up() -> None:
    rx = pdo("RxPdo", "#x1600", entry("#x7000", 1, 16) + entry("#x7000", 2, 32), sm=2)
    text = eni(slave("S", process_data(area("Send", 0, 40) + rx)))
    err = _raises(text)
    assert err.line == line_of(text, "<Send>")
    assert "48 bits" in err.message and "40" in err.message
    assert err.element == "ProcessData/Send"


def test_duplicate_physical_addresses() -> None:
    text = eni(servo_slave("A", phys=1001) + servo_slave("B", 48, 80, phys=1001))
    err = _raises(text)
    assert err.slave == 1 and err.line == line_of(text, "<Slave>", 1)
    assert "PhysAddr 1001" in err.message and err.element == "Info/PhysAddr"


def test_unknown_data_type_without_bit_length() -> None:
    rx = pdo(
        "RxPdo", "#x1600", entry("#x7000", 1, 8) + entry("#x7000", 2, None, "x", "FANCY"), sm=2
    )
    text = eni(slave("S", process_data(area("Send", 0, 8) + rx)))
    err = _raises(text)
    assert err.line == line_of(text, "<Entry>", 1)
    assert "FANCY" in err.message and "0x7000:02" in err.element


def test_entry_without_bit_length_or_type() -> None:
    rx = pdo("RxPdo", "#x1600", entry("#x7000", 1, None), sm=2)
    err = _raises(eni(slave("S", process_data(rx))))
    assert "no BitLen" in err.message


@pytest.mark.parametrize("missing", ["vendor", "product"])
def test_missing_identity(missing: str) -> None:
    kwargs = {missing: ""}
    text = eni(slave("S", "", **kwargs))
    err = _raises(text)
    assert err.line == line_of(text, "<Info>", 1)  # the slave's, after the master's
    assert ("VendorId" if missing == "vendor" else "ProductCode") in err.message
    assert err.slave == 0 and err.slave_name == "S"


def test_truncated_xml() -> None:
    text = eni(servo_slave())
    cut = text[: text.index("<TxPdo")]
    err = _raises(cut)
    assert err.line == cut.count("\n") + 1
    assert "malformed XML" in err.message


def test_doctype_with_external_entity_is_refused(tmp_path: Path) -> None:
    secret = tmp_path / "secret.txt"
    secret.write_text("TOP SECRET")
    text = (
        '<?xml version="1.0"?>\n'
        f'<!DOCTYPE EtherCATConfig [<!ENTITY x SYSTEM "file://{secret}">]>\n'
        "<EtherCATConfig><Config><Slave><Info><Name>&x;</Name>"
        "<VendorId>1</VendorId><ProductCode>1</ProductCode></Info></Slave></Config>"
        "</EtherCATConfig>\n"
    )
    err = _raises(text)
    assert err.line == 2 and "DOCTYPE" in err.message
    assert "TOP SECRET" not in str(err)


def test_billion_laughs_is_refused() -> None:
    text = (
        '<?xml version="1.0"?>\n<!DOCTYPE lolz [\n<!ENTITY lol "lol">\n'
        '<!ENTITY lol2 "&lol;&lol;&lol;&lol;&lol;&lol;&lol;&lol;&lol;&lol;">\n]>\n'
        "<EtherCATConfig>&lol2;</EtherCATConfig>\n"
    )
    err = _raises(text)
    assert err.line == 2


def test_undefined_entity_reference() -> None:
    err = _raises('<?xml version="1.0"?>\n<EtherCATConfig>\n&xxe;</EtherCATConfig>')
    assert err.line == 3


def test_stated_offset_contradicting_send_and_mapping() -> None:
    outs = variable("Drive.Outputs.Controlword", 0, 16) + variable(
        "Drive.Outputs.Target position", 24, 32
    )
    text = eni(servo_slave(), image("", outs))
    err = _raises(text)
    assert err.line == line_of(text, "<Variable><Name>Drive.Outputs.Target position")
    assert "bit 24" in err.message and "bit 16" in err.message
    assert "0x607A:00" in err.element


def test_variable_size_differs_from_entry() -> None:
    text = eni(servo_slave(), image(variable("Drive.Inputs.Statusword", 0, 8), ""))
    err = _raises(text)
    assert err.line == line_of(text, "<Variable>")
    assert "8 bits" in err.message


def test_byte_size_too_small() -> None:
    text = eni(servo_slave(), image("", "", 10, 4))
    err = _raises(text)
    assert err.line == line_of(text, "<ByteSize>4")
    assert "ByteSize 4" in err.message


def test_sm_assigns_a_pdo_the_file_does_not_describe() -> None:
    rx = pdo("RxPdo", "#x1600", entry("#x7000", 1, 8))
    sms = "<Sm2><Type>Outputs</Type><Pdo>#x1600</Pdo>\n<Pdo>#x1601</Pdo></Sm2>\n"
    text = eni(slave("S", process_data(area("Send", 0, 16) + sms + rx)))
    err = _raises(text)
    assert err.line == line_of(text, "<Pdo>#x1601")
    assert "#x1601" in err.message


def test_object_mapped_twice() -> None:
    rx = pdo("RxPdo", "#x1600", entry("#x7000", 1, 8) + entry("#x7000", 1, 8), sm=2)
    text = eni(slave("S", process_data(area("Send", 0, 16) + rx)))
    err = _raises(text)
    assert "mapped twice" in err.message and err.line == line_of(text, "<Slave>")


def test_non_contiguous_send_areas() -> None:
    rx = pdo("RxPdo", "#x1600", entry("#x7000", 1, 16), sm=2)
    text = eni(slave("S", process_data(area("Send", 0, 8) + area("Send", 64, 8) + rx)))
    err = _raises(text)
    assert err.line == line_of(text, "<Send>", 1) and "non-contiguous" in err.message


@pytest.mark.parametrize(
    ("bad", "needle"),
    [("<Index>#xZZ</Index>", "#xZZ"), ("<BitLen>-3</BitLen>", "<BitLen>-3")],
)
def test_bad_numbers(bad: str, needle: str) -> None:
    rx = pdo("RxPdo", "#x1600", f"<Entry><Index>#x7000</Index>{bad}</Entry>\n", sm=2)
    if "Index" in bad:
        rx = pdo("RxPdo", "#x1600", f"<Entry>{bad}<BitLen>8</BitLen></Entry>\n", sm=2)
    text = eni(slave("S", process_data(rx)))
    err = _raises(text)
    assert err.line == line_of(text, needle)


def test_bad_init_cmds() -> None:
    cmd = (
        "<Mailbox><CoE><InitCmds>\n<InitCmd><Transition>PS</Transition><Ccs>3</Ccs>"
        "<Index>1</Index></InitCmd>\n</InitCmds></CoE></Mailbox>\n"
    )
    text = eni(slave("S", cmd))
    err = _raises(text)
    assert err.line == line_of(text, "<InitCmd>") and "Ccs 3" in err.message
    cmd = (
        "<Mailbox><CoE><InitCmds>\n<InitCmd><Transition>PS</Transition><Index>1</Index>\n"
        "<Data>0g</Data></InitCmd>\n</InitCmds></CoE></Mailbox>\n"
    )
    text = eni(slave("S", cmd))
    assert _raises(text).line == line_of(text, "<Data>")
    cmd = "<Mailbox><CoE><InitCmds>\n<InitCmd><Index>1</Index></InitCmd></InitCmds></CoE></Mailbox>"
    assert "Transition" in _raises(eni(slave("S", cmd))).message


def test_wrong_root_and_missing_config() -> None:
    assert "no <Config>" in _raises("<EtherCATConfig>\n</EtherCATConfig>").message


def test_files_that_cannot_be_read(tmp_path: Path) -> None:
    with pytest.raises(EniError, match="cannot read") as info:
        read_eni(tmp_path / "missing.eni")
    assert info.value.file.endswith("missing.eni")
    empty = tmp_path / "empty.eni"
    empty.write_bytes(b"  \n")
    with pytest.raises(EniError, match="empty"):
        read_eni(empty)
