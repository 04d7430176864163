"""The unit of every GT parameter that is a quantity: one table, two faces.

The controller plans in profile units (pulse, pulse/ms, pulse/ms², ms); drive objects are in
CiA-402 units (counts, counts/s, counts/s², per mille). Mixing them is the classic mistake
(a homing speed of 40000 is 40 counts/ms), so the table below is declared once and gives
both the ``Units:`` paragraph of each GT function's docstring (:func:`with_units`, applied
by the GT decorator) and the "By function" table of ``docs/reference/units.md``
(:func:`markdown`; a test fails when the page drifts).
"""

from __future__ import annotations

import fnmatch
import re
from collections.abc import Callable
from dataclasses import dataclass
from functools import cache


@dataclass(frozen=True, slots=True)
class Row:
    """``functions`` (names, ``*`` patterns) take ``what`` in ``unit``."""

    functions: tuple[str, ...]
    what: str
    unit: str
    #: shown after the names in the reference page (the structure the fields are in)
    note: str = ""


def _r(functions: str, what: str, unit: str, note: str = "") -> Row:
    return Row(tuple(functions.split()), what, unit, note)


P, V, A = "pulse", "pulse/ms", "pulse/ms²"

# fmt: off
ROWS: tuple[Row, ...] = (
    _r("GT_SetTrapPrm GT_GetTrapPrm", "`acc`, `dec`", A, "TTrapPrm"),
    _r("GT_SetTrapPrm GT_GetTrapPrm", "`velStart`", V, "TTrapPrm"),
    _r("GT_SetTrapPrm GT_GetTrapPrm", "`smoothTime`", "ms (0..50)", "TTrapPrm"),
    _r("GT_SetJogPrm GT_GetJogPrm", "`acc`, `dec`", A, "TJogPrm"),
    _r("GT_SetJogPrm GT_GetJogPrm", "`smooth`", "ratio, [0, 1)", "TJogPrm"),
    _r("GT_SetPos GT_GetPos", "`pos`", P),
    _r("GT_SetVel GT_GetVel", "`vel`", "pulse/ms (Trap: > 0; Jog: signed)"),
    _r("GT_GetPrfPos GT_GetAxisPrfPos GT_SetPrfPos", "position", P),
    _r("GT_GetPrfVel GT_GetAxisPrfVel", "velocity", V),
    _r("GT_GetPrfAcc GT_GetAxisPrfAcc", "acceleration", A),
    _r("GT_GetEncPos GT_GetAxisEncPos GT_SetEncPos", "position", P),
    _r("GT_GetEncVel GT_GetAxisEncVel", "velocity", V),
    _r("GT_GetAxisEncAcc", "acceleration", A),
    _r("GT_GetAxisError", "planned − actual", P),
    _r("GT_SetPosErr GT_GetPosErr", "`error`", P),
    _r("GT_SetAxisBand GT_GetAxisBand", "`band`", P),
    _r("GT_SetAxisBand GT_GetAxisBand", "`time`", "250 µs units"),
    _r("GT_SetSoftLimit GT_GetSoftLimit", "`positive`, `negative`", P),
    _r("GT_SetStopDec GT_GetStopDec", "`decSmoothStop`, `decAbruptStop`", A),
    _r("GT_PtData", "`pos`", P),
    _r("GT_PtData", "`time`", "ms"),
    _r("GT_SetGearRatio GT_GetGearRatio", "`masterEven`, `slaveEven`",
       "ratio (slave travel : master travel)"),
    _r("GT_SetGearRatio GT_GetGearRatio", "`masterSlope`", "pulse of master travel (the clutch)"),
    _r("GT_SetFollowEvent GT_GetFollowEvent", "`pos`", P),
    _r("GT_FollowData", "master and slave segment", P),
    _r("GT_SetCrdPrm GT_GetCrdPrm", "`synVelMax`", V, "TCrdPrm"),
    _r("GT_SetCrdPrm GT_GetCrdPrm", "`synAccMax`", A, "TCrdPrm"),
    _r("GT_SetCrdPrm GT_GetCrdPrm", "`evenTime`", "ms", "TCrdPrm"),
    _r("GT_LnXY* GT_ArcXY* GT_ArcYZ* GT_ArcZX* GT_HelixXY*",
       "`x`, `y`, `z`, `aPos`, `xCenter`, `yCenter`, `zCenter`, `radius`", P),
    _r("GT_LnXY* GT_ArcXY* GT_ArcYZ* GT_ArcZX* GT_HelixXY*", "`synVel`, `velEnd`", V),
    _r("GT_LnXY* GT_ArcXY* GT_ArcYZ* GT_ArcZX* GT_HelixXY*", "`synAcc`", A),
    _r("GT_GetCrdPos", "coordinates", P),
    _r("GT_GetCrdVel", "`synVel`", V),
    _r("GT_SetOverride", "`synVelRatio`", "ratio of the programmed synthesised speed"),
    _r("GT_InitLookAhead", "`T`", "ms (corner speed = accMax · T / the change of direction)"),
    _r("GT_InitLookAhead", "`accMax`", A),
    _r("GT_BufMove", "`pos`", P),
    _r("GT_BufMove", "`vel`", V),
    _r("GT_BufMove", "`acc`", A),
    _r("GT_BufDelay", "`delayTime`", "ms"),
    _r("GT_CrdData", "`pos`, `radius`, centre", P, "TCrdData"),
    _r("GT_CrdData", "`vel`, `velEnd`", V, "TCrdData"),
    _r("GT_CrdData", "`acc`", A, "TCrdData"),
    _r("GT_MoveVelocity GT_GetMoveVelocity", "`vel`", V, "TMoveVelocityPrm"),
    _r("GT_MoveVelocity GT_GetMoveVelocity", "`acc`, `dec`", A, "TMoveVelocityPrm"),
    _r("GT_MoveVelocity GT_GetMoveVelocity", "`jerkBegin`, `jerkEnd`", "pulse/ms³",
       "TMoveVelocityPrm"),
    _r("GT_MoveAbsolute GT_GetMoveAbsolute", "`pos`", P, "TMoveAbsolutePrm"),
    _r("GT_MoveAbsolute GT_GetMoveAbsolute", "`vel`", V, "TMoveAbsolutePrm"),
    _r("GT_MoveAbsolute GT_GetMoveAbsolute", "`acc`, `dec`", A, "TMoveAbsolutePrm"),
    _r("GT_SetCrdStopDec GT_GetCrdStopDec", "decelerations", A),
    _r("GT_GoHome GT_GetHomePrm", "positions, offsets", P, "THomePrm, smart homing"),
    _r("GT_GoHome GT_GetHomePrm", "velocities", V, "THomePrm, smart homing"),
    _r("GT_GoHome GT_GetHomePrm", "`acc`, `dec`", A, "THomePrm, smart homing"),
    _r("GT_GoHome GT_GetHomePrm", "`smoothTime`", "ms", "THomePrm, smart homing"),
    _r("GT_GetHomeStatus", "`capturePos`, `targetPos`", P, "THomeStatus"),
    _r("GT_SetEcatHomingPrm",
       "`speed1` (6099h:01, to the switch), `speed2` (6099h:02, creep and index)",
       "**counts/s**"),
    _r("GT_SetEcatHomingPrm", "`acc` (609Ah)", "**counts/s²**"),
    _r("GT_SetEcatHomingPrm", "`offset` (607Ch)", "counts"),
    _r("GT_GetEcatEncPos", "6064h", "counts"),
    _r("GT_GetEcatEncVel", "606Ch", "counts/s"),
    _r("GT_GetEcatAxisPE", "60F4h", "counts"),
    _r("GT_SetEcatAxisPV", "`velocity` (60FFh)", "counts/s"),
    _r("GT_SetEcatAxisPT", "`torque` (6071h)", "per mille of rated torque"),
    _r("GT_GetEcatAxisAtITorque", "6077h", "per mille of rated torque"),
    _r("GT_GetEcatAxisAtICurrent", "6078h", "per mille of rated current"),
    _r("GT_GetTouchProbeStatus", "latched values (60BAh-60BDh)", "counts"),
    _r("GT_SetPosScale GT_GetPosScale", "`scale`", "exponent: counts = pulses · 2^scale"),
    _r("GT_ProfileScale GT_EncScale", "`alpha`, `beta`", "ratio"),
    _r("GT_GetEcatRawData GT_SetEcatRawData", "`offset`",
       "byte in the GT raw image (`gtecat map`)"),
    _r("GT_EcatIOReadInput GT_EcatIOWriteOutput GT_EcatIOBitWriteOutput", "`offset`",
       "byte inside the slave's region"),
    _r("GT_Home GT_HomeStop GT_Index", "`pos`, `offset`", P),
    _r("GT_Home GT_HomeStop", "`vel`", V),
    _r("GT_Home GT_HomeStop", "`acc`", A),
    _r("GT_BufGear GT_BufGearEx", "`pos`, `deltaPos`", P),
    _r("GT_CrdDataEx GT_LnXY*Ex GT_ArcXY*Ex", "positions, `radius`, centre",
       "pulse; mm after `GT_InitLookAheadEx` on the FIFO", "TCrdData"),
    _r("GT_CrdDataEx GT_LnXY*Ex GT_ArcXY*Ex", "`vel`, `velEnd`",
       "pulse/ms; mm/s after `GT_InitLookAheadEx` on the FIFO", "TCrdData"),
    _r("GT_CrdDataEx GT_LnXY*Ex GT_ArcXY*Ex", "`acc`",
       "pulse/ms²; mm/s² after `GT_InitLookAheadEx` on the FIFO", "TCrdData"),
    _r("GT_InitLookAheadEx", "`vMax`", "mm/s per axis", "TLookAheadParameter"),
    _r("GT_InitLookAheadEx", "`aMax`", "mm/s² per axis", "TLookAheadParameter"),
    _r("GT_InitLookAheadEx", "`scale`", "pulse/mm per axis", "TLookAheadParameter"),
    _r("GT_InitLookAheadEx", "`time`", "ms", "TLookAheadParameter"),
    _r("GT_SetVelModeLa GT_SetVelDefineModeLa GT_SetAccDefineModeLa GT_SetAxisVelValidModeLa",
       "`velMode`, `velDefMode`, `accDefMode`, `velValidAxis`", "a mode or an axis mask: no unit"),
    _r("GT*_SetPosCompareLinear* GT*_GetPosCompareLinear*",
       "`startPos*`, `interval*`", P, "TPosCompareLinear(2D)"),
    _r("GT*_PosCompareData GT*_PosCompareData2D", "`pos`, `posX`, `posY`", P,
       "TPosCompareData(2D)"),
    _r("GT*_PosCompareInfo", "`posX`, `posY`", P, "TPosCompareInfo"),
    _r("GT_PvtTable GT_PvtTableEx GT_PvtTableComplete", "`pTime`", "ms"),
    _r("GT_PvtTable GT_PvtTableEx GT_PvtTableComplete", "`pPos`", P),
    _r("GT_PvtTable GT_PvtTableEx GT_PvtTableComplete", "`pVel*`, `velBegin`, `velEnd`", V),
    _r("GT_SetLeadScrewComp", "`startPos`, `lenPos`, `pPositive`, `pNegative`", P),
    _r("GTN_RN_GetAbsEncPosEx", "`pEncPos`", "counts of the absolute encoder"),
    _r("GT_GetClock", "clock", "ms since `GT_Reset`"),
    _r("GTE_Wait", "`ms`", "ms of controller time"),
    _r("GTE_SetProgramSpeed", "`instructionsPerMs`", "motion-program instructions per ms"),
    _r("GTE_GetMachinePos", "position", "counts of the machine (its description sets them)"),
)
# fmt: on


def _matches(pattern: str, name: str) -> bool:
    return fnmatch.fnmatchcase(name, pattern) if "*" in pattern else pattern == name


@cache
def _index() -> tuple[dict[str, list[int]], list[tuple[str, Callable[[str], object], int]]]:
    """Row numbers by exact function name, and the wildcard patterns (compiled, with their
    longest literal part: a name without it is not matched against the pattern) with theirs."""
    exact: dict[str, list[int]] = {}
    wild: list[tuple[str, Callable[[str], object], int]] = []
    for i, r in enumerate(ROWS):
        for p in r.functions:
            if "*" in p:
                part = max(p.split("*"), key=len)
                wild.append((part, re.compile(fnmatch.translate(p)).match, i))
            else:
                exact.setdefault(p, []).append(i)
    return exact, wild


@cache
def units_of(name: str) -> tuple[Row, ...]:
    """The rows that name the GT function ``name`` (a ``GTN_`` twin: its ``GT_``'s; a
    ``GTN_`` function of its own, with no ``GT_`` form: its own), in table order."""
    return tuple(ROWS[i] for i in _rows_of(name))


@cache
def _rows_of(name: str) -> tuple[int, ...]:
    exact, wild = _index()
    if name.startswith("GTN_") and name not in exact:
        name = "GT_" + name[4:]
    hits = set(exact.get(name, ()))
    hits.update(i for part, match, i in wild if part in name and match(name))
    return tuple(sorted(hits))


def _plain(text: str) -> str:
    """Reference-page markup as docstring text: no backticks, bold or links."""
    text = re.sub(r"\[([^]]+)\]\([^)]+\)", r"\1", text)
    return text.replace("**", "").replace("`", "")


@cache
def _row_text(i: int) -> str:
    r = ROWS[i]
    return f"{_plain(r.what)}: {_plain(r.unit)}"


def units_text(name: str) -> str:
    """``Units: acc, dec: pulse/ms²; velStart: pulse/ms.`` ("" when nothing has a unit)."""
    rows = _rows_of(name)
    if not rows:
        return ""
    return "Units: " + "; ".join(_row_text(i) for i in rows) + "."


def with_units(name: str, doc: str | None) -> str | None:
    """``doc`` with the ``Units:`` paragraph of ``name`` after it."""
    text = units_text(name)
    if not text:
        return doc
    return f"{doc.rstrip()}\n\n{text}" if doc else text


#: the reference page's table sits between these lines
BEGIN = "<!-- generated from gtecat/gt/units.py (tests/gtecat/gt/test_units.py rewrites it) -->"
END = "<!-- end of the generated table -->"


def markdown() -> str:
    """The "By function" table of ``docs/reference/units.md``."""
    lines = ["| function | parameter | unit |", "|---|---|---|"]
    previous: tuple[str, ...] = ()
    for r in ROWS:
        cell = ""
        if (r.functions, r.note) != previous:
            cell = ", ".join(f"`{f}`" for f in r.functions)
            if r.note:
                first, *rest = r.note.split(", ", 1)
                cell += f" (`{first}`{', ' + rest[0] if rest else ''})"
        previous = (r.functions, r.note)
        lines.append(f"|{' ' + cell if cell else ''} | {r.what} | {r.unit} |")
    return "\n".join(lines) + "\n"


def write_page(path: str) -> bool:
    """Put :func:`markdown` between the markers of ``path``; True when it changed."""
    from pathlib import Path

    page = Path(path)
    text = page.read_text(encoding="utf-8")
    head, rest = text.split(BEGIN + "\n", 1)
    _, tail = rest.split(END, 1)
    new = f"{head}{BEGIN}\n{markdown()}{END}{tail}"
    if new != text:
        page.write_text(new, encoding="utf-8")
    return new != text


__all__ = ["ROWS", "Row", "markdown", "units_of", "units_text", "with_units", "write_page"]
