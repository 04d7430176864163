"""The SII of ``gtecat serve`` slaves follows what the ENI says about the devices (item 5)."""

from __future__ import annotations

from pathlib import Path

import pytest

from drives.esc.sii import SmType, parse_sii
from gtecat.cli.serve_cmd import build_chain
from gtecat.wire.eni_wire import product_name, read_wire
from tests.conftest import needs_fixture

ROOT = Path(__file__).resolve().parents[3]
TWINCAT = ROOT.parent / "shared" / "fixtures" / "eni" / "twincat_ek1100_el2008_el4002_el1809.xml"
EXAMPLES = ROOT / "examples"


def sii_of(eni: Path) -> list:
    chain, _ = build_chain(eni)
    return [parse_sii(bytes(esc.sii)) for esc in chain.escs], chain


def test_beckhoff_terminals_get_their_own_sm_layout() -> None:
    if not TWINCAT.is_file():
        pytest.skip(needs_fixture(TWINCAT.name))
    infos, chain = sii_of(TWINCAT)
    el2008, el4002, el1809 = infos[1], infos[2], infos[3]
    assert [(s.start, s.length, s.control, s.type) for s in el2008.sync_managers] == [
        (0x0F00, 1, 0x44, SmType.OUTPUTS)
    ]
    assert el2008.rx_pdos[0].sm == 0 and el2008.pdi_control == 0x0104
    assert [(s.start, s.type) for s in el1809.sync_managers] == [(0x1000, SmType.INPUTS)]
    sm = el4002.sync_managers
    assert (sm[0].start, sm[0].length, sm[1].start) == (0x1000, 128, 0x1080)
    assert (sm[2].start, sm[2].length, sm[2].control) == (0x1100, 4, 0x24)
    assert (sm[3].start, sm[3].length, sm[3].enable) == (0x1180, 0, 0)
    el4002_od = chain.escs[2].slave.od
    assert el4002_od.upload(0x1008, 0) == b"EL4002"


def test_drives_name_their_product_and_list_their_mapping() -> None:
    infos, chain = sii_of(EXAMPLES / "manual_fig5_2.eni")
    drive = infos[0]
    assert [e.index for p in drive.tx_pdos for e in p.entries] == [0x6041, 0x6064, 0x60FD]
    assert [e.index for p in drive.rx_pdos for e in p.entries] == [0x6040, 0x607A]
    name = chain.escs[0].slave.od.upload(0x1008, 0)
    assert b"gtecat" not in name and name == drive.name.encode()


def test_twelve_axes_modules_are_not_the_single_axis_drive() -> None:
    infos, _ = sii_of(EXAMPLES / "twelve_axes.eni")
    drive, module = infos[0], infos[4]
    assert drive.identity.product_code != module.identity.product_code
    assert module.ds402_channels == 4


@pytest.mark.parametrize(
    ("name", "revision", "product"),
    [
        ("Term 2 (EL2008)", "EL2008-0000-0018", "EL2008"),
        ("Term 2 (EL2008)", None, "EL2008"),
        ("GTHD 0", None, "GTHD 0"),
    ],
)
def test_product_name(name: str, revision: str | None, product: str) -> None:
    assert product_name(name, revision) == product


def test_a_googol_ini_states_no_wire_layout(tmp_path: Path) -> None:
    ini = ROOT.parent / "shared" / "fixtures" / "googol"
    files = sorted(ini.glob("*")) if ini.is_dir() else []
    eni = next((f for f in files if f.suffix.lower() in (".eni", ".ini")), None)
    if eni is None:
        pytest.skip(needs_fixture("a Googol INI Gecat.eni"))
    assert read_wire(eni) is None


def test_a_googol_ini_drive_names_its_product_in_1008h() -> None:
    """Googol's configuration tool writes the device's ESI name as ``slavename``; the drive
    answers it in 1008h (an outside check read "gtecat virtual CiA-402 servo drive")."""
    eni = ROOT.parent / "shared" / "fixtures" / "googol" / "Gecat_DM3E_stepper.eni"
    if not eni.is_file():
        pytest.skip(needs_fixture(eni.name))
    infos, chain = sii_of(eni)
    assert chain.escs[0].slave.od.upload(0x1008, 0) == b"DM3E_522_COE_"
    assert infos[0].name == "DM3E_522_COE_"
