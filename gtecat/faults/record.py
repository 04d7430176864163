"""Recordings: the GT call stream of a session, its faults and the bus at checkpoints; replay.

A recording is one JSON-lines file (gzip when its name ends in ``.gz``):

* a header ``{"gtecat_recording": 1, "calls": N, ...}``: N call lines follow (a replay
  refuses a file that holds fewer, one cut short at a line's end, or more);
  ``bus_config``: the ENI files and machine descriptions the session's buses were brought up
  from, compared before a replay runs (:mod:`gtecat.faults.bus_config`);
* one line per GT call: ``{"t": controller time in ns, "c": NAME, "a": [arguments], "r":
  return code, "k": {keywords}, "o": {index: value written back}}``, and ``"b"``: the
  controller time when the call began, where time passed since the call before (a
  controller process lets its clock follow the wall clock between its clients' calls);
* ``{"f": "inject", "v": {a [[fault]] table}}`` / ``{"f": "clear", "id": N}`` for faults
  injected from Python or the command line, at their place in the stream;
* ``{"cp": ns, "wkc": [got, expected], "states": [...], "ready": 0|1}`` checkpoints of the bus
  every :data:`CHECKPOINT_MS` of controller time.

Pointer arguments are kept by value (a ``c_long`` as ``{"c": "c_long", "v": 5}``, a structure
field by field (a class of the application's own with its layout, ``"lay"``, so that the
replay builds one like it), an array as its size and every value, which must agree, a buffer
as hex; a pointer into an object, ``byref(arr, 16)`` for C's ``&arr[2]``, with its byte
offset: ``{"ref": ..., "off": 16}``); replay builds fresh objects of the same types, makes the
same calls in the same order and compares every return code, every value the call leaves in
its pointer arguments (written back or left as it was) and every checkpoint: the first
difference is the divergence (call number, function, argument, recorded and new value).
Replays are deterministic in the ``auto`` and ``lockstep`` clocks; a ``realtime`` session
replays in ``auto`` (the values its wall clock decided may then differ, and are reported so).
"""

from __future__ import annotations

import ctypes
import gc
import hashlib
import json
import marshal
import os
import re
import struct
import sys
import threading
import time
import zlib
from array import array
from contextlib import contextmanager
from dataclasses import dataclass, field
from functools import lru_cache
from itertools import accumulate, chain, compress, repeat
from operator import contains, is_, is_not, itemgetter, not_
from pathlib import Path
from typing import Any

import numpy as np

from .._code_store import compiled as _compiled_code
from ..controller.core import process_froze, unfreeze
from ..errors import ParameterError
from ..gt.args import byref_address
from .tap import Listener, tap, untap

CHECKPOINT_MS = 100
#: the recording format this gtecat writes and reads (the header's ``gtecat_recording``)
FORMAT = 1
#: the settings a recording keeps and a replay restores (what GT_Open reads)
_ENV = (
    "GTECAT_ENI",
    "GTECAT_MACHINE",
    "GTECAT_CLOCK",
    "GTECAT_BACKEND",
    "GTECAT_IFACE",
    "GTECAT_BUS",
    "GTECAT_BANK",
    "GTECAT_CARD",
)
_CArg = type(ctypes.byref(ctypes.c_int()))
_SIMPLE = {
    name: getattr(ctypes, name)
    for name in dir(ctypes)
    if name.startswith("c_")
    and isinstance(getattr(ctypes, name), type)
    and issubclass(getattr(ctypes, name), ctypes._SimpleCData)  # type: ignore[attr-defined]
}
#: the simple types whose own name is their recorded name (an alias such as c_int32 records
#: its class's name)
_SIMPLE_NAME = {cls: cls.__name__ for cls in _SIMPLE.values() if cls.__name__ in _SIMPLE}
_PLAIN = (int, str, bool, type(None))


# --- values ------------------------------------------------------------------------------
def _scalar(v: Any) -> Any:
    if isinstance(v, bytes):
        return {"b": v.hex()}
    if isinstance(v, float) and (v != v or v in (_INF, -_INF)):
        return {"nan": 1} if v != v else {"inf": 1 if v > 0 else -1}
    return v


_INF = float("inf")


def _offset(p: Any) -> int:
    """The byte offset of ``byref(obj, offset)`` (0 for ``byref(obj)``, or a pointer object
    that holds no ctypes object): a C program's ``&arr[8]``, kept so the replay passes the
    same address into the same object."""
    try:
        return byref_address(p) - ctypes.addressof(p._obj)
    except (TypeError, AttributeError):
        return 0


def encode(x: Any) -> Any:
    """An argument as plain JSON (module docstring); ``byref(obj, offset)`` keeps its offset
    (``"off"``, bytes)."""
    if type(x) is _CArg:  # byref(c_long()), the usual pointer: the quick way to the same
        off = _offset(x)
        name = _SIMPLE_NAME.get(type(x._obj))
        if name is not None and not off:
            v = x._obj.value
            return {"ref": {"c": name, "v": v if type(v) is int else _scalar(v)}}
        out = {"ref": encode(x._obj)}
        if off:
            out["off"] = off
        return out
    if x is None or isinstance(x, bool | int | str):
        return x
    if isinstance(x, float):
        return _scalar(x)
    if isinstance(x, _CArg):
        return {"ref": encode(x._obj)}
    if isinstance(x, ctypes._SimpleCData):  # type: ignore[attr-defined]
        return {
            "c": type(x).__name__ if type(x).__name__ in _SIMPLE else _base(x),
            "v": _scalar(x.value),
        }
    if isinstance(x, ctypes.Array):
        et = x._type_
        if et in (ctypes.c_char, ctypes.c_ubyte, ctypes.c_uint8, ctypes.c_byte):
            return {"arr": et.__name__, "n": len(x), "hex": bytes(x).hex()}
        return {
            "arr": et.__name__ if et.__name__ in _SIMPLE else "",
            "n": len(x),
            "v": [encode(e) for e in x],
        }
    if isinstance(x, ctypes.Structure):
        out = {"st": type(x).__name__, "v": {f[0]: encode(getattr(x, f[0])) for f in x._fields_}}
        if not _of_gt(type(x)) or _gt_struct(type(x).__name__) is not type(x):
            out["lay"] = _layout(type(x))  # (the application's own: rebuilt from its layout)
        return out
    if isinstance(x, ctypes._Pointer):  # type: ignore[attr-defined]
        return {"ptr": encode(x.contents)} if x else None
    if isinstance(x, bytes):
        return {"b": x.hex()}
    if isinstance(x, bytearray):
        return {"ba": x.hex()}
    if isinstance(x, memoryview):
        return {"ba": bytes(x).hex()}
    if isinstance(x, list):
        return {"list": [encode(e) for e in x]}
    if isinstance(x, tuple):
        return {"tuple": [encode(e) for e in x]}
    if hasattr(x, "dtype") and hasattr(x, "tolist"):
        return {"np": str(x.dtype), "v": x.tolist()}
    return {"repr": repr(x)}


def _base(x: Any) -> str:
    for cls in type(x).__mro__:
        if cls.__name__ in _SIMPLE:
            return cls.__name__
    return "c_long"


def _unscalar(v: Any) -> Any:
    if isinstance(v, dict):
        if "b" in v:
            return bytes.fromhex(v["b"])
        if "nan" in v:
            return float("nan")
        if "inf" in v:
            return _INF if v["inf"] > 0 else -_INF
    return v


def decode(v: Any) -> Any:
    """A fresh object of the recorded type holding the recorded value."""
    if not isinstance(v, dict):
        return v
    if "nan" in v or "inf" in v:
        return _unscalar(v)
    if "ref" in v:
        off = v.get("off")
        if type(off) is int and off:
            return ctypes.byref(decode(v["ref"]), off)
        return ctypes.byref(decode(v["ref"]))
    if "c" in v:
        return _simple(v["c"])(_unscalar(v["v"]))
    if "arr" in v:
        et = _SIMPLE.get(v["arr"], ctypes.c_ubyte)
        arr = (et * _array_size(v))()
        if "hex" in v:
            ctypes.memmove(arr, bytes.fromhex(v["hex"]), min(v["n"], len(v["hex"]) // 2))
        else:
            for i, e in enumerate(v["v"]):
                arr[i] = _unscalar(e["v"]) if isinstance(e, dict) and "v" in e else _unscalar(e)
        return arr
    if "st" in v:
        lay = v.get("lay")
        cls = _rebuilt(v["st"], json.dumps(lay)) if lay is not None else _gt_struct(v["st"])
        if cls is None:
            raise ParameterError(f"structure {v['st']} is not part of gtecat.gt")
        obj = cls()
        for name, fv in v["v"].items():
            _set_field(obj, name, fv)
        return obj
    if "ptr" in v:
        return ctypes.pointer(decode(v["ptr"]))
    if "ba" in v:
        return bytearray.fromhex(v["ba"])
    if "list" in v:
        return [decode(e) for e in v["list"]]
    if "tuple" in v:
        return tuple(decode(e) for e in v["tuple"])
    if "np" in v:
        import numpy as np

        return np.array(v["v"], dtype=v["np"])
    if "b" in v:
        return bytes.fromhex(v["b"])
    return None  # a value that cannot be rebuilt (an object of the caller's)


def _of_gt(cls: type) -> bool:
    """``cls`` was made by gtecat.gt (a module of it, or its vendor surface): only such a
    class can be one of its structures, so another's name is not asked of it (which, in a
    process that left the GT layer's surface for later, would make all of it)."""
    return f"{cls.__module__}.".startswith("gtecat.gt.")


def _gt_struct(name: Any) -> Any:
    """gtecat.gt's structure of that name, or None."""
    from .. import gt

    cls = getattr(gt, name, None) if type(name) is str else None
    return cls if isinstance(cls, type) and issubclass(cls, ctypes.Structure) else None


def _layout(cls: Any) -> list[Any]:
    """An application's own structure's fields as a recording keeps them: ``[name, type]``
    (``[name, type, bits]`` for a bit field), a type being a simple type's name, ``{"arr":
    type, "n": n}`` or ``{"st": name, "lay": [...]}``.  The GT layer takes a structure of
    the prototype's layout whatever its class (a program defines its own, as the vendor's C#
    wrappers do), so the replay must build one with the same layout."""
    return [[f[0], _field_type(f[1]), *f[2:3]] for f in cls._fields_]


def _field_type(t: Any) -> Any:
    if issubclass(t, ctypes.Array):
        return {"arr": _field_type(t._type_), "n": t._length_}
    if issubclass(t, ctypes.Structure):
        if _gt_struct(t.__name__) is t:
            return {"st": t.__name__}
        return {"st": t.__name__, "lay": _layout(t)}
    for cls in t.__mro__:
        if cls.__name__ in _SIMPLE and _SIMPLE[cls.__name__] is cls:
            return cls.__name__
    raise TypeError(f"a field of type {t.__name__} cannot be recorded")


#: a rebuilt structure's fields at most, and its nesting (a damaged recording never makes a
#: huge type)
_MOST_FIELDS = 4096
_MOST_BYTES = 1 << 20
_MOST_DEPTH = 8


@lru_cache(maxsize=256)
def _rebuilt(name: Any, lay: str) -> Any:
    """The structure class a recording's layout (:func:`_layout`, as JSON text) describes,
    made once per layout (ValueError: a layout that is none)."""
    return _struct_of(name, json.loads(lay), 0)


def _struct_of(name: Any, lay: Any, depth: int) -> Any:
    if type(name) is not str or not name.isidentifier() or depth > _MOST_DEPTH:
        raise ValueError(f"a recorded structure {name!r} cannot be rebuilt")
    if type(lay) is not list or not 0 < len(lay) <= _MOST_FIELDS:
        raise ValueError(f"structure {name}: its recorded layout is not a list of fields")
    fields: list[tuple[Any, ...]] = []
    for f in lay:
        if (
            type(f) is not list
            or len(f) not in (2, 3)
            or type(f[0]) is not str
            or not f[0].isidentifier()
            or (len(f) == 3 and (type(f[2]) is not int or not 0 < f[2] <= 64))
        ):
            raise ValueError(f"structure {name}: a recorded field {f!r} is not one")
        fields.append((f[0], _type_of(f[1], depth), *f[2:]))
    return type(name, (ctypes.Structure,), {"_fields_": fields})


def _type_of(t: Any, depth: int) -> Any:
    if type(t) is str:
        return _simple(t)
    if type(t) is dict and "arr" in t:
        n = t.get("n")
        elem = _type_of(t["arr"], depth + 1)
        if type(n) is not int or not 0 <= n * ctypes.sizeof(elem) <= _MOST_BYTES:
            raise ValueError(f"a recorded field's array size {n!r} is not one")
        return elem * n
    if type(t) is dict and "st" in t:
        if "lay" not in t:
            cls = _gt_struct(t["st"])
            if cls is None:
                raise ValueError(f"structure {t['st']!r} is not part of gtecat.gt")
            return cls
        return _struct_of(t["st"], t["lay"], depth + 1)
    raise ValueError(f"a recorded field's type {t!r} is not one")


def _array_size(v: dict[str, Any]) -> int:
    """The size of a recorded array: its ``n``, which must be the number of values it holds
    (as :func:`encode` writes it), so that a damaged size never makes a huge array."""
    n = v.get("n")
    if type(n) is not int or n < 0:
        raise ValueError(f"an array's size {n!r} is not a count")
    if "hex" in v:
        held = v["hex"]
        have = len(held) // 2 if type(held) is str else -1
    else:
        held = v.get("v")
        have = len(held) if type(held) is list else -1
    if have != n:
        raise ValueError(
            f"an array of {n} values holds {have if have >= 0 else 'no list of'} values"
        )
    return n


def _check_arrays(x: Any) -> None:
    """Every array inside a recorded value holds as many values as its size says (ValueError:
    the one that does not)."""
    if type(x) is dict:
        if "arr" in x:
            _array_size(x)
        for k, y in x.items():
            if k != "lay":  # (a structure's layout: sizes, no values; _type_of bounds them)
                _check_arrays(y)
    elif type(x) is list:
        for y in x:
            _check_arrays(y)


def _set_field(obj: Any, name: str, fv: Any) -> None:
    cur = getattr(obj, name)
    if isinstance(cur, ctypes.Array):
        src = decode(fv) if isinstance(fv, dict) else fv
        for i in range(min(len(cur), len(src))):
            cur[i] = src[i]
    elif isinstance(cur, ctypes.Structure) and isinstance(fv, dict) and "st" in fv:
        for n2, v2 in fv["v"].items():
            _set_field(cur, n2, v2)
    else:
        setattr(
            obj, name, _unscalar(fv) if not isinstance(fv, dict) else _unscalar(fv.get("v", fv))
        )


def _mutable(x: Any) -> bool:
    return isinstance(
        x,
        _CArg
        | ctypes._SimpleCData
        | ctypes.Array
        | ctypes.Structure
        | bytearray
        | memoryview
        | list
        | ctypes._Pointer,
    ) or (  # type: ignore[attr-defined]
        hasattr(x, "dtype") and hasattr(x, "tolist")
    )


# --- recording ----------------------------------------------------------------------------
class Recorder(Listener):
    """Writes the stream of the calls this thread makes (``any_thread``: every thread's, in the
    order they ran: the tap takes them one at a time) and the faults injected."""

    def __init__(
        self, path: str | Path, meta: dict[str, Any] | None = None, *, any_thread: bool = False
    ) -> None:
        self.path = Path(path)
        self.lines: list[str] = []
        self.meta = dict(meta or {})
        #: the thread whose calls are the session's (None: every thread's, as in a controller
        #: process serving its clients' calls)
        self.thread = None if any_thread else threading.get_ident()
        self._last_cp = -(1 << 62)
        self._t_end = -1  # controller time (with the latency not yet run) after the last call
        self.calls = 0
        self._dumps = json.JSONEncoder(separators=(",", ":"), allow_nan=False).encode
        #: where the session ran: its folder and the GTECAT_* settings GT_Open reads
        self.where = {
            "cwd": os.getcwd(),
            "env": {k: v for k, v in os.environ.items() if k in _ENV},
        }
        #: the configuration files of every bus brought up (gtecat.faults.bus_config): the
        #: header's ``bus_config``, which the replay compares before it runs
        self.bus_config: list[dict[str, str]] = []

    def start(self) -> Recorder:
        from ..controller.core import Controller
        from . import injector

        tap(self)
        injector.OBSERVERS.append(self.fault_event)
        Controller.bus_up_hooks.append(self.bus_up)
        return self

    def stop(self) -> None:
        from ..controller.core import Controller
        from . import injector

        untap(self)
        if self.fault_event in injector.OBSERVERS:
            injector.OBSERVERS.remove(self.fault_event)
        if self.bus_up in Controller.bus_up_hooks:
            Controller.bus_up_hooks.remove(self.bus_up)

    def bus_up(self, ctl: Any) -> None:
        """A bus came up (``Controller.bus_up_hooks``): its configuration files noted."""
        from .bus_config import noted

        for note in noted(ctl):
            if note not in self.bus_config:
                self.bus_config.append(note)

    def before(self, name: str, args: tuple, kwargs: dict) -> Any:
        if self.thread is not None and threading.get_ident() != self.thread:
            return None
        ctl = _controller()
        gap = None
        if ctl is not None:  # time that passed between calls (a controller's wall-clock floor)
            total = ctl.clock.now_ns + ctl.clock._pending_ns
            if total != self._t_end and self._t_end >= 0:
                gap = total
        a: list[Any] = []
        held: list[tuple[str, Any, Any]] = []  # (index or keyword, object, its value before)
        for i, x in enumerate(args):
            if type(x) in _PLAIN:
                a.append(x)
                continue
            enc = encode(x)
            a.append(enc)
            if _mutable(x):
                held.append((str(i), x, enc))
        kw = {}
        for k, x in kwargs.items():
            kw[k] = enc = encode(x)
            if _mutable(x):
                held.append((k, x, enc))
        return a, kw, gap, held

    def after(self, name: str, args: tuple, kwargs: dict, rc: Any, token: Any) -> None:
        if token is None:
            return
        a, kw, gap, held = token
        outs = {}
        for k, x, enc in held:  # what the call wrote back into its pointer arguments
            now = encode(x)
            if now != enc:
                outs[k] = now
        ctl = _controller()
        t = ctl.clock.now_ns if ctl is not None else 0
        entry: dict[str, Any] = {
            "t": t,  # first: a reader finds calls that differ only in time (read)
            "c": name,
            "a": a,
            "r": rc if isinstance(rc, int) else encode(rc),
        }
        if kw:
            entry["k"] = kw
        if outs:
            entry["o"] = outs
        if gap is not None:
            entry["b"] = gap
        self._t_end = t + ctl.clock._pending_ns if ctl is not None else -1
        self.lines.append(self._dumps(entry))
        self.calls += 1
        if ctl is not None and t - self._last_cp >= CHECKPOINT_MS * 1_000_000:
            self._last_cp = t
            cp = checkpoint(ctl)
            if cp is not None:
                self.lines.append(self._dumps(cp))

    def fault_event(self, what: str, values: dict[str, Any]) -> None:
        same = threading.get_ident() == self.thread or self.thread is None
        entry = {"f": what, "v": values, "sync": same}
        ctl = _controller()
        if ctl is not None:
            entry["t"] = ctl.clock.now_ns
            entry["ms"] = (ctl.clock.now_ns - ctl.reset_ns) / 1e6
        self.lines.append(self._dumps(entry))

    def write(self) -> Path:
        lines = list(self.lines)  # (a client's call may still be adding one: these, counted)
        calls = sum(1 for x in lines if x.startswith('{"t":'))  # a call's line, as after() writes
        head = {"gtecat_recording": FORMAT, "calls": calls, **self.meta, **self.where}
        if self.bus_config:
            head["bus_config"] = self.bus_config
        text = json.dumps(head) + "\n" + "\n".join(lines) + ("\n" if lines else "")
        data = text.encode()
        if self.path.suffix == ".gz":
            import gzip  # (here: a replay of a plain recording never needs it)

            data = gzip.compress(data, 6)
        self.path.write_bytes(data)
        del text, lines
        _plan_ahead(self.path, data)
        return self.path


#: the signals by which a supervisor ends a program (a CI job's time-out, ``kill``, a closed
#: terminal); Ctrl-C (SIGINT) already raises KeyboardInterrupt
ENDING_SIGNALS = ("SIGTERM", "SIGHUP")


def end_on_signals() -> None:
    """Make SIGTERM and SIGHUP end this program as ``sys.exit(128 + signal)`` does.

    Python's default for them kills the process at once: a recording kept in memory until
    the program ends would be lost with it (a CI job's time-out sends SIGTERM).  As a
    SystemExit, the program's ``finally`` blocks and exit handlers run and the recording is
    written up to the call the signal interrupted, which replays.  Only a signal still at
    its default is taken, and only from the main thread (where Python runs handlers); a
    program that installs its own handler later keeps it."""
    import signal

    if threading.current_thread() is not threading.main_thread():
        return
    for name in ENDING_SIGNALS:
        num = getattr(signal, name, None)
        if num is not None and signal.getsignal(num) is signal.SIG_DFL:
            signal.signal(num, _exit_on_signal)


def _exit_on_signal(num: int, _frame: Any) -> None:
    raise SystemExit(128 + num)


def _controller() -> Any:
    session = _SESSION[0]
    if session is None:
        from ..gt._core import SESSION

        session = _SESSION[0] = SESSION
    return session.controllers.get(1)


_SESSION: list[Any] = [None]


def checkpoint(ctl: Any) -> dict[str, Any] | None:
    m = ctl.master
    if m is None or not m.opened:
        return None
    return {
        "cp": ctl.clock.now_ns,
        "wkc": [m.last.wkc, m.last.expected],
        "states": [int(s) for s in m.states],
        "ready": int(m.ready),
    }


# --- replay ------------------------------------------------------------------------------------
@dataclass
class Divergence:
    index: int  # the call's number in the stream (1-based)
    call: str
    what: str  # "return code", "argument 2", "bus state at 1200 ms"
    recorded: Any
    now: Any

    def __str__(self) -> str:
        recorded, now = _show(self.recorded), _show(self.now)
        if recorded == now:  # the same value of another type (or shape): say which
            recorded, now = _show_whole(self.recorded), _show_whole(self.now)
        return f"call {self.index} {self.call}: {self.what} recorded {recorded}, replay gives {now}"


def _first_element(div: Divergence) -> Divergence:
    """``div`` narrowed to the first element that differs where both values are arrays of
    one type and size (a byte buffer as hex text, an array of numbers, or a pointer to
    either): ``argument 3 element [100] recorded 0, replay gives 255``, as a form's arrays
    are named, rather than two long texts that may read alike where they are cut."""
    want, got = div.recorded, div.now
    if type(want) is dict and type(got) is dict and "ref" in want and "ref" in got:
        if want.get("off") != got.get("off"):
            return div
        want, got = want["ref"], got["ref"]
    if not (type(want) is dict and type(got) is dict and "arr" in want):
        return div
    if (want.get("arr"), want.get("n")) != (got.get("arr"), got.get("n")):
        return div
    if type(want.get("hex")) is str and type(got.get("hex")) is str:
        try:
            w, g = list(bytes.fromhex(want["hex"])), list(bytes.fromhex(got["hex"]))
        except ValueError:
            return div
    else:
        w, g = want.get("v"), got.get("v")
    if type(w) is not list or type(g) is not list or len(w) != len(g):
        return div
    for j, (a, b) in enumerate(zip(w, g, strict=True)):
        if a != b:
            return Divergence(div.index, div.call, f"{div.what} element [{j}]", a, b)
    return div


def _show(v: Any) -> str:
    if isinstance(v, dict) and "v" in v and len(v) <= 3:
        return _show(v["v"])
    if isinstance(v, dict) and "ref" in v:
        return _show(v["ref"])
    text = json.dumps(v) if not isinstance(v, str) else v
    return text if len(text) <= 200 else text[:197] + "..."


def _show_whole(v: Any) -> str:
    """A value with its type: ``c_long 5`` for a pointer to a simple value, else its JSON."""
    if isinstance(v, dict) and "ref" in v and len(v) == 1:
        return _show_whole(v["ref"])
    if isinstance(v, dict) and set(v) == {"c", "v"}:
        return f"{v['c']} {_show(v['v'])}"
    text = json.dumps(v) if not isinstance(v, str) else repr(v)
    return text if len(text) <= 200 else text[:197] + "..."


def _simple(c: Any) -> Any:
    """The ctypes type a recording names (ValueError: a name that is none)."""
    cls = _SIMPLE.get(c) if type(c) is str else None
    if cls is None:
        raise ValueError(f"the type {c!r} is not a ctypes type")
    return cls


def _open(path: str | Path) -> tuple[Path, dict[str, Any], list[str]]:
    """(path, header, the lines after it) of a recording."""
    p, head, body = _open_text(path)
    return p, head, body.split("\n") if body is not None else []


def _read_raw(p: Path) -> bytes:
    """A recording's bytes as they lie in its file."""
    try:
        return p.read_bytes()
    except FileNotFoundError:
        raise ParameterError(f"{p}: no such recording") from None


def _open_text(
    path: str | Path, raw: bytes | None = None
) -> tuple[Path, dict[str, Any], str | None]:
    """(path, header, the text after its line: None when there is none) of a recording
    (``raw``: its file's bytes, read already)."""
    p = Path(path)
    if raw is None:
        raw = _read_raw(p)
    if raw[:2] == b"\x1f\x8b":
        import gzip

        try:
            raw = gzip.decompress(raw)
        except EOFError:  # the compressed stream stops before its end marker
            raise ParameterError(
                f"{p}: the recording ends early: the compressed file is cut short (record it "
                "again, or copy the whole file)"
            ) from None
        except (OSError, zlib.error) as err:  # BadGzipFile, a wrong checksum, bad data
            raise ParameterError(
                f"{p}: damaged recording: the compressed file cannot be read ({err})"
            ) from None
    # (the header's line and the rest decoded apart: the text of the calls made once, from
    # the bytes as they lie, not from a decoded copy of the whole; a newline's byte is never
    # inside another character's, so the text is the same)
    end = raw.find(b"\n")
    sep = end >= 0
    first = str(memoryview(raw)[: end if sep else len(raw)], "utf-8", "replace")
    body = str(memoryview(raw)[end + 1 :], "utf-8", "replace") if sep else ""
    try:
        head = json.loads(first or "{}")
    except (json.JSONDecodeError, RecursionError):
        head = {}
    version = head.get("gtecat_recording") if isinstance(head, dict) else None
    if type(version) is int and version > FORMAT:
        raise ParameterError(
            f"{p} was written by a newer gtecat (recording format {version}; this one reads "
            f"up to format {FORMAT}): replay it with that gtecat, or update this one"
        )
    if version != FORMAT:
        raise ParameterError(f"{p} is not a gtecat recording (gtecat record -o FILE -- COMMAND)")
    if body and not body.endswith("\n"):  # every entry the recorder writes ends its line
        tail = body[body.rfind("\n") + 1 :]
        try:
            json.loads(tail)
        except (ValueError, RecursionError):
            raise ParameterError(
                f"{p}: the recording is cut short: its last line ({body.count(chr(10)) + 2}) "
                "stops in the middle of an entry (a copy that stopped, or a session killed "
                "while its recording was written): record it again, or copy the whole file"
            ) from None
    return p, head, body if sep else None


def _damaged(p: Path, lines: list[str]) -> ParameterError:
    """The error for a recording with a line that is not one entry: which line."""
    for no, line in enumerate(lines, 2):
        try:
            if line.strip() and not isinstance(json.loads(line), dict):
                raise json.JSONDecodeError("not an entry (a JSON object)", line, 0)
        except json.JSONDecodeError as err:
            return ParameterError(f"{p}: damaged recording: line {no}: {err}")
        except RecursionError:
            return ParameterError(f"{p}: damaged recording: line {no}: {_TOO_DEEP}")
    return ParameterError(f"{p}: damaged recording")


#: why a line nested deeper than JSON can be read here is refused (no entry nests so)
_TOO_DEEP = "nested too deeply to be an entry"


def read(path: str | Path) -> tuple[dict[str, Any], list[dict[str, Any]]]:
    """(header, entries) of a recording.  Calls that differ only in their time are one
    shared entry (an application polls the same way thousands of times): read them, never
    change them."""
    p, head, lines = _open(path)
    texts: list[str] = []  # the distinct lines, parsed at once below
    order: list[int] = []  # each entry's line in texts
    same: dict[str, int] = {}  # a call's line without its time -> its place in texts
    for line in lines:
        if line.startswith('{"t":'):  # as Recorder writes a call: the time first
            rest = line[line.find(",", 5) :]
            k = same.get(rest)
            if k is None:
                k = same[rest] = len(texts)
                texts.append(line)
            order.append(k)
        elif line.strip():
            order.append(len(texts))
            texts.append(line)
    try:
        parsed = json.loads("[" + ",".join(texts) + "]")
        if len(parsed) != len(texts) or not all(type(x) is dict for x in parsed):
            raise json.JSONDecodeError("a line that is not one entry", "", 0)
    except (json.JSONDecodeError, RecursionError):
        raise _damaged(p, lines) from None
    return head, [parsed[k] for k in order]


@contextmanager
def _where(head: dict[str, Any]) -> Any:
    """The recorded folder and GTECAT_* settings for the replay (a backend of real hardware
    is replaced by the emulated one)."""
    saved_env = {k: os.environ.get(k) for k in (*_ENV, "GTECAT_INSPECT")}
    saved_cwd = os.getcwd()
    env = head.get("env") or {}
    for k in _ENV:
        os.environ.pop(k, None)
    for k, v in env.items():
        if k in _ENV and isinstance(v, str):
            os.environ[k] = v
    if os.environ.get("GTECAT_BACKEND") == "pysoem":
        os.environ["GTECAT_BACKEND"] = "emulated"
    if os.environ.get("GTECAT_CLOCK") == "realtime":
        os.environ["GTECAT_CLOCK"] = "auto"
    # nothing to watch: a replay runs many times faster than real time
    os.environ["GTECAT_INSPECT"] = "0"
    cwd = head.get("cwd")
    if isinstance(cwd, str) and os.path.isdir(cwd):
        os.chdir(cwd)
    try:
        yield
    finally:
        os.chdir(saved_cwd)
        for k, v in saved_env.items():
            if v is None:
                os.environ.pop(k, None)
            else:
                os.environ[k] = v


def replay(
    path: str | Path,
    *,
    eni: str | None = None,
    machine: str | None = None,
) -> tuple[int, Divergence | None]:
    """Re-run a recording; (calls replayed, the first divergence or None).

    The recording's entries are read with the cyclic collector paused (a hundred thousand
    objects made at once, none in a cycle: the collector would walk them again and again
    while they are made, as Controller.init_ecat says of the bus model), and they are kept
    out of its later walks while the calls run (``gc.freeze``).

    The steps come from the recording's plan when one was kept for these very bytes
    (:func:`_plan_file`: by ``gtecat record`` when it wrote the file, or by the replay
    before), else from its text, and the plan is kept for the next replay."""
    p = Path(path)
    # files given to the replay are named from the folder it was started in, as a command
    # line's names are; the replay itself runs in the recorded folder (_where), so a name
    # found only there is left for it to find, as before
    eni, machine = _from_here(eni), _from_here(machine)
    # the file as it stands (named by its place, size and times): the plan its bytes had
    # when a replay read them, without reading them again (:func:`_plan_ref`)
    taken = time.time_ns()
    seen = _file_key(p)
    where = _plan_ref(seen) if seen is not None else None
    # (paused from the plan's load on: unmarshalling it makes as many objects as its steps)
    paused = gc.isenabled()
    if paused:
        gc.disable()
    marks = None  # (a plan's: where the opens and bring-ups are)
    freeze = False
    raw = None
    try:
        kept = _load_plan(where) if where is not None else None
        if kept is None:
            raw = _read_raw(p)
            where = _plan_file(raw)
            kept = _load_plan(where) if where is not None else None
            if kept is not None and seen is not None and where is not None:
                _keep_ref(p, seen, taken, where)
        steps = None
        calls = -1  # (the steps that are calls, where the plan says it)
        if kept is not None:
            head, plan = kept
            try:
                steps = _steps(p, "", plan=plan)
                marks = plan[5]
                calls = _plan_calls(plan)
            except ValueError:  # (a plan this gtecat does not make the same: the text)
                steps = None
        if steps is None:
            if raw is None:  # (a plan this gtecat no longer takes: the text, and its plan)
                raw = _read_raw(p)
                where = _plan_file(raw)
            p, head, body = _open_text(p, raw)
            raw = None  # (read: the bytes go before the text is made steps)
            keep: list[Any] | None = [] if where is not None else None
            text = [body or ""]
            del body
            steps = _steps(p, text.pop(), keep)  # (the text held by _steps alone: let go once read)
            if keep and keep[0] is not None and where is not None:
                _keep_plan(where, head, keep[0])
                if seen is not None:
                    _keep_ref(p, seen, taken, where)
        del raw
        if calls < 0:
            calls = len(steps) - sum(map(is_, map(itemgetter(0), steps), repeat(None)))
        _check_count(p, head, calls)
        # frozen before the collector runs again: it would walk every object just made
        # (all of them young) at its first collection
        freeze = not process_froze()  # (a process that froze its own: left so)
        if freeze:
            gc.freeze()
    finally:
        if paused:
            gc.enable()
    try:
        with _where(head):
            from .bus_config import check  # (the files as recorded: before anything runs)

            check(head.get("bus_config"), eni, machine)
            return _replay(steps, eni, machine, head.get("cwd"), marks)
    finally:
        if freeze:
            unfreeze()


def _from_here(name: str | None) -> str | None:
    """``name`` made absolute when it is a relative name of a file in the current folder."""
    if name and not os.path.isabs(name) and os.path.isfile(name):
        return os.path.abspath(name)
    return name


#: what a plan's file starts with, before its length and check (:data:`_PLAN_CHECK`)
_PLAN_MAGIC = b"gtecat replay plan 2\n"
#: a plan's length and CRC-32 (little-endian) after its magic.  The check guards against a
#: damaged file (a disk's or another program's fault: a plan is written under another name
#: and renamed, so a replay never reads one half written); it is no seal - whoever can write
#: the cache folder can write a matching digest of any kind beside a plan - so a
#: cryptographic digest (SHA-256, as before) bought nothing over a CRC, which detects every
#: burst of up to 32 bits and all but 2**-32 of other damage, at twice its speed (a 1 ms
#: 12-axis minute's plan: 27 MB)
_PLAN_CHECK = struct.Struct("<QI")
#: the plans kept at most, and their bytes at most (the least recently used go first; the
#: newest stays whatever its size)
PLANS_KEPT = 64
PLAN_BYTES = 256 << 20
#: the notes of which file holds which plan kept at most (:func:`_keep_ref`)
REFS_KEPT = 256


def _plan_file(raw: bytes) -> Path | None:
    """Where the plan of a recording with these bytes is kept: gtecat's cache folder
    (:func:`gtecat._cache.cache_root`), named by the SHA-256 of the bytes and of the
    code that reads them (this module, the interpreter's version), so that a recording
    changed by a single byte, or a gtecat that reads it another way, never finds the plan
    of another; None when ``GTECAT_REPLAY_CACHE=0`` turns plans off."""
    if os.environ.get("GTECAT_REPLAY_CACHE") == "0":
        return None
    from .._cache import cache_root

    h = hashlib.sha256(_code_tag())
    h.update(raw)
    return cache_root() / "replay" / f"{h.hexdigest()[:48]}.plan"


#: how recent a file's last change may be for its plan to be found by its name and times
#: (a change within the clock's tick of the one read would leave the times as they were)
_SETTLED_NS = 1_000_000_000


def _file_key(p: Path) -> tuple[Any, ...] | None:
    """The file ``p`` as it stands: its full name, device, inode, size, modification and
    change times (ns), None when it cannot be stat'ed or plans are off."""
    if os.environ.get("GTECAT_REPLAY_CACHE") == "0":
        return None
    try:
        st = os.stat(p)
        name = os.path.realpath(p)
    except (OSError, ValueError):
        return None
    return (name, st.st_dev, st.st_ino, st.st_size, st.st_mtime_ns, st.st_ctime_ns)


def _ref_file(key: tuple[Any, ...]) -> Path:
    from .._cache import cache_root

    h = hashlib.sha256(_code_tag())
    h.update(repr(key).encode("utf-8", "surrogatepass"))
    return cache_root() / "replay" / "by-file" / f"{h.hexdigest()[:48]}.ref"


def _plan_ref(key: tuple[Any, ...]) -> Path | None:
    """The plan :func:`_keep_ref` noted for a file that still has this key (its name, size
    and times: any write changes the change time), None when there is none."""
    try:
        name = _ref_file(key).read_text("ascii").strip()
    except (OSError, UnicodeDecodeError):
        return None
    if len(name) != 48 or not all(c in "0123456789abcdef" for c in name):
        return None
    from .._cache import cache_root

    return cache_root() / "replay" / f"{name}.plan"


def _keep_ref(p: Path, key: tuple[Any, ...], taken: int, plan: Path) -> None:
    """Note that the file with ``key`` holds the bytes whose plan is ``plan``: when the file
    is still as it was when ``key`` was taken (at ``taken``, before its bytes were read) and
    its last change was :data:`_SETTLED_NS` older than that (any later write then surely
    moves its change time).  Only the most recent :data:`REFS_KEPT` notes stay."""
    if taken - key[5] < _SETTLED_NS or _file_key(p) != key:
        return
    try:
        ref = _ref_file(key)
        ref.parent.mkdir(parents=True, exist_ok=True)
        tmp = ref.with_name(f"{ref.name}.{os.getpid()}.tmp")
        tmp.write_text(plan.stem, "ascii")
        os.replace(tmp, ref)
        refs = []
        for f in ref.parent.glob("*.ref"):
            try:
                refs.append((f.stat().st_mtime_ns, f))
            except OSError:
                continue
        if len(refs) > REFS_KEPT:
            for _, f in sorted(refs, key=itemgetter(0), reverse=True)[REFS_KEPT:]:
                f.unlink(missing_ok=True)
    except OSError:
        pass


@lru_cache(maxsize=1)
def _code_tag() -> bytes:
    """The digest of the code that makes a plan: this module's source, the interpreter."""
    h = hashlib.sha256(f"{sys.implementation.cache_tag} {FORMAT} {_PLAN}".encode())
    try:
        h.update(Path(__file__).read_bytes())
    except OSError:
        h.update(b"?")
    return h.digest()


def _load_plan(where: Path) -> tuple[dict[str, Any], Any] | None:
    """(header, plan) kept in ``where``, None when there is none or it is damaged."""
    try:
        data = where.read_bytes()
    except OSError:
        return None
    kept = _plan_from_bytes(data)
    if kept is not None:
        try:
            os.utime(where)  # (used: the last to go)
        except OSError:
            pass
    return kept


def _plan_from_bytes(data: bytes) -> tuple[dict[str, Any], Any] | None:
    """(header, plan) of a plan's file, None when it is damaged."""
    start = len(_PLAN_MAGIC) + _PLAN_CHECK.size
    if not data.startswith(_PLAN_MAGIC) or len(data) < start:
        return None
    size, crc = _PLAN_CHECK.unpack_from(data, len(_PLAN_MAGIC))
    payload = memoryview(data)[start:]
    if size != len(payload) or zlib.crc32(payload) != crc:
        return None
    try:
        kept = marshal.loads(payload)
    except (EOFError, ValueError, TypeError):
        return None
    if type(kept) is not tuple or len(kept) != 2 or type(kept[0]) is not dict:
        return None
    return kept


def _keep_plan(where: Path, head: dict[str, Any], plan: Any) -> None:
    """Keep a recording's plan in ``where`` (written under another name, then renamed);
    only the :data:`PLANS_KEPT` most recently used stay, :data:`PLAN_BYTES` at most.  A
    folder that takes no file only costs the next replay the reading of the text."""
    try:
        payload = marshal.dumps((head, plan))
    except ValueError:  # (a value marshal does not take: none of JSON's)
        return
    try:
        where.parent.mkdir(parents=True, exist_ok=True)
        tmp = where.with_name(f"{where.name}.{os.getpid()}.tmp")
        check = _PLAN_CHECK.pack(len(payload), zlib.crc32(payload))
        tmp.write_bytes(_PLAN_MAGIC + check + payload)
        os.replace(tmp, where)
        plans = []
        for f in where.parent.glob("*.plan"):
            try:
                st = f.stat()
            except OSError:
                continue
            plans.append((st.st_mtime_ns, st.st_size, f))
        total = 0
        for k, (_, size, f) in enumerate(sorted(plans, key=itemgetter(0), reverse=True)):
            total += size
            if k and (k >= PLANS_KEPT or total > PLAN_BYTES):
                f.unlink(missing_ok=True)
    except OSError:
        pass


def _plan_ahead(path: Path, raw: bytes) -> None:
    """Keep the plan of the recording just written to ``path`` (``raw``: its bytes), so
    that its first replay need not read its text (:func:`replay`)."""
    where = _plan_file(raw)
    if where is None:
        return
    paused = gc.isenabled()
    if paused:
        gc.disable()
    try:
        p, head, body = _open_text(path, raw)
        keep: list[Any] = []
        _steps(p, body or "", keep)
    except (ParameterError, ValueError, TypeError, RecursionError):
        return  # (a replay reads the text and says what is wrong)
    finally:
        if paused:
            gc.enable()
    if keep and keep[0] is not None:
        _keep_plan(where, head, keep[0])


def _check_count(p: Path, head: dict[str, Any], found: int) -> None:
    """The recording holds the calls its header counts: a file cut short at a line's end
    (a copy that stopped, ``head -1000``) is refused, never replayed as a pass."""
    want = head.get("calls")
    if want is None:  # a header that does not count them: nothing to compare
        return
    if type(want) is not int or want < 0:
        raise ParameterError(f"{p}: damaged recording: line 1: calls {want!r} is not a count")
    if found < want:
        raise ParameterError(
            f"{p}: the recording ends early: its header counts {want} calls, the file holds "
            f"{found} (cut short: record it again, or copy the whole file)"
        )
    if found > want:
        raise ParameterError(
            f"{p}: damaged recording: its header counts {want} calls, the file holds {found}"
        )


@dataclass(slots=True)
class _Call:
    """One recorded call made ready to run again: once per distinct entry, or once per
    *form* of entry (:func:`_steps`), the values that differ from one call of the form to the
    next (what its pointers held before the call and after it) given beside it as ``vals``."""

    fn: Any
    name: str
    args: list[Any]  # the arguments; a pooled pointer is its byref, a fresh one None
    sets: list[tuple[Any, int]]  # (pooled object, the value it held at the call: vals[k])
    fresh: list[tuple[int, Any]]  # (index, encoding): an object built anew for every call
    kw: dict[str, Any] | None  # encoded keywords (None: none)
    rc: Any
    #: what the call leaves in its pooled pointers: (the object, vals[k] it must hold, its
    #: argument's index, the recorded type's name); compared by value, the full encoding
    #: only when they differ
    quick: list[tuple[Any, int, int, str]]
    #: what the call leaves in its other pointer arguments: (index or keyword, the recorded
    #: value), compared encoded
    checks: list[tuple[int | str, Any]]
    before: int | None  # "b": the controller time the call began at
    opens: bool  # GT_Open: the replay's own settings
    #: the call in one compiled function (:func:`_compiled`), None: the loop runs it
    run: Any = None
    #: pooled arrays of numbers: (the array's bytes, the values it held at the call: vals[k]
    #: packed as its memory holds them)
    asets: list[tuple[Any, int]] = field(default_factory=list)
    #: what the call leaves in them: (their bytes, vals[k], argument index, element type),
    #: compared as bytes
    aquick: list[tuple[Any, int, int, str]] = field(default_factory=list)
    #: the slots of vals that hold arrays, and how a line's numbers become their bytes
    packs: tuple[tuple[int, Any], ...] = ()
    #: the slot of vals that holds "b" (the time the call began at) where the line's form
    #: takes it as a value (a controller process's calls: each has its own), else None
    before_at: int | None = None


def _prepare(
    e: dict[str, Any], fn: Any, pool: dict[tuple[str, int, str], tuple[Any, Any]]
) -> tuple[_Call, tuple[Any, ...]]:
    """``e`` made ready: (the call, its values).  The values are those of its pointers to
    simple values, in the order of the line: what each held before the call, then what
    the call left in them (``"o"``)."""
    name = e["c"]
    a = e["a"]
    outs = e.get("o") or {}
    args: list[Any] = []
    vals: list[Any] = []
    sets: list[tuple[Any, int]] = []
    fresh: list[tuple[int, Any]] = []
    pooled: list[tuple[int, Any, int, Any]] = []  # (index, object, its slot, its encoding)
    checks: list[tuple[int | str, Any]] = []
    asets: list[tuple[Any, int]] = []
    arrays: list[tuple[int, Any, int, str, Any]] = []
    packs: list[tuple[int, tuple[Any, ...]]] = []
    for i, x in enumerate(a):
        if not isinstance(x, dict):
            args.append(x)
            continue
        ref = x.get("ref")
        if (
            isinstance(ref, dict)
            and "c" in ref
            and not isinstance(ref.get("v"), dict)
            and "off" not in x  # (a pointer into the value: made as recorded, below)
        ):
            # a pointer to a simple value: one object per function and argument, set to the
            # recorded value before each call (an application polls with the same variable:
            # so does the replay, and the GT layer's fast path recognises it)
            obj, p = _pooled(pool, name, i, ref["c"])
            pooled.append((i, obj, len(vals), x))
            sets.append((obj, len(vals)))
            vals.append(ref["v"])
            args.append(p)
            continue
        kind = _kind(x)
        if kind is not None and kind[0] == "arr":
            # (into the array: its values are the array's, the pointer is made once)
            packed = _pack(kind, _held(x if len(kind) == 3 else x["ref"]))
            out = outs.get(str(i))
            out_packed = None
            if _kind(out) == kind:
                out_packed = _pack(kind, _held(out if len(kind) == 3 else out["ref"]))
            if packed is not None and (out is None or out_packed is not None):
                # an array of numbers: one array per function and argument, its memory set
                # to the recorded values before each call and compared with them after it
                obj, mv = _pooled_array(pool, name, i, kind)
                asets.append((mv, len(vals)))
                packs.append((len(vals), kind))
                vals.append(packed)
                arrays.append((i, mv, len(vals) - 1, kind, out_packed))
                args.append(obj if len(kind) == 3 else ctypes.byref(obj, kind[3]))
                continue
        fresh.append((i, x))
        args.append(None)
        if str(i) in outs or _round_trips(x):
            checks.append((i, outs.get(str(i), x)))  # not in "o": left as it was
    slots = {}
    packed_outs = {str(i): (kind, b) for i, _, _, kind, b in arrays if b is not None}
    for k, w in outs.items():
        slots[k] = len(vals)
        if k in packed_outs:
            kind, b = packed_outs[k]
            packs.append((len(vals), kind))
            vals.append(b)
            continue
        r = w.get("ref") if isinstance(w, dict) and len(w) == 1 else None
        vals.append(r.get("v") if isinstance(r, dict) else None)
    before_at = None
    if type(e.get("b")) is int and list(e)[-1] == "b":  # (last on its line: its value's place)
        before_at = len(vals)
        vals.append(e["b"])
    aquick = [(mv, slots.get(str(i), slot), i, kind) for i, mv, slot, kind, _ in arrays]
    quick: list[tuple[Any, int, int, str]] = []
    for i, obj, slot, x in pooled:
        want = outs.get(str(i), x)  # not in "o": the call left the value as it was
        w = want.get("ref") if isinstance(want, dict) and len(want) == 1 else None
        if (
            isinstance(w, dict)
            and len(w) == 2
            and w.get("c") == type(obj).__name__
            and "v" in w
            and not isinstance(w["v"], dict)
        ):
            quick.append((obj, slots.get(str(i), slot), i, w["c"]))
        else:
            checks.append((i, want))
    kw = e.get("k")
    for k, want in outs.items():
        if not k.isdigit():
            checks.append((k, want))
    for k, x in (kw or {}).items():
        if k not in outs and isinstance(x, dict) and _round_trips(x):
            checks.append((k, x))
    call = _Call(
        fn,
        name,
        args,
        sets,
        fresh,
        kw,
        e["r"],
        quick,
        checks,
        e.get("b") if before_at is None else None,
        name in ("GT_Open", "GTN_Open"),
    )
    call.asets, call.aquick = asets, aquick
    call.before_at = before_at
    call.packs = tuple(packs)
    if call.before is None and not fresh and kw is None and not call.opens and not checks:
        call.run = _compiled(call)
    return call, tuple(vals)


_DAMAGED = (TypeError, ValueError, KeyError, AttributeError)


def _compiled(p: _Call) -> Any:
    """``run(vals)``: the call of ``p`` made as the replay loop makes it (the pooled pointers
    set, the function called, its return code and the values it left compared), compiled
    into one function: None when everything matched, ``(rc,)`` when something may differ
    (the loop compares in full and reports), an exception when a value cannot be set."""
    fn, rc0, args = p.fn, p.rc, tuple(p.args)
    if p.before_at is not None:
        pass  # (the time it began at first: the general template below)
    elif (
        not p.sets and not p.quick and not p.asets
    ):  # GTE_Wait(10), GT_Update(mask): no pointer at all

        def run_plain(vals: Any) -> Any:
            rc = fn(*args)
            return None if rc == rc0 else (rc,)

        return run_plain
    elif len(p.sets) == 1 and len(p.quick) == 1 and not p.asets:  # GT_GetSts(axis, &s)
        ((obj, k),) = p.sets
        ((out, k_out, _, _),) = p.quick

        def run_one(vals: Any) -> Any:
            try:
                obj.value = vals[k]
            except _DAMAGED as err:
                return err
            rc = fn(*args)
            return None if rc == rc0 and out.value == vals[k_out] else (rc,)

        return run_one
    env: dict[str, Any] = {"fn": p.fn, "RC": p.rc, "_DAMAGED": _DAMAGED}
    lines = ["def run(vals):"]
    if p.before_at is not None:  # time passed between the calls: it passes here too (_call)
        env["CTL"] = _controller
        lines += [
            "    ctl = CTL()",
            "    if ctl is not None:",
            "        clock = ctl.clock",
            f"        gap = vals[{p.before_at}] - clock.now_ns - clock._pending_ns",
            "        if gap > 0:",
            "            clock.advance_ns(gap)",
        ]
    if p.sets or p.asets:
        lines.append("    try:")
        for j, (obj, k) in enumerate(p.sets):
            env[f"S{j}"] = obj
            lines.append(f"        S{j}.value = vals[{k}]")
        for j, (mv, k) in enumerate(p.asets):  # an array's bytes (of the recorded length)
            env[f"M{j}"] = mv
            lines.append(f"        M{j}[:] = vals[{k}]")
        lines += ["    except _DAMAGED as err:", "        return err"]
    for j, a in enumerate(p.args):
        env[f"A{j}"] = a
    lines.append(f"    rc = fn({', '.join(f'A{j}' for j in range(len(p.args)))})")
    same = [
        "rc != RC",
        *(f"Q{j}.value != vals[{k}]" for j, (_, k, _, _) in enumerate(p.quick)),
        *(f"N{j}.tobytes() != vals[{k}]" for j, (_, k, _, _) in enumerate(p.aquick)),
    ]
    for j, (mv, _, _, _) in enumerate(p.aquick):
        env[f"N{j}"] = mv
    for j, (obj, _, _, _) in enumerate(p.quick):
        env[f"Q{j}"] = obj
    lines += [f"    if {' or '.join(same)}:", "        return (rc,)", "    return None"]
    exec(_compiled_code("\n".join(lines), f"<replay {p.name}>"), env)
    return env["run"]


def _held(x: dict[str, Any]) -> Any:
    """A recorded array's values: its numbers, or a byte array's hex text."""
    return x["v"] if "v" in x else x["hex"]


@lru_cache(maxsize=256)
def _struct(kind: tuple[Any, ...]) -> struct.Struct:
    """How an array of numbers of ``kind`` (``("arr", c, n)``) lies in memory."""
    return struct.Struct(f"{kind[2]}{_ARRAY_CODE[kind[1]]}")


def _pack(kind: tuple[Any, ...], values: list[Any] | str) -> bytes | None:
    """The bytes of an array of ``kind`` holding ``values`` exactly, None when the type
    cannot hold them (a number out of its range, a fraction in an integer array, a double
    that a float would round: such an array is rebuilt and compared the general way).  A
    byte array's values are its recorded hex text (:func:`encode`)."""
    st = _struct(kind)
    if type(values) is str:
        try:
            b = bytes.fromhex(values)
        except ValueError:
            return None
        return b if len(b) == st.size and len(values) == 2 * st.size else None
    try:
        b = st.pack(*values)
    except struct.error:
        return None
    if _ARRAY_CODE[kind[1]] in "fd" and st.unpack(b) != tuple(values):
        return None
    return b


def _pooled_array(
    pool: dict[Any, Any], name: str, i: int, kind: tuple[Any, ...]
) -> tuple[Any, memoryview]:
    """The array (and a view of its bytes) an array argument of ``kind`` uses in replay."""
    key = (name, i, kind)
    hit = pool.get(key)
    if hit is None:
        obj = (_SIMPLE[kind[1]] * kind[2])()
        hit = pool[key] = (obj, memoryview(obj).cast("B"))
    return hit


def _pooled(
    pool: dict[tuple[str, int, str], tuple[Any, Any]], name: str, i: int, c: str
) -> tuple[Any, Any]:
    """The object (and its byref) a pointer argument of ``c`` uses in replay."""
    key = (name, i, c)
    hit = pool.get(key)
    if hit is None:
        try:
            obj = _simple(c)()
        except ValueError as err:
            raise ValueError(f"argument {i + 1}: {err}") from None
        hit = pool[key] = (obj, ctypes.byref(obj))
    return hit


def _round_trips(x: Any) -> bool:
    """A recorded argument that the call may write into and that comes back as recorded:
    the value it still holds after the call is then compared too."""
    try:
        v = decode(x)
    except ParameterError:
        return False
    return _mutable(v) and encode(v) == x


#: the value of a pointer to a simple value in a recorded call: its JSON number
_NUMBER = re.compile(r"-?(?:0|[1-9]\d*)(\.\d+)?([eE][+-]?\d+)?")
_V = '"v":'


#: struct's code of each simple type an array of numbers may hold (the ctypes type's own)
_ARRAY_CODE = {
    name: cls._type_  # type: ignore[attr-defined]
    for cls, name in _SIMPLE_NAME.items()
    if cls._type_ in "bBhHiIlLqQfd?"  # type: ignore[attr-defined]
}


def _kind(x: Any) -> tuple[Any, ...] | None:
    """What a recorded pointer argument is when one pooled object serves it: ``("ref", c)``
    for a pointer to a simple value, ``("arr", c, n)`` for an array of numbers,
    ``("arr", c, n, off)`` for a pointer ``off`` bytes into one (a C program's ``&arr[8]``:
    ``byref(arr, off)``, off on an element inside the array; 0: ``byref(arr)``, as a
    controller process records a C client's array); else None."""
    if type(x) is not dict or not 1 <= len(x) <= 3:
        return None
    if len(x) == 2:
        off = x.get("off")
        kind = _kind(x.get("ref"))
        if type(off) is not int or kind is None or kind[0] != "arr" or len(kind) != 3:
            return None
        size = _struct(kind).size
        if not 0 < off < size or off % (size // kind[2]):
            return None
        return (*kind, off)
    if len(x) == 1:
        ref = x.get("ref")
        if (
            type(ref) is dict
            and len(ref) == 2
            and type(ref.get("c")) is str
            and _SIMPLE_NAME.get(_SIMPLE.get(ref["c"])) == ref["c"]  # type: ignore[arg-type]
            and type(ref.get("v")) in (int, float)
        ):
            return ("ref", ref["c"])
        kind = _kind(ref) if type(ref) is dict and "arr" in ref else None
        if kind is not None and len(kind) == 3:
            return (*kind, 0)  # (a pointer to the array's start: a C client's double *)
        return None
    c, n, v = x.get("arr"), x.get("n"), x.get("v")
    if (
        type(c) is str
        and c in _ARRAY_CODE
        and type(n) is int
        and type(v) is list
        and len(v) == n
        and all(type(e) is int or type(e) is float for e in v)
    ):
        return ("arr", c, n)
    h = x.get("hex")
    if (
        type(h) is str
        and c in _HEX_ARRAYS
        and type(n) is int
        and 0 < n == len(h) // 2
        and len(h) % 2 == 0
        and _HEX.fullmatch(h)
    ):
        return ("arr", c, n)  # (a byte array: its hex text is its value)
    return None


#: the byte arrays :func:`encode` keeps as hex text (GT_GetEcatRawData's buffer), which a
#: form's pooled array takes as it takes an array of numbers
_HEX_ARRAYS = frozenset({"c_ubyte", "c_byte"})
_HEX = re.compile(r"[0-9a-f]*")


def _form(e: dict[str, Any]) -> int:
    """How many values a call of this form has (``"v":`` numbers and arrays of numbers, a
    byte array's ``"hex":`` text, the ``"b":`` time, in the order of the line), or -1 when
    the entry is not of a simple form: plain arguments,
    pointers to simple values (``{"ref": {"c": "c_long", "v": 5}}``) and arrays of numbers
    (``{"arr": "c_long", "n": 12, "v": [...]}``), the values those hold after the call in
    ``"o"``, no keywords.  Such an entry's values all come from :func:`_prepare`'s pooled
    objects, in the same order, so one prepared call serves every line of the form."""
    if "k" in e or type(e.get("a")) is not list or type(e.get("r")) is not int:
        return -1
    keys = list(e)
    if "o" in e and keys.index("o") < keys.index("a"):  # the values' order is the line's
        return -1
    a = e["a"]
    n = 0
    for x in a:
        if type(x) is dict:
            if _kind(x) is None:
                return -1
            n += 1
    outs = e.get("o", {})
    if type(outs) is not dict:
        return -1
    for k, w in outs.items():
        if not k.isdigit() or int(k) >= len(a) or type(a[int(k)]) is not dict:
            return -1
        if _kind(w) is None or _kind(w) != _kind(a[int(k)]):
            return -1
        n += 1
    if "b" in e:  # the time the call began at: a value, last on the line
        if type(e["b"]) is not int or keys[-1] != "b":
            return -1
        n += 1
    return n


def _steps(
    p: Path, lines: list[str] | str, keep: list[Any] | None = None, plan: Any = None
) -> list[tuple[Any, Any]]:
    """The recording's entries made ready to run: ``(call, its values)`` for a call,
    ``(None, entry)`` for a checkpoint or a fault, ``(_Stop, why)`` where a call cannot be
    made again (reported when the replay gets there).

    Calls that differ only in their time share one step: each distinct line (without the
    time) is made ready once, and the work done for every line is a few operations on the
    whole list.  Calls that differ only in the numbers their pointers held (a polling loop's
    clock and positions) share one prepared call: the line with those numbers taken out is
    the form's key, the numbers are read from the line (:data:`_NUMBER`, as JSON reads
    them) and the first line of each form is parsed and checked whole (:func:`_form`); a
    line of any other form is parsed whole.

    ``keep``: a list the steps' plan is appended to (:func:`_plan_of`: what a later replay
    of the same text makes its steps from without reading the text again; None appended
    when the recording has a step that stops the replay).  ``plan``: such a plan, made
    ready instead of ``lines`` (ValueError: one this gtecat cannot take)."""
    from .. import gt

    pool: dict[tuple[str, int, str], tuple[Any, Any]] = {}
    forms: dict[str, Any] = {}  # a line without its time and values -> its call (or None)
    number = _NUMBER.match
    # an array's bytes, one object for equal ones: what a call left in an array is what the
    # next call of its form finds there (a polling loop), so half of a recording's arrays are
    # equal to another; shared, the plan holds each once (marshal writes the others as
    # references: half the bytes to read, check and load)
    same_bytes: dict[bytes, bytes] = {}
    shared = same_bytes.setdefault
    # an array's values packed once per kind (the lines' equal arrays are one list:
    # :func:`_split`): id -> (the values, kept so the id stays theirs, the kind, the bytes)
    packs: dict[int, tuple[Any, Any, bytes | None]] = {}

    def pack(kind: tuple[Any, ...], v: Any) -> bytes | None:
        hit = packs.get(id(v))
        if hit is not None and hit[0] is v and hit[1] == kind:
            return hit[2]
        b = _pack(kind, v)
        if b is not None:
            b = shared(b, b)
        packs[id(v)] = (v, kind, b)
        return b

    def parse(key: str) -> Any:
        try:
            e = json.loads("{" + key[1:] if key[:1] == "," else key)
        except ValueError as err:  # JSONDecodeError, an integer too long to read
            raise ParameterError(
                f"{p}: damaged recording: line {keys.index(key) + 2}: {err}"
            ) from None
        except RecursionError:
            raise ParameterError(
                f"{p}: damaged recording: line {keys.index(key) + 2}: {_TOO_DEEP}"
            ) from None
        if type(e) is not dict:
            raise ParameterError(
                f"{p}: damaged recording: line {keys.index(key) + 2}: not an entry (a JSON object)"
            )
        return e

    def prepare(e: dict[str, Any], key: str) -> tuple[Any, Any]:
        name = e.get("c")
        fn = getattr(gt, name, None) if type(name) is str else None
        if fn is None:
            return _Stop, ("missing", name)
        try:
            _check_arrays(e.get("a"))
            _check_arrays(e.get("k"))
            _check_arrays(e.get("o"))
            return _prepare(e, fn, pool)
        except (KeyError, TypeError, ValueError, AttributeError, RecursionError) as err:
            why = _TOO_DEEP if isinstance(err, RecursionError) else f"{type(err).__name__}: {err}"
            return _Stop, (
                "damaged",
                f"({name}, line {keys.index(key) + 2}) cannot be made again: {why}",
            )

    def numbers(key: str) -> tuple[str, list[Any]] | None:
        """(the form's key, the numbers) of a call's line, one number at a time."""
        parts = key.split(_V)
        vals: list[Any] = []
        for k in range(1, len(parts)):
            part = parts[k]
            m = number(part)
            if m is None:
                return None
            lit = m.group()
            try:
                vals.append(float(lit) if m.lastindex else int(lit))
            except ValueError:  # an integer too long to read: as JSON reads it, below
                return None
            parts[k] = part[m.end() :]
        return _V.join(parts), vals

    def step(key: str, split: tuple[str, list[Any]] | None) -> tuple[Any, Any]:
        if split is not None and split[1]:
            form_key, vals = split
            form = forms.get(form_key, _NO)
            if form is _NO:  # the first line of this form
                form = forms[form_key] = None
                e = parse(key)
                if _form(e) == len(vals):
                    call = prepare(e, key)[0]
                    if call is not _Stop and not call.checks and not call.fresh:
                        form = forms[form_key] = call
                        form_lines[id(call)] = (call, key, len(vals))
            if form is not None:
                if not form.packs:
                    return form, tuple(vals)
                vals = list(vals)
                for k, kind in form.packs:  # an array's numbers: its bytes
                    v = vals[k]
                    b = pack(kind, v) if type(v) is list or type(v) is str else None
                    if b is None:  # (a length or number the array cannot hold)
                        break
                    vals[k] = b
                else:
                    return form, tuple(vals)
        e = parse(key)
        return (None, e) if "c" not in e else prepare(e, key)

    form_lines: dict[int, tuple[_Call, str, int]] = {}  # a form's call: (it, its line, values)
    if plan is not None:
        keys: list[str] = []  # (a plan's line that fails names no line: ValueError below)
        try:
            return _from_plan(plan, parse, prepare)
        except (ParameterError, LookupError, TypeError, AttributeError) as err:
            raise ValueError(f"a plan this gtecat cannot take: {err}") from None
    # a call's line without its time (from the comma after it), any other line whole; of a
    # recording's text, every line's at once (:data:`_KEY`)
    if type(lines) is str:
        keys = _KEY.findall(lines)
    else:
        keys = [x[x.find(",", 5) :] if x.startswith('{"t":') else x for x in lines]
    del lines  # (each line is its key now: the text goes where the caller let it go)
    made = dict.fromkeys(keys)
    made.pop("", None)  # the empty line after the last
    calls = [key for key in made if key[:5] == ',"c":']  # as Recorder writes a call
    split = _split(calls)
    if split is None:  # a value JSON would refuse: each line read on its own
        for key, one in zip(calls, map(numbers, calls), strict=True):
            made[key] = step(key, one)
    else:
        form_keys, values = split
        # the first line of each form made ready (its call, or None: not a form) ...
        first = dict(zip(reversed(form_keys), range(len(form_keys) - 1, -1, -1), strict=False))
        first.pop(None, None)
        for fk, i in first.items():
            made[calls[i]] = step(calls[i], (fk, values[i]))
        # ... then every line of a form without arrays at once (the common polling call),
        plain = {fk for fk, form in forms.items() if form is not None and not form.packs}
        sel = list(map(plain.__contains__, form_keys))
        made.update(
            zip(
                compress(calls, sel),
                zip(
                    map(forms.__getitem__, compress(form_keys, sel)),
                    compress(values, sel),
                    strict=False,
                ),
                strict=False,
            )
        )
        # ... and the others one by one (arrays packed, lines of no form)
        for key, fk, vals in compress(zip(calls, form_keys, values, strict=False), map(not_, sel)):
            if made[key] is None:
                made[key] = step(key, None if fk is None else (fk, vals))
    for key in made:
        if made[key] is None and key.strip():
            made[key] = step(key, None)
    steps = [s for s in map(made.get, keys) if s is not None]
    if keep is not None:
        keep.append(_plan_of(made, keys, form_lines))
    return steps


#: the layout of a plan (:func:`_plan_of`); a plan of another is made again
_PLAN = 4
#: a unit of a plan that is no form: an entry (a checkpoint, a fault), a call made whole;
#: form ``f`` is ``f + _FORMS``
_ENTRY, _WHOLE, _FORMS = 0, 1, 2


def _plan_of(
    made: dict[str, Any], keys: list[str], form_lines: dict[int, tuple[_Call, str, int]]
) -> tuple[Any, ...] | None:
    """What :func:`_steps` made of a recording's text, as plain data a later replay makes the
    same steps from (:func:`_from_plan`) without reading the text: the forms (their first
    line, how many values), per distinct line (a *unit*) its form's number and values, or
    the entry (:data:`_ENTRY`), or the line of a call made whole (:data:`_WHOLE`), and per
    step its unit's number.  None when a step stops the replay (the text is read again, to
    report it as it does)."""
    number: dict[int, int] = {id(None): _ENTRY}  # (each call's unit kind, by its identity)
    forms = []
    for call, key, n in form_lines.values():
        number[id(call)] = len(forms) + _FORMS
        forms.append((key, n))
    # (the work per unit done by the interpreter's own loops: a long recording has ~300,000)
    made_steps = list(made.values())
    present = list(map(is_not, made_steps, repeat(None)))
    ukeys = list(compress(made, present))
    usteps = list(compress(made_steps, present))
    del made_steps, present
    ucalls = list(map(itemgetter(0), usteps))
    if any(map(is_, ucalls, repeat(_Stop))):
        return None
    kinds = array("I", map(number.get, map(id, ucalls), repeat(_WHOLE)))
    values: list[Any] = list(map(itemgetter(1), usteps))
    for i in compress(range(len(kinds)), map(_WHOLE.__eq__, kinds)):
        values[i] = ukeys[i]  # (a call made whole: its line)
    unit = dict(zip(ukeys, range(len(ukeys)), strict=True))
    order = array("I", map(unit.__getitem__, filter(unit.__contains__, keys)))
    # the steps :func:`_check_files` looks at (opens, bring-ups): found here once
    distinct = dict(zip(map(id, ucalls), ucalls, strict=True))
    asked_ids = {i for i, c in distinct.items() if _asked(c)}
    asked = list(compress(range(len(ucalls)), map(asked_ids.__contains__, map(id, ucalls))))
    marks = []
    if asked:
        at = np.isin(np.frombuffer(order, np.uintc), np.array(asked, np.uintc))
        marks = np.flatnonzero(at).tolist()
    return (_PLAN, forms, kinds.tobytes(), values, order.tobytes(), marks)


def _from_plan(plan: Any, parse: Any, prepare: Any) -> list[tuple[Any, Any]]:
    """The steps of a plan (:func:`_plan_of`), each form's and each whole call's line parsed
    and made ready as :func:`_steps` makes them (``parse``, ``prepare``: its own); ValueError
    (or LookupError, TypeError) for a plan that is not one, or one whose lines do not make
    the steps they made (another gtecat's functions)."""
    version, forms, kinds_b, values, order_b, _ = plan
    if version != _PLAN or type(values) is not list:
        raise ValueError(f"plan layout {version!r}")
    calls: list[Any] = []
    for key, n in forms:
        e = parse(key)
        if _form(e) != n:
            raise ValueError(f"a form of {n} values is not one: {key[:60]}")
        call = prepare(e, key)[0]
        if call is _Stop or call.checks or call.fresh:
            raise ValueError(f"a form is not made the same: {key[:60]}")
        calls.append(call)
    # (the unsigned ints of array("I") that _plan_of wrote, read by numpy: the loops over the
    # ~100,000 units and ~200,000 steps of a long recording in its compiled code)
    kinds = np.frombuffer(kinds_b, np.uintc)
    order = np.frombuffer(order_b, np.uintc)
    if len(kinds) != len(values):
        raise ValueError("units of no form")
    # (a number past the end: IndexError, as the steps of no unit below)
    calls[:0] = (None, _Stop)  # (_ENTRY: no call, _WHOLE: made below)
    units = list(zip(map(calls.__getitem__, kinds.tolist()), values, strict=True))
    for i in np.flatnonzero(kinds == _WHOLE).tolist():
        key = values[i]
        if type(key) is not str:
            raise ValueError("a whole call's line is no text")
        e = parse(key)
        one = (None, e) if "c" not in e else prepare(e, key)
        if one[0] is _Stop or one[0] is None:
            raise ValueError(f"a call is not made the same: {key[:60]}")
        units[i] = one
    return np.fromiter(units, object, len(units))[order].tolist()


def _plan_calls(plan: Any) -> int:
    """How many of a plan's steps are calls (not a checkpoint or a fault: :data:`_ENTRY`)."""
    kinds = np.frombuffer(plan[2], np.uintc)
    order = np.frombuffer(plan[4], np.uintc)
    return len(order) - int(np.count_nonzero(kinds[order] == _ENTRY))


#: each line of a recording's text as :func:`_steps` keys it: a line that starts ``{"t":``
#: from the first comma after that (``line[line.find(",", 5):]``: with no comma there, its
#: last character), any other line whole; one pass of the regular-expression engine over
#: the text instead of splitting it into lines and cutting each
_KEY = re.compile(r'^(?:\{"t":[^,\n]*(?=,)|(?=\{"t":[^,\n]*$)[^\n]*?(?=[^\n]$))?(.*)$', re.M)

_NUMBER_START = frozenset("-0123456789")
_NUMBER_TYPES = frozenset({int, float})
_VALUE_TYPES = frozenset({int, float, list, str})


#: a value of a call's line that a form takes out: a JSON number, an array of numbers
#: (``"v":[1,2.5]``), a byte array's hex text (``"hex":"0f00"``), or the time a call began
#: at, the line's last (``,"b":123}``); the group is the value's text, read by one JSON
#: parse (a literal quote first: the scan of a long text stays fast)
_VALUE = re.compile(
    r'"(?:v":|hex":(?=")|(?<=,")b":(?=-?[0-9]+}$))'
    r'(\[[-0-9.eE+,]*\]|-?[0-9][-0-9.eE+]*|(?<="hex":)"[0-9a-f]*")',
    re.M,
)
#: the mark of a value in its form's key, by the value's first character
_MARK = {
    "[": "\x02\x01",
    '"': "\x03\x01",
    "-": "\x01",
    **dict.fromkeys("0123456789", "\x01"),
}


def _numbers(calls: list[str]) -> list[tuple[str, tuple[Any, ...]] | None] | None:
    """(the form's key, the values) of each call's line (:func:`_split`), None for a line
    of no form; None for all when a value is not plain JSON."""
    split = _split(calls)
    if split is None:
        return None
    return [None if k is None else (k, v) for k, v in zip(*split, strict=True)]


def _split(calls: list[str]) -> tuple[list[str | None], list[tuple[Any, ...]]] | None:
    """(the form's key of each call's line, its values): its numbers and arrays of numbers
    (``"v":``), all the lines' values read in one JSON parse, the keys made by one pass over
    the lines' text, the work per line done by the interpreter's own loops; the key is None
    for a line with another ``"v":`` (a structure, a value JSON keeps as text: the line is
    read whole); None for all when a value is not plain JSON (each line is then read on its
    own, where the damaged one is reported)."""
    if not calls:
        return [], []
    text = "\n".join(calls)
    if "\x01" in text or "\x02" in text or "\x03" in text:  # (never raw in JSON text)
        return None
    parts = _VALUE.split(text)  # the text between the values, each value's own text
    lits = parts[1::2]
    # each distinct text read once, equal texts one value (a polling loop's array before a
    # call is the text the call before left in it: about half a recording's arrays)
    distinct = list(dict.fromkeys(lits))
    try:
        read = json.loads("[" + ",".join(distinct) + "]")
    except ValueError:
        return None
    if len(read) != len(distinct):
        return None
    values = tuple(map(dict(zip(distinct, read, strict=True)).__getitem__, lits))
    kinds = set(map(type, read))
    if not kinds <= _VALUE_TYPES:
        return None
    if list in kinds:  # arrays: of numbers only
        arrays = [v for v in read if type(v) is list]
        if not set(map(type, chain.from_iterable(arrays))) <= _NUMBER_TYPES:
            return None
    # the keys: each value replaced by a mark of its kind (an array's \x02\x01, a byte
    # array's hex \x03\x01, a number's \x01: the values of a line are its \x01s; control
    # characters never stand raw in JSON)
    marks = list(map(_MARK.__getitem__, map(itemgetter(0), lits)))
    marks.append("")
    keys: list[Any] = "".join(chain.from_iterable(zip(parts[0::2], marks, strict=True))).split("\n")
    ends = list(accumulate(map(str.count, keys, repeat("\x01"))))
    vals = list(map(values.__getitem__, map(slice, [0, *ends[:-1]], ends)))
    for i in compress(range(len(keys)), map(contains, keys, repeat(_V))):
        keys[i] = None  # a value of another kind
    return keys, vals


_NO: Any = object()


class _Stop:
    """A step that ends the replay: a divergence (a function gtecat lacks) or an error."""


def _replay(
    steps: list[tuple[Any, Any]],
    eni: str | None,
    machine: str | None,
    cwd: Any = None,
    marks: Any = None,
) -> tuple[int, Divergence | None]:
    """Make every step's call again, in order, and compare it: (calls made, the first
    divergence or None).

    Every call is made, one at a time, as the application made it: those of the simple
    forms (their compiled runs) by the C entries' loop where it is available
    (:func:`_replay_in_c`: no Python frame per call), the others here.  Answering runs of
    pure reads without making them (one snapshot of the readers' values per cycle, taken
    through the readers' own array forms with the call latency set to 0, the recorded
    values compared with it, the cycles made by the calls whose latency makes them due)
    was built and measured on dense 12-axis recordings (1 ms polls of every axis): exact,
    but slower - a one-axis read through its C entry costs about what a Python test of
    it against a snapshot costs, and a snapshot costs what the array reads cost, five of
    them each cycle for twenty calls.  Even with every pure read skipped outright (no
    value, no comparison) the replay was only 10-30 % faster: its time is the cycles the
    calls' latency makes due, the calls that change things, and the start (the
    performance notes, "Batching a replay's pure reads").  Nor does making the compiled
    calls from the interpreter's own loops (``map``/``filter`` over the runs between the
    steps made alone) pay: a call from C into each compiled run costs what the loop's
    bytecodes cost (the same CPU, 1.7 % more instructions)."""
    from .. import faults, gt
    from ..gt.centry import replay_loop

    eni = str(Path(eni).resolve()) if eni else None
    machine = str(Path(machine).resolve()) if machine else None
    _check_files(steps, eni, machine, cwd, marks)
    gt.GT_Close()
    loop = replay_loop() if C_LOOP else None
    try:
        if loop is None:
            n = 0
            for p, vals in steps:
                run = p.run if type(p) is _Call else None
                if run is not None:  # (the common call, compiled: _step's first way, inline)
                    n += 1
                    r = run(vals)
                    if r is None:
                        continue
                    div = _ran(p, vals, n, r)
                else:
                    n, div = _step(p, vals, n, eni, machine, faults)
                if div is not None:
                    return n, div
            return n, None
        return _replay_in_c(loop, steps, eni, machine, faults)
    finally:
        gt.GT_Close()


#: a replay makes the calls of the simple forms in the C entries' loop where it is available
#: (:func:`gtecat.gt.centry.replay_loop`); False: every call from Python (tests compare both)
C_LOOP = True


def _replay_in_c(
    loop: Any, steps: list[tuple[Any, Any]], eni: str | None, machine: str | None, faults: Any
) -> tuple[int, Divergence | None]:
    """:func:`_replay`'s loop with the C entries' loop making the calls it was taught (each
    compiled form's call, the first time it stops there: :func:`_teach`); every other step,
    and a call whose code or left value may differ, here as :func:`_step` makes it."""
    run = loop.run
    whole = tuple(steps)
    total = len(whole)
    n = i = 0
    while i < total:
        r = run(whole, i)
        if type(r) is int:
            j, made = r, None
        else:
            j, made = r[0], r
        n += j - i  # (each step the loop made is a call that matched)
        if j >= total:
            break
        p, vals = whole[j]
        if made is not None:  # (made: compared in full)
            n += 1
            div = _compared(p, vals, n, p.args, {}, made[1])
        elif p is not None and p is not _Stop and not loop.knows(p) and _teach(loop, p):
            i = j  # (taught: the loop makes it from here)
            continue
        else:
            n, div = _step(p, vals, n, eni, machine, faults)
        if div is not None:
            return n, div
        i = j + 1
    return n, None


def _teach(loop: Any, p: _Call) -> bool:
    """Tell the C loop how to make ``p``'s call as its compiled run makes it (the values its
    pooled objects are set to and left with), or to leave it to Python (no compiled run, a
    time it began at, an object the loop does not take); True where the loop makes it."""
    if p.run is None or p.before_at is not None:
        return loop.teach(p)  # type: ignore[no-any-return]
    return loop.teach(  # type: ignore[no-any-return]
        p,
        p.fn,
        tuple(p.args),
        p.rc,
        [*p.sets, *p.asets],
        [(obj, k) for obj, k, _, _ in p.quick] + [(mv, k) for mv, k, _, _ in p.aquick],
    )


def _step(
    p: Any, vals: Any, n: int, eni: str | None, machine: str | None, faults: Any
) -> tuple[int, Divergence | None]:
    """One step of the replay (a call made and compared, a checkpoint compared, a fault
    injected or cleared): (calls made so far, the divergence or None)."""
    if p is None:
        return n, _other(vals, n, faults)
    n += 1
    if p is _Stop:
        what, text = vals
        if what == "missing":
            return n, Divergence(n, text, "function", "present", "missing")
        raise ParameterError(f"damaged recording: call {n} {text}")
    run = p.run
    if run is not None:  # the common call, compiled: compared in full only if it may differ
        r = run(vals)
        return n, None if r is None else _ran(p, vals, n, r)
    args, kw, rc = _call(p, vals, n, eni, machine)
    return n, _compared(p, vals, n, args, kw, rc)


def _ran(p: _Call, vals: Any, n: int, r: Any) -> Divergence | None:
    """Call ``n`` after its compiled run said it may differ (``(rc,)``) or that an argument
    could not be set (the exception): compared in full, or the damage reported."""
    if type(r) is not tuple:
        raise ParameterError(
            f"damaged recording: call {n} ({p.name}): an argument cannot be made "
            f"again: {type(r).__name__}: {r}"
        )
    return _compared(p, vals, n, p.args, {}, r[0])


def _compared(
    p: _Call, vals: Any, n: int, args: Any, kw: dict[str, Any], rc: Any
) -> Divergence | None:
    """Call ``n`` compared in full: its code, the values it left in its pointers."""
    if rc != p.rc and (type(rc) is int or encode(rc) != p.rc):
        return Divergence(n, p.name, "return code", p.rc, rc)
    for obj, k, i, c in p.quick:
        if obj.value != vals[k]:
            want = {"ref": {"c": c, "v": vals[k]}}
            got = encode(args[i])
            if got != want:
                return Divergence(n, p.name, f"argument {i + 1}", want, got)
    for mv, k, i, kind in p.aquick:
        if mv.tobytes() != vals[k]:
            return _array_divergence(n, p.name, i, kind, vals[k], mv.tobytes())
    for where, want in p.checks:
        got = encode(args[where] if type(where) is int else kw.get(where))
        if got != want:
            what = f"argument {where + 1}" if type(where) is int else where
            return _first_element(Divergence(n, p.name, what, want, got))
    return None


#: the calls that bring a bus up from the files an open named
_BRING_UP = frozenset({"GT_InitEcatComm", "GTN_InitEcatComm"})


def _asked(p: Any) -> bool:
    """A step :func:`_check_files` looks at: an open, a bring-up."""
    return p is not None and p is not _Stop and (p.opens or p.name in _BRING_UP)


def _check_files(
    steps: list[tuple[Any, Any]],
    eni: str | None,
    machine: str | None,
    cwd: Any = None,
    marks: Any = None,
) -> None:
    """Refuse, before anything runs, a replay whose session brought a bus up from an ENI file
    or a machine description that is no longer where the recording found it (the folder it
    ran in, or the file itself, moved or deleted): which file, and how to give it instead.
    The files of an open whose bring-up failed in the recording too are not asked for.
    ``marks``: where the opens and bring-ups are among the steps (a plan's), else found
    here."""
    opened: list[tuple[str, str, str]] = []  # (what, the file as named, the option)
    picked = None
    if type(marks) is list:
        try:
            picked = [steps[i][0] for i in marks]
        except (IndexError, TypeError):
            picked = None
        if picked is not None and not all(map(_asked, picked)):
            picked = None
    if picked is None:
        # the opens and bring-ups only, picked from the distinct calls (a few among many)
        calls = list(map(itemgetter(0), steps))
        distinct = dict(zip(map(id, calls), calls, strict=True))
        asked = {i for i, p in distinct.items() if _asked(p)}
        picked = list(compress(calls, map(asked.__contains__, map(id, calls))))
    for p in picked:
        if p.opens:
            kw = p.kw or {}
            opened = []
            if not eni:
                name = kw.get("eni", os.environ.get("GTECAT_ENI"))
                if type(name) is str and name:
                    opened.append(("ENI file", name, "--eni FILE"))
            if not machine:
                name = kw.get("machine", os.environ.get("GTECAT_MACHINE"))
                if type(name) is str and name:
                    opened.append(("machine description", name, "--machine FILE"))
        elif p.rc == 0 and opened:
            for what, name, option in opened:
                if not Path(name).exists():
                    where = Path(name).resolve()
                    if not Path(name).is_absolute() and type(cwd) is str and cwd:
                        where = Path(cwd) / name  # (its folder may be gone too)
                    raise ParameterError(
                        f"the {what} the recorded session used is missing: {where} (put it "
                        f"back, or give it with {option})"
                    )
            opened = []


def _array_divergence(
    n: int, name: str, i: int, kind: tuple[Any, ...], want: bytes, got: bytes
) -> Divergence:
    """The first element where an array a call left differs from the recorded one."""
    size = _struct(kind).size // kind[2]
    one = struct.Struct(_ARRAY_CODE[kind[1]])
    for j in range(kind[2]):
        w, g = want[j * size : (j + 1) * size], got[j * size : (j + 1) * size]
        if w != g:
            return Divergence(
                n, name, f"argument {i + 1} element [{j}]", one.unpack(w)[0], one.unpack(g)[0]
            )
    return Divergence(n, name, f"argument {i + 1}", want.hex(), got.hex())  # (not reached)


def _call(
    p: _Call, vals: Any, n: int, eni: str | None, machine: str | None
) -> tuple[Any, dict[str, Any], Any]:
    """Call ``n`` made as recorded (the general way): (its arguments, keywords, code)."""
    before = p.before if p.before_at is None else vals[p.before_at]
    if before is not None:  # time passed between the calls: let it pass here too
        ctl = _controller()
        if ctl is not None:
            gap = before - ctl.clock.now_ns - ctl.clock._pending_ns
            if gap > 0:
                ctl.clock.advance_ns(gap)
    args = p.args
    try:
        for obj, k in p.sets:
            obj.value = vals[k]
        for mv, k in p.asets:
            mv[:] = vals[k]
        if p.fresh:
            args = list(args)
            for i, x in p.fresh:
                args[i] = decode(x)
    except _DAMAGED as err:
        raise ParameterError(
            f"damaged recording: call {n} ({p.name}): an argument cannot be made "
            f"again: {type(err).__name__}: {err}"
        ) from None
    if p.kw is None and not p.opens:
        return args, {}, p.fn(*args)
    try:
        kw = {k: decode(v) for k, v in (p.kw or {}).items()}
    except _DAMAGED as err:
        raise ParameterError(
            f"damaged recording: call {n} ({p.name}): a keyword cannot be made again: "
            f"{type(err).__name__}: {err}"
        ) from None
    if p.opens:
        if eni:
            kw["eni"] = str(eni)
        if machine:
            kw["machine"] = str(machine)
        if kw.get("clock") == "realtime":
            kw["clock"] = "auto"
        if kw.get("backend") == "pysoem":
            kw["backend"] = "emulated"
        kw["log"] = ""  # the session's master log is not written again
    return args, kw, p.fn(*args, **kw)


def _other(e: dict[str, Any], n: int, faults: Any) -> Divergence | None:
    """A checkpoint (compared) or a fault (injected or cleared again)."""
    if "cp" in e:
        ctl = _controller()
        got = checkpoint(ctl) if ctl is not None else None
        if got != e:
            return Divergence(n, "(bus)", f"bus state at {e['cp'] / 1e6:g} ms", e, got)
    elif "f" in e:
        ctl = _controller()
        if ctl is None:
            return None
        t = e.get("t")
        if type(t) is int and t > ctl.clock.now_ns:
            # armed (or cleared) while a call ran, at a cycle of it: at that cycle again
            _Later.add(ctl, t, lambda e=e, ctl=ctl: _fault(e, ctl, faults))
        else:  # between two calls: here, with its own trigger (none: at once)
            _fault(e, ctl, faults)
    return None


def _fault(e: dict[str, Any], ctl: Any, faults: Any) -> None:
    """A recorded fault injected (with the trigger it was given) or cleared again."""
    if e["f"] == "inject":
        faults.inject(faults.spec_from_dict(dict(e["v"])), ctl=ctl)
    elif e["f"] == "clear":
        faults.clear(e["v"].get("id"), ctl=ctl)


class _Later:
    """Faults injected or cleared from outside the session (``gtecat fault``, the panel)
    while one of its calls ran: the controller's ``before_cycle`` hook that does each at
    the first cycle at or after the controller time it was recorded at, first in that
    cycle, where the request was served (:mod:`gtecat.inspect.endpoint`)."""

    def __init__(self, ctl: Any) -> None:
        self.ctl = ctl
        self.due: list[tuple[int, Any]] = []

    @classmethod
    def add(cls, ctl: Any, t: int, do: Any) -> None:
        hook = next((g for g in ctl.before_cycle if isinstance(g, _Later)), None)
        if hook is None:
            hook = cls(ctl)
            ctl.before_cycle = [hook, *ctl.before_cycle]
        hook.due.append((t, do))

    def __call__(self) -> None:
        now = self.ctl.clock.now_ns
        while self.due and self.due[0][0] <= now:
            self.due.pop(0)[1]()
        if not self.due:  # a new list: the cycle goes on over the one it began with
            self.ctl.before_cycle = [g for g in self.ctl.before_cycle if g is not self]


__all__ = [
    "CHECKPOINT_MS",
    "Divergence",
    "Recorder",
    "checkpoint",
    "decode",
    "encode",
    "read",
    "replay",
]
