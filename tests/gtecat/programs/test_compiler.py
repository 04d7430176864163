"""The language of manual 10.4: what compiles, and every refusal with its line and reason."""

from __future__ import annotations

import configparser

import pytest

from gtecat.programs import image
from gtecat.programs.compiler import CompileFailed, compile_source
from gtecat.programs.model import Kind, Op, VarType

SUM = """\
/* example 10-1 */
int sum;

int add(int begin, int end)
{
    int i;
    int cc;

    i = begin;
lbl_loop:
    cc = i > end;
    if(cc) goto lbl_end;
    sum = sum + i;
    i = i + 1;
    goto lbl_loop;
lbl_end:
    return sum;
}
"""


def errors(src: str) -> list[tuple[int, str]]:
    with pytest.raises(CompileFailed) as e:
        compile_source(src, "t.c")
    return [(x.line, x.message) for x in e.value.errors]


def fn(body: str, head: str = "") -> str:
    """A program: ``head`` at file level, then ``int f(int a)`` whose body starts on line 3."""
    return f"{head}\nint f(int a)\n{{\n{body}\n}}\n" if head else f"int f(int a)\n{{\n{body}\n}}\n"


# --- what compiles -----------------------------------------------------------------------------
def test_example_10_1_compiles_to_one_instruction_per_statement():
    p = compile_source(SUM, "sum.c")
    (f,) = p.functions
    assert (f.name, f.id, f.params, f.returns) == ("add", 0, ("begin", "end"), VarType.INT)
    assert [v.name for v in f.locals] == ["begin", "end", "i", "cc"]
    assert [v.address for v in f.locals] == [0, 1, 2, 3]
    assert [(v.name, v.address) for v in p.globals] == [("sum", 0)]
    ops = [(i.op, i.line) for i in p.code[f.entry : f.end]]
    assert ops == [
        (Op.MOV, 9),
        (Op.BINARY, 11),
        (Op.JUMP_IF, 12),
        (Op.BINARY, 13),
        (Op.BINARY, 14),
        (Op.JUMP, 15),
        (Op.RETURN, 17),
        (Op.RETURN, 18),  # falling off the end
    ]
    assert p.code[2].target == 6 and p.code[5].target == 1


def test_the_manual_10_4_3_forms_compile():
    src = """\
#define MC_GPO 12 // a macro outside functions (10.4.3 note)
#define NEG (-3)
#define BIG 0xFFFFFFFF
long g;
double d = 1.5;
int arr[MC_GPO];
double darr[4];
void f(void)
{
    int i, sum, cc;
    int a = 5;
    double x;
    i = 1;
    sum = 0;
lbl_loop:
    sum = sum + i;
    i = i + 1;
    cc = i <= 10;
    if(cc) goto lbl_loop;
    arr[3] = NEG;
    arr[i] = sum;
    g = arr[3];
    g = BIG;
    x = d * 2;
    x = -x;
    x = (double)i;
    i = (int)x;
    i = (long)i;
    cc = x != d;
    cc = !cc;
    cc = ~cc;
    cc = i && sum;
    cc = i << 2;
    darr[i] = x;
    x = 1e-3;
    x = .5;
    if(cc) return;
    if(1) goto lbl_end;
lbl_end:
}
"""
    p = compile_source(src, "forms.c")
    assert p.functions[0].returns is None
    assert p.global_init == ((p.global_var("d").address, 98304),)  # 1.5 * 65536
    consts = [o.value for i in p.code for o in i.operands if o.kind is Kind.CONST]
    assert -3 in consts and -1 in consts  # NEG, 0xFFFFFFFF as the 32-bit pattern


def test_gt_calls_compile_with_every_argument_and_pointer_forms():
    src = """\
double pos[4];
int sts[2];
int f()
{
    int clk;
    int loop;
    int rtn;
    double prm[4];
    GT_GetClock(&clk, &loop);
    rtn = GT_GetSts(1, &sts[0], 2, 0);
    GT_GetPrfPos(1, pos, 4, &clk);
    GT_GetTrapPrm(1, prm);
    GT_SetVel(1, 2);
    GT_SetVel(1, 2.5);
    GT_Stop(0xFFF, 0);
    GT_Delay(10);
    GT_SetDataPage(3);
    return rtn;
}
"""
    p = compile_source(src, "calls.c")
    assert set(p.strings) == {
        "GT_GetClock",
        "GT_GetSts",
        "GT_GetPrfPos",
        "GT_GetTrapPrm",
        "GT_SetVel",
        "GT_Stop",
        "GT_Delay",
        "GT_SetDataPage",
    }
    calls = [i for i in p.code if i.op is Op.CALL]
    sts = calls[1]
    assert sts.operands[0].kind is Kind.LOCAL  # rtn = ...
    assert sts.operands[2].pointer and sts.operands[2].size == 2
    assert sts.operands[4].kind is Kind.NONE  # 0 for the optional pClock
    vel = calls[4]
    assert vel.operands[2].type is VarType.DOUBLE and vel.operands[2].value == 2 << 16


def test_image_and_symbols_round_trip(tmp_path):
    src = tmp_path / "sum.c"
    src.write_text(SUM)
    p = compile_source(SUM, "sum.c")
    bin_path, ini_path = image.write(p, src)
    assert (bin_path.name, ini_path.name) == ("sum.bin", "sum.ini")
    q = image.load(bin_path)
    assert q == p and len(q.build) == 32
    cp = configparser.ConfigParser()
    cp.read(ini_path)
    assert cp["function add"]["params"] == "begin, end"
    assert cp["local add.end"]["id"] == "1" and cp["global sum"]["type"] == "int"
    assert bin_path.read_bytes()[:8] == image.MAGIC


def test_damaged_or_mismatched_images_are_refused(tmp_path):
    src = tmp_path / "sum.c"
    src.write_text(SUM)
    bin_path, ini_path = image.write(compile_source(SUM, "sum.c"), src)
    data = bytearray(bin_path.read_bytes())
    data[-3] ^= 0xFF
    bad = tmp_path / "bad.bin"
    bad.write_bytes(bytes(data))
    (tmp_path / "bad.ini").write_text(ini_path.read_text())
    with pytest.raises(image.ImageError) as e:
        image.load(bad)
    assert e.value.code == 2008 and "damaged" in str(e.value)
    with pytest.raises(image.ImageError) as e:
        image.load(tmp_path / "missing.bin")
    assert e.value.code == 2007
    ini_path.unlink()
    with pytest.raises(image.ImageError) as e:
        image.load(bin_path)
    assert e.value.code == 2008 and ".ini" in str(e.value)
    other = tmp_path / "other.c"
    other.write_text(SUM.replace("i + 1", "i + 2"))
    image.write(compile_source(other.read_text(), "sum.c"), other)
    (tmp_path / "sum.ini").write_text((tmp_path / "other.ini").read_text())
    with pytest.raises(image.ImageError) as e:
        image.load(bin_path)
    assert e.value.code == 2008 and "another build" in str(e.value)


def test_listing_names_every_instruction():
    text = compile_source(SUM, "sum.c").listing()
    assert "function 0 int add(begin, end)" in text
    assert "BINARY >" in text and "JUMP_IF -> 6" in text


# --- what does not ------------------------------------------------------------------------------
REFUSED = [
    # (program, line, a piece of the message)
    (fn("    a = a + a + a;"), 3, "only two operands per operation"),
    (fn("    int b;\n    b = (a + 1) * 2;"), 4, "only two operands"),
    (fn("    int cc;\n    if(a > 1) goto l;\nl:"), 4, "condition of if must be a variable"),
    (fn("    if(a) a = 1;"), 3, "takes only `goto label;` or `return value;`"),
    (fn("    double d;\n    a = d;"), 4, "mixed types"),
    (fn("    double d;\n    d = d + a;"), 4, "mixed types"),
    (fn("    double d;\n    a = d > a;"), 4, "mixed types"),
    (fn("    a = 2.5;"), 3, "double constant where an int is needed"),
    (fn("    double d;\n    a = d % d;"), 4, "% takes int operands"),
    (fn("    g(1);", "int g(int x)\n{\n    return x;\n}"), 7, "functions cannot call each other"),
    (fn("    GT_GetClock(&a);"), 3, "2 argument(s) (pClock, pLoop), 1 given"),
    (fn("    GT_NoSuchThing(1);"), 3, "unknown GT function GT_NoSuchThing"),
    (fn("    foo(1);"), 3, "unknown function foo"),
    (fn("    GT_Open(0, 1);"), 3, "belongs to the host application"),
    (fn("    GT_LoadConfig(a);"), 3, "GT_LoadConfig belongs to the host"),
    (fn("    GT_SetVel(1, a);"), 3, "vel is double"),
    (fn("    double d;\n    GT_GetEcatEncPos(1, &d);"), 4, "points to long"),
    (fn("    GT_GetEcatEncPos(1, 0);"), 3, "may not be NULL"),
    (fn("    GT_GetEcatEncPos(1, a);"), 3, "pass &a"),
    (fn("    GT_SetVel(1, a + 1);"), 3, "expression"),
    (fn("    GT_SetPos(40000, 1);"), 3, "out of range"),
    (fn("    int b[2];\n    GT_GetSts(1, &b[0], 3, 0);"), 4, "room for 3"),
    (fn("    int b[4];\n    a = b[b[1]];"), 4, "an array element is not an index"),
    (fn("    int b[4];\n    a = b[a + 1];"), 4, "must be a constant or a variable"),
    (fn("    int b[4];\n    a = b[4];"), 4, "index 4 out of range"),
    (fn("    int b[4];\n    a = b;"), 4, "needs an index"),
    (fn("    int b[2][2];"), 3, "one-dimensional"),
    (fn("    a = c;"), 3, "unknown variable c"),
    (fn("    goto nowhere;"), 3, "no label nowhere"),
    (fn("l:\nl:"), 4, "label l is defined twice"),
    (fn("    int a;"), 3, "a is declared twice"),
    (fn("    a++;"), 3, "++ and -- are not supported"),
    (fn("    a += 1;"), 3, "compound assignment"),
    (fn("    while(a) { a = a - 1; }"), 3, "while loops are not supported"),
    (fn("    for(;;) { }"), 3, "for loops are not supported"),
    (fn("    if(a) goto x; else goto y;\nx:\ny:"), 3, "else is not supported"),
    (fn("    { a = 1; }"), 3, "blocks"),
    (fn("    a = a ? 1 : 2;"), 3, "conditional expressions"),
    (fn("    a = 1\n    a = 2;"), 3, "missing ';'"),
    (fn("    char c;"), 3, "type char does not exist"),
    (fn("    #define X 1"), 3, "#define must stand outside functions"),
    (fn("    return;"), 3, "return needs a value"),
    (fn("    double d;\n    return d;"), 4, "mixed types: f returns int"),
    (fn("    a = &a;"), 3, "& only passes a variable"),
    (fn("    a = 99999999999;"), 3, "outside the 32-bit int range"),
    (fn("    double d;\n    d = 40000.0;"), 4, "outside the motion-program double range"),
    (fn("    a = GT_GetClock(&a, &a) + 1;", ""), 3, "a GT call is a statement"),
    ("#include <gts.h>\n" + fn("    return a;"), 1, "#include is not supported"),
    ("int x[2000];\n" + fn("    return a;"), 1, "too many globals"),
    (fn("    int big[1024];"), 3, "too many locals"),
    ("int f(int a);\n" + fn("    return a;"), 1, "prototype"),
    ("int g;\nint g;\n" + fn("    return a;"), 2, "declared twice"),
    ('int f()\n{\n    GT_LoadConfig("x");\n}\n', 3, "text constants"),
    ("/* open comment\nint f()\n{\n}\n", 1, "never closed"),
    ("int g;\n", 0, "no function"),
]


@pytest.mark.parametrize(("src", "line", "fragment"), REFUSED, ids=[r[2][:40] for r in REFUSED])
def test_refused_with_line_and_reason(src, line, fragment):
    found = errors(src)
    assert any(ln == line and fragment in msg for ln, msg in found), found


def test_table_10_2_functions_gtecat_lacks_are_named_so():
    from gtecat.gt.table import FUNCTIONS
    from gtecat.programs.gtcalls import TABLE_10_2

    missing = sorted(TABLE_10_2 - set(FUNCTIONS) - {"GT_Delay", "GT_SetDataPage"})
    if not missing:
        pytest.skip("gtecat has every function of table 10-2")
    found = errors(fn(f"    {missing[0]}(1);"))
    assert found == [
        (
            3,
            f"{missing[0]} is callable from motion programs on the vendor's "
            "controller (table 10-2), but gtecat does not emulate it",
        )
    ]


def test_every_error_of_a_file_is_reported_in_line_order():
    src = fn("    a = a + a + a;\n    a = 2.5;\n    GT_Foo(1);\n    a++;")
    lines = [ln for ln, _ in errors(src)]
    assert lines == [3, 4, 5, 6]


def test_compile_file_reads_gbk_sources(tmp_path):
    from gtecat.programs.compiler import compile_file

    p = tmp_path / "gbk.c"
    p.write_bytes(("// 累加求和\n" + SUM).encode("gbk"))
    assert compile_file(p).functions[0].name == "add"
    with pytest.raises(CompileFailed) as e:
        compile_file(tmp_path / "none.c")
    assert e.value.first.line == 0 and "cannot read" in e.value.first.message
