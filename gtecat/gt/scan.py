"""What an application's sources use of the GT API, and whether gtecat has it.

Reads C, C++, C# and VB.NET files (or folders of them) and finds every ``GT_``/``GTN_``
function it calls and every vendor constant it names (``MC_AXIS``, ``CMD_SUCCESS``,
``HOME_MODE_LIMIT``...).  Declarations are not uses: the lines of a vendor header or wrapper
(``GT_API GT_x(...)``, ``[DllImport] ... extern short GT_x``, ``Declare Function GT_x``,
``#define`` / ``const`` of a constant) are skipped, so a project that ships the vendor's
``gts.h`` or ``gts.cs`` lists only what its own code calls.  Comments are skipped too.
"""

from __future__ import annotations

import re
from collections.abc import Iterable
from dataclasses import dataclass, field
from pathlib import Path

from .surface import by_name, constants

EXTENSIONS = {".c", ".h", ".cpp", ".hpp", ".cc", ".cxx", ".hxx", ".cs", ".vb", ".bas"}
SKIP_DIRS = {".git", ".svn", ".vs", "bin", "obj", "node_modules", "__pycache__"}

#: prefixes of the vendor's constants (a name with one of them that gtecat lacks is missing)
CONSTANT_PREFIXES = (
    "CMD_", "MC_", "CAPTURE_", "HOME_", "CRD_", "FOLLOW_", "PT_", "GEAR_", "PROFILE_MODE_",
    "ECAT_", "LIMIT_", "AXIS_STATUS_", "INTERPOLATION_", "CHANNEL_", "DLL_VERSION_",
    "FIFO_", "TRIGGER_", "POS_COMPARE_", "COMPARE_", "STOP_", "PVT_", "CAM_", "LASER_",
)  # fmt: skip

_FUNCTION = re.compile(r"\bGTN?_[A-Za-z0-9_]+")
_CONSTANT = re.compile(r"\b[A-Z][A-Z0-9]*_[A-Z0-9_]+\b")
#: an enum member line of a vendor header (``TIME_ELAPSE_PROFILE = 1000,``)
_ENUM_MEMBER = re.compile(r"^\s*[A-Z][A-Z0-9]*_[A-Z0-9_]*\s*(?:=\s*[^;()]*)?,?\s*$")
_DECLARATION = re.compile(
    r"\bGT_API\b|\bextern\s+(?:\"C\"\s+)?short\b|\bDeclare\s+(?:Function|Sub)\b|"
    r"^\s*#\s*define\b|\bconst\s+\w+\s+[A-Z][A-Z0-9_]*\s*=|\bConst\s+[A-Z][A-Z0-9_]*\b|"
    r"\bDllImport\b|^\s*(?:public\s+|private\s+|internal\s+)?static\s+extern\b",
    re.I,
)
_C_COMMENTS = re.compile(r"/\*.*?\*/|//[^\n]*|\"(?:\\.|[^\"\\\n])*\"", re.S)
_VB_COMMENT = re.compile(r"'[^\n]*|\"[^\"\n]*\"")


@dataclass
class Use:
    name: str
    kind: str  #: "function" | "constant"
    status: str  #: "emulated" | "declared only" | "missing" | "defined"
    count: int = 0
    where: list[str] = field(default_factory=list)  #: first few file:line

    def ok(self) -> bool:
        return self.status in ("emulated", "defined")


def files(paths: Iterable[str | Path]) -> list[Path]:
    """Source files under ``paths`` (FileNotFoundError for a path that does not exist)."""
    out: list[Path] = []
    for p in map(Path, paths):
        if p.is_dir():
            for f in sorted(p.rglob("*")):
                if (
                    f.suffix.lower() in EXTENSIONS
                    and f.is_file()
                    and not SKIP_DIRS & set(f.relative_to(p).parts[:-1])
                ):
                    out.append(f)
        elif p.is_file():
            out.append(p)
        else:
            raise FileNotFoundError(f"{p}: no such file or folder")
    return out


def _strip(text: str, vb: bool) -> str:
    """Comments and string literals blanked, line numbers kept."""

    def blank(m: re.Match[str]) -> str:
        s = m.group(0)
        return re.sub(r"[^\n]", " ", s)

    return (_VB_COMMENT if vb else _C_COMMENTS).sub(blank, text)


def scan(paths: Iterable[str | Path]) -> list[Use]:
    """Every GT function and vendor constant the sources use, sorted by name."""
    known_fn = by_name()
    known_const = constants()
    uses: dict[str, Use] = {}
    for f in files(paths):
        raw = f.read_bytes()
        try:
            text = raw.decode("utf-8")
        except UnicodeDecodeError:
            text = raw.decode("gbk", "replace")  # Chinese Windows sources
        text = _strip(text, f.suffix.lower() in (".vb", ".bas"))
        for lineno, line in enumerate(text.splitlines(), 1):
            if "_" not in line or _DECLARATION.search(line) or _ENUM_MEMBER.match(line):
                continue
            for m in _FUNCTION.finditer(line):
                name = m.group(0)
                if name == "GT_API":
                    continue
                u = uses.get(name)
                if u is None:
                    e = known_fn.get(name)
                    status = (
                        "missing" if e is None else "emulated" if e.emulated else "declared only"
                    )
                    u = uses[name] = Use(name, "function", status)
                u.count += 1
                if len(u.where) < 3:
                    u.where.append(f"{f}:{lineno}")
            for m in _CONSTANT.finditer(line):
                name = m.group(0)
                if name.startswith(("GT_", "GTN_", "GTE_")):
                    continue
                if name not in known_const and not name.startswith(CONSTANT_PREFIXES):
                    continue
                u = uses.get(name)
                if u is None:
                    status = "defined" if name in known_const else "missing"
                    u = uses[name] = Use(name, "constant", status)
                u.count += 1
                if len(u.where) < 3:
                    u.where.append(f"{f}:{lineno}")
    return sorted(uses.values(), key=lambda u: (u.kind, u.name))


__all__ = ["EXTENSIONS", "Use", "files", "scan"]
