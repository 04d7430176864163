"""``gtecat compile FILE.c...``: compile motion programs (manual 10.3.2), as GT_Compile does.

    gtecat compile sum.c            # writes sum.bin and sum.ini beside sum.c
    gtecat compile --check sum.c    # only report errors
    gtecat compile --list sum.c     # also print the instructions

Errors go to stderr as ``file:line: message`` (every error of a file, not only the
first) and the exit status is 1; nothing is written for a file with errors.
docs/programs.md describes the language and the two output files.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path


def add_parser(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser(
        "compile",
        help="compile motion programs (.c -> .bin + .ini, manual chapter 10)",
        description=__doc__,
        epilog="examples:\n  gtecat compile sum.c\n  gtecat compile --check sum.c\n"
        "  gtecat compile --list sum.c",
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    p.add_argument("sources", nargs="+", metavar="FILE.c", help="motion program source")
    p.add_argument("--check", action="store_true", help="report errors, write nothing")
    p.add_argument("--list", action="store_true", help="print the compiled instructions")
    p.add_argument("-q", "--quiet", action="store_true", help="print nothing on success")
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    from ..programs import compiler, image

    status = 0
    for source in args.sources:
        path = Path(source)
        try:
            program = compiler.compile_file(path)
        except compiler.CompileFailed as e:
            for err in e.errors:
                print(err.format(str(path)), file=sys.stderr)
            status = 1
            continue
        if args.list:
            print(program.listing())
        if args.check:
            if not args.quiet:
                print(f"{path}: ok ({len(program.functions)} functions)")
            continue
        try:
            bin_path, ini_path = image.write(program, path)
        except OSError as e:
            print(f"{path}:0: cannot write the program image: {e.strerror or e}", file=sys.stderr)
            status = 1
            continue
        if not args.quiet:
            print(
                f"{path}: {len(program.functions)} function(s), {len(program.code)} "
                f"instructions -> {bin_path}, {ini_path}"
            )
    return status
