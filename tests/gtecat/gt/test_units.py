"""Every GT function whose parameters are quantities says their units in its docstring, from
the one units table (gtecat/gt/units.py) that also writes docs/reference/units.md's table.

A parameter is a quantity when its name (or a field of the structure it points to) has a
position, speed, acceleration or deceleration word; readers named ``GT_Get...Pos/Vel/Acc``
return one through ``pValue``."""

from __future__ import annotations

import os
import re

import pytest

from gtecat import gt
from gtecat.gt import units
from gtecat.gt.table import FUNCTIONS, emulated
from gtecat.native import cdecl
from tests.conftest import ROOT

PAGE = ROOT / "docs" / "reference" / "units.md"
QUANTITY = {"pos", "vel", "velocity", "acc", "dec", "speed"}


def _words(name: str) -> set[str]:
    """camelCase words of a C name, lower case, digits dropped: ``pDecSmoothStop`` -> p, dec, ..."""
    return {w.lower().rstrip("0123456789") for w in re.findall(r"[a-z]+\d*|[A-Z][a-z]*\d*", name)}


def _is_quantity(param) -> bool:
    if "slave" in param.name.lower():
        return False  # slave_position: an index
    if param.is_struct:
        try:
            fields = [f[0] for f in cdecl.structure(param.ctype)._fields_]
        except KeyError:
            return False
        return any(_words(f) & QUANTITY for f in fields)
    return bool(_words(param.name) & QUANTITY) and "ratio" not in _words(param.name)


def _has_quantity(name: str) -> bool:
    proto = FUNCTIONS[name]
    if any(_is_quantity(p) for p in proto.params):
        return True
    reader = name.startswith("GT_Get") and any(p.name == "pValue" for p in proto.params)
    return reader and bool(_words(name[3:]) & {"pos", "vel", "acc"})


QUANTITIES = sorted(n for n in emulated() if _has_quantity(n))  # declared-only: not run


def test_the_rule_finds_the_functions_users_mix_up() -> None:
    for name in ("GT_SetVel", "GT_SetTrapPrm", "GT_SetEcatHomingPrm", "GT_GetPrfVel",
                 "GT_LnXYZA", "GT_GoHome", "GT_SetEcatAxisPV", "GT_GetEcatEncVel"):  # fmt: skip
        assert name in QUANTITIES, name
    assert len(QUANTITIES) > 50


@pytest.mark.parametrize("name", QUANTITIES)
def test_a_function_with_a_position_speed_or_acceleration_names_its_units(name: str) -> None:
    rows = units.units_of(name)
    assert rows, f"{name}: no row in gtecat/gt/units.py"
    for fn in (getattr(gt, name), getattr(gt, "GTN_" + name[3:], None)):
        if fn is None:
            continue
        doc = fn.__doc__ or ""
        assert units.units_text(name) in doc, fn.__name__
        for r in rows:
            assert r.unit.replace("**", "").split(" (")[0].replace("`", "") in doc


def test_the_homing_speeds_are_counts_per_second_and_trap_speeds_pulse_per_ms() -> None:
    assert "speed2 (6099h:02, creep and index): counts/s;" in gt.GT_SetEcatHomingPrm.__doc__
    assert "acc (609Ah): counts/s²" in gt.GT_SetEcatHomingPrm.__doc__
    assert "Units: vel: pulse/ms" in gt.GT_SetVel.__doc__
    assert "velocities: pulse/ms" in gt.GT_GoHome.__doc__  # smart homing plans in pulse


def test_every_name_in_the_units_table_is_a_gt_function() -> None:
    for r in units.ROWS:
        for pattern in r.functions:
            assert any(units._matches(pattern, n) for n in FUNCTIONS), pattern


def test_the_reference_page_table_is_the_units_table() -> None:
    """``GTECAT_REGEN_GOLDEN=1`` rewrites the page's table (review the diff)."""
    if os.environ.get("GTECAT_REGEN_GOLDEN") == "1":
        units.write_page(str(PAGE))
    text = PAGE.read_text(encoding="utf-8")
    table = text.split(units.BEGIN + "\n", 1)[1].split(units.END, 1)[0]
    assert table == units.markdown(), "docs/reference/units.md drifted: GTECAT_REGEN_GOLDEN=1"
