"""The machine description: what the mechanics around each axis look like.

A TOML file (DESIGN.md "Machine description"), one table per GT axis, all
positions in drive counts of the *machine* (the scale a ruler on the machine
would read; homing later redefines what the encoder reports, not where the
switches are)::

    [axis.1]
    position = 0                 # where the mechanics stand at power-on
    counts_per_rev = 10000       # encoder counts per motor revolution
    negative_limit = -200000     # switch active at or below this position
    positive_limit = 200000      # switch active at or above this position
    home_switch = [[50000, 60000]]   # [low, high) windows where the switch is active
    index_offset = 1234          # an index pulse here and every counts_per_rev
    probe1 = [[30000, 30500]]    # windows where probe input 1 is active
    probe2 = []
    following_error_window = 10000
    switch_wiring = "normally_closed"   # or "normally_open"; absent: as the .cfg expects

Every key is optional: no switches, no index pulse, no probe marks.  ``switch_wiring`` says
how the axis's limit and home switches are wired, for a configuration file's ``reverse``
to meet: left out, each switch is wired the way the loaded configuration expects (its
``reverse=1`` means a normally-closed switch), so an application's own ``.cfg`` runs as on
the machine it was written for (gtecat.controller.config_file.switch_sense).
"""

from __future__ import annotations

import hashlib
import math
from collections.abc import Iterable, Mapping
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any

from gtecat.eni.errors import GtecatError


class MachineError(GtecatError):
    """A machine description that cannot be used."""


Window = tuple[float, float]


@dataclass(frozen=True, slots=True)
class AxisMachine:
    """Mechanics around one axis (see the module docstring for the keys)."""

    position: float = 0.0
    counts_per_rev: int = 10000
    negative_limit: float | None = None
    positive_limit: float | None = None
    home_switch: tuple[Window, ...] = ()
    index_offset: float | None = None
    probe1: tuple[Window, ...] = ()
    probe2: tuple[Window, ...] = ()
    following_error_window: int | None = None
    switch_wiring: str | None = None  #: "normally_open" | "normally_closed" | None (as the cfg)

    # --- levels -----------------------------------------------------------
    def negative_limit_active(self, pos: float) -> bool:
        return self.negative_limit is not None and pos <= self.negative_limit

    def positive_limit_active(self, pos: float) -> bool:
        return self.positive_limit is not None and pos >= self.positive_limit

    def home_active(self, pos: float) -> bool:
        return _in_windows(self.home_switch, pos)

    def probe_active(self, probe: int, pos: float) -> bool:
        return _in_windows(self.probe1 if probe == 1 else self.probe2, pos)

    # --- index pulses crossed between two samples ----------------------------
    # (exact edges of the switch windows: drives/signal_edges.py)
    def index_positions(self, p0: float, p1: float) -> list[float]:
        """Index pulse positions in the half-open travel ``(p0, p1]`` (or ``[p1, p0)``),
        in the order they are met."""
        if self.index_offset is None or p0 == p1 or self.counts_per_rev <= 0:
            return []
        cpr = self.counts_per_rev
        lo, hi = min(p0, p1), max(p0, p1)
        k0 = math.floor((lo - self.index_offset) / cpr)
        out = []
        k = k0
        while True:
            x = self.index_offset + k * cpr
            if x > hi:
                break
            if (p1 > p0 and p0 < x <= p1) or (p1 < p0 and p1 <= x < p0):
                out.append(float(x))
            k += 1
        if p1 < p0:
            out.reverse()
        return out

    @property
    def travel(self) -> tuple[float, float]:
        """The usable travel: between the limit switches (or +-1e12 counts)."""
        lo = self.negative_limit if self.negative_limit is not None else -1e12
        hi = self.positive_limit if self.positive_limit is not None else 1e12
        return lo, hi


def _in_windows(windows: Iterable[Window], pos: float) -> bool:
    return any(lo <= pos < hi for lo, hi in windows)


@dataclass(frozen=True, slots=True)
class MachineDescription:
    axes: Mapping[int, AxisMachine] = field(default_factory=dict)
    source: str = ""
    #: ``[ext.N]`` extension IO modules, ``[glink.N]`` gLink slaves (drives/ext_modules.py)
    ext: Mapping[int, Any] = field(default_factory=dict)
    glink: Mapping[int, Any] = field(default_factory=dict)
    #: ``[[fault]]`` tables as written (the fault vocabulary, :mod:`gtecat.faults`, reads them)
    faults: tuple[Mapping[str, Any], ...] = ()
    #: ``[card.N]`` and ``[core.N]`` tables as written: the other cards and cores of the
    #: controller (:mod:`gtecat.controller.cards` reads them)
    cards: Mapping[int, Mapping[str, Any]] = field(default_factory=dict)
    cores: Mapping[int, Mapping[str, Any]] = field(default_factory=dict)
    #: the first 16 hex digits of the SHA-256 of the file's bytes as read (:func:`load_machine`;
    #: "" for a description not read from a file): the master log names it, so two runs whose
    #: results differ show whether they read the same description (not compared: the same
    #: description read from two files is the same machine)
    digest: str = field(default="", compare=False)

    def axis(self, n: int) -> AxisMachine:
        """The description of GT axis ``n`` (defaults when the file omits it)."""
        got = self.axes.get(n)
        return _DEFAULT_AXIS if got is None else got  # (frozen: one default serves every axis)


_DEFAULT_AXIS = AxisMachine()

_KEYS = {
    "position",
    "counts_per_rev",
    "negative_limit",
    "positive_limit",
    "home_switch",
    "index_offset",
    "probe1",
    "probe2",
    "following_error_window",
    "switch_wiring",
}
SWITCH_WIRINGS = ("normally_open", "normally_closed")


def _windows(raw: Any, where: str) -> tuple[Window, ...]:
    if raw is None:
        return ()
    if not isinstance(raw, list):
        raise MachineError(f"{where}: expected a list of [low, high) windows, got {raw!r}")
    if len(raw) == 2 and all(isinstance(v, int | float) for v in raw):
        raw = [raw]  # a single window written flat
    out = []
    for w in raw:
        if (
            not isinstance(w, list)
            or len(w) != 2
            or not all(isinstance(v, int | float) for v in w)
            or not w[0] < w[1]
        ):
            raise MachineError(f"{where}: window {w!r} is not [low, high) with low < high")
        out.append((float(w[0]), float(w[1])))
    return tuple(sorted(out))


#: the tables of a machine description, as they are written in it
TABLES = {
    "axis": "[axis.N]",
    "fault": "[[fault]]",
    "ext": "[ext.N]",
    "glink": "[glink.N]",
    "card": "[card.N]",
    "core": "[core.N]",
}


def refuse_unknown(keys: Any, known: Any, where: str, what: str = "key(s)", has: str = "") -> None:
    """A key or table a description does not know is a typo that would be ignored: one
    error naming it (``has``: what the description knows, said after it)."""
    unknown = sorted(set(keys) - set(known))
    if unknown:
        names = ", ".join(f"[{k}]" if what.startswith("table") else k for k in unknown)
        raise MachineError(f"{where}: unknown {what} {names}" + (f"; {has}" if has else ""))


def machine_from_dict(
    data: Mapping[str, Any], source: str = "", extra_keys: Any = ()
) -> MachineDescription:
    """The machine description of a TOML file's tables (or a dict of them); a table it does
    not know is refused (``extra_keys``: other keys the caller reads beside them)."""
    if not isinstance(data, Mapping):
        raise MachineError(f"{source}: a machine description is a table of tables")
    refuse_unknown(
        data,
        {*TABLES, *extra_keys},
        source or "machine description",
        "table(s)",
        "a machine description has " + ", ".join(TABLES.values()),
    )
    axes_raw = data.get("axis", {})
    if not isinstance(axes_raw, dict):
        raise MachineError(f"{source}: [axis.N] tables expected")
    axes: dict[int, AxisMachine] = {}
    for key, table in axes_raw.items():
        where = f"{source}: [axis.{key}]"
        try:
            n = int(key)
        except ValueError:
            raise MachineError(f"{where}: axis number must be an integer") from None
        if n < 1:
            raise MachineError(f"{where}: axes are numbered from 1")
        refuse_unknown(table, _KEYS, where)

        def num(name: str, default: Any = None, *, where: str = where, table: Any = table) -> Any:
            v = table.get(name, default)
            if v is not None and not isinstance(v, int | float):
                raise MachineError(f"{where}: {name} must be a number, got {v!r}")
            return v

        cpr = num("counts_per_rev", 10000)
        if cpr <= 0:
            raise MachineError(f"{where}: counts_per_rev must be positive")
        nl, pl = num("negative_limit"), num("positive_limit")
        if nl is not None and pl is not None and nl >= pl:
            raise MachineError(f"{where}: negative_limit {nl} must be below positive_limit {pl}")
        wiring = table.get("switch_wiring")
        if wiring is not None and wiring not in SWITCH_WIRINGS:
            raise MachineError(
                f"{where}: switch_wiring {wiring!r}: one of {', '.join(SWITCH_WIRINGS)}"
            )
        axes[n] = AxisMachine(
            position=float(num("position", 0)),
            counts_per_rev=int(cpr),
            negative_limit=None if nl is None else float(nl),
            positive_limit=None if pl is None else float(pl),
            home_switch=_windows(table.get("home_switch"), f"{where} home_switch"),
            index_offset=None if num("index_offset") is None else float(num("index_offset")),
            probe1=_windows(table.get("probe1"), f"{where} probe1"),
            probe2=_windows(table.get("probe2"), f"{where} probe2"),
            following_error_window=num("following_error_window"),
            switch_wiring=wiring,
        )
    from .ext_modules import ext_modules_from_dict, glink_from_dict

    faults = data.get("fault", [])
    if isinstance(faults, dict):
        faults = [faults]
    if not isinstance(faults, list) or not all(isinstance(f, dict) for f in faults):
        raise MachineError(f"{source}: [[fault]] tables expected (one per fault)")
    return MachineDescription(
        axes=axes,
        source=source,
        ext=ext_modules_from_dict(data, source),
        glink=glink_from_dict(data, source),
        faults=tuple(faults),
        cards=_numbered(data, "card", source),
        cores=_numbered(data, "core", source),
    )


def _numbered(data: Mapping[str, Any], name: str, source: str) -> dict[int, Mapping[str, Any]]:
    """``[name.N]`` tables by number (their content is checked where it is used)."""
    raw = data.get(name, {})
    if not isinstance(raw, dict) or not all(isinstance(t, dict) for t in raw.values()):
        raise MachineError(f"{source}: [{name}.N] tables expected")
    out = {}
    for key, table in raw.items():
        try:
            out[int(key)] = table
        except ValueError:
            raise MachineError(f"{source}: [{name}.{key}]: a number is expected") from None
    return out


def load_machine(path: str | Path) -> MachineDescription:
    import tomllib  # (read here: a bus without a machine description never needs it)

    p = Path(path)
    try:
        raw = p.read_bytes()  # (one read: the digest is of the very bytes parsed)
        data = tomllib.loads(raw.decode("utf-8"))
    except FileNotFoundError:
        raise MachineError(f"{p}: machine description not found") from None
    except UnicodeDecodeError as e:
        raise MachineError(f"{p}: not UTF-8 text: {e}") from None
    except tomllib.TOMLDecodeError as e:
        raise MachineError(f"{p}: not valid TOML: {e}") from None
    digest = hashlib.sha256(raw).hexdigest()[:16]
    return replace(machine_from_dict(data, str(p)), digest=digest)


def read_note(machine: MachineDescription) -> str:
    """The master log's line about a description read from a file: its path, digest and the
    axes it describes.  A run's results follow from its program *and* its inputs: when two
    runs of one program differ, this line shows whether they read the same description (a
    file rewritten by another program while GT_Open read it may read empty).  "" for a
    description not read from a file."""
    if not machine.source or not machine.digest:
        return ""
    head = f"Machine description {machine.source} (sha256 {machine.digest})"
    if not machine.axes and not machine.ext and not machine.glink and not machine.faults:
        if not (machine.cards or machine.cores):
            return f"{head} is empty: every axis has the defaults (no switches, no probe marks)."
    axes = ", ".join(str(n) for n in sorted(machine.axes)) or "none"
    return f"{head}: axes described: {axes}."
