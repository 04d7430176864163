"""Which ENI files keep their parsed model between processes: a 12-axis file does (its
parse is a noticeable part of a short script's or replay's process), the small example
files do not, ``GTECAT_ENI_CACHE=0`` none."""

from __future__ import annotations

import pytest

from gtecat.controller.core import ENI_CACHE_MIN_BYTES, _eni_cache
from tests.conftest import EXAMPLES


def test_a_twelve_axis_file_keeps_its_model_a_small_one_not(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    monkeypatch.delenv("GTECAT_ENI_CACHE", raising=False)
    twelve = EXAMPLES / "twelve_axes.eni"
    small = EXAMPLES / "manual_fig5_2.eni"
    assert twelve.stat().st_size >= ENI_CACHE_MIN_BYTES > small.stat().st_size
    assert _eni_cache(twelve) is not None
    assert _eni_cache(small) is None
    monkeypatch.setenv("GTECAT_ENI_CACHE", "0")
    assert _eni_cache(twelve) is None
