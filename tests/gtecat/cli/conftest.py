"""CLI tests run ``gtecat.cli.main.main`` in-process and read what it printed."""

from __future__ import annotations

from collections.abc import Callable

import pytest

from gtecat import gt
from gtecat.cli.main import main

Cli = Callable[..., tuple[int, str, str]]


@pytest.fixture(autouse=True)
def _clean(monkeypatch: pytest.MonkeyPatch):
    """No GTECAT_* from the caller's shell, no controller left open."""
    for k in (
        "GTECAT_ENI",
        "GTECAT_MACHINE",
        "GTECAT_CLOCK",
        "GTECAT_BACKEND",
        "GTECAT_IFACE",
        "GTECAT_BUS",
        "GTECAT_LOG",
        "GTECAT_CONTROLLER",
    ):
        monkeypatch.delenv(k, raising=False)
    gt.GT_Close()
    yield
    gt.GT_Close()


@pytest.fixture
def cli(capsys: pytest.CaptureFixture[str]) -> Cli:
    """``cli("slaves", "--json")`` -> (exit code, stdout, stderr)."""

    def call(*argv: str) -> tuple[int, str, str]:
        rc = main(list(argv))
        out, err = capsys.readouterr()
        return rc, out, err

    return call
