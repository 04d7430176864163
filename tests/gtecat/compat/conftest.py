"""Compat-layer tests: each test opens a lockstep gts:4 card and always closes it."""

from __future__ import annotations

import pytest

from gtecat import gt
from gtecat.compat import adt850, mcx314


@pytest.fixture(autouse=True)
def _closed():
    gt.GT_Close()
    yield
    adt850._close_all()
    mcx314._CARD[0] = None
    gt.GT_Close()


def open_card(**machine_axes) -> None:
    """GT_Open a lockstep gts:4 card whose axis N has ``machine_axes[f"a{N}"]``."""
    from gtecat.drives.machine import AxisMachine, MachineDescription

    m = MachineDescription({int(k[1:]): AxisMachine(**v) for k, v in machine_axes.items()})
    assert gt.GT_Open(card="gts:4", machine=m, clock="lockstep", log="") == 0
