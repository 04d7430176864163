"""The ``gtecat`` command: one module per verb, each with ``add_parser`` and ``run``.

Errors print one line (``error: ...``) and exit 1; ``--debug`` shows the traceback.
"""

from __future__ import annotations

import argparse
import atexit
import errno
import importlib
import os
import sys
import threading
from collections.abc import Sequence

from gtecat.eni.errors import GtecatError

#: verb modules under gtecat.cli, in help order
COMMANDS = (
    "demo_cmd",
    "example_cmd",
    "map_cmd",
    "eni_cmd",
    "bus_cmd",
    "sdos_cmd",
    "states_cmd",
    "reg_cmd",
    "sii_cmd",
    "data_cmd",
    "cstruct_cmd",
    "graph_cmd",
    "ifaces_cmd",
    "run_cmd",
    "serve_cmd",
    "controller_cmd",
    "lib_cmd",
    "compile_cmd",
    "sweep_cmd",
    "api_cmd",
    "scan_cmd",
    "ps_cmd",
    "panel_cmd",
    "fault_cmd",
    "record_cmd",
    "replay_cmd",
)


#: the verbs that a module of another name adds (a verb's module is else ``VERB_cmd``); a verb
#: not found where it is looked for runs all the same, after every verb's parser is built
#: (every verb's parser takes eight times as long as one module's)
_VERB_MODULES = {"slaves": "bus_cmd", "pdos": "bus_cmd", "sdo": "bus_cmd"}


def build_parser(verb: str | None = None) -> argparse.ArgumentParser:
    """The whole command line; ``verb``: only that verb's module is imported and its parser
    added, when its module (``VERB_cmd``) gives it (a run of one verb needs no other), else
    every verb's."""
    parser = argparse.ArgumentParser(
        prog="gtecat",
        description="EtherCAT master emulator with virtual CiA-402 drives and the GT_* API.",
        epilog="examples:\n"
        "  gtecat example manual_fig5_2 -o .    a bus and a first script, into this folder\n"
        "  gtecat map manual_fig5_2.eni         its GT raw offsets\n"
        "  gtecat demo                          the figure 5-2 demo, plotted\n"
        "every command has --help with examples",
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    parser.add_argument("--debug", action="store_true", help="show tracebacks on errors")
    from .. import __version__

    parser.add_argument("--version", action="version", version=f"gtecat {__version__}")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND")
    name = _VERB_MODULES.get(verb, f"{verb}_cmd")
    if verb is not None and name in COMMANDS:
        _add_verbs(sub, name)
        if verb in sub.choices:
            return parser
        return build_parser()
    for name in COMMANDS:
        _add_verbs(sub, name)
    return parser


def _add_verbs(sub: argparse._SubParsersAction, name: str) -> None:
    """The verbs of module ``gtecat.cli.NAME`` added to ``sub``."""
    try:
        mod = importlib.import_module(f"gtecat.cli.{name}")
    except ModuleNotFoundError as e:
        if e.name != f"gtecat.cli.{name}":
            raise
        return
    before = set(sub.choices)
    mod.add_parser(sub)
    for verb in set(sub.choices) - before:
        if sub.choices[verb].get_default("func") is None:
            sub.choices[verb].set_defaults(func=mod.run)
        _debug_anywhere(sub.choices[verb])


def _verb(argv: list[str]) -> str | None:
    """The verb of a command line (its first word after ``--debug``), None when it has none."""
    for word in argv:
        if word != "--debug":
            return None if word.startswith("-") else word
    return None


def _debug_anywhere(p: argparse.ArgumentParser) -> None:
    """``gtecat VERB ... --debug`` works as ``gtecat --debug VERB ...`` does."""
    if "--debug" not in p._option_string_actions:
        p.add_argument(
            "--debug", action="store_true", default=argparse.SUPPRESS, help=argparse.SUPPRESS
        )
    for action in p._actions:  # nested verbs: gtecat eni new ... --debug
        if isinstance(action, argparse._SubParsersAction):
            for child in set(action.choices.values()):
                _debug_anywhere(child)


def _tolerant_streams() -> None:
    """Never fail on printing a name: slave names are GBK/Latin-1/UTF-8 text in the files,
    and a console may not hold them (Windows code pages, ``LANG=C``)."""
    for stream in (sys.stdout, sys.stderr):
        reconfigure = getattr(stream, "reconfigure", None)
        if reconfigure is not None:
            try:
                reconfigure(errors="backslashreplace")
            except (ValueError, OSError):
                pass


def _leave_at_once(code: int) -> None:
    """End the ``gtecat`` process with ``code`` now that its verb is done, as the normal exit
    would (the exit handlers run: logs and caches written; the output flushed) but without
    taking the interpreter apart object by object, which after a replay costs a tenth of
    its time.  Not while another thread that the normal exit waits for still runs."""
    main_thread = threading.current_thread()
    if any(t is not main_thread and not t.daemon for t in threading.enumerate()):
        return
    try:
        atexit._run_exitfuncs()
        sys.stdout.flush()
        sys.stderr.flush()
    except Exception:  # (a closed pipe, a handler's error: the normal exit says what)
        return
    os._exit(code)


_ERRNO_SENTENCES = {
    errno.EISDIR: "{f} is a folder; give a file name (for example {f}/NAME)",
    errno.EEXIST: "{f} is in the way: it already exists and is not a folder",
    errno.ENOENT: "{f} does not exist",
    errno.ENOTDIR: "{f}: a part of this path is a file, not a folder",
    errno.EACCES: "no permission to use {f}",
    errno.EPERM: "no permission to use {f}",
    errno.ENOSPC: "no space left on the disk for {f}",
    errno.EROFS: "{f} is on a read-only file system",
    errno.ENAMETOOLONG: "the name {f} is too long",
}


def os_sentence(e: OSError) -> str:
    """An OSError as a sentence about the file (``[Errno 21] Is a directory: 'out'`` reads
    "out is a folder; give a file name ..."); the system's words when no sentence fits."""
    name = e.filename if e.filename is not None else None
    if name is not None:
        f = os.fsdecode(name)
        sentence = _ERRNO_SENTENCES.get(e.errno or 0)
        if sentence is not None:
            return sentence.format(f=f)
        if e.strerror:
            return f"{f}: {e.strerror[0].lower()}{e.strerror[1:]}"
    return e.strerror or str(e)


def main(argv: Sequence[str] | None = None) -> int:
    _tolerant_streams()
    parser = build_parser(_verb(sys.argv[1:] if argv is None else list(argv)))
    args = parser.parse_args(argv)
    # (the words as given: argparse drops the `--` that follows a positional, which a verb
    # taking another program's arguments must tell from an option of its own)
    args.raw_argv = list(sys.argv[1:] if argv is None else argv)
    if not getattr(args, "command", None) or not hasattr(args, "func"):
        parser.print_help()
        return 2
    try:
        code = int(args.func(args) or 0)
        if argv is None and getattr(args, "leave_at_once", False):
            _leave_at_once(code)
        return code
    except KeyboardInterrupt:
        return 130
    except BrokenPipeError:  # ``gtecat map x.eni | head``: the reader left, nothing to report
        try:
            sys.stdout = open(os.devnull, "w")  # silence the flush at exit
        except OSError:
            pass
        return 0
    except (GtecatError, OSError) as e:
        if args.debug:
            raise
        print(f"error: {os_sentence(e) if isinstance(e, OSError) else e}", file=sys.stderr)
        return 1
    except Exception as e:  # one clear line, never a traceback by default
        if args.debug:
            raise
        print(
            f"error: internal error: {type(e).__name__}: {e} (run with --debug for details)",
            file=sys.stderr,
        )
        return 1


if __name__ == "__main__":
    sys.exit(main())
