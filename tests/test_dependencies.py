"""Dependency direction (DESIGN.md "Layout", STYLE.md "Shape"): eni -> drives -> the rest of gtecat.

Installed, the package occupies the ``gtecat`` name only: ``gtecat.eni`` and ``gtecat.drives``
are its lowest layers.

Walks every module's imports with ``ast`` (lazy imports inside functions count too).
"""

from __future__ import annotations

import ast
import functools
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent
#: top-level names no module of the package may import
FORBIDDEN_TOP = {"tools", "tests", "eni", "drives"}
#: the gtecat subpackages the lowest layers may import (their own and those below)
LOWEST = {"eni": {"eni"}, "drives": {"eni", "drives"}}


@functools.cache  # the tests below walk the same modules: parse each once per process
def _tree(path: Path) -> ast.Module:
    return ast.parse(path.read_text(encoding="utf-8"))


def _imports(path: Path) -> set[str]:
    tree = _tree(path)
    out: set[str] = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            out.update(a.name.split(".")[0] for a in node.names)
        elif isinstance(node, ast.ImportFrom) and node.level == 0 and node.module:
            out.add(node.module.split(".")[0])
    return out


@pytest.mark.long
def test_package_imports_no_top_level_neighbours():
    """A user's own ``eni.py``, ``drives.py`` or ``tools/`` beside their script change nothing."""
    bad = []
    for path in sorted((ROOT / "gtecat").rglob("*.py")):
        wrong = _imports(path) & FORBIDDEN_TOP
        if wrong:
            bad.append(f"{path.relative_to(ROOT)} imports {', '.join(sorted(wrong))}")
    assert not bad, "\n".join(bad)


@pytest.mark.parametrize("layer", sorted(LOWEST))
@pytest.mark.sample(1)
def test_lowest_layers_import_only_downwards(layer):
    bad = []
    for path in sorted((ROOT / "gtecat" / layer).rglob("*.py")):
        wrong = _gtecat_imports(path) - LOWEST[layer]
        if wrong:
            bad.append(f"{path.relative_to(ROOT)} imports gtecat.{', '.join(sorted(wrong))}")
    assert not bad, "\n".join(bad)


def _gtecat_imports(path: Path) -> set[str]:
    """Absolute ``gtecat.X`` subpackages a module imports (relative imports resolved)."""
    tree = _tree(path)
    pkg = list(path.relative_to(ROOT).with_suffix("").parts)
    pkg = pkg[:-1]  # the module's package ( __init__ counts as its own package's module)
    out: set[str] = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.ImportFrom):
            if node.level:
                base = pkg[: len(pkg) - (node.level - 1)]
                mod = [*base, *(node.module.split(".") if node.module else [])]
            else:
                mod = (node.module or "").split(".")
            if mod == ["gtecat"]:
                out.update(a.name for a in node.names)  # from .. import controller
            elif mod[:1] == ["gtecat"]:
                out.add(mod[1])
        elif isinstance(node, ast.Import):
            for a in node.names:
                parts = a.name.split(".")
                if parts[0] == "gtecat" and len(parts) > 1:
                    out.add(parts[1])
    return out


#: inside gtecat/ (DESIGN.md "Layout inside gtecat/"): the master knows nothing of the layers above
INNER_FORBIDDEN = {
    "master": {"controller", "gt", "cli", "native", "programs", "wire"},
    "controller": {"gt", "cli", "native", "wire"},
}


@pytest.mark.parametrize("sub", sorted(INNER_FORBIDDEN))
@pytest.mark.sample(1)
def test_gtecat_subpackages_import_only_downwards(sub):
    bad = []
    for path in sorted((ROOT / "gtecat" / sub).rglob("*.py")):
        wrong = _gtecat_imports(path) & INNER_FORBIDDEN[sub]
        if wrong:
            bad.append(f"{path.relative_to(ROOT)} imports gtecat.{', '.join(sorted(wrong))}")
    assert not bad, "\n".join(bad)


@pytest.mark.long
def test_users_own_modules_beside_the_script_change_nothing(tmp_path):
    """A user's ``eni.py``, ``drives.py``, ``tools.py`` and ``tests/`` next to their script."""
    import shutil
    import subprocess
    import sys

    for name in ("eni.py", "drives.py", "tools.py"):
        (tmp_path / name).write_text("raise ImportError('the user module was imported')\n")
    (tmp_path / "tests").mkdir()
    (tmp_path / "tests" / "__init__.py").write_text("raise ImportError('user tests imported')\n")
    script = (
        "import sys; sys.path.insert(0, '.')\n"
        "from gtecat import gt\n"
        "print(gt.GT_Open(eni='manual_fig5_2.eni', clock='lockstep'), gt.GT_InitEcatComm())\n"
    )
    shutil.copy(ROOT / "gtecat" / "examples" / "manual_fig5_2.eni", tmp_path)
    run = subprocess.run(
        [sys.executable, "-c", script], cwd=tmp_path, capture_output=True, text=True, timeout=60
    )
    assert run.returncode == 0, run.stderr
    assert run.stdout.split() == ["0", "0"]
