"""The source language of motion programs (manual 10.4): parsing with line numbers.

The grammar below (lark, LALR(1)) reads a deliberately *wider* C than 10.4 allows:
whole expressions, casts, calls, array indexing, blocks, compound assignment,
``++``.  The compiler (:mod:`gtecat.programs.compiler`) then checks the restrictions
of 10.4 on the tree, so a program that steps outside them gets a message naming
the rule ("only two operands per operation", "the condition of if must be a
variable") instead of a bare syntax error.  Before parsing, comments are blanked
(keeping the line breaks) and the C keywords the language lacks (``while``,
``for``, ``else``, ``switch``, ``char``, ``float`` ...) are reported where they stand.

Why lark: a real grammar in one readable string, an LALR parser that is fast and
reports the line and the expected tokens of a syntax error, positions on every
tree node, pure Python with no build step.  pycparser would read full C99 and need
a preprocessor run first (which loses the ``#define`` lines 10.4.3 asks for and
shifts line numbers); the language is small enough that its own grammar says
exactly what it accepts.
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from functools import cache

from lark import Lark, Token, Tree
from lark.exceptions import UnexpectedCharacters, UnexpectedEOF, UnexpectedInput, UnexpectedToken

GRAMMAR = r"""
start: item*

?item: DIRECTIVE                                   -> directive
     | declaration
     | function
     | prototype

function: type_name NAME "(" [param_list] ")" "{" stmt* "}"
prototype: type_name NAME "(" [param_list] ")" ";"
param_list: VOID                                   -> void_params
          | param ("," param)*
param: type_name NAME array_suffix*

type_name: INT | LONG | DOUBLE | VOID
declaration: type_name declarator ("," declarator)* ";"
declarator: NAME array_suffix* ["=" expr]
array_suffix: "[" [expr] "]"

?stmt: declaration
     | NAME ":"                                    -> label
     | unary "=" expr ";"                          -> assign
     | unary COMPOUND expr ";"                     -> compound
     | expr ";"                                    -> expr_stmt
     | IF "(" expr ")" stmt                        -> if_stmt
     | GOTO NAME ";"                               -> goto
     | RETURN [expr] ";"                           -> return_stmt
     | "{" stmt* "}"                               -> block
     | ";"                                         -> empty
     | DIRECTIVE                                   -> directive

?expr: lor
?lor: land | lor OROR land                         -> binop
?land: bor | land ANDAND bor                       -> binop
?bor: bxor | bor BAR bxor                          -> binop
?bxor: band | bxor CARET band                      -> binop
?band: eq | band AMP eq                            -> binop
?eq: rel | eq (EQ | NE) rel                        -> binop
?rel: shift | rel (LE | GE | LT | GT) shift        -> binop
?shift: add | shift (SHL | SHR) add                -> binop
?add: mul | add (PLUS | MINUS) mul                 -> binop
?mul: unary | mul (STAR | SLASH | PERCENT) unary   -> binop
?unary: postfix
      | (MINUS | PLUS | BANG | TILDE) unary        -> unop
      | AMP unary                                  -> addr
      | STAR unary                                 -> deref
      | INCDEC unary                               -> incdec
      | "(" type_name ")" unary                    -> cast
?postfix: primary
        | postfix "[" expr "]"                     -> index
        | NAME "(" [arg_list] ")"                  -> call
        | postfix INCDEC                           -> incdec
arg_list: expr ("," expr)*
?primary: NAME                                     -> name
        | FLOAT                                    -> float_const
        | HEX                                      -> int_const
        | DEC                                      -> int_const
        | "(" expr ")"

INT: "int"
LONG: "long"
DOUBLE: "double"
VOID: "void"
IF: "if"
GOTO: "goto"
RETURN: "return"

DIRECTIVE: /#[^\n]*/
FLOAT.3: /(\d+\.\d*|\.\d+)([eE][+-]?\d+)?[fF]?|\d+[eE][+-]?\d+[fF]?/
HEX.2: /0[xX][0-9a-fA-F]+[uUlL]*/
DEC.1: /\d+[uUlL]*/
NAME: /[A-Za-z_][A-Za-z0-9_]*/

COMPOUND: "+=" | "-=" | "*=" | "/=" | "%=" | "&=" | "|=" | "^=" | "<<=" | ">>="
INCDEC: "++" | "--"
OROR: "||"
ANDAND: "&&"
BAR: "|"
CARET: "^"
AMP: "&"
EQ: "=="
NE: "!="
LE: "<="
GE: ">="
LT: "<"
GT: ">"
SHL: "<<"
SHR: ">>"
PLUS: "+"
MINUS: "-"
STAR: "*"
SLASH: "/"
PERCENT: "%"
BANG: "!"
TILDE: "~"

%import common.WS
%ignore WS
"""

#: C words that motion programs do not have, and what to write instead (10.4)
UNSUPPORTED: dict[str, str] = {
    **dict.fromkeys(
        ("while", "for", "do"),
        "{} loops are not supported: write them with a label, `cc = ...;`, "
        "`if(cc) goto label;` and `goto label;` (10.4.3)",
    ),
    "else": "else is not supported: jump over the other branch with `if(cc) goto label;` (10.4.3)",
    **dict.fromkeys(
        ("switch", "case", "default"),
        "{} is not supported: compare and jump, `cc = a==1; if(cc) goto lbl_1;` (10.4.3)",
    ),
    **dict.fromkeys(("break", "continue"), "{} is not supported: jump with `goto label;` (10.4.3)"),
    **dict.fromkeys(
        ("char", "short", "float", "unsigned", "signed", "struct", "union", "enum", "typedef"),
        "type {} does not exist in motion programs: only int (long) and double (10.4.1)",
    ),
    **dict.fromkeys(
        ("static", "const", "extern", "volatile", "register", "auto", "sizeof"),
        "{} is not supported in motion programs (10.4.1)",
    ),
}

_COMMENT = re.compile(r"//[^\n]*|/\*.*?\*/", re.S)
_WORD = re.compile(r"[A-Za-z_][A-Za-z0-9_]*")
_UNSUPPORTED_CHAR = {
    '"': "text constants are not supported in motion programs",
    "'": "character constants are not supported in motion programs",
    "?": "conditional expressions (a ? b : c) are not supported: compare and jump (10.4.3)",
    ".": "structures are not supported in motion programs",
}


@dataclass(frozen=True, slots=True, order=True)
class SourceError:
    """One compile error: its line (1-based; 0 = the file as a whole) and message."""

    line: int
    message: str

    def format(self, filename: str) -> str:
        return f"{filename}:{self.line}: {self.message}"


class CompileFailed(Exception):
    """The source has errors (``errors`` sorted by line)."""

    def __init__(self, errors: list[SourceError]) -> None:
        self.errors = sorted(errors)
        super().__init__("; ".join(f"line {e.line}: {e.message}" for e in self.errors))

    @property
    def first(self) -> SourceError:
        return self.errors[0]


def strip_comments(text: str) -> str:
    """``text`` with every comment blanked; line breaks stay, so lines keep their numbers."""
    unterminated = text.find("/*", _last_comment_end(text))
    if unterminated >= 0 and "*/" not in text[unterminated:]:
        line = text.count("\n", 0, unterminated) + 1
        raise CompileFailed([SourceError(line, "comment /* is never closed")])
    return _COMMENT.sub(lambda m: re.sub(r"[^\n]", " ", m.group()), text)


def _last_comment_end(text: str) -> int:
    end = 0
    for m in _COMMENT.finditer(text):
        end = m.end()
    return end


def check_words(text: str) -> list[SourceError]:
    """The unsupported C keywords of a comment-free source, where they stand."""
    errors = []
    for lineno, line in enumerate(text.splitlines(), 1):
        if line.lstrip().startswith("#"):
            continue  # directives are checked by the compiler
        for m in _WORD.finditer(line):
            hint = UNSUPPORTED.get(m.group())
            if hint is not None:
                errors.append(SourceError(lineno, hint.format(m.group())))
    return errors


@cache
def parser() -> Lark:
    """The LALR parser; lark keeps its tables in a cache file of the temporary directory
    (keyed by grammar and lark version), so a new process loads them in ~15 ms instead
    of building them (~200 ms)."""
    return Lark(
        GRAMMAR, parser="lalr", propagate_positions=True, maybe_placeholders=True, cache=True
    )


def parse(text: str) -> tuple[Tree, list[SourceError]]:
    """The syntax tree of a source file and the unsupported keywords found in it.

    CompileFailed (with lines) when the text cannot be read at all; a keyword error
    does not stop the parse, so the compiler can report the other errors too.
    """
    clean = strip_comments(text)
    errors = check_words(clean)
    try:
        return parser().parse(clean), errors
    except UnexpectedInput as e:
        syntax = _syntax_error(e, clean)
        if syntax.line not in {w.line for w in errors}:
            errors.append(syntax)
        raise CompileFailed(errors) from None


def _syntax_error(e: UnexpectedInput, text: str) -> SourceError:
    if isinstance(e, UnexpectedCharacters):
        ch = text[e.pos_in_stream] if e.pos_in_stream < len(text) else ""
        hint = _UNSUPPORTED_CHAR.get(ch, f"character {ch!r} is not part of the language")
        return SourceError(e.line, f"syntax error: {hint}")
    if isinstance(e, UnexpectedEOF):
        line = text.count("\n") + 1
        return SourceError(line, "syntax error: the file ends inside a declaration or function")
    if isinstance(e, UnexpectedToken):
        tok: Token = e.token
        if tok.type == "$END":
            line = text.count("\n") + 1
            return SourceError(line, "syntax error: the file ends inside a function (missing })")
        history = getattr(e, "token_history", None) or []
        if "SEMICOLON" in e.expected and history and tok.line > history[-1].line:
            last = history[-1]
            return SourceError(last.line, f"syntax error: missing ';' after {str(last)!r}")
        if "SEMICOLON" in e.expected and tok.type in _STATEMENT_START:
            return SourceError(tok.line, f"syntax error: missing ';' before {str(tok)!r}")
        expected = sorted(_pretty(t) for t in e.expected)
        want = f"; expected {', '.join(expected[:6])}" if expected else ""
        if expected and len(expected) > 6:
            want += ", ..."
        return SourceError(tok.line, f"syntax error at {str(tok)!r}{want}")
    return SourceError(getattr(e, "line", 0) or 0, f"syntax error: {e}")


_STATEMENT_START = frozenset(
    {"RBRACE", "LBRACE", "NAME", "IF", "GOTO", "RETURN", "INT", "LONG", "DOUBLE", "VOID"}
)
_PRETTY = {
    "SEMICOLON": "';'",
    "RPAR": "')'",
    "LPAR": "'('",
    "RBRACE": "'}'",
    "LBRACE": "'{'",
    "RSQB": "']'",
    "LSQB": "'['",
    "COMMA": "','",
    "COLON": "':'",
    "EQUAL": "'='",
    "NAME": "a name",
    "DEC": "a number",
    "HEX": "a number",
    "FLOAT": "a number",
}


def _pretty(terminal: str) -> str:
    if terminal in _PRETTY:
        return _PRETTY[terminal]
    for t in parser().terminals:
        if t.name == terminal and t.pattern.type == "str":
            return repr(t.pattern.value)
    return terminal.lower()


__all__ = [
    "GRAMMAR",
    "UNSUPPORTED",
    "CompileFailed",
    "SourceError",
    "check_words",
    "parse",
    "parser",
    "strip_comments",
]
