"""``read_sii``: the SII through a slave's EEPROM interface (pysoem's ``eeprom_read``), read
category by category up to the end marker, wherever that falls in a 4-byte read."""

from __future__ import annotations

import pytest

from gtecat.controller.inspect import read_sii
from gtecat.drives.esc.sii import build_sii, iter_categories, parse_sii, sii_info_for
from gtecat.eni.layout import build_layout
from gtecat.eni.reader import read_eni
from gtecat.master.factory import build_slaves
from tests.conftest import EXAMPLES


@pytest.mark.parametrize("position", [0, 2])
def test_read_sii_stops_at_the_end_category_and_decodes_as_the_whole(position: int) -> None:
    slave = build_slaves(build_layout(read_eni(EXAMPLES / "manual_fig5_2.eni")))[position]
    whole = build_sii(sii_info_for(slave))
    padded = whole + b"\xff" * 4096  # an EEPROM larger than its content
    reads: list[int] = []

    def eeprom_read(word: int) -> bytes:
        reads.append(word)
        return padded[2 * word : 2 * word + 4]

    got = read_sii(eeprom_read)
    assert parse_sii(got) == parse_sii(whole)
    assert list(iter_categories(got)) == list(iter_categories(whole))
    assert len(got) <= len(whole) + 4 and max(reads) * 2 < len(whole)  # no read past the end
