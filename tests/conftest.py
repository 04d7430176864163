"""Shared test fixtures: where the real-tool configuration files live."""

from __future__ import annotations

import os
from pathlib import Path

import pytest
from hypothesis import settings

# CI runs the property tests with a fixed derandomised seed (reproducible, never flaky);
# developers' runs keep exploring new examples.
settings.register_profile("ci", derandomize=True, deadline=None)
if os.environ.get("CI"):
    settings.load_profile("ci")

ROOT = Path(__file__).resolve().parent.parent
EXAMPLES = ROOT / "examples"
# ../shared/fixtures beside the checkout (CI clones main with shared/ beside it)
SHARED_FIXTURES = ROOT.parent / "shared" / "fixtures"


def needs_fixture(what: object) -> str:
    """The skip reason of a test that reads the vendors' sample files: they are not shipped
    with gtecat (a repository checkout keeps them in a fixtures folder beside it)."""
    return (
        f"needs the vendors' sample files, not shipped with gtecat ({what} not found; a "
        "repository checkout has them beside it)"
    )


@pytest.fixture
def shared_fixtures() -> Path:
    if not SHARED_FIXTURES.is_dir():
        pytest.skip(needs_fixture(SHARED_FIXTURES))
    return SHARED_FIXTURES


@pytest.fixture
def examples_dir() -> Path:
    return EXAMPLES
