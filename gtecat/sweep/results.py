"""A sweep's results: one row per case, written as cases finish, resumable.

Rows go first to a journal beside RESULTS (``RESULTS.journal``, one JSON line per case,
flushed as each arrives), so an interrupted sweep loses nothing; RESULTS itself (``.parquet``
through pyarrow, or ``.csv``) is rewritten from all rows every few seconds and at the end,
each time through a temporary file and a rename, so it is always a whole file.  A second run
with the same RESULTS reads both and computes only the missing cases.

Decision: Parquet cannot be appended to, and a CSV's columns are only known once every
case's values are; the journal is what makes "incremental" and "resumable" true for both.
"""

from __future__ import annotations

import csv
import hashlib
import json
import math
import os
import time
from collections.abc import Iterable
from pathlib import Path
from typing import Any

from ..errors import ParameterError

FORMATS = (".parquet", ".csv")
#: columns first in every file, in this order; then parameters and values by first appearance
LEADING = ("id", "ok", "seed")
TRAILING = ("seconds", "error", "kept")


def check_path(path: str | Path) -> Path:
    p = Path(path)
    if p.suffix not in FORMATS:
        raise ParameterError(f"{p}: results are written as .parquet or .csv (give -o NAME.parquet)")
    if p.is_dir():
        raise ParameterError(f"{p} is a folder; give a file name ending in .parquet or .csv")
    if not p.parent.is_dir():
        raise ParameterError(f"{p.parent}: no such folder for the results")
    return p


def journal_of(path: Path) -> Path:
    return path.with_name(path.name + ".journal")


def read_rows(path: str | Path) -> list[dict[str, Any]]:
    """Every row of RESULTS and its journal (journal rows win; each id once)."""
    p = Path(path)
    rows: dict[str, dict[str, Any]] = {}
    if p.is_file():
        for row in _read_table(p):
            rows[str(row["id"])] = row
    j = journal_of(p)
    if j.is_file():
        with j.open(encoding="utf-8") as f:
            for line in f:
                try:
                    row = json.loads(line)
                except json.JSONDecodeError:
                    continue  # a line cut by a kill: that case runs again
                if isinstance(row, dict) and "id" in row:
                    rows[str(row["id"])] = row
    return list(rows.values())


def _read_table(p: Path) -> list[dict[str, Any]]:
    try:
        if p.suffix == ".parquet":
            import pyarrow.parquet as pq

            table = pq.read_table(p)
            return [{k: v for k, v in row.items() if v is not None} for row in table.to_pylist()]
        with p.open(newline="", encoding="utf-8") as f:
            return [{k: _from_csv(v) for k, v in r.items() if v != ""} for r in csv.DictReader(f)]
    except Exception as e:  # a damaged file is the user's to look at, not ours to drop
        raise ParameterError(f"{p}: cannot read the results ({e})") from None


def _from_csv(text: str) -> Any:
    if text in ("True", "False"):
        return text == "True"
    for kind in (int, float):
        try:
            return kind(text)
        except ValueError:
            pass
    return text


class ResultsWriter:
    """Rows in, the journal at once, RESULTS every ``every_s`` seconds and at :meth:`close`."""

    def __init__(self, path: Path, done: Iterable[dict[str, Any]] = (), every_s: float = 5.0):
        self.path = path
        self.rows: list[dict[str, Any]] = list(done)
        self.every_s = every_s
        self._journal = journal_of(path).open("a", encoding="utf-8")
        self._last = time.monotonic()

    def add(self, row: dict[str, Any]) -> None:
        self.rows.append(row)
        self._journal.write(json.dumps(row, default=str) + "\n")
        self._journal.flush()
        if time.monotonic() - self._last >= self.every_s:
            self.flush()

    def flush(self) -> None:
        write_table(self.path, self.rows)
        self._last = time.monotonic()

    def close(self) -> None:
        self.flush()
        self._journal.close()
        journal_of(self.path).unlink(missing_ok=True)  # every row is in RESULTS now


def columns(rows: list[dict[str, Any]]) -> list[str]:
    seen: dict[str, None] = dict.fromkeys(LEADING)
    for row in rows:
        for k in row:
            if k not in TRAILING:
                seen.setdefault(k)
    seen.update(dict.fromkeys(k for k in TRAILING if any(k in r for r in rows)))
    return list(seen)


def write_table(path: Path, rows: list[dict[str, Any]]) -> None:
    cols = columns(rows)
    tmp = path.with_name(f".{path.name}.{os.getpid()}.tmp")
    if path.suffix == ".parquet":
        import pyarrow as pa
        import pyarrow.parquet as pq

        data = {c: [_cell(r.get(c)) for r in rows] for c in cols}
        arrays = {}
        for c, values in data.items():
            try:
                arrays[c] = pa.array(values)
            except (pa.ArrowInvalid, pa.ArrowTypeError):  # mixed kinds: keep them as text
                arrays[c] = pa.array([None if v is None else str(v) for v in values])
        pq.write_table(pa.table(arrays), tmp)
    else:
        with tmp.open("w", newline="", encoding="utf-8") as f:
            w = csv.DictWriter(f, fieldnames=cols, extrasaction="ignore")
            w.writeheader()
            for r in rows:
                w.writerow({k: _cell(v) for k, v in r.items()})
    os.replace(tmp, path)


def _cell(value: Any) -> Any:
    if isinstance(value, float) and not math.isfinite(value):
        return str(value)
    return value


def meta_of(path: Path) -> Path:
    return path.with_name(path.name + ".sweep.json")


def write_meta(path: Path, scenario: Path, grid: Path) -> None:
    """Which scenario and grid made RESULTS: the report's re-run commands need them."""
    meta = {"scenario": str(scenario), "grid": str(grid), "scenario_sha": scenario_sha(scenario)}
    meta_of(path).write_text(json.dumps(meta, indent=1) + "\n", encoding="utf-8")


def scenario_sha(scenario: Path) -> str:
    """What the scenario file holds, in short: a changed scenario re-runs the failed cases."""
    try:
        return hashlib.sha256(scenario.read_bytes()).hexdigest()[:16]
    except OSError:
        return ""


def read_meta(path: Path) -> dict[str, str]:
    try:
        meta = json.loads(meta_of(path).read_text(encoding="utf-8"))
    except (OSError, json.JSONDecodeError):
        return {}
    return meta if isinstance(meta, dict) else {}
