"""What a C, C++, C# or VB.NET program needs to use libgts.

C and C++ (the header gts.h and libgts.so, built on first use into a per-version cache;
with no C compiler this says so and exits 1):

    gcc prog.c $(python3 -m gtecat lib --cflags --libs)
    g++ prog.cpp $(python3 -m gtecat lib --cflags --libs)
    python3 -m gtecat lib --path            the library itself (ctypes.CDLL)

``--cflags`` prints the include directory of ``gts.h`` and a forced include
(``gtecat_vendor.h``) with which the vendor's own header, as it ships for Windows, compiles
too (``__stdcall``, NULL without <stddef.h>, Windows type names); ``--libs`` the ``-L``, the
rpath (so the program finds ``libgts.so`` without ``LD_LIBRARY_PATH``) and ``-lgts``;
``--path`` the library itself (``ctypes.CDLL``).  The library is built on first use
into a per-version cache (docs/native.md); with no C compiler this says so and exits 1.

``--abi gts-multicard`` gives the older multi-card GTS ABI instead (``libgts_mc.so``, every
``GT_x`` with ``short cardNum`` first; the emulator is card 0):

    gcc prog.c $(python3 -m gtecat lib --abi gts-multicard --cflags --libs)
--cflags prints the include directory of gts.h; --libs the -L, the rpath (the program
finds libgts.so without LD_LIBRARY_PATH) and -lgts.

C# and VB.NET on Mono (docs/csharp.md): --mono-config writes the dllmap that sends the
vendor's DLL names (gts.dll, gen.dll, gxn.dll) to libgts's Windows-long build (C# int is
C long there); put it beside the program as App.exe.config, or name it in MONO_CONFIG.
--csharp writes gts.cs, the GT API for new C# code:

    python3 -m gtecat lib --csharp -o gts.cs
    mcs App.cs gts.cs && python3 -m gtecat lib --mono-config -o App.exe.config && mono App.exe

A C# program whose own wrapper passes the card first (GT_Open(short cardNum, short channel,
short param)) needs the multi-card map: --abi gts-multicard --mono-config sends gts.dll to
libgts_mc-llp64.so, the multi-card layer built for C# int:

    python3 -m gtecat lib --abi gts-multicard --mono-config -o App.exe.config

A program compiled on Linux against the vendor's own gts.h (its structures hold C long,
4 bytes on Windows, 8 on 64-bit Linux) builds as a 32-bit program with --m32, so every
structure has the layout it has on Windows (needs Debian's gcc-multilib / g++-multilib):

    g++ prog.cpp -I vendor_include $(python3 -m gtecat lib --m32 --cflags --libs)

Windows (docs/windows.md): --windows x64|x86 -o DIR writes gts.dll (the GT API with the vendor
DLL's undecorated __stdcall export names, reaching a gtecat controller over TCP), its import
library gts.lib, gts.def and gts.h into DIR, cross-compiled with mingw-w64 on first use
(x86_64-w64-mingw32-gcc / i686-w64-mingw32-gcc):

    python3 -m gtecat lib --windows x86 -o win32
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
        "  gtecat lib --header > gts.h     the generated header alone, no build\n"
        "  gtecat lib --windows x64 -o win64   gts.dll, gts.lib, gts.h for 64-bit Windows",
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    p.add_argument("--cflags", action="store_true", help="-I for gts.h")
    p.add_argument("--libs", action="store_true", help="-L, rpath and -lgts")
    p.add_argument("--path", action="store_true", help="the path of libgts.so")
    p.add_argument("--include-dir", action="store_true", help="the directory of gts.h")
    p.add_argument("--header", action="store_true", help="print gts.h (generated, no build)")
    p.add_argument("--rebuild", action="store_true", help="compile again even if cached")
    p.add_argument(
        "--abi",
        choices=["gtn", "gts-multicard"],
        default="gtn",
        help="gtn: the vendor's (one card, GTN twins; default); gts-multicard: the older "
        "GTS header with short cardNum first (libgts_mc.so)",
    )
    p.add_argument(
        "--mono-config",
        action="store_true",
        help="the Mono dllmap sending gts.dll / gen.dll / gxn.dll to libgts (App.exe.config; "
        "with --abi gts-multicard to the multi-card layer)",
    )
    p.add_argument(
        "--m32",
        action="store_true",
        help="with --cflags/--libs/--path: a 32-bit program (-m32 -malign-double) whose C long "
        "has 4 bytes, as on Windows: for code compiled against the vendor's own gts.h",
    )
    p.add_argument("--csharp", action="store_true", help="gts.cs: the GT API for C# (generated)")
    p.add_argument(
        "--windows",
        choices=["x64", "x86"],
        help="gts.dll for Windows (with gts.lib, gts.def, gts.h) into the folder -o names "
        "(mingw-w64 cross compiler)",
    )
    p.add_argument(
        "-o",
        "--output",
        metavar="PATH",
        help="write --mono-config / --csharp here; the folder of --windows",
    )
    p.set_defaults(func=run)


def _abi(args: argparse.Namespace) -> str:
    return "" if args.abi == "gtn" else args.abi


def run(args: argparse.Namespace) -> int:
    abi = _abi(args)
    if args.windows:
        return _windows(args)
    if args.mono_config or args.csharp:
        return _csharp(args)
    if args.header:
        from ..native.header import render

        sys.stdout.write(render(abi))
        return 0
    from ..native.build import ensure_built

    if args.m32:
        if abi:
            print(
                f"error: --m32 builds the one-card API only, not --abi {args.abi}", file=sys.stderr
            )
            return 1
        from ..cbuild import NativeBuildError
        from ..native.llp64 import ensure_built_m32

        try:
            build = ensure_built_m32(force=args.rebuild)
        except NativeBuildError as e:
            print(
                "error: the 32-bit libgts does not build here (it needs a 32-bit C library: "
                f"Debian's gcc-multilib, g++-multilib for C++):\n{e}",
                file=sys.stderr,
            )
            return 1
    else:
        build = ensure_built(force=args.rebuild, abi=abi)
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


def _csharp(args: argparse.Namespace) -> int:
    from pathlib import Path

    from ..native import csharp

    if args.mono_config and args.csharp:
        print("error: --mono-config and --csharp write different files; ask for one")
        return 1
    if args.csharp and _abi(args):
        print(
            f"error: --csharp writes gts.cs for the one-card API only, not --abi {args.abi}; "
            f"a program with a multi-card wrapper keeps its own and needs only "
            f"--abi {args.abi} --mono-config"
        )
        return 1
    if args.csharp:
        text = csharp.render()
    else:
        from ..native.llp64 import ensure_built

        text = csharp.mono_config(ensure_built(force=args.rebuild, abi=_abi(args)))
    if args.output:
        Path(args.output).write_text(text, encoding="utf-8")
    else:
        sys.stdout.write(text)
    return 0


def _windows(args: argparse.Namespace) -> int:
    from ..native import windows

    if not args.output:
        print(
            "error: --windows writes several files: name their folder with -o DIR", file=sys.stderr
        )
        return 1
    for path in windows.write(args.windows, args.output, force=args.rebuild):
        print(path)
    return 0
