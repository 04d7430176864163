"""The suite's own plumbing: the asserts rewritten ahead of the workers (tests/conftest.py)
are the ones pytest's rewriter makes, locations included."""

from __future__ import annotations

import ast

import pytest

from tests.conftest import ROOT, faster_rewriter

rewrite = pytest.importorskip("_pytest.assertion.rewrite")


def _rewritten(path) -> str:
    source = path.read_text(encoding="utf-8")
    tree = ast.parse(source)
    rewrite.rewrite_asserts(tree, source.encode(), str(path), None)
    return ast.dump(tree, include_attributes=True)


@pytest.mark.parametrize("name", ["gtecat/gt/test_pvt_calls.py", "drives/test_homing.py"])
def test_the_faster_pass_gives_the_same_rewritten_module(name: str) -> None:
    if not hasattr(rewrite, "traverse_node"):
        pytest.skip("this pytest's rewriter has no traverse_node: the workers rewrite as usual")
    path = ROOT / "tests" / name
    before = _rewritten(path)
    with faster_rewriter(rewrite):
        after = _rewritten(path)
    assert rewrite.AssertionRewriter.visit_Assert.__name__ == "visit_Assert"  # restored
    assert "@py_assert" in after and after == before
