"""Entry-by-entry check of a program image before ``GT_Download`` loads it.

The image's CRC says the file was not damaged in transit; it says nothing of a file that was
written wrong on purpose or by another tool and then checksummed again.  The runtime trusts
what it links (an address is a list index, a jump target the next program counter), so every
entry the runtime will use is checked here, once, at download: function ranges, operand
counts and kinds per instruction, addresses and sizes inside their area, constant indices
inside their variable, jump targets inside their function, called GT functions known to the
program catalogue with as many arguments as their prototype.  A failure names the function,
the instruction and what is wrong; ``GT_Download`` returns 7 with it and the controller keeps
its previous program.
"""

from __future__ import annotations

from .gtcalls import Catalog
from .model import (
    MAX_FUNCTIONS,
    MAX_GLOBAL_WORDS,
    MAX_LOCAL_WORDS,
    PAGE_WORDS,
    BinOp,
    Function,
    Instr,
    Kind,
    Op,
    Operand,
    Program,
    UnOp,
    VarType,
)

#: operands each instruction has (CALL: the destination, then one per parameter)
_OPERANDS = {
    Op.MOV: 2,
    Op.UNARY: 2,
    Op.BINARY: 3,
    Op.CAST: 2,
    Op.JUMP: 0,
    Op.JUMP_IF: 1,
    Op.RETURN: 1,
    Op.RETURN_IF: 2,
}
#: instructions after which control never reaches the next one
_ENDS = (Op.RETURN, Op.JUMP)
_WORD_MIN, _WORD_MAX = -(1 << 31), (1 << 31) - 1


class ImageInvalid(ValueError):
    """An image entry the runtime cannot run safely (the message says which and why)."""


def verify(program: Program) -> None:
    """Raise :class:`ImageInvalid` unless every entry of ``program`` is runnable."""
    n_code = len(program.code)
    if not program.functions:
        raise ImageInvalid("the image holds no function")
    if len(program.functions) > MAX_FUNCTIONS:
        raise ImageInvalid(f"{len(program.functions)} functions, at most {MAX_FUNCTIONS}")
    if not 0 <= program.global_words <= MAX_GLOBAL_WORDS:
        raise ImageInvalid(f"{program.global_words} global words, at most {MAX_GLOBAL_WORDS}")
    for addr, word in program.global_init:
        if not 0 <= addr < program.global_words:
            raise ImageInvalid(
                f"an initial value at global word {addr}, outside 0..{program.global_words - 1}"
            )
        if not _WORD_MIN <= word <= _WORD_MAX:
            raise ImageInvalid(f"initial value {word} of global word {addr} is not a 32-bit word")
    owner = [-1] * n_code
    for f in program.functions:
        if not 0 <= f.entry < f.end <= n_code:
            raise ImageInvalid(
                f"function {f.name}: instructions {f.entry}..{f.end - 1} outside the image's "
                f"0..{n_code - 1}"
            )
        if not 0 <= f.local_words <= min(MAX_LOCAL_WORDS, PAGE_WORDS):
            raise ImageInvalid(f"function {f.name}: {f.local_words} local words, at most 1024")
        if len(f.params) > f.local_words:
            raise ImageInvalid(
                f"function {f.name}: {len(f.params)} parameters in {f.local_words} local words"
            )
        for pc in range(f.entry, f.end):
            if owner[pc] != -1:
                raise ImageInvalid(
                    f"function {f.name}: instruction {pc} belongs to another function too"
                )
            owner[pc] = f.id
        if program.code[f.end - 1].op not in _ENDS:
            raise ImageInvalid(
                f"function {f.name}: its last instruction ({f.end - 1}) neither returns nor "
                "jumps, so a thread would run past the function"
            )
    catalog = Catalog()
    for f in program.functions:
        for pc in range(f.entry, f.end):
            try:
                _instruction(program, f, pc, program.code[pc], catalog)
            except ImageInvalid as e:
                raise ImageInvalid(f"function {f.name}, instruction {pc}: {e}") from None


def _instruction(program: Program, f: Function, pc: int, ins: Instr, catalog: Catalog) -> None:
    ops = ins.operands
    op = ins.op
    if op is Op.CALL:
        if not 0 <= ins.target < len(program.strings):
            raise ImageInvalid(
                f"calls string {ins.target}, the image names {len(program.strings)} functions"
            )
        name = program.strings[ins.target]
        proto, why = catalog.lookup(name)
        if proto is None:
            raise ImageInvalid(why)
        if len(ops) != 1 + len(proto.params):
            raise ImageInvalid(
                f"{name} with {len(ops) - 1} arguments, its prototype has {len(proto.params)}"
            )
        _operand(f, ops[0], write=True, may_be_none=True)
        for p, o in zip(proto.params, ops[1:], strict=True):
            if p.pointer:
                if o.kind is Kind.NONE and p.optional:
                    continue
                if o.kind not in (Kind.GLOBAL, Kind.LOCAL):
                    raise ImageInvalid(f"{name}: {p.name} is a pointer, the operand is not memory")
            _operand(f, o, write=False, may_be_none=False)
        return
    want = _OPERANDS[op]
    if len(ops) != want:
        raise ImageInvalid(f"{op.name} with {len(ops)} operands, it takes {want}")
    if op is Op.UNARY:
        _enum(UnOp, ins.sub, "unary operator")
    elif op is Op.BINARY:
        _enum(BinOp, ins.sub, "binary operator")
    elif op is Op.CAST:
        _enum(VarType, ins.sub, "cast type")
    if op in (Op.JUMP, Op.JUMP_IF) and not f.entry <= ins.target < f.end:
        raise ImageInvalid(f"jumps to {ins.target}, outside its function's {f.entry}..{f.end - 1}")
    if op in (Op.MOV, Op.UNARY, Op.BINARY, Op.CAST):
        _operand(f, ops[0], write=True, may_be_none=False)
        for o in ops[1:]:
            _operand(f, o, write=False, may_be_none=False)
    elif op is Op.JUMP_IF:
        _operand(f, ops[0], write=False, may_be_none=False)
    elif op is Op.RETURN:
        _operand(f, ops[0], write=False, may_be_none=True)
    elif op is Op.RETURN_IF:
        _operand(f, ops[0], write=False, may_be_none=False)
        _operand(f, ops[1], write=False, may_be_none=True)
    if pc + 1 >= f.end and op not in _ENDS:  # pragma: no cover - verify() checked the last
        raise ImageInvalid("runs past its function")


def _enum(cls: type, value: int, what: str) -> None:
    try:
        cls(value)
    except ValueError:
        raise ImageInvalid(f"{what} {value} does not exist") from None


def _area_words(kind: Kind, f: Function) -> int:
    return MAX_GLOBAL_WORDS if kind is Kind.GLOBAL else PAGE_WORDS


def _operand(f: Function, o: Operand, *, write: bool, may_be_none: bool) -> None:
    if o.kind is Kind.NONE:
        if may_be_none:
            return
        raise ImageInvalid("an operand is missing")
    if o.kind is Kind.CONST:
        if write:
            raise ImageInvalid("writes into a constant")
        if not _WORD_MIN <= o.value <= _WORD_MAX:
            raise ImageInvalid(f"constant {o.value} is not a 32-bit word")
        if o.index_kind is not Kind.NONE or o.pointer:
            raise ImageInvalid("a constant with an index or as a pointer")
        return
    words = _area_words(o.kind, f)
    where = "global" if o.kind is Kind.GLOBAL else "local"
    if o.size < 1 or not 0 <= o.value or o.value + o.size > words:
        raise ImageInvalid(
            f"{where} variable at word {o.value} of {o.size} words, outside the area's "
            f"0..{words - 1}"
        )
    if o.index_kind is Kind.CONST:
        if not 0 <= o.index < o.size:
            raise ImageInvalid(f"index {o.index} outside its variable's 0..{o.size - 1}")
    elif o.index_kind in (Kind.GLOBAL, Kind.LOCAL):
        iwords = _area_words(o.index_kind, f)
        if not 0 <= o.index < iwords:
            raise ImageInvalid(f"its index variable at word {o.index}, outside 0..{iwords - 1}")
    elif o.index_kind is not Kind.NONE:
        raise ImageInvalid(f"index kind {o.index_kind} does not exist")


__all__ = ["ImageInvalid", "verify"]
