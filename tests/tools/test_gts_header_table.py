"""tools/gts_header_table.py: C# wrappers read as headers, and --only-missing."""

from __future__ import annotations

from pathlib import Path

from tools import gts_header_table as tool

WRAPPER = """
using System.Runtime.InteropServices;
namespace GTN {
    public class mc {
        public const short GP_CORE = 1;
        public const short MC_AXIS = 30;
        public enum EMode { MODE_A = 0, MODE_B }
        public struct TInfo {
            public short a;
            public Int32 b;
            [MarshalAs(UnmanagedType.ByValArray, SizeConst = 4)]
            public double[] c;
        }
        [StructLayout(LayoutKind.Explicit)]
        public struct TPick { [FieldOffset(0)] public short s; [FieldOffset(1)] public double d; }
        [DllImport("gts.dll")]
        public static extern short GT_Known(short axis);
        [DllImport("gxn.dll")]
        public static extern short GTN_RN_SetMulti(short core, short encoder, UInt64 multiLines);
        [DllImport("gxn.dll")]
        public static extern short GTN_GetThing(short core, out Int32 pSts, ref uint pClock,
            short[] pList, string pFile, System.IntPtr pPrm, EMode mode, int segNum);
        [DllImport("gxn.dll")]
        public static extern short GTN_Opaque(short core, ref TInfo pInfo);
        [DllImport("gxn.dll")]
        public static extern short GTN_ByValue(short core, TInfo info);
    }
}
"""

GROUP = '''NAME = "vendor_basic"
TITLE = "basic functions"
DECLARED_ONLY = True
PROTOTYPES = r"""
short GT_Known(short axis);
"""
CONSTANTS = r"""
#define MC_AXIS 30
"""
'''

EXPORTS = '''NAME = "vendor_exports"
TITLE = "exported"
DECLARED_ONLY = True
PROTOTYPES = r"""
short GTN_Opaque(...);
short GTN_Other(...);
"""
'''


def test_a_csharp_wrapper_reads_as_table_lines(tmp_path: Path) -> None:
    cs = tmp_path / "w.cs"
    cs.write_text(WRAPPER)
    functions, tds, consts = tool.extract([cs])
    assert functions["GTN_RN_SetMulti"] == [
        "short core",
        "short encoder",
        "unsigned long long multiLines",
    ]
    assert functions["GTN_GetThing"] == [
        "short core",
        "long *pSts",
        "unsigned long *pClock /*inout*/",
        "short *pList /*inout[?]*/",
        "char *pFile /*str*/",
        "void *pPrm",
        "EMode mode",
        "long segNum",  # C#'s int is the vendor's 32-bit long; not "in t"
    ]
    assert "GTN_ByValue" not in functions  # a structure by value: left out
    kinds = {td.name: td.kind for td in tds}
    assert kinds == {"EMode": "enum", "TInfo": "struct", "TPick": "union"}
    assert consts["GP_CORE"] == 1


def test_only_missing_writes_what_the_table_lacks(tmp_path: Path) -> None:
    groups = tmp_path / "groups"
    groups.mkdir()
    (groups / "vendor_basic.py").write_text(GROUP)
    (groups / "vendor_exports.py").write_text(EXPORTS)
    cs = tmp_path / "w.cs"
    cs.write_text(WRAPPER)
    assert tool.main(["--only-missing", "--out", str(groups), str(cs)]) == 0
    written = {p.name for p in groups.glob("vendor_gtn_*.py")}
    assert "vendor_gtn_types.py" in written
    text = "".join((groups / n).read_text() for n in written)
    assert "GT_Known" not in text  # the table has it
    line = "short GTN_RN_SetMulti(short core, short encoder, unsigned long long multiLines);"
    assert line in text
    assert "GP_CORE 1" in text and "MC_AXIS" not in text
    exports = (groups / "vendor_exports.py").read_text()
    assert "GTN_Opaque" not in exports and "GTN_Other(...)" in exports  # now has a prototype
    # run again: the same files (its own vendor_gtn_* do not count as the table)
    assert tool.main(["--only-missing", "--out", str(groups), str(cs)]) == 0
    assert {p.name for p in groups.glob("vendor_gtn_*.py")} == written


def test_headers_that_disagree_first_named_wins_and_the_line_says_so(tmp_path: Path) -> None:
    newer = tmp_path / "newer.h"
    newer.write_text("GT_API GTN_SetFifoMode(short core, short index, short mode);\n")
    older = tmp_path / "older.h"
    older.write_text("GT_API GTN_SetFifoMode(short core, short index, short mode, short on);\n")
    tool.OTHERS.clear()
    functions, _, _ = tool.extract([newer, older])
    (line,) = tool.lines(functions)["basic"]
    assert line.startswith("short GTN_SetFifoMode(short core, short index, short mode);")
    assert "other public copies declare (short, short, short, short)" in line


NEWER = """
typedef short (*TUserCallback)(void *, long, void *);
typedef struct { short varId; short stationId; } StVar;
typedef struct Flags { unsigned short a : 1; unsigned short b : 1;
                       unsigned short rest : 14; } TFlags;
GT_API GTN_Upload(short card, char *path, void (*pfnProgress)(void *, short *), short &progress);
GT_API GTN_Close2(short card, bool en, int16_t mode, __int64 *pPos, TUserCallback cb);
GT_API GTN_AddVar(short card, StVar var);
GT_API GTN_GetFlags(short card, TFlags *pFlags);
GT_API GTN_Other(short core, short index);
"""


def test_the_constructs_of_a_newer_header_read_as_table_lines(tmp_path: Path) -> None:
    h = tmp_path / "newer.h"
    h.write_text(NEWER)
    functions, tds, _ = tool.extract([h])
    assert functions["GTN_Upload"] == [
        "short card",
        "char *path",
        "void *pfnProgress",  # a function pointer spelled in place
        "short *progress",  # a C++ reference travels as a pointer
    ]
    assert functions["GTN_Close2"] == [
        "short card",
        "unsigned char en",  # C++ bool: one byte
        "short mode",  # <stdint.h> names as the table spells them
        "long long *pPos",
        "void *cb",
    ]
    flags = next(td for td in tds if td.name == "TFlags")
    assert [(f.ctype, f.name) for f in flags.fields] == [("unsigned short", "bits1")]


def test_add_keeps_an_earlier_runs_lines_and_adds_the_newer_headers(tmp_path: Path) -> None:
    groups = tmp_path / "groups"
    groups.mkdir()
    (groups / "vendor_basic.py").write_text(GROUP)
    (groups / "vendor_exports.py").write_text(EXPORTS)
    cs = tmp_path / "w.cs"
    cs.write_text(WRAPPER)
    assert tool.main(["--only-missing", "--out", str(groups), str(cs)]) == 0
    before = "".join(p.read_text() for p in groups.glob("vendor_gtn_*.py"))
    assert "short GTN_Other(...);" not in before  # still in vendor_exports
    h = tmp_path / "newer.h"
    h.write_text(NEWER)
    assert tool.main(["--only-missing", "--add", "--out", str(groups), str(h)]) == 0
    after = "".join(p.read_text() for p in groups.glob("vendor_gtn_*.py"))
    line = "short GTN_RN_SetMulti(short core, short encoder, unsigned long long multiLines);"
    assert line in after  # the earlier run's line stays
    assert "short GTN_Upload(short card, char *path, void *pfnProgress" in after
    assert "GTN_AddVar" not in after  # a structure by value the table cannot name
    assert "typedef struct { unsigned short bits1; } TFlags;" in after
    assert "GTN_Other(...)" not in (groups / "vendor_exports.py").read_text()
    assert "short GTN_Other(short core, short index);" in after
    # the same run again changes nothing
    assert tool.main(["--only-missing", "--add", "--out", str(groups), str(h)]) == 0
    assert "".join(p.read_text() for p in groups.glob("vendor_gtn_*.py")) == after
