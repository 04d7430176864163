"""Replays of a program that polls the process image every millisecond (GT_GetEcatRawData
into a c_ubyte buffer, the manual's 5.2.2.4 raw access) and writes outputs with
GT_SetEcatRawData: the byte buffers, recorded as hex text, are values of their line's form
(one prepared call serves every line, its buffer pooled) and are compared byte for byte."""

from __future__ import annotations

import json
from ctypes import byref, c_ubyte, c_ulong
from pathlib import Path

import pytest

from gtecat import gt
from gtecat.faults.record import _open_text, _steps, replay
from tests.conftest import EXAMPLES

from .conftest import changed, fig5_2_jogging, recorded

POLLS = 400


def _session() -> None:
    fig5_2_jogging(5.0)
    buf = (c_ubyte * 8)()
    out = (c_ubyte * 2)()
    clk = c_ulong()
    for i in range(POLLS):
        assert gt.GT_GetEcatRawData(0, 8, buf) == 0
        if i % 50 == 0:
            out[0], out[1] = i & 0xFF, 0xA5
            gt.GT_SetEcatRawData(32, 2, out)  # (slave 2's outputs, manual 5.2.2.4)
        gt.GT_GetClock(byref(clk))
        gt.GTE_Wait(1)
    gt.GT_Close()


@pytest.fixture(scope="module")
def raw(tmp_path_factory: pytest.TempPathFactory) -> Path:
    return recorded(tmp_path_factory.mktemp("raw") / "raw.gtrec", _session)


def _raw_lines(path: Path) -> list[tuple[int, dict]]:
    out, calls = [], 0
    for line in path.read_text().splitlines()[1:]:
        if '"c":' in line:
            calls += 1
            if '"GT_GetEcatRawData"' in line:
                out.append((calls, json.loads(line)))
    return out


def test_the_session_replays_exactly_and_the_buffers_share_their_forms(raw: Path) -> None:
    raws = _raw_lines(raw)
    assert len(raws) == POLLS
    # (a buffer the call left as it was has no "o"; the encoder moves: many differ)
    assert len({e["o"]["2"]["hex"] for _, e in raws if "o" in e}) > POLLS // 4
    _, div = replay(raw, eni=str(EXAMPLES / "manual_fig5_2.eni"))
    assert div is None, str(div)
    p, _, body = _open_text(raw, raw.read_bytes())
    calls = {id(c) for c, _ in _steps(p, body) if c is not None and c.name == "GT_GetEcatRawData"}
    # every line made by one of two prepared calls: the buffer written back, or left as it was
    assert len(calls) == 2


def _tamper(src: Path, dst: Path, nth: int, change) -> int:
    """The ``nth`` GT_GetEcatRawData that wrote its buffer back, changed."""
    return changed(
        src, dst, lambda line: '"GT_GetEcatRawData"' in line and '"o":' in line, nth, change
    )


def test_a_tampered_byte_is_named_with_its_index(raw: Path, tmp_path: Path) -> None:
    bad = tmp_path / "byte.gtrec"
    was = []

    def flip(e: dict) -> None:
        h = e["o"]["2"]["hex"]
        was.append(int(h[10:12], 16))
        e["o"]["2"]["hex"] = h[:10] + f"{int(h[10:12], 16) ^ 0xFF:02x}" + h[12:]

    at = _tamper(raw, bad, 123, flip)
    n, div = replay(bad)
    assert div is not None and (n, div.call, div.what) == (
        at,
        "GT_GetEcatRawData",
        "argument 3 element [5]",
    )
    assert (div.recorded, div.now) == (was[0] ^ 0xFF, was[0])


def test_a_buffer_of_another_spelling_is_compared_the_general_way(
    raw: Path, tmp_path: Path
) -> None:
    """Upper-case hex is no form's value: the line is made whole and still compared, the
    first byte that differs named as a form's would be; the other lines unchanged."""
    bad = tmp_path / "upper.gtrec"
    at = _tamper(raw, bad, 200, lambda e: e["o"]["2"].update(hex="FF" + e["o"]["2"]["hex"][2:]))
    n, div = replay(bad)
    assert div is not None and (n, div.call, div.what) == (
        at,
        "GT_GetEcatRawData",
        "argument 3 element [0]",
    )
    assert div.recorded == 0xFF and div.now != 0xFF
    same = tmp_path / "same.gtrec"
    _tamper(raw, same, 200, lambda e: e["o"]["2"].update(hex=e["o"]["2"]["hex"]))
    assert replay(same)[1] is None
