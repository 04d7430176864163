"""``gtecat lib --cflags --libs | --path | --header``: what a C/C++ build needs.

    gcc prog.c $(python3 -m gtecat lib --cflags --libs)
    g++ prog.cpp $(python3 -m gtecat lib --cflags --libs)

``--cflags`` prints the include directory of ``gts.h``; ``--libs`` the ``-L``, the
rpath (so the program finds ``libgts.so`` without ``LD_LIBRARY_PATH``) and ``-lgts``;
``--path`` the library itself (``ctypes.CDLL``).  The library is built on first use
into a per-version cache (docs/native.md); with no C compiler this says so and exits 1.
"""

from __future__ import annotations

import argparse
import shlex
import sys


def add_parser(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser(
        "lib",
        help="compiler and linker flags for libgts / gts.h (C, C++)",
        description=__doc__,
        epilog="examples:\n"
        "  gtecat lib --cflags --libs      flags for gcc/g++ (builds libgts on first use)\n"
        "  gtecat lib --header > gts.h     the generated header alone, no build",
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    p.add_argument("--cflags", action="store_true", help="-I for gts.h")
    p.add_argument("--libs", action="store_true", help="-L, rpath and -lgts")
    p.add_argument("--path", action="store_true", help="the path of libgts.so")
    p.add_argument("--include-dir", action="store_true", help="the directory of gts.h")
    p.add_argument("--header", action="store_true", help="print gts.h (generated, no build)")
    p.add_argument("--rebuild", action="store_true", help="compile again even if cached")
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    if args.header:
        from ..native.header import render

        sys.stdout.write(render())
        return 0
    from ..native.build import ensure_built

    build = ensure_built(force=args.rebuild)
    words: list[str] = []
    if args.cflags:
        words += build.cflags()
    if args.libs:
        words += build.libs()
    lines = []
    if words:
        lines.append(" ".join(shlex.quote(w) for w in words))
    if args.path:
        lines.append(str(build.library))
    if args.include_dir:
        lines.append(str(build.include_dir))
    if not lines and not args.rebuild:
        lines.append(str(build.library))
    for line in lines:
        print(line)
    return 0
