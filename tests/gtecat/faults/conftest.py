"""Every test of the fault vocabulary, recording and replay starts and ends with no GT
session open (a failed test leaves none behind for the next)."""

from __future__ import annotations

from collections.abc import Iterator

import pytest

from gtecat import gt


@pytest.fixture(autouse=True)
def _closed() -> Iterator[None]:
    gt.GT_Close()
    yield
    gt.GT_Close()
