"""One ENI reader, two faces: ``gtecat serve``'s chain and the in-process bus see the same
devices in every spelling ETG.2100 allows.

The generated ENIs are real files respelled: every xs:boolean (``<Enable>``) as ``true`` /
``false`` or ``1`` / ``0``, every number of the wire layout (sync manager start, length and
control byte, mailbox, addresses, identity, PDO indexes and bit sizes) as decimal (leading
zeros, a plus sign) or ``#x`` hexadecimal (either case of digits, zero padded), blanks
around.  Each must give what the file as written gives: the model the reader builds, the
process image layout (where the FMMUs map), and the SII bytes of every slave - built by
``gtecat serve`` (what a master reading the EEPROM finds: sync managers, mailbox, FMMU
usage, PDOs) and by the in-process bus (``gtecat sii read``).
"""

from __future__ import annotations

import re
from functools import cache
from pathlib import Path

from hypothesis import HealthCheck, Phase, given, settings
from hypothesis import strategies as st

from gtecat.cli.serve_cmd import build_chain
from gtecat.eni.layout import build_layout
from gtecat.eni.reader import read_eni
from tests.conftest import examples

ROOT = Path(__file__).resolve().parents[3]
TWINCAT = ROOT.parent / "shared" / "fixtures" / "eni" / "twincat_ek1100_el2008_el4002_el1809.xml"
#: the files respelled: the manual's figure 5-2 (shipped) and a TwinCAT export of Beckhoff
#: terminals (a repository checkout has it beside the project; without it the shipped one)
SOURCES = [ROOT / "examples" / "manual_fig5_2.eni"] + ([TWINCAT] if TWINCAT.is_file() else [])

#: the elements whose number says where and what the devices are (ETG.2100 HexDecValue)
NUMBER_TAGS = (
    "Start|Length|StartAddress|ControlByte|PhysAddr|AutoIncAddr|VendorId|ProductCode|"
    "RevisionNo|SerialNo|Index|SubIndex|BitLen|BitSize|BitOffs|BitStart|BitLength|"
    "DefaultSize|ByteSize|InputOffs|OutputOffs|Control"
)
_NUMBER = re.compile(rf"<({NUMBER_TAGS})>\s*(#x[0-9A-Fa-f]+|[0-9]+)\s*</\1>")
_ENABLE = re.compile(r"<Enable>\s*(true|false|1|0)\s*</Enable>")


def _value(text: str) -> int:
    return int(text[2:], 16) if text.startswith("#x") else int(text)


def spell_number(value: int, form: int, pad: int) -> str:
    """One of the spellings of ``value`` (``form`` picks which)."""
    hexa = f"{value:X}"
    return [
        str(value),
        "0" * pad + str(value),
        f"+{value}",
        f"#x{hexa}",
        f"#x{hexa.lower()}",
        "#x" + "0" * pad + hexa,
    ][form % 6]


def spell_bool(value: bool, form: int) -> str:
    return [("false", "true"), ("0", "1")][form % 2][value]


BLANKS = ["", " ", "\n  ", "\t"]


@cache
def faces(text: str) -> tuple:
    """What both faces make of one file's text (memoised: the originals are asked often)."""
    import tempfile

    from gtecat import gt
    from gtecat.controller.inspect import BusView

    with tempfile.TemporaryDirectory() as tmp:
        eni = Path(tmp) / "variant.xml"
        eni.write_text(text, encoding="utf-8")
        config = read_eni(eni)
        layout = build_layout(config)
        chain, _ = build_chain(eni)  # gtecat serve
        served = [bytes(esc.sii) for esc in chain.escs]
        assert gt.GT_Open(eni=str(eni), clock="lockstep", log="") == 0, gt.GTE_GetLastError()
        try:
            assert gt.GT_InitEcatComm() == 0
            view = BusView(gt.GTE_Controller())
            in_process = [view.sii(pos) for pos in range(len(config.slaves))]
        finally:
            gt.GT_Close()
    model = [
        (
            s.identity,
            s.phys_addr,
            s.auto_inc_addr,
            s.rx_pdos,
            s.tx_pdos,
            s.outputs,
            s.inputs,
            s.mailbox,
            s.sync_managers,
            s.mailbox_layout,
            s.product_revision,
        )
        for s in config.slaves
    ]
    image = (layout.slaves, layout.gt_raw_bytes, layout.outputs_bytes, layout.inputs_bytes)
    return model, image, served, in_process


@settings(
    max_examples=examples(40, 4),
    deadline=None,
    phases=[Phase.explicit, Phase.reuse, Phase.generate],  # a failure shows its file as made
    suppress_health_check=[HealthCheck.too_slow],
)
@given(st.sampled_from(SOURCES), st.randoms(use_true_random=False))
def test_every_spelling_gives_the_same_devices_on_both_faces(source: Path, rnd) -> None:
    text = source.read_text(encoding="utf-8")
    assert _NUMBER.search(text) and (_ENABLE.search(text) or source != TWINCAT)

    def number(m: re.Match[str]) -> str:
        value = spell_number(_value(m.group(2)), rnd.randrange(6), rnd.randrange(1, 4))
        return f"<{m.group(1)}>{rnd.choice(BLANKS)}{value}{rnd.choice(BLANKS)}</{m.group(1)}>"

    def boolean(m: re.Match[str]) -> str:
        value = spell_bool(m.group(1) in ("true", "1"), rnd.randrange(2))
        return f"<Enable>{rnd.choice(BLANKS)}{value}{rnd.choice(BLANKS)}</Enable>"

    variant = _ENABLE.sub(boolean, _NUMBER.sub(number, text))
    assert variant != text
    model, image, served, in_process = faces(variant)
    want_model, want_image, want_served, _ = faces(text)
    assert model == want_model
    assert image == want_image
    for pos, (a, b, want) in enumerate(zip(served, in_process, want_served, strict=True)):
        assert a == b, f"slave {pos}: serve and in-process SII differ"
        assert a == want, f"slave {pos}: the respelled file gives another SII"


def test_the_respelling_reaches_every_wire_field() -> None:
    """The generator is not idle: the files hold booleans and numbers of each kind."""
    if TWINCAT.is_file():
        text = TWINCAT.read_text(encoding="utf-8")
        assert {"true", "false"} <= {
            spell_bool(m.group(1) in ("true", "1"), 0) for m in _ENABLE.finditer(text)
        }
    tags = {m.group(1) for s in SOURCES for m in _NUMBER.finditer(s.read_text(encoding="utf-8"))}
    assert {"Start", "Length", "PhysAddr", "VendorId", "ProductCode", "Index", "BitLen"} <= tags
