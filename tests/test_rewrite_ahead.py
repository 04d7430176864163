"""The suite's own plumbing: the asserts rewritten ahead of the workers (tests/conftest.py)
are the ones pytest's rewriter makes, locations included."""

from __future__ import annotations

import ast

import pytest

from tests.conftest import ROOT, _every_node

rewrite = pytest.importorskip("_pytest.assertion.rewrite")


def _rewritten(path) -> str:
    source = path.read_text(encoding="utf-8")
    tree = ast.parse(source)
    rewrite.rewrite_asserts(tree, source.encode(), str(path), None)
    return ast.dump(tree, include_attributes=True)


def test_the_faster_walk_gives_the_same_rewritten_module() -> None:
    if not hasattr(rewrite, "traverse_node"):
        pytest.skip("this pytest's rewriter has no traverse_node: the workers rewrite as usual")
    path = ROOT / "tests" / "gtecat" / "gt" / "test_pvt_calls.py"
    before = _rewritten(path)
    walk = rewrite.traverse_node
    rewrite.traverse_node = _every_node
    try:
        after = _rewritten(path)
    finally:
        rewrite.traverse_node = walk
    assert "@py_assert" in after and after == before
    assert {type(n) for n in _every_node(ast.parse("a = [b, (c, d)]"))} == {
        type(n) for n in ast.walk(ast.parse("a = [b, (c, d)]"))
    }
