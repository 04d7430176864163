"""Fuzz the function table through libgts, in a child process: C codes == Python codes.

``python -m tests.gtecat.native.fuzz_lib_worker [--examples N] [NAME...]`` brings up the
manual's figure 5-2 bus in lockstep in this process, serves it on a socket
(:class:`~gtecat.native.server.Server`), loads ``libgts.so`` through
``gtecat.native.cdll()`` (argtypes from the table; it attaches with
``GTECAT_CONTROLLER``) and, for every function of the table (``GT_*`` and its ``GTN_*``
twin with a random core, ``GTE_*``), runs a hypothesis test that makes each call twice
with arguments generated from the table's parameter types: once through Python
(``gt.GT_x``), once through the library, each with its own copy of the memory.  What C
can pass is what is generated: integers of the C argument type (narrowed as C narrows;
``long`` is 64 bits here, so values beyond the vendor's 32 bits too), any double (nan,
inf, the table's edges and beyond), NULL or a buffer of the size the table says for
every pointer (NULL where that would pass 4 MB: the library reads and writes what the
count says, as the vendor's does), text, and any core for the twins.

Each pair must agree on 7 (the library refuses exactly what Python refuses); an
argument that is certainly illegal (a NULL required pointer, a value outside the table's
range or the vendor's 32 bits, a core other than a card's 1 and 2) must give 7 on both; a
7 from the library leaves its out-pointers untouched; the library never returns -7 or a code the
manual does not have.  Other codes may differ where the first call changed what the
second sees (they are listed as ``note`` lines).  Output: ``ok NAME`` / ``FAIL NAME: ...``
per function; exit status 0 when every one passed.  ``CI`` derandomises.
"""

from __future__ import annotations

import argparse
import ctypes
import logging
import math
import os
import sys
import tempfile
from ctypes import byref, c_short
from typing import Any

from hypothesis import HealthCheck, given, note, settings
from hypothesis import strategies as st

from gtecat import gt
from gtecat.gt import _core
from gtecat.gt.table import ENUMS, SAME_PARAM_TWINS, SCALARS, Param
from gtecat.native import cdll, protocol
from gtecat.native.server import Server
from tests.conftest import EXAMPLES

#: state-changing or slow calls the pair cannot repeat on one bus (as test_server's fuzz)
SKIP = {
    "GT_Open", "GT_Close", "GT_Reset", "GT_InitEcatComm", "GT_TerminateEcatComm",
    "GT_StartEcatComm", "GT_LoadConfig", "GTE_Wait", "GTE_UnplugSlave", "GTE_ReplugSlave",
    "GT_EcatIOSynch", "GT_SetCardNo", "GT_SetCore",
}  # fmt: skip
CODES = {0, 1, 7, -1, -6, -8, -9, -10}
TEXTS = [b"", b"x.cfg", str(EXAMPLES / "servo.cfg").encode(), b"/nonexistent/a.cfg", b"a" * 300]
MAX_BUFFER = 4 << 20
LONG_BITS = ctypes.sizeof(ctypes.c_long) * 8


def _scalar(p: Param) -> str:
    """``p``'s scalar type: a C enum is an int."""
    return "int" if p.ctype in ENUMS else p.ctype


def c_range(p: Param) -> tuple[int, int]:
    """What a C caller can pass for ``p`` (``long`` is this platform's long)."""
    if p.ctype == "long":
        return -(1 << (LONG_BITS - 1)), (1 << (LONG_BITS - 1)) - 1
    if p.ctype == "unsigned long":
        return 0, (1 << LONG_BITS) - 1
    _, lo, hi, _ = SCALARS[_scalar(p)]
    return int(lo), int(hi)


def legal_range(p: Param) -> tuple[int, int]:
    """What the table accepts (the vendor's 32-bit long, the /*lo..hi*/ range, masks)."""
    _, lo, hi, _ = SCALARS[_scalar(p)]
    if p.mask:
        lo, hi = min(lo, -(1 << 31)), max(hi, (1 << 32) - 1)
    if p.lo is not None:
        lo, hi = max(lo, math.ceil(p.lo)), min(hi, math.floor(p.hi))  # type: ignore[arg-type]
    return int(lo), int(hi)


def narrow(p: Param, v: int) -> int:
    """``v`` as C holds it in ``p``'s type (ctypes wraps, as a C conversion does)."""
    t = getattr(ctypes, SCALARS[_scalar(p)][0]) if _scalar(p) in SCALARS else ctypes.c_long
    if p.ctype == "long":
        t = ctypes.c_long
    elif p.ctype == "unsigned long":
        t = ctypes.c_ulong
    return int(t(v).value)


def draw_int(data: Any, p: Param, is_count: bool) -> tuple[int, bool]:
    """(value as C passes it, certainly illegal)."""
    lo, hi = legal_range(p)
    clo, chi = c_range(p)
    small = st.integers(max(lo, 0 if is_count else -1), min(hi, 4 if is_count else 9))
    edges = (lo - 1, hi + 1, clo, chi, 1 << 31, -(1 << 31) - 1, 1 << 32)
    bad = [v for v in edges if clo <= v <= chi and not lo <= v <= hi]
    choices = [small, small, st.integers(lo, hi), st.sampled_from([lo, hi])]
    if bad:
        choices.append(st.sampled_from(bad))
    v = narrow(p, data.draw(st.one_of(*choices), label=p.name))
    return v, not lo <= v <= hi


def draw_real(data: Any, p: Param, fname: str) -> tuple[float, bool]:
    edges = [0.0, 1.0, -1.0, 0.5, math.nan, math.inf, -math.inf, 1e300]
    if p.lo is not None:
        edges += [p.lo, p.hi, p.lo - 1, p.hi + 1]  # type: ignore[operator]
    if fname.endswith("_Wait"):
        edges = [0.0, 1.0]
    v = data.draw(
        st.one_of(st.sampled_from(edges), st.floats(-1e4, 1e4), st.floats()), label=p.name
    )
    bad = not math.isfinite(v) or (p.lo is not None and not p.lo <= v <= p.hi)  # type: ignore[operator]
    return v, bad


class Buffer:
    """One pointer's memory: the library's copy and Python's, the same bytes."""

    def __init__(self, elem: Any, n: int, content: bytes) -> None:
        size = ctypes.sizeof(elem) * n
        self.c = (ctypes.c_ubyte * size).from_buffer_copy(content[:size].ljust(size, b"\0"))
        self.py = (elem * n).from_buffer_copy(bytes(self.c))
        self.before = bytes(self.c)  # before the library's call


def fuzz_function(lib: Any, plan: protocol.FunctionPlan, examples: int, notes: list[str]) -> None:
    proto = plan.proto
    fn_py = _core.REGISTRY[plan.name]
    twin_py = _core.REGISTRY.get("GTN_" + plan.name[3:]) if proto.gtn else None
    fn_c = getattr(lib, plan.name)
    twin_c = getattr(lib, "GTN_" + plan.name[3:]) if proto.gtn else None
    counts = {a.count_arg for a in plan.args if a.count_arg >= 0}

    def example(data: Any) -> None:
        must7 = False
        scalars: list[Any] = []
        for i, a in enumerate(plan.args):
            if a.kind is protocol.Kind.INT:
                v, bad = draw_int(data, a.param, i in counts)
            elif a.kind is protocol.Kind.DOUBLE:
                v, bad = draw_real(data, a.param, plan.name)
            else:
                v, bad = None, False
            scalars.append(v)
            must7 |= bad
        c_args: list[Any] = []
        py_args: list[Any] = []
        outs: list[Buffer] = []
        keep: list[Any] = []
        for a, v in zip(plan.args, scalars, strict=True):
            p = a.param
            if not p.pointer:
                c_args.append(v)
                py_args.append(v)
                continue
            if data.draw(st.integers(0, 4), label=f"{p.name} NULL?") == 0:
                c_args.append(None)
                py_args.append(None)
                must7 |= not p.optional
                continue
            if a.kind is protocol.Kind.TEXT:
                text = data.draw(st.sampled_from(TEXTS), label=p.name)
                buf = ctypes.create_string_buffer(text)
                keep.append(buf)
                c_args.append(ctypes.addressof(buf))
                py_args.append(text)
                continue
            elem = protocol.element_type(p.ctype, ctypes.sizeof(ctypes.c_long))
            if a.kind is protocol.Kind.OUT_ANY:
                n = 4096 // ctypes.sizeof(elem)
            else:
                n = scalars[a.count_arg] if a.count_arg >= 0 else a.count
                n = max(int(n), 1)  # C passes memory for all the table moves
            size = ctypes.sizeof(elem) * n
            if size > MAX_BUFFER:  # no caller has that much memory behind a pointer
                c_args.append(None)
                py_args.append(None)
                must7 |= not p.optional
                continue
            if a.kind in (protocol.Kind.IN, protocol.Kind.INOUT):
                content = data.draw(st.binary(min_size=size, max_size=size), label=p.name)
            else:
                content = b"\xa5" * size
            b = Buffer(elem, n, content)
            keep.append(b)
            c_args.append(ctypes.addressof(b.c))
            py_args.append(b.py)
            if a.carries_back:
                outs.append(b)
        calls = [(plan.name, fn_py, fn_c, [])]
        if twin_py is not None and plan.name in SAME_PARAM_TWINS:  # GTN_Compile: no core
            calls.append(("GTN_" + plan.name[3:], twin_py, twin_c, []))
        elif twin_py is not None:
            core = data.draw(st.sampled_from([1, 1, 1, 0, 2, -1, 32767]), label="core")
            calls.append(("GTN_" + plan.name[3:], twin_py, twin_c, [core]))
        for name, py, c, core_args in calls:
            bad = must7 or (core_args and core_args[0] not in (1, 2))
            desc = f"{name}({', '.join(_short(x) for x in core_args + py_args)})"
            note(desc)
            rc_py = py(*core_args, *py_args)
            why_py = gt.GTE_GetLastError()
            for b in outs:
                b.before = bytes(b.c)
            rc_c = c(*core_args, *c_args)
            why_c = _lib_error(lib)
            where = f"{desc}: Python {rc_py} ({why_py}), libgts {rc_c} ({why_c})"
            assert rc_c != -7, f"internal error through the library: {where}"
            assert rc_c in CODES or rc_c == rc_py, f"not a manual code: {where}"
            assert (rc_py == 7) == (rc_c == 7), f"7 from one side only: {where}"
            if bad:
                assert rc_c == 7, f"an illegal argument must give 7: {where}"
            if rc_c == 7:
                for b in outs:
                    assert bytes(b.c) == b.before, f"a 7 wrote an out-pointer: {where}"
            elif rc_py != rc_c:
                notes.append(f"note {where}")

    # a one-line hypothesis test around ``example``: hypothesis hashes the source of the test
    # it runs once or twice per function, and tokenizing the long body was a third of the time
    @settings(
        max_examples=examples,
        deadline=None,
        database=None,
        derandomize=bool(os.environ.get("CI")),
        suppress_health_check=list(HealthCheck),
        print_blob=False,
    )
    @given(st.data())
    def run(data: Any) -> None:
        example(data)

    run()


def _short(v: Any) -> str:
    r = repr(v)
    return r if len(r) < 40 else r[:37] + "..."


def _lib_error(lib: Any) -> str:
    buf = ctypes.create_string_buffer(1024)
    lib.GTE_GetLastError(buf, 1024)
    return buf.value.decode("utf-8", "replace")


def bring_up() -> None:
    opts = {"eni": str(EXAMPLES / "manual_fig5_2.eni"), "clock": "lockstep", "log": ""}
    assert gt.GT_Open(controller="local", **opts) == 0, gt.GTE_GetLastError()
    assert gt.GT_InitEcatComm() == 0, gt.GTE_GetLastError()
    ready = c_short()
    for _ in range(2000):
        gt.GTE_Wait(1)
        if gt.GT_IsEcatReady(byref(ready)) == 0 and ready.value == 1:
            break
    assert ready.value == 1, gt.GTE_GetLastError()
    assert gt.GT_StartEcatComm() == 0, gt.GTE_GetLastError()


def declared_calls(lib: Any, sample: int) -> int:
    """Declared-only functions through the library and in Python: 8 and the same reason,
    with zeros and NULLs for their arguments (a seeded sample; every one with GTECAT_LONG)."""
    import random

    from gtecat.gt.declared import reason

    plans = [p for p in protocol.plans() if p.declared and not p.proto.unknown]
    if not os.environ.get("GTECAT_LONG"):
        plans = random.Random(25).sample(plans, min(sample, len(plans)))
    failed = 0
    for plan in plans:
        fn_c = getattr(lib, plan.name)
        if fn_c.argtypes is None and plan.proto.params:
            continue  # a structure passed by value: cdll() leaves it untyped
        args = [
            None if t is ctypes.c_void_p else 0.0 if t in (ctypes.c_double, ctypes.c_float) else 0
            for t in (fn_c.argtypes or [])
        ]
        rc_c = fn_c(*args)
        buf = ctypes.create_string_buffer(512)
        lib.GTE_GetLastError(buf, 512)
        rc_py = getattr(gt, plan.name)(*args)
        want = f"{plan.name} returned 8: {reason(plan.name)}"
        if (rc_c, rc_py, buf.value.decode(), gt.GTE_GetLastError()) != (8, 8, want, want):
            failed += 1
            print(f"FAIL {plan.name}: C {rc_c} {buf.value!r}, Python {rc_py}", flush=True)
        else:
            print(f"ok {plan.name} (declared)", flush=True)
    return failed


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--examples", type=int, default=15)
    ap.add_argument("names", nargs="*", help="functions (default: every one the pair can run)")
    ap.add_argument(
        "--declared", type=int, default=0, help="also N declared-only functions (GTECAT_LONG: all)"
    )
    a = ap.parse_args(argv)
    logging.getLogger("gtecat").setLevel(logging.CRITICAL)
    bring_up()
    tmp = tempfile.mkdtemp(prefix="gtecat-fuzz-")
    address = f"unix:{tmp}/ctl.sock"
    server = Server(address, wall_floor=False).start()
    os.environ["GTECAT_CONTROLLER"] = address
    os.environ.setdefault("GTECAT_TIMEOUT_MS", "20000")
    lib = cdll()
    assert lib.GT_Open(0, 1) == 0, _lib_error(lib)
    wanted = set(a.names)
    failed = 0
    notes: list[str] = []
    for plan in protocol.plans():
        if wanted and plan.name not in wanted:
            continue
        if plan.name in SKIP or plan.unsupported or plan.name not in _core.REGISTRY:
            continue
        if os.environ.get("FUZZ_TRACE"):
            print(f"start {plan.name}", flush=True)
        try:
            fuzz_function(lib, plan, a.examples, notes)
        except Exception as e:
            failed += 1
            print(f"FAIL {plan.name}: {str(e)[-3000:]}", flush=True)
        else:
            print(f"ok {plan.name}", flush=True)
    if a.declared:
        failed += declared_calls(lib, a.declared)
    for line in notes[:200]:
        print(line)
    lib.GT_Close()
    server.stop()
    gt.GT_Close()
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
