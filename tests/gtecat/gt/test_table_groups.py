"""The function table as group files: how groups combine (gtecat/gt/groups/)."""

from __future__ import annotations

import pytest

from gtecat.gt import table
from gtecat.gt.groups import Group, groups


def _g(name: str, protos: str, *, vendor: bool = False) -> Group:
    return Group(name, f"{name} words", f"tests.{name}", protos, declared_only=vendor)


def test_a_name_in_two_groups_is_an_error_naming_both():
    a = _g("first", "short GT_Foo(short axis);")
    b = _g("second", "short GT_Foo(short axis, short x);")
    with pytest.raises(ValueError, match=r"GT_Foo is declared in two groups: first .* second"):
        table.collect([a, b])
    # the twin counts: GTN_Foo of another group is GT_Foo's twin
    c = _g("third", "short GTN_Foo(short core, short axis);")
    with pytest.raises(ValueError, match="GTN_Foo is declared in two groups: first"):
        table.collect([a, c])


def test_a_vendor_group_yields_to_the_group_that_owns_the_function():
    owner = _g("ext_io", "short GT_SetExtIoValue(short mdl, unsigned short value);")
    vendor = _g(
        "vendor_ext_io",
        "short GT_SetExtIoValue(short mdl, unsigned short value);\nshort GT_Other(void);",
        vendor=True,
    )
    out = table.collect([vendor, owner])  # file order does not matter
    assert out["GT_SetExtIoValue"].group == "ext_io"
    assert out["GT_Other"].group == "vendor_ext_io"
    two = _g("vendor_b", "short GT_Other(void);", vendor=True)
    with pytest.raises(ValueError, match="two groups"):
        table.collect([vendor, two])


def test_own_gtn_lines_core_taking_gt_lines_and_unknown_parameters():
    out = table.collect([_g("x", """
short GT_FindStation(short mode);
short GTN_FindStation(short core, short mode, long *pCount);
short GT_SetCore(short core);
short GTN_Secret(...);
""")])  # fmt: skip
    assert not out["GT_FindStation"].gtn  # the GTN_ line of its own is the twin
    assert len(out["GTN_FindStation"].params) == 3
    assert not out["GT_SetCore"].gtn  # takes the core itself: no GTN_SetCore(core, core)
    assert out["GTN_Secret"].unknown and out["GTN_Secret"].params == ()


def test_vendor_parameter_spellings_parse():
    out = table.parse(
        "short GT_GetVersion(char **pVersion);\n"
        "short GT_SetAxes(short axis[8], unsigned long long mask, void *pData=NULL);\n"
        "short GT_ClearTime(ETimeElapse item);\n"
    )
    v = out["GT_GetVersion"].params[0]
    assert (v.stars, v.pointer, v.c_decl()) == (2, True, "char **pVersion")
    axes, mask, data = out["GT_SetAxes"].params
    assert (axes.pointer, axes.count, mask.ctype, data.optional) == (
        True,
        8,
        "unsigned long long",
        True,
    )
    assert out["GT_ClearTime"].params[0].ctype == "ETimeElapse"
    with pytest.raises(ValueError, match="scalar type 'wobble' unknown"):
        table.parse("short GT_X(wobble w);")


def test_every_group_module_has_the_contract_and_the_table_is_their_union():
    gs = groups()
    assert len({g.name for g in gs}) == len(gs)
    assert all(g.title and g.name.isidentifier() for g in gs)
    assert {p.group for p in table.FUNCTIONS.values()} <= {g.name for g in gs}
    assert table.group_of("GTN_AxisOn").name == "ecat_axis"
