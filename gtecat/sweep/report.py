"""``gtecat sweep report``: an HTML page and PNGs of a sweep's results.

The page holds: the pass/fail map over two parameters (the two numeric parameters with the
most distinct values unless ``--x``/``--y`` name them), the distribution of every measured
value with its percentiles, and the worst cases (every failure, then the extremes of each
value) each with the command that re-runs it alone.
"""

from __future__ import annotations

import html
import math
from pathlib import Path
from typing import Any

import numpy as np

from ..errors import ParameterError
from .results import LEADING, TRAILING, read_meta, read_rows

PERCENTILES = (1, 5, 50, 95, 99)
WORST = 20


def _numeric(rows: list[dict[str, Any]], key: str) -> np.ndarray | None:
    values = [r.get(key) for r in rows]
    if not any(isinstance(v, int | float) and not isinstance(v, bool) for v in values):
        return None
    out = np.full(len(values), np.nan)
    for i, v in enumerate(values):
        if isinstance(v, int | float) and not isinstance(v, bool):
            out[i] = float(v)
    return out


def split_columns(rows: list[dict[str, Any]], params: set[str]) -> tuple[list[str], list[str]]:
    """(parameters, measured values) among the columns, in first-seen order."""
    cols: dict[str, None] = {}
    for r in rows:
        cols.update(dict.fromkeys(r))
    skip = set(LEADING) | set(TRAILING)
    names = [c for c in cols if c not in skip]
    return [c for c in names if c in params], [c for c in names if c not in params]


def write_report(results: Path, out: Path, x: str | None = None, y: str | None = None) -> Path:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    if not results.is_file():
        raise ParameterError(f"{results}: results file not found")
    rows = read_rows(results)
    if not rows:
        raise ParameterError(f"{results}: no cases in it yet")
    meta = read_meta(results)
    params = _params_of(meta, rows)
    pnames, vnames = split_columns(rows, params)
    ok = np.array([bool(r.get("ok")) for r in rows])
    out.mkdir(parents=True, exist_ok=True)
    parts = [
        f"<h1>Sweep report: {html.escape(results.name)}</h1>",
        f"<p>{len(rows)} cases, {int(ok.sum())} passed, {int((~ok).sum())} failed.</p>",
    ]
    numeric_params = [p for p in pnames if _numeric(rows, p) is not None]
    for name, given in (("--x", x), ("--y", y)):
        if given is not None and given not in pnames:
            raise ParameterError(f"{name} {given!r} is not a parameter; these are: {pnames}")
    ranked = sorted(numeric_params, key=lambda p: -len({r.get(p) for r in rows}))
    x = x or (ranked[0] if ranked else None)
    y = y or next((p for p in ranked if p != x), None)
    if x is not None:
        fig, ax = plt.subplots(figsize=(7, 5))
        xs = _numeric(rows, x)
        ys = _numeric(rows, y) if y else np.zeros(len(rows))
        if xs is not None and ys is not None:
            ax.scatter(xs[ok], ys[ok], s=12, c="tab:green", label="passed")
            ax.scatter(xs[~ok], ys[~ok], s=24, c="tab:red", marker="x", label="failed")
            ax.set_xlabel(x)
            ax.set_ylabel(y or "")
            ax.set_title("pass/fail map")
            ax.legend()
            fig.tight_layout()
            fig.savefig(out / "map.png", dpi=100)
            parts.append('<h2>Pass/fail map</h2><img src="map.png" alt="pass/fail map">')
        plt.close(fig)
    table = ["<tr><th>value</th><th>n</th>", *(f"<th>p{p}</th>" for p in PERCENTILES), "</tr>"]
    for v in vnames:
        data = _numeric(rows, v)
        if data is None or not np.isfinite(data).any():
            continue
        finite = data[np.isfinite(data)]
        pct = np.percentile(finite, PERCENTILES)
        table.append(
            f"<tr><td>{html.escape(v)}</td><td>{finite.size}</td>"
            + "".join(f"<td>{_fmt(q)}</td>" for q in pct)
            + "</tr>"
        )
        fig, ax = plt.subplots(figsize=(6, 3.5))
        ax.hist(finite, bins=min(50, max(5, int(math.sqrt(finite.size)))), color="tab:blue")
        for q, p in zip(pct[[0, 2, 4]], (1, 50, 99), strict=True):
            ax.axvline(q, color="k", ls=":", lw=1)
            ax.annotate(f"p{p}", (q, ax.get_ylim()[1] * 0.95), fontsize=8)
        ax.set_xlabel(v)
        ax.set_ylabel("cases")
        fig.tight_layout()
        png = f"value_{_safe(v)}.png"
        fig.savefig(out / png, dpi=100)
        plt.close(fig)
        parts.append(f'<h3>{html.escape(v)}</h3><img src="{png}" alt="{html.escape(v)}">')
    parts.insert(2, "<h2>Measured values</h2><table>" + "".join(table) + "</table>")
    parts.append("<h2>Worst cases</h2>" + _worst(rows, vnames, meta))
    page = out / "index.html"
    page.write_text(
        "<!doctype html><meta charset='utf-8'><title>gtecat sweep report</title>"
        "<style>body{font-family:sans-serif;margin:2em}td,th{padding:2px 8px;text-align:right}"
        "code{white-space:pre-wrap}</style>" + "\n".join(parts),
        encoding="utf-8",
    )
    return page


def _params_of(meta: dict[str, str], rows: list[dict[str, Any]]) -> set[str]:
    """The grid's parameter names (from the grid file when it is still there)."""
    grid = meta.get("grid")
    if grid:
        try:
            from .grid import load_grid

            g = load_grid(grid)
            return set(g.grid) | set(g.random)
        except ParameterError:
            pass
    return {k for k in rows[0] if k.startswith("machine.")}


def _worst(rows: list[dict[str, Any]], vnames: list[str], meta: dict[str, str]) -> str:
    picked: dict[str, str] = {}
    for r in rows:
        if not r.get("ok"):
            first = str(r.get("error", "")).strip().splitlines()
            picked.setdefault(str(r["id"]), "failed: " + (first[-1] if first else ""))
    for v in vnames:
        data = _numeric(rows, v)
        if data is None or not np.isfinite(data).any():
            continue
        for i, label in (
            (int(np.nanargmax(data)), "largest"),
            (int(np.nanargmin(data)), "smallest"),
        ):
            picked.setdefault(str(rows[i]["id"]), f"{label} {v} = {_fmt(data[i])}")
    scenario, grid = meta.get("scenario", "SCENARIO.py"), meta.get("grid", "GRID.toml")
    items = [
        f"<li>{html.escape(why)}<br><code>gtecat sweep {html.escape(scenario)} --grid "
        f"{html.escape(grid)} --case {html.escape(cid)}</code></li>"
        for cid, why in list(picked.items())[:WORST]
    ]
    return "<ul>" + "".join(items) + "</ul>" if items else "<p>none</p>"


def _fmt(v: float) -> str:
    return f"{v:.6g}"


def _safe(name: str) -> str:
    return "".join(c if c.isalnum() else "_" for c in name)[:60]
