"""A sweep's grid file: the base machine and the cases, each with a stable id and seed.

The grid is TOML::

    [base]
    eni = "manual_fig5_2.eni"            # a path (relative to the grid file) or a shipped example
    machine = "machine.toml"             # optional: the machine description every case starts from

    [grid]                               # lists are crossed: every combination is a case
    method = [19, 35]
    "machine.axis.1.index_offset" = [0, 2500, 5000, 7500]

    [random]                             # seeded samples, drawn n times per grid point
    n = 50
    seed = 1
    "machine.axis.1.home_switch.0.0" = { uniform = [99000, 101000] }
    speed = { normal = [40000, 2000] }

A parameter named ``machine.<path>`` overrides that key of the machine description for the
case; path parts that are numbers index lists (``home_switch.0.0`` is the low edge of the
first home-switch window).  Every other parameter reaches the scenario in ``case``.

Decisions: the cases are the product of ``[grid]`` (in the file's key order) times ``n``
draws of ``[random]``; a case's id is a hash of its parameters (so it names the same case in
any run, on any worker, whatever else the grid holds) and its seed is derived from that id,
so ``--case ID`` re-runs one case alone with the same numbers.
"""

from __future__ import annotations

import copy
import hashlib
import itertools
import json
import math
import tomllib
from collections.abc import Iterator, Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from ..errors import ParameterError

MACHINE_PREFIX = "machine."
#: the most cases one sweep holds (each is a row in memory and in RESULTS)
MAX_CASES = 1_000_000
DISTRIBUTIONS = ("uniform", "normal")


class Case(Mapping[str, Any]):
    """One case: its parameters (``case["speed"]``), ``case.id`` and ``case.seed``."""

    __slots__ = ("id", "params", "seed")

    def __init__(self, params: Mapping[str, Any], case_id: str | None = None) -> None:
        self.params = dict(params)
        self.id = case_id or case_id_of(self.params)
        self.seed = int(self.id, 16) % (2**31 - 1)

    def __getitem__(self, key: str) -> Any:
        return self.params[key]

    def __iter__(self) -> Iterator[str]:
        return iter(self.params)

    def __len__(self) -> int:
        return len(self.params)

    def __repr__(self) -> str:
        return f"Case({self.id}, {self.params})"

    def scenario_params(self) -> dict[str, Any]:
        """The parameters that are not machine overrides."""
        return {k: v for k, v in self.params.items() if not k.startswith(MACHINE_PREFIX)}


def case_id_of(params: Mapping[str, Any]) -> str:
    """12 hex digits of SHA-256 over the parameters in canonical JSON (sorted keys)."""
    text = json.dumps(params, sort_keys=True, separators=(",", ":"), default=_jsonable)
    return hashlib.sha256(text.encode()).hexdigest()[:12]


def _jsonable(value: Any) -> Any:
    if isinstance(value, np.generic):
        return value.item()
    raise TypeError(f"parameter value {value!r} is not a number, text, list or table")


@dataclass(frozen=True)
class Grid:
    """What a grid file says, with paths resolved against the file's folder."""

    path: Path
    eni: str  #: where the ENI came from (a file or a shipped example's name), for messages
    eni_bytes: bytes  #: its content: a remote worker needs no shared folder
    machine: dict[str, Any] = field(default_factory=dict)
    grid: dict[str, list[Any]] = field(default_factory=dict)
    random: dict[str, tuple[str, float, float]] = field(default_factory=dict)
    n: int = 1
    seed: int = 0
    card: str | None = None  #: ``[base] card = "gts:4"``: a pulse card instead of EtherCAT

    def size(self) -> int:
        """How many cases the grid describes (before identical ones are dropped)."""
        return math.prod(len(v) for v in self.grid.values()) * (self.n if self.random else 1)

    def check(self) -> None:
        """Refuse, before any case runs, what would fail every case alike: more cases than
        one sweep holds, and ``machine.*`` keys or values the machine description refuses
        (each [grid] value, and each [random] key at its first draw)."""
        from ..drives.machine import machine_from_dict

        if self.size() > MAX_CASES:
            raise ParameterError(
                f"{self.path}: the grid describes {self.size():,} cases; a sweep holds at most "
                f"{MAX_CASES:,} (split it into several grids, or sample with [random])"
            )
        first = {k: v[0] for k, v in self.grid.items()}
        rng = np.random.default_rng(self.seed)
        first.update({k: v[0] for k, v in self._draw(rng).items()})
        # each key alone on the base first, then each value beside the others' first ones
        trials = [(key, first[key], {}) for key in [*self.random, *self.grid]]
        trials += [(k, v, first) for k, values in self.grid.items() for v in values]
        seen: set[tuple[str, str, bool]] = set()
        for key, value, rest in trials:
            if not key.startswith(MACHINE_PREFIX) or (key, repr(value), bool(rest)) in seen:
                continue
            seen.add((key, repr(value), bool(rest)))
            try:
                machine_from_dict(self.machine_for(Case({**rest, key: value})), "machine")
            except Exception as e:  # every refusal of the description
                where = "[grid]" if key in self.grid else "[random]"
                raise ParameterError(f"{self.path}: {where} {key} = {value!r}: {e}") from None

    def cases(self) -> list[Case]:
        """Every case in a fixed order; ids repeat only for identical parameters (dropped)."""
        if self.size() > MAX_CASES:
            self.check()
        names = list(self.grid)
        points = list(itertools.product(*(self.grid[k] for k in names))) if names else [()]
        rng = np.random.default_rng(self.seed)
        out: dict[str, Case] = {}
        for point in points:
            draws = self._draw(rng)
            for i in range(self.n if self.random else 1):
                params = dict(zip(names, point, strict=True))
                params.update({k: v[i] for k, v in draws.items()})
                case = Case(params)
                out.setdefault(case.id, case)
        return list(out.values())

    def _draw(self, rng: np.random.Generator) -> dict[str, list[float]]:
        draws = {}
        for key, (kind, a, b) in self.random.items():
            sample = rng.uniform(a, b, self.n) if kind == "uniform" else rng.normal(a, b, self.n)
            draws[key] = [float(x) for x in sample]
        return draws

    def find(self, case_id: str) -> Case:
        for case in self.cases():
            if case.id == case_id:
                return case
        raise ParameterError(
            f"no case {case_id!r} in {self.path} (`gtecat sweep ... --list` shows the ids)"
        )

    def machine_for(self, case: Case) -> dict[str, Any]:
        """The base machine description with the case's ``machine.*`` overrides applied."""
        data = copy.deepcopy(self.machine)
        for key, value in case.params.items():
            if key.startswith(MACHINE_PREFIX):
                set_path(data, key[len(MACHINE_PREFIX) :], value, key)
        return data


def set_path(data: dict[str, Any], path: str, value: Any, name: str) -> None:
    """Set ``a.b.0.c`` in nested tables and lists; tables are made on the way, lists not."""
    parts = path.split(".")
    node: Any = data
    for i, part in enumerate(parts):
        last = i == len(parts) - 1
        if isinstance(node, list):
            try:
                index = int(part)
                if not 0 <= index < len(node):
                    raise IndexError(index)
            except (ValueError, IndexError):
                raise ParameterError(
                    f"{name}: {'.'.join(parts[:i]) or 'machine'} is a list of {len(node)}; "
                    f"{part!r} is not an index in it"
                ) from None
            if last:
                node[index] = value
            else:
                node = node[index]
        elif isinstance(node, dict):
            if last:
                node[part] = value
            else:
                node = node.setdefault(part, {})
        else:
            raise ParameterError(f"{name}: {'.'.join(parts[:i])} is a value, not a table or list")


def load_grid(path: str | Path) -> Grid:
    """Read and check a grid file; every mistake is one :class:`ParameterError` line."""
    p = Path(path)
    try:
        data = tomllib.loads(p.read_text(encoding="utf-8"))
    except FileNotFoundError:
        raise ParameterError(f"{p}: grid file not found") from None
    except IsADirectoryError:
        raise ParameterError(f"{p} is a folder; give the grid's TOML file") from None
    except (tomllib.TOMLDecodeError, UnicodeDecodeError) as e:
        raise ParameterError(f"{p}: not valid TOML: {e}") from None
    unknown = set(data) - {"base", "grid", "random"}
    if unknown:
        raise ParameterError(
            f"{p}: unknown table(s) {sorted(unknown)}; use [base], [grid], [random]"
        )
    base = _table(data, "base", p)
    if "eni" not in base or not isinstance(base["eni"], str):
        raise ParameterError(f'{p}: [base] needs eni = "FILE.eni" (or a shipped example name)')
    eni, eni_bytes = _eni(base["eni"], p)
    card = base.get("card")
    if card is not None and not isinstance(card, str):
        raise ParameterError(f'{p}: [base] card is a text like "gts:4"')
    machine: dict[str, Any] = {}
    if "machine" in base:
        m = base["machine"]
        if isinstance(m, str):
            mp = p.parent / m
            try:
                machine = tomllib.loads(mp.read_text(encoding="utf-8"))
            except (OSError, tomllib.TOMLDecodeError, UnicodeDecodeError) as e:
                raise ParameterError(f"{p}: [base] machine {m!r}: {e}") from None
        elif isinstance(m, dict):
            machine = m
        else:
            raise ParameterError(f"{p}: [base] machine is a file name or a table")
    grid: dict[str, list[Any]] = {}
    for key, values in _table(data, "grid", p).items():
        if not isinstance(values, list) or not values:
            raise ParameterError(f"{p}: [grid] {key} must be a non-empty list of values")
        grid[key] = values
    rnd = dict(_table(data, "random", p))
    n, seed = rnd.pop("n", 1), rnd.pop("seed", 0)
    if not isinstance(n, int) or isinstance(n, bool) or not 1 <= n <= MAX_CASES:
        raise ParameterError(f"{p}: [random] n must be a whole number from 1 to {MAX_CASES}")
    if not isinstance(seed, int) or isinstance(seed, bool) or seed < 0:
        raise ParameterError(f"{p}: [random] seed must be a whole number >= 0")
    random: dict[str, tuple[str, float, float]] = {}
    for key, spec in rnd.items():
        random[key] = _distribution(key, spec, p)
    if set(random) & set(grid):
        raise ParameterError(f"{p}: {sorted(set(random) & set(grid))} in both [grid] and [random]")
    return Grid(p, eni, eni_bytes, machine, grid, random, n, seed, card)


def _table(data: dict[str, Any], name: str, p: Path) -> dict[str, Any]:
    t = data.get(name, {})
    if not isinstance(t, dict):
        raise ParameterError(f"{p}: {name} must be a table ([{name}])")
    return t


def _distribution(key: str, spec: Any, p: Path) -> tuple[str, float, float]:
    where = f"{p}: [random] {key}"
    if not isinstance(spec, dict) or len(spec) != 1 or next(iter(spec)) not in DISTRIBUTIONS:
        raise ParameterError(
            f"{where}: write {{ uniform = [lo, hi] }} or {{ normal = [mean, sd] }}"
        )
    kind, args = next(iter(spec.items()))
    if (
        not isinstance(args, list)
        or len(args) != 2
        or not all(isinstance(a, int | float) and not isinstance(a, bool) for a in args)
        or not all(math.isfinite(a) for a in args)
    ):
        raise ParameterError(f"{where}: {kind} takes two finite numbers")
    a, b = float(args[0]), float(args[1])
    if kind == "uniform" and not a <= b:
        raise ParameterError(f"{where}: uniform needs lo <= hi, got [{a}, {b}]")
    if kind == "normal" and b < 0:
        raise ParameterError(f"{where}: normal needs sd >= 0, got {b}")
    return kind, a, b


def _eni(name: str, grid_path: Path) -> tuple[str, bytes]:
    """The ENI beside the grid file, else a shipped example of that name."""
    candidate = grid_path.parent / name
    try:
        return str(candidate), candidate.read_bytes()
    except FileNotFoundError:
        pass
    except OSError as e:
        raise ParameterError(f"{grid_path}: [base] eni {name!r}: {e.strerror}") from None
    from ..cli import example_cmd

    try:
        example = example_cmd.find(Path(name).stem)
    except ParameterError:
        raise ParameterError(
            f"{grid_path}: [base] eni {name!r} is neither a file beside the grid "
            "nor a shipped example (`gtecat example` lists them)"
        ) from None
    eni = next((f for f in example.files if f.endswith(".eni")), None)
    if eni is None:
        raise ParameterError(f"{grid_path}: example {example.name!r} has no ENI")
    return example.name, example_cmd.read_bytes(eni)
