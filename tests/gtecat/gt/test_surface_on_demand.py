"""The vendor surface (declared-only functions, the groups' structures and constants) is
made at the first look at one of its names: every way of looking finds it."""

from __future__ import annotations

import subprocess
import sys

from gtecat import gt
from gtecat.gt import table


def test_every_way_of_looking_finds_the_vendor_names():
    name = table.declared_only()[0]
    assert callable(getattr(gt, name)) and hasattr(gt, "GTN_" + name[3:])
    assert name in dir(gt)
    ns: dict = {}
    exec("from gtecat.gt import *", ns)
    assert name in ns and "TTrapPrm" in ns and "GT_Open" in ns
    assert not any(k.startswith("_") for k in ns if k != "__builtins__")
    gt._complete()  # built once
    assert set(table.FUNCTIONS) <= set(vars(gt))
    assert getattr(gt, "_no_such_name", None) is None
    assert getattr(gt, "GT_NoSuchFunction", None) is None


def test_import_leaves_it_for_the_first_look():
    code = (
        "import gc; from gtecat import gt; import gtecat.gt as m;"
        "assert gc.isenabled(); before = m._SURFACE[0];"
        f"fn = gt.{table.declared_only()[0]}; print(before, m._SURFACE[0], fn(1) != 0)"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=60)
    assert out.stdout.split() == ["0", "2", "True"], out.stderr
