"""The motion-program compiler: source text (manual 10.4) -> :class:`.model.Program`.

:func:`compile_source` parses with :mod:`gtecat.programs.language` and checks the
rules of 10.4 on the tree, reporting every violation with its line:

* types ``int`` (``long`` is the same 32-bit type) and ``double`` (16.16 fixed point);
  ``void`` only as a return type;
* constants: decimal, hexadecimal (up to ``0xFFFFFFFF``, taken as the 32-bit
  pattern) and floating; ``#define NAME constant`` outside functions, before use;
* globals (at most 1024 words) and locals (at most 1024 words per function,
  parameters included), scalars or one-dimensional arrays of a constant size, with
  an optional initial value (a constant for globals, set at download; for a local
  the declaration is an assignment executed where it stands);
* an array element is indexed by a constant (checked against the size) or by an
  ``int`` variable (checked at run time) - never by an array element or an expression;
* statements: ``x = a;``, ``x = op a;`` (``-``, ``!``, ``~``), ``x = a op b;`` (two
  operands), ``x = (int) a;`` / ``x = (double) a;``, ``GT_f(args);`` / ``x = GT_f(args);``,
  ``if(var) goto label;``, ``if(var) return value;``, ``goto label;``, ``return value;``,
  ``label:``;
* operands of one operation are of one type, the result goes to a variable of
  its type (relational and logical results are ``int``); an integer constant takes
  the type of the other operand (``d = d + 1``), a floating constant never becomes
  an ``int``; ``%``, the logical and the bit operators take ``int`` only;
* functions may call GT functions (:mod:`gtecat.programs.gtcalls`) but not each
  other; every parameter of a GT function is passed (10.3.1), a pointer parameter
  as ``&variable``, ``&array[i]`` or ``array`` of the pointed-to type (``0`` for a
  pointer the table marks optional); a structure pointer (``TTrapPrm *``) takes an
  array whose words are the structure's fields in order.

Every statement that does something is one instruction; falling off the end of a
function is a ``return`` (result 0).
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace
from fractions import Fraction
from pathlib import Path
from typing import Any

from lark import Token, Tree

from . import fixed
from .gtcalls import Catalog
from .language import CompileFailed, SourceError, parse
from .model import (
    BINOP_SYMBOLS,
    INT_ONLY,
    MAX_GLOBAL_WORDS,
    MAX_LOCAL_WORDS,
    RELATIONAL,
    Function,
    Instr,
    Kind,
    Op,
    Operand,
    Program,
    UnOp,
    Variable,
    VarType,
)

_TYPES = {"int": VarType.INT, "long": VarType.INT, "double": VarType.DOUBLE, "void": None}
_UNARY = {"-": UnOp.NEG, "!": UnOp.NOT, "~": UnOp.INV}


class _Error(Exception):
    def __init__(self, line: int, message: str) -> None:
        super().__init__(message)
        self.line = line
        self.message = message


@dataclass
class _Const:
    """A constant known while compiling (exact value, its type)."""

    value: int | Fraction
    type: VarType
    hex: bool = False

    def text(self) -> str:
        if self.type is VarType.DOUBLE:
            try:
                return f"{float(self.value):g}"
            except OverflowError:
                return "a number beyond the double range"
        if abs(self.value) >= 10**60:  # the parser keeps literals shorter than this
            return "a number of more than 60 digits"  # pragma: no cover - folded results
        return str(self.value)


@dataclass
class _Ref:
    """A variable (scalar) or an array element as an operand."""

    var: Variable
    scope: Kind
    index_kind: Kind = Kind.NONE
    index: int = 0
    text: str = ""

    @property
    def type(self) -> VarType:
        return self.var.type

    def operand(self) -> Operand:
        return Operand(
            self.scope,
            self.var.type,
            self.var.address,
            self.var.size,
            self.index_kind,
            self.index,
        )


_Value = _Const | _Ref


@dataclass
class _Scope:
    """One function being compiled."""

    name: str
    returns: VarType | None
    locals: dict[str, Variable] = field(default_factory=dict)
    words: int = 0
    labels: dict[str, int] = field(default_factory=dict)
    fixups: list[tuple[int, str, int]] = field(default_factory=list)


def _line(node: Tree | Token) -> int:
    if isinstance(node, Token):
        return node.line or 0
    return getattr(node.meta, "line", 0) or 0


class _Compiler:
    def __init__(self, source: str, filename: str, catalog: Catalog) -> None:
        self.src = source
        self.filename = filename
        self.catalog = catalog
        self.errors: list[SourceError] = []
        self.macros: dict[str, _Const] = {}
        self.globals: dict[str, Variable] = {}
        self.global_words = 0
        self.global_init: list[tuple[int, int]] = []
        self.function_names: set[str] = set()
        self.functions: list[Function] = []
        self.code: list[Instr] = []
        self.strings: dict[str, int] = {}

    # --- driver -----------------------------------------------------------------------------
    def run(self, tree: Tree) -> Program:
        for item in tree.children:
            if isinstance(item, Tree) and item.data == "function":
                self.function_names.add(str(item.children[1]))
        for item in tree.children:
            try:
                kind = item.data
                if kind == "directive":
                    self.directive(item.children[0])
                elif kind == "declaration":
                    self.declaration(None, item)
                elif kind == "function":
                    self.function(item)
                elif kind == "prototype":
                    raise _Error(
                        _line(item),
                        f"prototype of {item.children[1]}: not needed, and not supported "
                        "(functions of a program cannot call each other, 10.4.1)",
                    )
            except _Error as e:
                self.error(e.line, e.message)
        if not self.functions and not self.errors:
            self.error(0, "the program has no function")
        if self.errors:
            raise CompileFailed(self.errors)
        return Program(
            source=self.filename,
            functions=tuple(self.functions),
            globals=tuple(self.globals.values()),
            global_words=self.global_words,
            global_init=tuple(self.global_init),
            code=tuple(self.code),
            strings=tuple(self.strings),
        )

    def error(self, line: int, message: str) -> None:
        self.errors.append(SourceError(line, message))

    def text(self, node: Tree | Token) -> str:
        if isinstance(node, Token):
            return str(node)
        m = node.meta
        if getattr(m, "empty", True):
            return ""
        return " ".join(self.src[m.start_pos : m.end_pos].split())

    # --- #define ----------------------------------------------------------------------------
    def directive(self, tok: Token, inside: bool = False) -> None:
        line = tok.line or 0
        text = str(tok)[1:].strip()
        word, _, rest = text.partition(" ")
        if inside:
            raise _Error(line, "#define must stand outside functions (10.4.3)")
        if word != "define":
            raise _Error(
                line,
                f"#{word} is not supported: motion programs know only #define "
                "(the GT functions need no header)",
            )
        parts = rest.strip().split(None, 1)
        if not parts or not parts[0].isidentifier():
            if parts and "(" in parts[0]:
                raise _Error(line, "macros with parameters are not supported: #define NAME value")
            raise _Error(line, "#define needs a name and a constant: #define NAME value")
        name = parts[0]
        if len(parts) < 2:
            raise _Error(line, f"#define {name} needs a constant value")
        if name in self.macros:
            raise _Error(line, f"macro {name} is defined twice")
        self.macros[name] = self.macro_value(parts[1].strip(), line)

    def macro_value(self, text: str, line: int) -> _Const:
        body = text
        while body.startswith("(") and body.endswith(")"):
            body = body[1:-1].strip()
        sign = 1
        if body[:1] in "+-":
            sign = -1 if body[0] == "-" else 1
            body = body[1:].strip()
        if body in self.macros:
            c = self.macros[body]
            return _Const(sign * c.value, c.type, c.hex)
        try:
            tree = _CONST_PARSER(body)
        except ValueError:
            raise _Error(
                line, f"a macro's value must be a constant (a number or a macro), not {text!r}"
            ) from None
        return _Const(sign * tree.value, tree.type, tree.hex)

    # --- declarations -----------------------------------------------------------------------
    def declaration(self, scope: _Scope | None, node: Tree) -> None:
        type_node, *declarators = node.children
        vtype = self.var_type(type_node, "a variable")
        for d in declarators:
            try:
                self.declarator(scope, vtype, d)
            except _Error as e:
                self.error(e.line, e.message)

    def var_type(self, type_node: Tree, what: str) -> VarType:
        word = str(type_node.children[0])
        t = _TYPES[word]
        if t is None:
            raise _Error(_line(type_node), f"{what} cannot be void")
        return t

    def declarator(self, scope: _Scope | None, vtype: VarType, d: Tree) -> None:
        name_tok, *rest = d.children
        init = rest.pop() if rest else None
        suffixes = rest
        name, line = str(name_tok), _line(name_tok)
        self.check_new_name(scope, name, line)
        size, array = 1, False
        if len(suffixes) > 1:
            raise _Error(line, f"{name}: only one-dimensional arrays are supported (10.4.1)")
        if suffixes:
            array = True
            size_node = suffixes[0].children[0]
            if size_node is None:
                raise _Error(line, f"array {name} needs a size: {name}[10]")
            c = self.value(scope, size_node, f"the size of array {name}")
            if not isinstance(c, _Const) or c.type is not VarType.INT:
                raise _Error(line, f"the size of array {name} must be an int constant")
            size = int(c.value)
            if size < 1:
                raise _Error(line, f"array {name} must have at least one element, not {size}")
        if scope is None:
            address = self.global_words
            if address + size > MAX_GLOBAL_WORDS:
                raise _Error(
                    line,
                    f"{name}: too many globals ({address + size} words; at most "
                    f"{MAX_GLOBAL_WORDS}, 10.4.1)",
                )
            var = Variable(name, vtype, address, size, array, line)
            self.global_words += size
            self.globals[name] = var
            if init is not None:
                if array:
                    raise _Error(line, f"array {name} cannot have an initial value")
                c = self.value(None, init, f"the initial value of {name}")
                if not isinstance(c, _Const):
                    raise _Error(line, f"the initial value of global {name} must be a constant")
                self.global_init.append((address, self.word(c, vtype, line)))
            return
        address = scope.words
        if address + size > MAX_LOCAL_WORDS:
            raise _Error(
                line,
                f"{name}: too many locals in {scope.name} ({address + size} words; at most "
                f"{MAX_LOCAL_WORDS} per function, 10.4.1)",
            )
        var = Variable(name, vtype, address, size, array, line)
        scope.words += size
        scope.locals[name] = var
        if init is not None:
            if array:
                raise _Error(line, f"array {name} cannot have an initial value")
            self.assign_value(scope, _Ref(var, Kind.LOCAL, text=name), init, line)

    def check_new_name(self, scope: _Scope | None, name: str, line: int) -> None:
        if name in self.macros:
            raise _Error(line, f"{name} is a macro (#define); choose another variable name")
        if name in self.function_names:
            raise _Error(line, f"{name} is a function of this program; choose another name")
        where = self.globals if scope is None else scope.locals
        if name in where:
            raise _Error(line, f"{name} is declared twice")

    # --- functions --------------------------------------------------------------------------
    def function(self, node: Tree) -> None:
        type_node, name_tok, params, *body = node.children
        name, line = str(name_tok), _line(name_tok)
        if any(f.name == name for f in self.functions):
            raise _Error(line, f"function {name} is defined twice")
        if name in self.globals:
            raise _Error(line, f"{name} is a global variable; a function needs another name")
        returns = _TYPES[str(type_node.children[0])]
        scope = _Scope(name, returns)
        names: list[str] = []
        if params is not None and params.data == "param_list":
            for p in params.children:
                ptype, pname, *suffix = p.children
                try:
                    t = self.var_type(ptype, f"parameter {pname}")
                    if suffix:
                        raise _Error(_line(pname), f"parameter {pname}: parameters are scalars")
                    self.check_new_name(scope, str(pname), _line(pname))
                except _Error as e:
                    self.error(e.line, e.message)
                    continue
                scope.locals[str(pname)] = Variable(
                    str(pname), t, scope.words, 1, False, _line(pname)
                )
                scope.words += 1
                names.append(str(pname))
        entry = len(self.code)
        for stmt in body:
            try:
                self.statement(scope, stmt)
            except _Error as e:
                self.error(e.line, e.message)
        end_line = getattr(node.meta, "end_line", line) or line
        self.emit(Op.RETURN, end_line, operands=(Operand.none(),))  # falling off the end
        for pc, label, ln in scope.fixups:
            target = scope.labels.get(label)
            if target is None:
                self.error(ln, f"goto {label}: no label {label} in function {name}")
                continue
            self.code[pc] = replace(self.code[pc], target=target)
        self.functions.append(
            Function(
                name=name,
                id=len(self.functions),
                returns=returns,
                params=tuple(names),
                locals=tuple(scope.locals.values()),
                local_words=scope.words,
                entry=entry,
                end=len(self.code),
                line=line,
            )
        )

    def emit(self, op: Op, line: int, sub: int = 0, target: int = 0, operands=()) -> int:
        self.code.append(Instr(op, line, int(sub), target, tuple(operands)))
        return len(self.code) - 1

    # --- statements -------------------------------------------------------------------------
    def statement(self, scope: _Scope, node: Tree) -> None:
        kind = node.data
        line = _line(node)
        if kind == "declaration":
            self.declaration(scope, node)
        elif kind == "label":
            label = str(node.children[0])
            if label in scope.labels:
                raise _Error(line, f"label {label} is defined twice in {scope.name}")
            scope.labels[label] = len(self.code)
        elif kind == "assign":
            lhs, rhs = node.children
            self.assign_value(scope, self.target(scope, lhs), rhs, line)
        elif kind == "compound":
            lhs, op, rhs = node.children
            raise _Error(
                line,
                f"compound assignment {op} is not supported: write "
                f"`{self.text(lhs)} = {self.text(lhs)} {str(op)[:-1]} {self.text(rhs)};`",
            )
        elif kind == "expr_stmt":
            expr = node.children[0]
            if isinstance(expr, Tree) and expr.data == "call":
                self.call(scope, expr, None, line)
            elif isinstance(expr, Tree) and expr.data == "incdec":
                raise _Error(line, _INCDEC)
            else:
                raise _Error(
                    line,
                    f"`{self.text(expr)};` does nothing: a statement assigns a value "
                    "or calls a GT function",
                )
        elif kind == "if_stmt":
            _, cond, body = node.children
            c = self.condition(scope, cond, line)
            if isinstance(body, Tree) and body.data == "goto":
                pc = self.emit(Op.JUMP_IF, line, operands=(c,))
                scope.fixups.append((pc, str(body.children[1]), line))
            elif isinstance(body, Tree) and body.data == "return_stmt":
                self.emit(Op.RETURN_IF, line, operands=(c, self.return_value(scope, body, line)))
            else:
                raise _Error(
                    line,
                    "if(var) takes only `goto label;` or `return value;` (10.4.2): "
                    "jump to the code to run",
                )
        elif kind == "goto":
            pc = self.emit(Op.JUMP, line)
            scope.fixups.append((pc, str(node.children[1]), line))
        elif kind == "return_stmt":
            self.emit(Op.RETURN, line, operands=(self.return_value(scope, node, line),))
        elif kind == "block":
            raise _Error(line, "blocks { ... } are not supported inside a function (10.4.3)")
        elif kind == "empty":
            return
        elif kind == "directive":
            self.directive(node.children[0], inside=True)
        else:  # pragma: no cover - the grammar has no other statement
            raise _Error(line, f"unsupported statement {self.text(node)!r}")

    def condition(self, scope: _Scope, cond: Tree, line: int) -> Operand:
        if isinstance(cond, Tree) and cond.data not in ("name", "index", "int_const"):
            if cond.data not in ("float_const", "unop", "cast") or not self.is_constant(cond):
                raise _Error(
                    line,
                    f"the condition of if must be a variable (10.4.2), not the expression "
                    f"`{self.text(cond)}`: compute it first, `cc = {self.text(cond)}; if(cc) ...`",
                )
        v = self.value(scope, cond, "the condition of if")
        return self.operand(v, v.type, line)

    def is_constant(self, node: Tree) -> bool:
        try:
            return isinstance(self.value(None, node, ""), _Const)
        except _Error:
            return False

    def return_value(self, scope: _Scope, node: Tree, line: int) -> Operand:
        expr = node.children[1]
        if expr is None:
            if scope.returns is not None:
                raise _Error(
                    line, f"return needs a value: {scope.name} returns {scope.returns.c_name}"
                )
            return Operand.none()
        if scope.returns is None:
            raise _Error(line, f"{scope.name} is void: return takes no value")
        v = self.value(scope, expr, "the return value", operation_hint=True)
        if isinstance(v, _Ref) and v.type is not scope.returns:
            raise _Error(
                line,
                f"mixed types: {scope.name} returns {scope.returns.c_name}, "
                f"{v.text} is {v.type.c_name} (convert it with ({scope.returns.c_name}) first)",
            )
        return self.operand(v, scope.returns, line)

    def target(self, scope: _Scope, node: Tree) -> _Ref:
        line = _line(node)
        if isinstance(node, Tree) and node.data == "incdec":
            raise _Error(line, _INCDEC)
        if not (isinstance(node, Tree) and node.data in ("name", "index")):
            raise _Error(line, f"cannot assign to `{self.text(node)}`: not a variable")
        if node.data == "name" and str(node.children[0]) in self.macros:
            raise _Error(line, f"cannot assign to {node.children[0]}: it is a macro (a constant)")
        v = self.value(scope, node, "the assigned variable")
        if not isinstance(v, _Ref):
            raise _Error(line, f"cannot assign to `{self.text(node)}`")
        return v

    def assign_value(self, scope: _Scope, dst: _Ref, rhs: Tree | Token, line: int) -> None:
        kind = rhs.data if isinstance(rhs, Tree) else ""
        if kind == "call":
            self.call(scope, rhs, dst, line)
            return
        if kind == "binop":
            a_node, op_tok, b_node = rhs.children
            op = BINOP_SYMBOLS[str(op_tok)]
            for side in (a_node, b_node):
                if isinstance(side, Tree) and side.data == "binop":
                    raise _Error(
                        line,
                        f"only two operands per operation (10.4.2): split "
                        f"`{self.text(rhs)}` into several statements",
                    )
            a = self.value(scope, a_node, "an operand", operation_hint=True)
            b = self.value(scope, b_node, "an operand", operation_hint=True)
            t = self.unify(a, b, line, f"`{self.text(rhs)}`")
            if op in INT_ONLY and t is VarType.DOUBLE:
                raise _Error(line, f"{op_tok} takes int operands (10.4.2); these are double")
            result = VarType.INT if op in RELATIONAL else t
            self.check_result(dst, result, rhs, line)
            self.emit(
                Op.BINARY,
                line,
                op,
                operands=(dst.operand(), self.operand(a, t, line), self.operand(b, t, line)),
            )
            return
        if kind == "unop" and not self.is_constant(rhs):
            op_tok, a_node = rhs.children
            a = self.value(scope, a_node, "an operand", operation_hint=True)
            if str(op_tok) == "+":
                self.assign_value(scope, dst, a_node, line)
                return
            op = _UNARY[str(op_tok)]
            t = a.type
            if op is not UnOp.NEG and t is VarType.DOUBLE:
                raise _Error(line, f"{op_tok} takes an int operand (10.4.2); {a.text} is double")
            self.check_result(dst, t, rhs, line)
            self.emit(Op.UNARY, line, op, operands=(dst.operand(), self.operand(a, t, line)))
            return
        if kind == "cast" and not self.is_constant(rhs):
            type_node, a_node = rhs.children
            to = _TYPES[str(type_node.children[0])]
            if to is None:
                raise _Error(line, "(void) is not a cast of motion programs: (int) or (double)")
            a = self.value(scope, a_node, "the operand of a cast", operation_hint=True)
            self.check_result(dst, to, rhs, line)
            if a.type is to:
                self.emit(Op.MOV, line, operands=(dst.operand(), self.operand(a, to, line)))
            else:
                self.emit(
                    Op.CAST, line, to, operands=(dst.operand(), self.operand(a, a.type, line))
                )
            return
        if kind == "addr":
            raise _Error(line, "& only passes a variable to a GT function (10.3.1)")
        v = self.value(scope, rhs, "the assigned value", operation_hint=True)
        if isinstance(v, _Ref) and v.type is not dst.type:
            raise _Error(
                line,
                f"mixed types: {dst.text} is {dst.type.c_name}, {v.text} is {v.type.c_name} "
                f"(convert with ({dst.type.c_name}){v.text})",
            )
        self.emit(Op.MOV, line, operands=(dst.operand(), self.operand(v, dst.type, line)))

    def check_result(self, dst: _Ref, result: VarType, rhs: Tree, line: int) -> None:
        if dst.type is not result:
            raise _Error(
                line,
                f"mixed types: `{self.text(rhs)}` is {result.c_name}, {dst.text} is "
                f"{dst.type.c_name} (10.4.2)",
            )

    def unify(self, a: _Value, b: _Value, line: int, what: str) -> VarType:
        if isinstance(a, _Ref) and isinstance(b, _Ref):
            if a.type is not b.type:
                raise _Error(
                    line,
                    f"mixed types in {what}: {a.text} is {a.type.c_name}, {b.text} is "
                    f"{b.type.c_name}; both operands must be of one type (10.4.2), "
                    "convert one with (int) or (double)",
                )
            return a.type
        if isinstance(a, _Ref) or isinstance(b, _Ref):
            ref, c = (a, b) if isinstance(a, _Ref) else (b, a)
            assert isinstance(c, _Const)
            if c.type is VarType.DOUBLE and ref.type is VarType.INT:
                raise _Error(
                    line,
                    f"mixed types in {what}: {c.text()} is a double constant, {ref.text} is int",
                )
            return ref.type
        return VarType.DOUBLE if VarType.DOUBLE in (a.type, b.type) else VarType.INT

    # --- values -----------------------------------------------------------------------------
    def value(
        self, scope: _Scope | None, node: Tree | Token, what: str, operation_hint: bool = False
    ) -> _Value:
        """A constant, a variable or an array element; anything else is an error."""
        line = _line(node)
        kind = node.data if isinstance(node, Tree) else ""
        if kind in ("int_const", "float_const"):
            try:
                return _CONST_PARSER(str(node.children[0]))
            except ValueError as e:
                raise _Error(
                    line, f"constant {shown_literal(str(node.children[0]))}: {e}"
                ) from None
        if kind == "name":
            name = str(node.children[0])
            if name in self.macros:
                return self.macros[name]
            var, where = self.lookup(scope, name)
            if var is None:
                if name in self.function_names:
                    raise _Error(line, f"{name} is a function, not a value")
                raise _Error(line, f"unknown variable {name}")
            if var.array:
                raise _Error(line, f"array {name} needs an index here: {name}[i]")
            return _Ref(var, where, text=name)
        if kind == "index":
            return self.element(scope, node, line)
        if kind == "unop":
            op_tok, a_node = node.children
            a = self.value(scope, a_node, what, operation_hint)
            if isinstance(a, _Const):
                return self.fold_unary(str(op_tok), a, line)
        if kind == "cast":
            type_node, a_node = node.children
            a = self.value(scope, a_node, what, operation_hint)
            to = _TYPES[str(type_node.children[0])]
            if isinstance(a, _Const) and to is not None:
                if to is VarType.INT and a.type is VarType.DOUBLE:
                    return _Const(int(a.value), VarType.INT)  # int() truncates toward 0
                return _Const(a.value, to, a.hex)
        if kind == "call":
            name = str(node.children[0])
            if name in self.function_names:
                raise _Error(
                    line,
                    f"{name} is a function of this program: functions cannot call each "
                    "other (10.4.1), only GT functions",
                )
            raise _Error(
                line,
                f"{what}: a GT call is a statement of its own, `x = {name}(...);` "
                "(its value is the return code)",
            )
        if kind == "incdec":
            raise _Error(line, _INCDEC)
        if kind == "addr":
            raise _Error(line, "& only passes a variable to a GT function (10.3.1)")
        if kind == "deref":
            raise _Error(line, "pointers are not supported in motion programs")
        text = self.text(node)
        if kind == "binop" and operation_hint:
            raise _Error(
                line,
                f"only two operands per operation (10.4.2): `{text}` is an expression "
                "inside an operation; compute it into a variable first",
            )
        raise _Error(
            line,
            f"{what} must be a constant or a variable, not the expression `{text}` (10.4.2): "
            "compute it into a variable first",
        )

    def lookup(self, scope: _Scope | None, name: str) -> tuple[Variable | None, Kind]:
        if scope is not None and name in scope.locals:
            return scope.locals[name], Kind.LOCAL
        if name in self.globals:
            return self.globals[name], Kind.GLOBAL
        return None, Kind.NONE

    def element(self, scope: _Scope | None, node: Tree, line: int) -> _Ref:
        base, idx = node.children
        if not (isinstance(base, Tree) and base.data == "name"):
            if isinstance(base, Tree) and base.data == "index":
                raise _Error(line, "only one-dimensional arrays are supported (10.4.1)")
            raise _Error(line, f"`{self.text(base)}` cannot be indexed")
        name = str(base.children[0])
        var, where = self.lookup(scope, name)
        if var is None:
            raise _Error(line, f"unknown variable {name}")
        if not var.array:
            raise _Error(line, f"{name} is not an array")
        if isinstance(idx, Tree) and idx.data == "index":
            raise _Error(
                line,
                f"an array element is not an index (10.4.1): copy {self.text(idx)} into an "
                "int variable first",
            )
        if isinstance(idx, Tree) and idx.data not in ("name", "int_const", "float_const"):
            if not self.is_constant(idx):
                raise _Error(
                    line,
                    f"the index of {name} must be a constant or a variable (10.4.1), not "
                    f"`{self.text(idx)}`",
                )
        i = self.value(scope, idx, f"the index of {name}")
        text = f"{name}[{self.text(idx)}]"
        if isinstance(i, _Const):
            if i.type is not VarType.INT:
                raise _Error(line, f"the index of {name} must be an int, not {i.text()}")
            k = int(i.value)
            if not 0 <= k < var.size:
                raise _Error(line, f"index {k} out of range: {name} has {var.size} elements")
            return _Ref(var, where, Kind.CONST, k, text)
        if i.type is not VarType.INT:
            raise _Error(line, f"the index of {name} must be an int; {i.text} is double")
        return _Ref(var, where, i.scope, i.var.address, text)

    def fold_unary(self, op: str, a: _Const, line: int) -> _Const:
        if op == "-":
            return _Const(-a.value, a.type, a.hex)
        if op == "+":
            return a
        if a.type is VarType.DOUBLE:
            raise _Error(line, f"{op} takes an int operand (10.4.2), not {a.text()}")
        w = self.word(a, VarType.INT, line)
        return _Const(int(not w) if op == "!" else fixed.wrap32(~w), VarType.INT)

    def word(self, c: _Const, t: VarType, line: int) -> int:
        """The word of constant ``c`` used as type ``t`` (an int constant becomes a double)."""
        if t is VarType.INT:
            if c.type is VarType.DOUBLE:
                raise _Error(
                    line, f"{c.text()} is a double constant where an int is needed (10.4.2)"
                )
            v = int(c.value)
            if fixed.INT_MIN <= v <= fixed.INT_MAX:
                return v
            if c.hex and -0xFFFFFFFF <= v <= 0xFFFFFFFF:
                return fixed.wrap32(v)
            raise _Error(line, f"constant {v} is outside the 32-bit int range")
        try:
            return fixed.from_fraction(Fraction(c.value))
        except OverflowError as e:
            raise _Error(line, f"constant {c.text()}: {e}") from None

    def operand(self, v: _Value, t: VarType, line: int) -> Operand:
        if isinstance(v, _Const):
            return Operand.const(t, self.word(v, t, line))
        return v.operand()

    # --- GT calls ---------------------------------------------------------------------------
    def call(self, scope: _Scope, node: Tree, dst: _Ref | None, line: int) -> None:
        name_tok, arg_list = node.children
        name = str(name_tok)
        args = list(arg_list.children) if arg_list is not None else []
        if name in self.function_names:
            raise _Error(
                line,
                f"{name} is a function of this program: functions cannot call each other "
                "(10.4.1), only GT functions",
            )
        proto, why = self.catalog.lookup(name)
        if proto is None:
            raise _Error(line, why)
        params = proto.params
        if len(args) != len(params):
            listed = ", ".join(p.name for p in params) or "none"
            raise _Error(
                line,
                f"{name} takes {len(params)} argument(s) ({listed}), {len(args)} given: a "
                "motion program passes every argument, defaults included (10.3.1)",
            )
        if dst is not None and dst.type is not VarType.INT:
            raise _Error(line, f"{name} returns its return code, an int: {dst.text} is double")
        known: dict[str, _Value] = {}
        ops: list[Operand | None] = [None] * len(params)
        for k in sorted(range(len(params)), key=lambda k: params[k].pointer):  # scalars first:
            op, v = self.argument(scope, name, params[k], args[k], line, known)  # counts size
            ops[k] = op  # the pointers' room
            if v is not None:
                known[params[k].name] = v
        operands = [dst.operand() if dst is not None else Operand.none(), *ops]
        index = self.strings.setdefault(name, len(self.strings))
        self.emit(Op.CALL, line, target=index, operands=operands)

    def argument(
        self, scope: _Scope, fname: str, p: Any, a: Tree, line: int, known: dict[str, _Value]
    ) -> tuple[Operand, _Value | None]:
        if not p.pointer:
            v = self.value(scope, a, f"{fname} argument {p.name}")
            want = VarType.DOUBLE if p.is_float else VarType.INT
            if isinstance(v, _Ref) and v.type is not want:
                raise _Error(
                    line,
                    f"{fname}: {p.name} is {p.ctype}; {v.text} is {v.type.c_name} "
                    f"(convert it with ({want.c_name}) first)",
                )
            op = self.operand(v, want, line)
            if isinstance(v, _Const) and want is VarType.INT:
                self.check_constant(fname, p, c_value(p, op.value), line)
            return op, v
        if p.text:
            raise _Error(
                line, f"{fname}: {p.name} is text (char *), which motion programs do not have"
            )
        return self.pointer(scope, fname, p, a, line, known), None

    def check_constant(self, fname: str, p: Any, value: int, line: int) -> None:
        from ..errors import ParameterError
        from ..gt.args import _int_converter  # the binder's own check

        try:
            _int_converter(p)(value)
        except ParameterError as e:
            raise _Error(line, f"{fname}: {e}") from None

    def pointer(
        self, scope: _Scope, fname: str, p: Any, a: Tree, line: int, known: dict[str, _Value]
    ) -> Operand:
        kind = a.data if isinstance(a, Tree) else ""
        if self.is_constant(a):
            c = self.value(scope, a, p.name)
            if isinstance(c, _Const) and c.value == 0:
                if not p.optional:
                    raise _Error(
                        line, f"{fname}: {p.name} must point to a variable (it may not be NULL)"
                    )
                return Operand(Kind.NONE, pointer=True)
            raise _Error(line, f"{fname}: {p.name} is a pointer: pass &variable")
        ref: _Ref
        if kind == "addr":
            target = a.children[1]
            tkind = target.data if isinstance(target, Tree) else ""
            if tkind == "name":
                name = str(target.children[0])
                var, where = self.lookup(scope, name)
                if var is None:
                    raise _Error(line, f"unknown variable {name}")
                ref = _Ref(var, where, text=name)
            elif tkind == "index":
                ref = self.element(scope, target, line)
            else:
                raise _Error(line, f"{fname}: & takes a variable, not `{self.text(target)}`")
        elif kind == "name":
            name = str(a.children[0])
            var, where = self.lookup(scope, name)
            if var is None:
                raise _Error(line, f"unknown variable {name}")
            if not var.array:
                raise _Error(line, f"{fname}: {p.name} is a pointer: pass &{name}")
            ref = _Ref(var, where, text=name)
        else:
            raise _Error(
                line, f"{fname}: {p.name} is a pointer: pass &variable, not `{self.text(a)}`"
            )
        room: int | None = ref.var.size
        if ref.index_kind is Kind.CONST:
            room = ref.var.size - ref.index
        elif ref.index_kind is not Kind.NONE:
            room = None  # known at run time
        if p.is_struct:
            try:
                cls = self.catalog.struct(p.ctype)
            except KeyError:
                raise _Error(line, f"{fname}: structure {p.ctype} is unknown") from None
            fields = len(cls._fields_)
            if not ref.var.array:
                raise _Error(
                    line,
                    f"{fname}: {p.name} is a {p.ctype} ({fields} fields): pass an array "
                    f"of {fields} elements, its words are the fields in order",
                )
            if room is not None and room < fields:
                raise _Error(
                    line, f"{fname}: {p.ctype} has {fields} fields, {ref.text} holds {room}"
                )
        else:
            want = VarType.DOUBLE if p.ctype in ("double", "float") else VarType.INT
            if ref.type is not want:
                raise _Error(
                    line,
                    f"{fname}: {p.name} points to {p.ctype}: pass the address of "
                    f"{'a double' if want is VarType.DOUBLE else 'an int'} variable, "
                    f"{ref.text} is {ref.type.c_name}",
                )
            need: int | None = None
            if isinstance(p.count, int) and p.count > 0:
                need = p.count
            elif isinstance(p.count, str):
                c = known.get(p.count)
                if isinstance(c, _Const):
                    need = int(c.value)
            if need is not None and room is not None and room < need:
                raise _Error(
                    line,
                    f"{fname}: {p.name} needs room for {need} value(s), {ref.text} holds {room}",
                )
        op = ref.operand()
        return replace(op, pointer=True)


def c_value(p: Any, word: int) -> int:
    """An ``int`` word passed to scalar parameter ``p`` as C converts it: a negative word
    to ``unsigned long`` (same width) is its bit pattern; anything else stays as it is and
    the GT function's own range check decides."""
    if word < 0 and (p.ctype == "unsigned long" or p.mask):
        return word & 0xFFFFFFFF
    return word


_INCDEC = "++ and -- are not supported: write `i = i + 1;` (10.4.2)"


#: longest literal read: a program's words are 32 bits and its doubles 16.16, so a longer
#: number is out of range anyway; reading it would cost time (``int()`` of 10**6 digits is
#: quadratic, a ``Fraction`` of ``1e99999999`` builds a 100-million-digit integer)
_MAX_DIGITS = 60
_MAX_EXPONENT = 400


def shown_literal(text: str) -> str:
    return text if len(text) <= 24 else f"{text[:12]}...({len(text)} characters)"


class _ConstParser:
    """Number literals of the language -> :class:`_Const` (ValueError, with the reason, when
    not one or beyond what a program word can hold)."""

    def __call__(self, text: str) -> _Const:
        t = text.strip()
        low = t.lower()
        if len(low) > _MAX_DIGITS + 8:
            raise ValueError(
                f"more than {_MAX_DIGITS} digits; a program word holds 32 bits (int) or "
                "16.16 fixed point (double)"
            )
        if low.startswith("0x"):
            digits = low[2:].rstrip("ul")
            return _Const(int(digits, 16), VarType.INT, hex=True)
        if any(ch in low for ch in ".e") and not low.startswith("0x"):
            body = low.rstrip("f")
            _, e, exponent = body.partition("e")
            if e and exponent.lstrip("+-").isdigit() and abs(int(exponent)) > _MAX_EXPONENT:
                raise ValueError(
                    "the exponent is beyond the double range (16.16 fixed point in a program)"
                )
            try:
                return _Const(Fraction(body), VarType.DOUBLE)
            except (ValueError, ZeroDivisionError):
                raise ValueError(f"{text} is not a number") from None
        digits = low.rstrip("ul")
        if not digits.isdigit():
            raise ValueError(f"{text} is not a number")
        return _Const(int(digits, 10), VarType.INT)


_CONST_PARSER = _ConstParser()


def compile_source(
    text: str, filename: str = "<source>", catalog: Catalog | None = None
) -> Program:
    """Compile a program's text; CompileFailed lists the errors with their lines."""
    tree, word_errors = parse(text)
    compiler = _Compiler(text, filename, catalog or Catalog())
    try:
        program = compiler.run(tree)
    except CompileFailed as e:
        if not word_errors:
            raise
        seen = {w.line for w in word_errors}
        raise CompileFailed(word_errors + [x for x in e.errors if x.line not in seen]) from None
    if word_errors:
        raise CompileFailed(word_errors)
    return program


def compile_file(path: str | Path, catalog: Catalog | None = None) -> Program:
    """Compile a source file (UTF-8, or GBK as Chinese Windows editors save it)."""
    p = Path(path)
    try:
        raw = p.read_bytes()
    except OSError as e:
        raise CompileFailed([SourceError(0, f"cannot read {p}: {e.strerror or e}")]) from None
    try:
        text = raw.decode("utf-8-sig")
    except UnicodeDecodeError:
        text = raw.decode("gbk", "replace")
    return compile_source(text, p.name, catalog)


__all__ = ["CompileFailed", "SourceError", "c_value", "compile_file", "compile_source"]
