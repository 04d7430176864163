"""The TOML topology format (gtecat.eni.topology docstring) and the ENI it makes."""

from __future__ import annotations

from pathlib import Path

import pytest

from gtecat.eni.errors import EniError
from gtecat.eni.layout import build_layout
from gtecat.eni.model import Direction
from gtecat.eni.topology import (
    GTEC_VENDOR_ID,
    MAX_SLAVES,
    build_config,
    load_topology,
    parse_topology,
    station_address,
)

OUT, IN = Direction.OUT, Direction.IN


def test_servo_defaults_are_figure_5_2_and_carry_assignment_init_cmds() -> None:
    cfg = parse_topology('[[slave]]\nkind = "servo"\n')
    (s,) = cfg.slaves
    assert s.name == "servo 0" and s.identity.vendor_id == GTEC_VENDOR_ID
    assert [(e.index, e.bit_len, e.data_type) for e in s.rx_pdos[0].entries] == [
        (0x6040, 16, "UINT"),
        (0x607A, 32, "DINT"),
    ]
    assert [e.index for e in s.tx_pdos[0].entries] == [0x6041, 0x6064, 0x60FD]
    assert s.mailbox and cfg.cycle_time_ns == 1_000_000
    cmds = [(c.index, c.subindex, c.data) for c in s.init_cmds]
    assert all(c.transitions == ("PS",) for c in s.init_cmds)
    # clear the assignments, map 0x1600 (CiA 301 mapping value index<<16 | sub<<8 | bits)
    assert cmds[:3] == [(0x1C12, 0, b"\x00"), (0x1C13, 0, b"\x00"), (0x1600, 0, b"\x00")]
    assert cmds[3] == (0x1600, 1, (0x60400010).to_bytes(4, "little"))
    assert cmds[4] == (0x1600, 2, (0x607A0020).to_bytes(4, "little"))
    assert cmds[5] == (0x1600, 0, b"\x02")
    # ... then assign 0x1600 to SM2 and 0x1A00 to SM3, count last
    assert cmds[-4:] == [
        (0x1C12, 1, b"\x00\x16"),
        (0x1C12, 0, b"\x01"),
        (0x1C13, 1, b"\x00\x1a"),
        (0x1C13, 0, b"\x01"),
    ]


def test_multi_channel_servo_repeats_profile_objects() -> None:
    cfg = parse_topology(
        '[[slave]]\nkind = "servo"\nchannels = 3\n'
        'rx = ["0x6040:0:16", "0:0:8"]\ntx = ["0x6041:0:16"]\n'
    )
    s = cfg.slaves[0]
    assert [p.index for p in s.rx_pdos] == [0x1600, 0x1610, 0x1620]
    assert [p.entries[0].index for p in s.tx_pdos] == [0x6041, 0x6841, 0x7041]
    assert s.rx_pdos[2].entries[1].is_padding
    assert build_layout(cfg).slaves[0].axes == (1, 2, 3)


def test_io_packing_and_coupler_modules() -> None:
    cfg = parse_topology(
        '[[slave]]\nkind = "io"\ndo = 12\ndi = 3\npacking = "bits"\n'
        '[[slave]]\nkind = "io"\ndo = 12\n'
        '[[slave]]\nkind = "coupler"\ncoupler_word = false\nmodules = ["AO2", "DI8"]\n'
    )
    bits, nbytes, coupler = cfg.slaves
    assert [(e.subindex, e.bit_len) for e in bits.rx_pdos[0].entries][-1] == (12, 1)
    assert len(bits.tx_pdos[0].entries) == 3 and not bits.mailbox
    assert [(e.index, e.subindex, e.bit_len) for e in nbytes.rx_pdos[0].entries] == [
        (0x7000, 1, 8),
        (0x7000, 2, 8),
    ]
    assert nbytes.tx_pdos == ()
    # module 0 AO2 -> 0x7000:01..02; module 1 DI8 -> 0x6010:01
    assert [(e.index, e.subindex) for p in coupler.rx_pdos for e in p.entries] == [
        (0x7000, 1),
        (0x7000, 2),
    ]
    assert [(e.index, e.bit_len) for p in coupler.tx_pdos for e in p.entries] == [(0x6010, 8)]
    assert coupler.mailbox and coupler.init_cmds == ()


def test_generic_with_explicit_pdos_and_logical_layout() -> None:
    cfg = parse_topology("""
cycle_time_us = 250
master = "bench"
[[slave]]
kind = "generic"
name = "G"
vendor_id = 0x2
product_code = "0x044c2c52"
rx_pdos = [{ index = 0x1601, name = "A", entries = ["0x7000:1:1:BOOL:Lamp", "0:0:7"] },
           { index = 0x1602, entries = [{ index = 0x7001, subindex = 2, type = "DINT" }] }]
tx = ["0x6000:1:16:INT"]
""")
    assert cfg.cycle_time_ns == 250_000 and cfg.master_name == "bench"
    s = cfg.slaves[0]
    assert s.identity.product_code == 0x044C2C52
    assert [p.index for p in s.rx_pdos] == [0x1601, 0x1602]
    lamp = s.rx_pdos[0].entries[0]
    assert (lamp.name, lamp.data_type, lamp.logical_bit) == ("Lamp", "BOOL", 0)
    assert s.rx_pdos[1].entries[0].bit_len == 32 and s.rx_pdos[1].entries[0].logical_bit == 8
    assert s.outputs.bit_len == 40 and s.inputs.bit_len == 16
    assert [v.name for v in cfg.variables] == [
        "G.Inputs.0x6000:01",
        "G.A.Lamp",
        "G.RxPDO 0x1602.0x7001:02",
    ]


def test_logical_images_are_zero_based_and_byte_aligned() -> None:
    cfg = parse_topology(
        '[[slave]]\nkind = "io"\ndo = 3\npacking = "bits"\n[[slave]]\nkind = "io"\ndo = 8\n'
    )
    assert cfg.slaves[0].outputs.bit_start == 0 and cfg.slaves[0].outputs.bit_len == 3
    assert cfg.slaves[1].outputs.bit_start == 8
    assert cfg.outputs_bytes == 2 and cfg.inputs_bytes == 0


@pytest.mark.parametrize(
    ("toml", "needle"),
    [
        ('[[slave]]\nkind = "robot"\n', "kind must be"),
        ('[[slave]]\nkind = "servo"\ncolour = 1\n', "unknown key"),
        ('[[slave]]\nkind = "servo"\nrx = ["0x6040:0"]\n', "index:subindex:bits"),
        ('[[slave]]\nkind = "servo"\nrx = ["0x6040:0:zz"]\n', "not an integer"),
        ('[[slave]]\nkind = "servo"\nrx = ["0x6040:0:16:DINT"]\n', "is not 16 bits"),
        ('[[slave]]\nkind = "servo"\nchannels = 9\n', "channels must be"),
        ('[[slave]]\nkind = "servo"\nchannels = 2\nrx = ["0x2000:0:8"]\n', "channel-0"),
        ('[[slave]]\nkind = "coupler"\nmodules = ["XY3"]\n', "is not DIn"),
        ('[[slave]]\nkind = "coupler"\nmodules = ["DI12"]\n', "8, 16 or 32"),
        ('[[slave]]\nkind = "io"\nmailbox = false\ninit_cmds = true\n', "need a mailbox"),
        ('[[slave]]\nkind = "generic"\nrx = ["0x7000:1:8", "0x7000:1:8"]\n', "mapped twice"),
        ('[[slave]]\nkind = "generic"\nname = "a\\u0001"\n', "control characters"),
        ("cycle_time_us = -1\n", "positive"),
        ("slave = 3\n", "array of tables"),
    ],
)
def test_topology_errors(toml: str, needle: str) -> None:
    with pytest.raises(EniError, match=needle) as info:
        parse_topology(toml, "t.toml")
    assert info.value.file == "t.toml"


def test_invalid_toml_names_the_line(tmp_path: Path) -> None:
    p = tmp_path / "bad.toml"
    p.write_text('[[slave]]\nkind = "servo"\nname = \n')
    with pytest.raises(EniError, match="invalid TOML") as info:
        load_topology(p)
    assert info.value.line == 3 and info.value.file == str(p)
    with pytest.raises(EniError, match="cannot read"):
        load_topology(tmp_path / "nope.toml")


def test_station_addresses_reach_every_slave_a_bus_holds() -> None:
    # 1001 + position as TwinCAT numbers them, then the 16-bit addresses left below 1001
    assert MAX_SLAVES == 0xFFFF
    stations = [station_address(p) for p in range(MAX_SLAVES)]
    assert stations[:2] == [1001, 1002] and stations[64534:64536] == [0xFFFF, 1]
    assert stations[-1] == 1000 and sorted(stations) == list(range(1, 0x10000))


def test_more_slaves_than_a_bus_holds_is_refused_before_building() -> None:
    with pytest.raises(EniError, match=r"65536 slaves: an EtherCAT bus holds at most 65535"):
        build_config({"slave": [{"kind": "io"}] * (MAX_SLAVES + 1)})
