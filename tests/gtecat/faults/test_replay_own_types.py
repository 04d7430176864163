"""Replays of what an application passes in its own way: a structure class of its own with
the prototype's layout (as the vendor's C# wrappers and many ports define TTrapPrm and
TCrdPrm themselves), and a pointer into a single value (``byref(x, 4)``, C's ``(char *)&x
+ 4``).  Each replays as recorded, and a tampered value is still found."""

from __future__ import annotations

import ctypes
from ctypes import byref, c_double, c_long, c_short
from pathlib import Path

import pytest

from gtecat import gt
from gtecat.errors import ParameterError
from gtecat.faults.record import replay
from tests.conftest import EXAMPLES

from .conftest import changed, recorded

ENI = EXAMPLES / "manual_fig5_2.eni"


class MyTrap(ctypes.Structure):
    """The manual's TTrapPrm (13.x GT_SetTrapPrm) under the application's own name."""

    _fields_ = [
        ("acc", c_double),
        ("dec", c_double),
        ("velStart", c_double),
        ("smoothTime", c_short),
    ]


class MyCrdPrm(ctypes.Structure):
    """TCrdPrm's layout (GT_SetCrdPrm), arrays inside, under another name and field names."""

    _fields_ = [
        ("dim", ctypes.c_int16),
        ("prof", ctypes.c_int16 * 8),
        ("vmax", c_double),
        ("amax", c_double),
        ("even", ctypes.c_int16),
        ("setOrigin", ctypes.c_int16),
        ("origin", ctypes.c_int32 * 8),
    ]


def _session() -> list[int]:
    """Set and read back a Trap's parameters and a coordinate system's through the
    application's own classes; poll a status word through a pointer 4 bytes into a c_long
    (no room for the value: refused) and through the c_long itself; the codes."""
    codes = [gt.GT_Open(eni=str(ENI), clock="lockstep", log="")]
    codes += [gt.GT_InitEcatComm(), gt.GTE_Wait(300), gt.GT_StartEcatComm(), gt.GT_AxisOn(1)]
    codes.append(gt.GT_PrfTrap(1))
    codes.append(gt.GT_SetTrapPrm(1, byref(MyTrap(0.5, 0.25, 0.0, 5))))
    back = MyTrap()
    codes.append(gt.GT_GetTrapPrm(1, byref(back)))
    assert (back.acc, back.dec, back.smoothTime) == (0.5, 0.25, 5)
    crd = MyCrdPrm(dim=2, vmax=100.0, amax=1.0, even=0, setOrigin=1)
    crd.prof[0], crd.prof[1] = 1, 2
    codes.append(gt.GT_SetCrdPrm(1, byref(crd)))
    crd_back = MyCrdPrm()
    codes.append(gt.GT_GetCrdPrm(1, byref(crd_back)))
    assert list(crd_back.prof[:2]) == [1, 2]
    s = c_long()
    codes.append(gt.GT_GetSts(1, byref(s, 4)))
    codes.append(gt.GT_GetSts(1, byref(s)))
    codes.append(gt.GT_Close())
    return codes


@pytest.fixture(scope="module")
def own(tmp_path_factory: pytest.TempPathFactory) -> Path:
    codes: list[int] = []
    path = recorded(tmp_path_factory.mktemp("own") / "own.gtrec", lambda: codes.extend(_session()))
    assert codes[-3] == 7 and codes.count(7) == 1  # (the pointer with no room: refused)
    assert set(codes) == {0, 7}
    return path


def test_the_session_replays_exactly(own: Path) -> None:
    n, div = replay(own)
    assert div is None, str(div)
    assert n == sum('"c":' in x for x in own.read_text().splitlines()[1:])


def _changed(src: Path, dst: Path, name: str, change) -> int:
    """The first call of ``name``, changed."""
    return changed(src, dst, lambda line: f'"c":"{name}"' in line, 1, change)


def test_a_tampered_field_of_an_own_structure_is_found(own: Path, tmp_path: Path) -> None:
    bad = tmp_path / "bad.gtrec"
    at = _changed(
        own,
        bad,
        "GT_GetCrdPrm",
        lambda e: e["o"]["1"]["ref"]["v"]["prof"]["v"].__setitem__(1, 3),
    )
    n, div = replay(bad)
    assert div is not None and (n, div.call, div.what) == (at, "GT_GetCrdPrm", "argument 2")


def test_the_refused_pointer_into_a_value_is_refused_again(own: Path, tmp_path: Path) -> None:
    """The recorded 7 stands only where the replay passes the pointer with its offset: the
    same recording with the offset dropped diverges there (0 against 7)."""
    bad = tmp_path / "nooff.gtrec"
    at = _changed(own, bad, "GT_GetSts", lambda e: e["a"][1].pop("off"))
    n, div = replay(bad)
    assert div is not None and (n, div.what, div.recorded, div.now) == (at, "return code", 7, 0)


@pytest.mark.parametrize(
    "field",
    [
        ["smoothTime", "c_bogus"],
        ["smoothTime", {"arr": "c_short", "n": 1 << 40}],
        ["1x", "c_short"],
    ],
)
def test_a_damaged_layout_is_refused_with_its_reason(
    own: Path, tmp_path: Path, field: list
) -> None:
    bad = tmp_path / "lay.gtrec"
    _changed(own, bad, "GT_SetTrapPrm", lambda e: e["a"][1]["ref"]["lay"].__setitem__(3, field))
    with pytest.raises(ParameterError, match=r"damaged recording.*GT_SetTrapPrm"):
        replay(bad)


def test_a_structure_is_recorded_with_its_layout_unless_it_is_the_gt_layers():
    """gtecat.gt's own structure is recorded by its name; an application's, also one named
    as gtecat.gt's (as the C# wrappers name TTrapPrm), with its layout."""
    from gtecat.faults.record import encode

    class TTrapPrm(ctypes.Structure):  # (the application's own, the GT layer's name)
        _fields_ = list(MyTrap._fields_)

    assert "lay" not in encode(gt.TTrapPrm())
    assert "lay" in encode(TTrapPrm())
    assert "lay" in encode(MyTrap())
