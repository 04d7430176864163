"""The wheel's build (pyproject.toml holds the project's metadata): gtecat's small C parts
built into the package where a C compiler is, so that a new install's first run compiles
nothing (gtecat/cparts.py says which parts and how a first use finds them).

``pip install`` needs no C compiler: without one, or for a part that does not build, the
wheel is built without it and a first use compiles it into the per-user cache, as before.
An editable install (``pip install -e``) builds nothing here either: its sources may change.
A wheel that holds built parts is tagged for this platform (``py3-none-<platform>``: the
parts use no Python header, so any Python 3 of the platform loads them).
"""

from __future__ import annotations

import importlib.util
import shutil
from pathlib import Path
from types import ModuleType

from setuptools import Distribution, setup
from setuptools.command.build_py import build_py

try:
    from setuptools.command.bdist_wheel import bdist_wheel
except ImportError:  # setuptools before 70.1: the wheel package's, which pip installs for a
    try:  # wheel's build with such a setuptools
        from wheel.bdist_wheel import bdist_wheel
    except ImportError:  # (no wheel built: ``setup.py build_py`` alone, as a test runs it)
        bdist_wheel = None

HERE = Path(__file__).resolve().parent


def _cparts() -> ModuleType:
    """gtecat/cparts.py, loaded by its path: importing the package would import its
    dependencies, which the build environment does not have."""
    spec = importlib.util.spec_from_file_location("_gtecat_cparts", HERE / "gtecat" / "cparts.py")
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


CPARTS = _cparts()
CC, NO_CC = CPARTS.find_compiler()


class BuildPy(build_py):
    """The package's files, then its C parts built beside them (``gtecat/_prebuilt/``)."""

    def run(self) -> None:
        super().run()
        if getattr(self, "editable_mode", False):
            return
        root = Path(self.build_lib)
        dest = root / "gtecat" / "_prebuilt"
        shutil.rmtree(dest, ignore_errors=True)  # (a build folder's older parts go)
        if CC is None:
            self.announce(f"gtecat: C parts not prebuilt ({NO_CC}): built on first use", 2)
            return
        try:
            failed = CPARTS.prebuild(root, dest, CC)
        except Exception as e:  # whatever goes wrong, the install goes on without them
            shutil.rmtree(dest, ignore_errors=True)
            failed = [f"{type(e).__name__}: {e}"]
        for why in failed:
            self.warn(f"gtecat: a C part not prebuilt (built on first use): {why}")


class BinaryDistribution(Distribution):
    """A distribution with native code where a compiler is: its wheel gets a platform tag."""

    def has_ext_modules(self) -> bool:
        return CC is not None


COMMANDS: dict[str, type] = {"build_py": BuildPy}
if bdist_wheel is not None:

    class BdistWheel(bdist_wheel):
        """``py3-none-<platform>`` for a wheel with built parts (no Python ABI in them)."""

        def get_tag(self) -> tuple[str, str, str]:
            impl, abi, plat = super().get_tag()
            if self.root_is_pure:
                return impl, abi, plat
            return "py3", "none", plat

    COMMANDS["bdist_wheel"] = BdistWheel


setup(distclass=BinaryDistribution, cmdclass=COMMANDS)
