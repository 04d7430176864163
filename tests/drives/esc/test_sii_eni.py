"""The SII of virtual slaves follows what the ENI says about the devices, the same on
``gtecat serve`` and in-process; the ENI reader is the only one that reads it."""

from __future__ import annotations

import re
from pathlib import Path

import pytest

from gtecat.cli.serve_cmd import build_chain
from gtecat.drives.esc.sii import SmType, parse_sii
from gtecat.drives.esc.sii_eni import product_name
from gtecat.eni.model import Direction
from gtecat.eni.reader import read_eni
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
    config = read_eni(eni)
    assert all(not s.sync_managers and s.mailbox_layout is None for s in config.slaves)


def test_a_googol_ini_drive_names_its_product_in_1008h() -> None:
    """Googol's configuration tool writes the device's ESI name as ``slavename``; the drive
    answers it in 1008h (an outside check read "gtecat virtual CiA-402 servo drive")."""
    eni = ROOT.parent / "shared" / "fixtures" / "googol" / "Gecat_DM3E_stepper.eni"
    if not eni.is_file():
        pytest.skip(needs_fixture(eni.name))
    infos, chain = sii_of(eni)
    assert chain.escs[0].slave.od.upload(0x1008, 0) == b"DM3E_522_COE_"
    assert infos[0].name == "DM3E_522_COE_"


def _twincat() -> Path:
    if not TWINCAT.is_file():
        pytest.skip(f"shared fixture {TWINCAT} not found")
    return TWINCAT


@pytest.mark.parametrize(
    ("true", "false"), [("true", "false"), ("1", "0"), (" true ", "\n false\n"), ("1 ", " 0")]
)
def test_enable_takes_every_xs_boolean_form(tmp_path: Path, true: str, false: str) -> None:
    """ETG.2100 writes ``<Enable>`` as xs:boolean: ``true``/``false`` as well as 1/0; the
    reader and therefore ``gtecat serve`` take every form (serve once refused ``true``)."""
    text = _twincat().read_text(encoding="utf-8")
    assert "<Enable>1</Enable>" in text
    mutated = text.replace("<Enable>1</Enable>", f"<Enable>{true}</Enable>").replace(
        "<Enable>0</Enable>", f"<Enable>{false}</Enable>"
    )
    eni = tmp_path / "bool.xml"
    eni.write_text(mutated, encoding="utf-8")
    original, changed = read_eni(TWINCAT), read_eni(eni)
    assert [s.sync_managers for s in changed.slaves] == [s.sync_managers for s in original.slaves]
    el4002 = changed.slaves[2].sync_managers
    assert [(sm.number, sm.direction, sm.enable) for sm in el4002] == [
        (2, Direction.OUT, True),
        (3, Direction.IN, False),
    ]
    chain, _ = build_chain(eni)  # what serve builds
    assert parse_sii(bytes(chain.escs[2].sii)).sync_managers[3].enable == 0


@pytest.mark.parametrize("word", ["yes", "True1", "2", "on"])
def test_an_enable_that_is_no_xs_boolean_is_refused_with_its_line(tmp_path: Path, word) -> None:
    from gtecat.eni.errors import EniError

    text = (
        _twincat()
        .read_text(encoding="utf-8")
        .replace("<Enable>1</Enable>", f"<Enable>{word}</Enable>", 1)
    )
    eni = tmp_path / "bad.xml"
    eni.write_text(text, encoding="utf-8")
    with pytest.raises(EniError, match="xs:boolean") as info:
        read_eni(eni)
    assert re.search(r"bad\.xml:\d+: slave 1 ", str(info.value))


def test_serve_and_in_process_show_the_same_sii(tmp_path: Path) -> None:
    """``gtecat sii read`` in-process and a master reading ``gtecat serve``'s EEPROM see the
    same bytes for every slave, IO terminals included."""
    from gtecat import gt

    eni = _twincat()
    chain, config = build_chain(eni)
    assert gt.GT_Open(eni=str(eni), clock="lockstep", log="") == 0
    try:
        assert gt.GT_InitEcatComm() == 0
        from gtecat.controller.inspect import BusView

        view = BusView(gt.GTE_Controller())
        for pos, esc in enumerate(chain.escs):
            assert view.sii(pos) == bytes(esc.sii), f"slave {pos} ({config.slaves[pos].name})"
    finally:
        gt.GT_Close()
