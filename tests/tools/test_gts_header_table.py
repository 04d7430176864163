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
