"""The vendor surface of ``gtecat.gt`` (declared-only functions, the groups' structures,
enums and constants) is made when first asked for: in a fresh interpreter, every way a
user or a tool reaches a name still finds it."""

from __future__ import annotations

import json
import subprocess
import sys

from tests.conftest import ROOT

_CHILD = r"""
import json
from gtecat import gt
from gtecat.gt import table

lazy_at_import = "GT_SetHSIOOpt" not in vars(gt)
# a declared-only function by attribute, before anything else made the surface
rc = gt.GT_SetHSIOOpt(1, 2)
reason = gt.GTE_GetLastError()
star = {}
exec("from gtecat.gt import *", star)
names = set(dir(gt))
from gtecat.gt import typedefs
print(json.dumps({
    "lazy_at_import": lazy_at_import,
    "rc": rc,
    "declared": getattr(gt.GT_SetHSIOOpt, "declared", False),
    "reason": str(reason),
    "missing_dir": sorted(set(table.exported_names()) - names)[:5],
    "missing_star": sorted(set(table.exported_names()) - set(star))[:5],
    "vars_after": all(n in vars(gt) for n in table.exported_names()),
    "enums": len(typedefs.BUILT.enums),
    "struct": "TTrapPrm" in star and any(
        k.startswith("T") and k not in vars(__import__("gtecat.gt.structs").gt.structs)
        and isinstance(v, type) for k, v in star.items()
    ),
    "no_such": hasattr(gt, "GT_NoSuchFunction"),
    "hook_after": "__getattr__" in vars(gt),
}))
"""


def test_every_name_is_found_in_a_fresh_process():
    out = subprocess.run(
        [sys.executable, "-c", _CHILD],
        capture_output=True,
        text=True,
        cwd=ROOT,
        check=True,
    )
    got = json.loads(out.stdout.strip().splitlines()[-1])
    assert got["lazy_at_import"]  # made on demand, not at import
    assert got["rc"] == 8 and got["declared"] and "declared but not emulated" in got["reason"]
    assert got["missing_dir"] == [] and got["missing_star"] == []
    assert got["vars_after"]
    assert got["enums"] > 0 and got["struct"]
    assert got["no_such"] is False
    assert got["hook_after"] is False  # (every name made: attribute loads specialise)


def test_the_kept_table_is_the_table(tmp_path, monkeypatch):
    """The function table kept between processes reads back as the groups read it: the same
    prototypes in the same order, the enum names; a damaged file is read from the groups."""
    from gtecat.gt import table

    monkeypatch.setenv("GTECAT_CACHE_DIR", str(tmp_path))
    key = table._cache_key(table.GROUPS)
    assert key is not None and table._read_cache(key) is None  # nothing kept yet
    fresh = table.collect(table.GROUPS)
    table._write_cache(key, fresh)
    enums, kept = table._read_cache(key)
    assert list(kept) == list(fresh) and set(enums) == table.ENUMS
    assert all(kept[k] == fresh[k] and kept[k].by_name == fresh[k].by_name for k in fresh)
    table._cache_file(key).write_bytes(b"\x00damaged")
    assert table._read_cache(key) is None
    monkeypatch.setenv("GTECAT_PYC_CACHE", "0")
    assert table._cache_key(table.GROUPS) is None
