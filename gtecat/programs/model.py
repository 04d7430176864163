"""The compiled motion program: variables, functions and instructions (what ``.bin`` holds).

One :class:`Program` is what the compiler makes of a source file, what the program
image (``.bin``) and the symbol file (``.ini``) store (:mod:`gtecat.programs.image`)
and what ``GT_Download`` loads into the controller (:mod:`gtecat.programs.threads`).

Memory is words: the global area (at most 1024 words) and 32 data pages of 1024
words each, where a function's parameters and locals live.  A variable is a run
of words (1 for a scalar, ``n`` for ``int a[n]``) at an address of its area; an
``int`` word is the value, a ``double`` word its 16.16 fixed-point form
(:mod:`gtecat.programs.fixed`).

Every statement that does something is one instruction (:class:`Op`), and each
instruction costs the same controller time (``GT_Delay`` aside, which sleeps).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from enum import IntEnum

MAX_GLOBAL_WORDS = 1024  #: 10.4.1: at most 1024 global variables
MAX_LOCAL_WORDS = 1024  #: 10.4.1: at most 1024 local variables per function
PAGE_WORDS = 1024  #: a data page holds one function's locals
THREADS = 32  #: 10.2 / 10.3.5
PAGES = 32  #: 10.3.5
MAX_FUNCTIONS = 32  #: entry 10: a file holds at most 32 threads (functions)


class VarType(IntEnum):
    """``TVarInfo.dataType``: 0 ``int`` (``long`` is the same type), 1 ``double`` (16.16)."""

    INT = 0
    DOUBLE = 1

    @property
    def c_name(self) -> str:
        return "int" if self is VarType.INT else "double"


class Kind(IntEnum):
    """Where an operand's value is (also the kind of an index)."""

    NONE = 0  #: no operand (a call without destination, a bare ``return``) / no index
    CONST = 1  #: an immediate word (``value``)
    GLOBAL = 2  #: the global area, address ``value``
    LOCAL = 3  #: the thread's current data page, address ``value``


class Op(IntEnum):
    """Instruction codes (the ``.bin`` keeps these numbers)."""

    MOV = 1  #: dst = a
    UNARY = 2  #: dst = <sub> a   (sub: :class:`UnOp`)
    BINARY = 3  #: dst = a <sub> b (sub: :class:`BinOp`)
    CAST = 4  #: dst = (sub) a    (sub: the target :class:`VarType`)
    JUMP = 5  #: goto target
    JUMP_IF = 6  #: if (a) goto target
    RETURN = 7  #: return a       (a may be NONE)
    RETURN_IF = 8  #: if (a) return b
    CALL = 9  #: dst = GT function ``strings[target]`` (args...)  (dst may be NONE)


class UnOp(IntEnum):
    NEG = 1  #: -a
    NOT = 2  #: !a
    INV = 3  #: ~a


class BinOp(IntEnum):
    ADD = 1
    SUB = 2
    MUL = 3
    DIV = 4
    MOD = 5
    LT = 6
    GT = 7
    LE = 8
    GE = 9
    EQ = 10
    NE = 11
    LAND = 12
    LOR = 13
    BAND = 14
    BOR = 15
    BXOR = 16
    SHL = 17
    SHR = 18


BINOP_SYMBOLS: dict[str, BinOp] = {
    "+": BinOp.ADD,
    "-": BinOp.SUB,
    "*": BinOp.MUL,
    "/": BinOp.DIV,
    "%": BinOp.MOD,
    "<": BinOp.LT,
    ">": BinOp.GT,
    "<=": BinOp.LE,
    ">=": BinOp.GE,
    "==": BinOp.EQ,
    "!=": BinOp.NE,
    "&&": BinOp.LAND,
    "||": BinOp.LOR,
    "&": BinOp.BAND,
    "|": BinOp.BOR,
    "^": BinOp.BXOR,
    "<<": BinOp.SHL,
    ">>": BinOp.SHR,
}
SYMBOL_OF: dict[int, str] = {v: k for k, v in BINOP_SYMBOLS.items()}
RELATIONAL = frozenset({BinOp.LT, BinOp.GT, BinOp.LE, BinOp.GE, BinOp.EQ, BinOp.NE})
INT_ONLY = frozenset(
    {BinOp.MOD, BinOp.LAND, BinOp.LOR, BinOp.BAND, BinOp.BOR, BinOp.BXOR, BinOp.SHL, BinOp.SHR}
)


@dataclass(frozen=True, slots=True)
class Operand:
    """One operand of an instruction.

    ``kind``/``value``: a constant word, or the base address of a variable in the
    global area or the data page.  ``size``: the variable's words (bounds of an
    index; what a pointer argument may reach).  ``index_kind``/``index``: an array
    element's index, a constant or an ``int`` variable's address.  ``pointer``: a
    GT function's pointer argument (``&x``, ``&a[i]``, ``a``): the memory from that
    word to the end of the variable.
    """

    kind: Kind
    type: VarType = VarType.INT
    value: int = 0
    size: int = 1
    index_kind: Kind = Kind.NONE
    index: int = 0
    pointer: bool = False

    @staticmethod
    def none() -> Operand:
        return _NONE

    @staticmethod
    def const(type_: VarType, word: int) -> Operand:
        return Operand(Kind.CONST, type_, word)

    def describe(self) -> str:
        if self.kind is Kind.NONE:
            return "-"
        if self.kind is Kind.CONST:
            return f"#{self.value}" + ("d" if self.type is VarType.DOUBLE else "")
        area = "g" if self.kind is Kind.GLOBAL else "l"
        text = f"{area}{self.value}"
        if self.index_kind is Kind.CONST:
            text += f"[{self.index}]"
        elif self.index_kind is not Kind.NONE:
            text += f"[{'g' if self.index_kind is Kind.GLOBAL else 'l'}{self.index}]"
        if self.pointer:
            text = "&" + text
        return text + (":d" if self.type is VarType.DOUBLE else "")


_NONE = Operand(Kind.NONE)


@dataclass(frozen=True, slots=True)
class Instr:
    """One instruction; ``line`` is its source line (``TThreadSts.line``)."""

    op: Op
    line: int
    sub: int = 0
    target: int = 0  #: jump target (index in the code) or the called function's string
    operands: tuple[Operand, ...] = ()


@dataclass(frozen=True, slots=True)
class Variable:
    """A global or local variable (parameters are locals, first)."""

    name: str
    type: VarType
    address: int
    size: int = 1
    array: bool = False
    line: int = 0


@dataclass(frozen=True, slots=True)
class Function:
    """A function: its id is its position in the file (``GT_GetFunId``)."""

    name: str
    id: int
    returns: VarType | None  #: None: ``void``
    params: tuple[str, ...]
    locals: tuple[Variable, ...]
    local_words: int
    entry: int  #: first instruction
    end: int  #: one past the last instruction
    line: int = 0

    def local(self, name: str) -> Variable | None:
        for v in self.locals:
            if v.name == name:
                return v
        return None


@dataclass(frozen=True, slots=True)
class Program:
    """A compiled source file."""

    source: str  #: the source file's name (as given to the compiler)
    functions: tuple[Function, ...]
    globals: tuple[Variable, ...]
    global_words: int
    global_init: tuple[tuple[int, int], ...]  #: (address, word) set at download
    code: tuple[Instr, ...]
    strings: tuple[str, ...]  #: names of the GT functions the code calls
    build: str = field(default="", compare=False)  #: image digest, set by the image writer

    def function(self, name: str) -> Function | None:
        for f in self.functions:
            if f.name == name:
                return f
        return None

    def global_var(self, name: str) -> Variable | None:
        for v in self.globals:
            if v.name == name:
                return v
        return None

    def listing(self) -> str:
        """A readable disassembly (``gtecat compile --list``)."""
        out = []
        for f in self.functions:
            ret = f.returns.c_name if f.returns is not None else "void"
            out.append(f"function {f.id} {ret} {f.name}({', '.join(f.params)})")
            for pc in range(f.entry, f.end):
                ins = self.code[pc]
                if ins.op is Op.CALL:
                    what = f"CALL {self.strings[ins.target]}"
                elif ins.op in (Op.JUMP, Op.JUMP_IF):
                    what = f"{ins.op.name} -> {ins.target}"
                elif ins.op is Op.BINARY:
                    what = f"BINARY {SYMBOL_OF[ins.sub]}"
                elif ins.op is Op.UNARY:
                    what = f"UNARY {UnOp(ins.sub).name}"
                elif ins.op is Op.CAST:
                    what = f"CAST ({VarType(ins.sub).c_name})"
                else:
                    what = ins.op.name
                ops = " ".join(o.describe() for o in ins.operands)
                out.append(f"  {pc:5d}  line {ins.line:4d}  {what} {ops}".rstrip())
        return "\n".join(out)


__all__ = [
    "BINOP_SYMBOLS",
    "INT_ONLY",
    "MAX_FUNCTIONS",
    "MAX_GLOBAL_WORDS",
    "MAX_LOCAL_WORDS",
    "PAGES",
    "PAGE_WORDS",
    "RELATIONAL",
    "SYMBOL_OF",
    "THREADS",
    "BinOp",
    "Function",
    "Instr",
    "Kind",
    "Op",
    "Operand",
    "Program",
    "UnOp",
    "VarType",
    "Variable",
]
