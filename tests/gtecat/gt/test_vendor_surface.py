"""The vendor surface of ``gtecat.gt`` (declared-only functions, the groups' structures, enums
and constants) is in the module's namespace from its import on: no module ``__getattr__`` (so
CPython specialises ``gt.X``), every way a user or a tool reaches a name finds it, and what
is made from the kept plain values is what the groups' text says."""

from __future__ import annotations

import copy
import ctypes
import inspect
import json
import marshal
import pickle
import subprocess
import sys
import types
import weakref

import pytest

from gtecat import gt
from gtecat.gt import _core, table, typedefs, vendor
from gtecat.gt.declared import DeclaredFunction
from tests.conftest import ROOT

_CHILD = r"""
import dis, json
from gtecat import gt
from gtecat.gt import _core, table

# the GT layer's public names, and which of them are its registered functions
names = sorted(k for k in vars(gt) if not k.startswith("_"))
public = [names, [k for k in names if _core.REGISTRY.get(k) is getattr(gt, k)]]
hook = "__getattr__" in vars(gt)
whole = all(n in vars(gt) for n in table.exported_names())

def load():
    return gt.GT_SetHSIOOpt

for _ in range(100):  # (warmed up: the adaptive interpreter specialises the load)
    load()
ops = [i.opname for i in dis.get_instructions(load, adaptive=True) if "ATTR" in i.opname]
# a declared-only function found through the module, called first
rc = gt.GT_SetHSIOOpt(1, 2)
reason = gt.GTE_GetLastError()
star = {}
exec("from gtecat.gt import *", star)
names = set(dir(gt))
from gtecat.gt import typedefs
print(json.dumps({
    "hook": hook,
    "whole": whole,
    "ops": ops,
    "rc": rc,
    "declared": getattr(gt.GT_SetHSIOOpt, "declared", False),
    "reason": str(reason),
    "missing_dir": sorted(set(table.exported_names()) - names)[:5],
    "missing_star": sorted(set(table.exported_names()) - set(star))[:5],
    "enums": len(typedefs.BUILT.enums),
    "struct": "TTrapPrm" in star and any(
        k.startswith("T") and k not in vars(__import__("gtecat.gt.structs").gt.structs)
        and isinstance(v, type) for k, v in star.items()
    ),
    "no_such": hasattr(gt, "GT_NoSuchFunction"),
    "public": public,
}))
"""


@pytest.fixture(scope="module")
def ordinary() -> dict:
    """What a fresh process that imports ``gtecat.gt`` finds (``_CHILD``); read-only."""
    out = subprocess.run(
        [sys.executable, "-c", _CHILD], capture_output=True, text=True, cwd=ROOT, check=True
    )
    return json.loads(out.stdout.strip().splitlines()[-1])


def test_every_name_is_there_from_the_import_on(ordinary):
    """In a fresh process: no module ``__getattr__``, every exported name in ``vars(gt)``
    before anything asked for one, ``gt.X`` specialised; a declared-only function found
    through the module returns 8 with its reason; ``dir``, ``import *`` and the enums."""
    got = ordinary
    assert got["hook"] is False and got["whole"]
    assert got["ops"] == ["LOAD_ATTR_MODULE"], got["ops"]  # CPython 3.11's specialised load
    assert got["rc"] == 8 and got["declared"]
    assert "GT_SetHSIOOpt is declared but not emulated" in got["reason"], got["reason"]
    assert got["missing_dir"] == [] and got["missing_star"] == []
    assert got["enums"] > 0 and got["struct"]
    assert got["no_such"] is False


def test_a_declared_function_is_used_as_a_function_is():
    """Called with anything it returns 8 with its reason; its docstring and signature are the
    table's; pickled, copied, weakly referenced, bound as a method, a routine to inspect."""
    fn, twin = gt.GT_SetHSIOOpt, gt.GTN_SetHSIOOpt
    assert isinstance(fn, DeclaredFunction) and fn.declared
    assert fn(1, 2, "x", pAny=None) == _core.CMD_DECLARED
    assert "GT_SetHSIOOpt returned 8: GT_SetHSIOOpt is declared" in gt.GTE_GetLastError()
    assert twin() == _core.CMD_DECLARED and fn.prototype is twin.prototype
    assert fn.__doc__.startswith("``short GT_SetHSIOOpt(unsigned short value")
    assert twin.__doc__.startswith("``short GTN_SetHSIOOpt(short core, unsigned short value")
    assert "returns 8 (CMD_ERROR_UNKNOWN) whatever the arguments" in fn.__doc__
    assert str(inspect.signature(fn)) == "(*args: 'Any', **kwargs: 'Any') -> 'int'"
    assert (fn.__name__, fn.__qualname__) == ("GT_SetHSIOOpt", "GT_SetHSIOOpt")
    assert DeclaredFunction.__doc__.startswith("``GT_x`` (or its ``GTN_x`` twin)")
    for f in (fn, twin, gt.GTN_CrdBlendOn):
        assert pickle.loads(pickle.dumps(f)) is f
        assert copy.copy(f) is f and copy.deepcopy(f) is f
        assert weakref.ref(f)() is f
        assert inspect.isroutine(f)

    class Holder:
        call = gt.GT_SetHSIOOpt

    assert isinstance(Holder().call, types.MethodType) and Holder().call() == 8
    assert Holder.call is fn
    assert ("GT_SetHSIOOpt", fn) in inspect.getmembers(gt, inspect.isroutine)


def test_the_surface_is_what_the_groups_say():
    """The classes, enum members and constants made from the kept plain values are those
    typedefs.build and parse_constants make of the groups' C text."""
    made = vendor._MADE
    g = vars(gt)
    existing = {
        k: v
        for k, v in g.items()
        if vendor.is_public(k, v) and isinstance(v, type) and k not in made
    }
    read = [td for grp in table.GROUPS for td in typedefs.parse(grp.structs, grp.name)]
    want = typedefs.build(read, existing)
    assert list(made) == list(want.classes)

    def layout(cls: type) -> list:
        return [(n, ctypes.sizeof(t), getattr(t, "__name__", "")) for n, t, *_ in cls._fields_]

    for name, cls in made.items():
        other = want.classes[name]
        assert layout(cls) == layout(other), name
        assert ctypes.sizeof(cls) == ctypes.sizeof(other) and cls.__doc__ == other.__doc__
        assert cls.__module__ == "gtecat.gt" and g[name] is cls
    assert typedefs.BUILT.classes == made and list(typedefs.BUILT.enums) == list(want.enums)
    for td in want.enums.values():
        for member, value in td.members:
            assert g[member] == value or member in existing or member in table.FUNCTIONS
    own = {k for m in gt._MODULES if (mod := sys.modules.get(f"gtecat.gt.{m}")) for k in vars(mod)}
    known: dict = {}
    for grp in table.GROUPS:
        for name, value in typedefs.parse_constants(grp.constants, known).items():
            known[name] = value
            assert g[name] == value or name in own, name  # (gtecat.gt's own value wins)
    # a vendor structure's object pickles: its class is found where it says it lives
    cls = next(iter(made.values()))
    assert type(pickle.loads(pickle.dumps(cls()))) is cls


def test_the_kept_table_is_the_table(tmp_path, monkeypatch):
    """The function table and the surface's plain values kept between processes read back as
    the groups read them; a damaged file is read from the groups again."""
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

    monkeypatch.setattr(table, "CACHE_KEY", [key])
    surface = table._cache_file(key, "surface")
    assert not surface.exists()
    read = typedefs.surface(table.GROUPS)  # from the groups, then kept
    assert surface.exists() and typedefs.surface(table.GROUPS) == read
    surface.write_bytes(b"\x00damaged")
    assert typedefs.surface(table.GROUPS) == read
    monkeypatch.setattr(table, "CACHE_KEY", [None])
    assert typedefs.surface(table.GROUPS) == read
    # kept values that read back but are not of the surface's shape: made from the groups
    monkeypatch.setattr(table, "CACHE_KEY", [key])
    surface.write_bytes(marshal.dumps(((("struct", "TBroken"),), ((1, 2),))))
    ns: dict = {}
    monkeypatch.setattr(vendor, "_MADE", {})  # (gtecat.gt's own stay as they are)
    vendor.install(ns, _core.REGISTRY)
    assert ns["TTrapPrm"]._fields_ and ns["GT_SetHSIOOpt"].declared and "TBroken" not in ns
    assert typedefs.surface(table.GROUPS) == read  # (kept again)

    monkeypatch.setenv("GTECAT_PYC_CACHE", "0")
    assert table._cache_key(table.GROUPS) is None


@pytest.mark.parametrize("text", ["#define A 3\n#define B (A+1)\n#define C (B*2)\n"])
def test_a_define_may_name_another(text):
    """A ``#define`` whose value names another constant is kept as its expression and
    evaluated against the constants when the surface is made."""
    kept = typedefs._defines(text)
    assert kept == (("A", 3, "3"), ("B", None, "(A+1)"), ("C", None, "(B*2)"))
    g: dict = {"MC_NONE": 7}
    vendor._constants((kept,), g, set())
    assert (g["A"], g["B"], g["C"]) == (3, 4, 8)


_LATER = r"""
import json
import gtecat
gtecat._SURFACE_LATER = True  # (as gtecat replay sets it)
from gtecat import gt
from gtecat.gt import _core, table

before = {
    "hook": "__getattr__" in vars(gt),
    "declared_there": "GT_SetHSIOOpt" in vars(gt),
    "own_there": "GT_GetSts" in vars(gt) and "TTrapPrm" in vars(gt),
    "later_module_there": "GT_GetDi" in vars(gt),
}
fn = gt.GT_SetHSIOOpt  # (the first vendor name asked: the surface made)
names = sorted(k for k in vars(gt) if not k.startswith("_"))
public = [names, [k for k in names if _core.REGISTRY.get(k) is getattr(gt, k)]]
after = {
    "hook": "__getattr__" in vars(gt) or "__dir__" in vars(gt),
    "whole": all(n in vars(gt) for n in table.exported_names()),
    "rc": fn(1, 2),
    "no_such": hasattr(gt, "GT_NoSuchFunction"),
}
print(json.dumps([before, after, public]))
"""


@pytest.fixture(scope="module")
def later() -> list:
    """What a fresh process finds that imports ``gtecat.gt`` as a replay does (``_LATER``);
    read-only."""
    out = subprocess.run(
        [sys.executable, "-c", _LATER], capture_output=True, text=True, cwd=ROOT, check=True
    )
    return json.loads(out.stdout.strip().splitlines()[-1])


def test_a_process_that_runs_no_program_makes_the_vendor_surface_at_its_first_name(later):
    """``gtecat replay``'s start: with ``gtecat._SURFACE_LATER`` set before the import, the GT
    layer's own functions and structures are there and the vendor surface is not; the first
    vendor name asked makes it whole, and the namespace is then an ordinary import's."""
    before, after, _ = later
    assert before == {
        "hook": True,
        "declared_there": False,
        "own_there": True,
        "later_module_there": False,  # (its module left for later too)
    }
    assert after == {"hook": False, "whole": True, "rc": 8, "no_such": False}


def test_the_surface_made_later_is_an_ordinary_imports(later, ordinary):
    """The GT modules and vendor surface a replay's process makes at its first name are the
    namespace an ordinary import makes: the same names, the same registered functions (each
    read by the processes above: the replay's once its first vendor name is asked, the
    ordinary one's right after its import)."""
    got = {"later": later[2], "now": ordinary["public"]}
    assert got["later"] == got["now"]
    assert len(got["now"][1]) > 500
