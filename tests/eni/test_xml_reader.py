"""ETG.2100 XML reading: the variants real tools write (hand-written, one idea per test)."""

from __future__ import annotations

import pytest

from gtecat.eni.errors import EniError
from gtecat.eni.layout import build_layout
from gtecat.eni.model import Direction
from gtecat.eni.reader import detect_format, parse_eni

from .snippets import (
    area,
    eni,
    entry,
    image,
    pdo,
    process_data,
    servo_slave,
    slave,
    variable,
)

OUT, IN = Direction.OUT, Direction.IN


def test_minimal_servo_and_cycle_time() -> None:
    cfg = parse_eni(eni(servo_slave(), cycle_us=500), "t.xml")
    assert cfg.cycle_time_ns == 500_000
    assert cfg.master_name == "test master"
    (s,) = cfg.slaves
    assert (s.identity.vendor_id, s.identity.product_code) == (2, 1)
    assert s.out_bits == 48 and s.in_bits == 80
    assert s.outputs.bit_start == 0 and s.inputs.bit_len == 80
    # no ProcessImage: image sizes cover the areas
    assert (cfg.outputs_bytes, cfg.inputs_bytes) == (6, 10)
    assert build_layout(cfg).axes[0].slave == 0


def test_namespaces_and_prefixes_are_ignored() -> None:
    text = eni(servo_slave(), root_attrs=' xmlns="urn:ethercat:config" Version="1.3"')
    assert parse_eni(text, "ns.xml").slaves[0].out_bits == 48
    prefixed = text.replace("<", "<ec:").replace("<ec:/", "</ec:").replace("<ec:?xml", "<?xml")
    prefixed = prefixed.replace("<ec:EtherCATConfig", '<ec:EtherCATConfig xmlns:ec="urn:x"', 1)
    cfg = parse_eni(prefixed, "prefixed.xml")
    assert cfg.slaves[0].in_bits == 80


@pytest.mark.parametrize("spelling", ["#x6040", "0x6040", "24640", "#X6040"])
def test_hex_and_decimal_spellings(spelling: str) -> None:
    rx = pdo("RxPdo", "5632", entry(spelling, 0, 16), sm=2)
    text = eni(slave("S", process_data(area("Send", 0, 16) + rx), vendor="0x00000002", product="1"))
    s = parse_eni(text, "t.xml").slaves[0]
    assert s.rx_pdos[0].index == 0x1600
    assert s.rx_pdos[0].entries[0].index == 0x6040
    assert s.identity.vendor_id == 2


def test_only_assigned_pdos_count_and_sm_list_order() -> None:
    # 0x1601 is offered but not assigned; Sm2 lists 0x1602 before 0x1600
    rx = (
        pdo("RxPdo", "#x1600", entry("#x7000", 1, 8))
        + pdo("RxPdo", "#x1601", entry("#x7001", 1, 32))
        + pdo("RxPdo", "#x1602", entry("#x7002", 1, 16))
    )
    sms = "<Sm2><Type>Outputs</Type><Pdo>#x1602</Pdo><Pdo>#x1600</Pdo></Sm2>\n"
    s = parse_eni(eni(slave("S", process_data(area("Send", 8, 24) + sms + rx))), "t").slaves[0]
    assert [p.index for p in s.rx_pdos] == [0x1602, 0x1600]
    assert all(p.sm == 2 for p in s.rx_pdos)
    layout = build_layout(
        parse_eni(eni(slave("S", process_data(area("Send", 8, 24) + sms + rx))), "t")
    )
    assert layout.entry(0, 0x7002, 1).logical_bit == 8
    assert layout.entry(0, 0x7000, 1).logical_bit == 24
    assert layout.entry(0, 0x7001, 1) is None


def test_sm_attribute_assigns_and_direction_comes_from_pdo_kind() -> None:
    # a terminal without mailbox: inputs on SM0 (TwinCAT EL1xxx style)
    tx = pdo("TxPdo", "#x1A00", entry("#x6000", 1, 1, "In 1", "BIT"), sm=0) + pdo(
        "TxPdo", "#x1A01", entry("#x6010", 1, 1, "In 2", "BIT"), sm=0
    )
    unassigned = pdo("TxPdo", "#x1A02", entry("#x6020", 1, 1))
    s = parse_eni(
        eni(slave("T", process_data(area("Recv", 100, 2) + tx + unassigned))), "t"
    ).slaves[0]
    assert s.rx_pdos == ()
    assert [p.index for p in s.tx_pdos] == [0x1A00, 0x1A01]
    assert [p.direction for p in s.tx_pdos] == [IN, IN]
    layout = build_layout(
        parse_eni(eni(slave("T", process_data(area("Recv", 100, 2) + tx + unassigned))), "t")
    )
    assert layout.entry(0, 0x6010, 1).logical_bit == 101
    assert layout.slaves[0].in_bytes == 1


def test_bit_length_from_data_type_and_padding() -> None:
    rx = pdo(
        "RxPdo",
        "#x1600",
        entry("#x7000", 1, None, "Word", "UINT")
        + "<Entry><Index>#x0</Index><BitLen>6</BitLen></Entry>\n"
        + entry("#x7000", 2, 2, "Two bits", "BIT2"),
        sm=2,
    )
    s = parse_eni(eni(slave("S", process_data(area("Send", 0, 24) + rx))), "t").slaves[0]
    e0, pad, e2 = s.rx_pdos[0].entries
    assert e0.bit_len == 16 and pad.is_padding and pad.bit_len == 6 and e2.bit_len == 2
    layout = build_layout(parse_eni(eni(slave("S", process_data(area("Send", 0, 24) + rx))), "t"))
    assert layout.entry(0, 0x7000, 2).gt_bit == 22
    assert layout.slaves[0].out_bytes == 3


def test_send_length_rounded_to_whole_bytes_is_accepted() -> None:
    rx = pdo("RxPdo", "#x1600", entry("#x7000", 1, 1) + entry("#x7000", 2, 1), sm=2)
    s = parse_eni(eni(slave("S", process_data(area("Send", 16, 8) + rx))), "t").slaves[0]
    assert s.out_bits == 2 and s.outputs.bit_len == 2


def test_variables_give_logical_bits_and_are_checked() -> None:
    vars_out = variable("Drive.Outputs.Controlword", 0, 16, "UINT") + variable(
        "Drive.Outputs.Target position", 16, 32, "DINT"
    )
    vars_in = variable("Drive.Inputs.Statusword", 0, 16) + variable("Other", 4000, 8)
    cfg = parse_eni(eni(servo_slave(), image(vars_in, vars_out, 64, 64)), "t")
    s = cfg.slaves[0]
    assert [e.logical_bit for e in s.rx_pdos[0].entries] == [0, 16]
    assert [e.logical_bit for e in s.tx_pdos[0].entries] == [0, None, None]
    assert (cfg.outputs_bytes, cfg.inputs_bytes) == (64, 64)
    assert [v.name for v in cfg.variables][:2] == ["Drive.Inputs.Statusword", "Other"]


def test_frame_relative_offsets_are_taken_as_written() -> None:
    text = eni(
        servo_slave(start_out=8 * 26, start_in=8 * 40),
        image(
            variable("Drive.Inputs.Statusword", 320, 16),
            variable("Drive.Outputs.Controlword", 208, 16),
            1536,
            1536,
        ),
    )
    layout = build_layout(parse_eni(text, "t"))
    assert layout.entry(0, 0x6040).logical_bit == 208
    assert layout.entry(0, 0x6041).logical_bit == 320
    assert layout.entry(0, 0x6064).logical_bit == 336  # derived from Recv + mapping order
    assert layout.entry(0, 0x6041).gt_bit == 48  # GT raw view ignores frame offsets
    assert (layout.outputs_bytes, layout.inputs_bytes) == (1536, 1536)


def test_no_pdo_lists_synthesised_from_variables() -> None:
    """A file with Send/Recv and ProcessImage variables but no RxPdo/TxPdo."""
    body = process_data(area("Send", 16, 56) + area("Recv", 0, 40))
    outs = variable("Axis.Controlword", 16, 16, "UINT") + variable(
        "Axis.Target position", 40, 32, "DINT"
    )  # a gap of 8 bits at 32
    ins = variable("Axis.Statusword", 0, 16, "UINT") + variable("Axis.Io.0x60FD:00", 16, 24)
    cfg = parse_eni(eni(slave("Axis", body), image(ins, outs, 10, 9)), "syn.xml")
    s = cfg.slaves[0]
    out = s.rx_pdos[0].entries
    assert [(e.index, e.bit_len, e.logical_bit) for e in out] == [
        (0x6040, 16, 16),
        (0, 8, None),
        (0x607A, 32, 40),
    ]
    assert out[0].name == "Controlword"
    assert s.out_bits == 56 and s.in_bits == 40
    ins_e = s.tx_pdos[0].entries
    assert (ins_e[1].index, ins_e[1].subindex) == (0x60FD, 0)
    layout = build_layout(cfg)
    assert layout.slaves[0].axes == (1,)  # controlword + statusword named: an axis
    assert layout.entry(0, 0x6041).gt_bit == 7 * 8
    # nothing to name the area by: one padding entry keeps the size
    bare = parse_eni(eni(slave("Bare", process_data(area("Send", 0, 12)))), "b").slaves[0]
    assert bare.out_bits == 12 and bare.rx_pdos[0].entries[0].is_padding


def test_unassigned_pdos_taken_only_when_they_fill_the_area() -> None:
    rx = pdo("RxPdo", "#x1600", entry("#x7000", 1, 16))
    s = parse_eni(eni(slave("S", process_data(area("Send", 0, 16) + rx))), "t").slaves[0]
    assert [p.index for p in s.rx_pdos] == [0x1600]
    s = parse_eni(eni(slave("S", process_data(area("Send", 0, 24) + rx))), "t").slaves[0]
    assert s.rx_pdos[0].index == 0x1600 and s.rx_pdos[0].entries[0].is_padding


def test_init_cmds() -> None:
    cmds = """<Mailbox><Protocol>CoE</Protocol><CoE><InitCmds>
<InitCmd CompleteAccess="true"><Transition>PS</Transition><Transition>IP</Transition>
<Comment>assign</Comment><Timeout>3000</Timeout><Ccs>1</Ccs><Index>#x1c12</Index>
<SubIndex>0</SubIndex><Data>0100 0016</Data></InitCmd>
<InitCmd><Transition>ps</Transition><Ccs>2</Ccs><Index>24672</Index></InitCmd>
</InitCmds></CoE></Mailbox>
"""
    s = parse_eni(eni(slave("M", cmds)), "t").slaves[0]
    assert s.mailbox
    a, b = s.init_cmds
    assert a.transitions == ("PS", "IP") and a.complete_access and a.timeout_ms == 3000
    assert (a.index, a.subindex, a.data, a.comment, a.upload) == (
        0x1C12,
        0,
        b"\x01\x00\x00\x16",
        "assign",
        False,
    )
    assert (b.transitions, b.index, b.upload, b.data) == (("PS",), 0x6060, True, b"")
    no_mbx = parse_eni(eni(slave("N")), "t").slaves[0]
    assert not no_mbx.mailbox and no_mbx.init_cmds == ()


def test_optional_elements_absent() -> None:
    cfg = parse_eni(eni(slave("Bare", ""), cycle_us=None), "t")
    s = cfg.slaves[0]
    assert s.rx_pdos == () and s.outputs is None and s.phys_addr == 0
    assert cfg.cycle_time_ns is None and cfg.variables == ()
    layout = build_layout(cfg)
    assert layout.gt_raw_bytes == 0 and layout.slaves[0].gt_size == 0


def test_pdos_without_area_are_placed_after_the_others() -> None:
    rx = pdo("RxPdo", "#x1600", entry("#x7000", 1, 8), sm=2)
    text = eni(servo_slave() + slave("NoArea", process_data(rx)))
    cfg = parse_eni(text, "t")
    assert cfg.slaves[1].outputs.bit_start == 48
    assert build_layout(cfg).entry(1, 0x7000, 1).logical_bit == 48


def test_utf16_and_latin1_files() -> None:
    text = eni(slave("Ä-Slave", ""))
    cfg = parse_eni(("\ufeff" + text.replace("utf-8", "utf-16")).encode("utf-16-le"), "u16")
    assert cfg.slaves[0].name == "Ä-Slave"
    latin = text.replace("utf-8", "iso-8859-1").encode("latin-1")
    assert parse_eni(latin, "l1").slaves[0].name == "Ä-Slave"


def test_format_detection() -> None:
    assert detect_format(eni(slave("S"))) == "xml"
    assert detect_format("<!-- c -->\n<EtherCATConfig/>") == "xml"
    assert detect_format(b"<?xml version='1.0'?><EncryptedEtherCATConfig/>") == "encrypted"
    assert detect_format("//x\n[CommonInfo]\nParam0=name=version") == "googol"
    assert detect_format("hello") == "unknown"
    assert detect_format("<html/>") == "unknown"


def test_encrypted_eni_is_refused() -> None:
    with pytest.raises(EniError, match="EncryptedEtherCATConfig"):
        parse_eni(
            '<?xml version="1.0"?>\n<EncryptedEtherCATConfig><Data>xx</Data>'
            "</EncryptedEtherCATConfig>",
            "enc.eni",
        )


def test_not_an_eni() -> None:
    with pytest.raises(EniError, match="not an ENI") as info:
        parse_eni("just some text", "x.eni")
    assert info.value.file == "x.eni"
