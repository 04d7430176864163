"""The picture of a :class:`~gtecat.controller.recorder.Recorder`: what a trace PNG shows.

Panels from top to bottom, sharing the time axis:

* values, one panel per quantity (positions, following error, velocities, then any other
  value), each line labelled in the panel's legend;
* bands: the CiA-402 state of every axis whose statusword (or state) was recorded, and the
  mode of operation (6061h), as coloured spans with the state's or mode's name written in;
* bit rows: every bit of every bit word (statusword, controlword, 60FDh, IO bytes) that was
  set at some time, one stepped row each, named.

Event marks (``Recorder.mark``) are vertical lines with their text in staggered rows above
the first panel, so labels of close events never overlap.
"""

from __future__ import annotations

import re
from pathlib import Path
from typing import Any

import numpy as np

from .recorder import MODE_NAMES, STATE_NAMES, SW_BITS, state_of


def envelope(t: Any, y: Any, bins: int = 600) -> tuple[Any, Any, Any, Any]:
    """(t, low, high, mean) of ``y`` in ``bins`` runs of samples: a signal that toggles by a
    count every cycle (rounding of the set-point) drawn sample by sample fills its panel
    like a solid block at this resolution; its band and mean show what it really does."""
    t, y = np.asarray(t, dtype=float), np.asarray(y, dtype=float)
    if len(y) <= 2 * bins:
        return t, y, y, y
    edges = np.linspace(0, len(y), bins + 1).astype(int)
    starts = edges[:-1]
    lo = np.minimum.reduceat(y, starts)
    hi = np.maximum.reduceat(y, starts)
    mean = np.add.reduceat(y, starts) / np.diff(edges)
    return t[starts], lo, hi, mean


def plot_noisy(ax: Any, t: Any, y: Any, color: str, label: str | None) -> None:
    """A fast-changing signal as its min-max band and its mean line (see :func:`envelope`)."""
    tb, lo, hi, mean = envelope(t, y)
    ax.fill_between(tb, lo, hi, step="post", color=color, alpha=0.25, lw=0)
    ax.plot(tb, mean, color=color, lw=1.2, drawstyle="steps-post", label=label)


_AXIS = re.compile(r"^axis(\d+)\.(\w+)$")
COLORS = ["tab:blue", "tab:orange", "tab:green", "tab:purple", "tab:brown", "tab:pink",
          "tab:olive", "tab:cyan", "tab:gray", "tab:red"]  # fmt: skip
STYLE = {"prf": "--", "enc": "-", "machine": ":", "vel": "--", "encvel": "-", "err": "-"}
GROUPS = (
    ("position", {"prf", "enc", "machine"}),
    ("following error (pulse)", {"err"}),
    ("velocity (per ms)", {"vel", "encvel"}),
)
STATE_COLORS = {
    "not ready to switch on": "0.85",
    "switch on disabled": "0.75",
    "ready to switch on": "#c6dbef",
    "switched on": "#9ecae1",
    "operation enabled": "#74c476",
    "quick stop active": "#fdae6b",
    "fault reaction active": "#fb6a4a",
    "fault": "#de2d26",
    "unknown": "white",
}


def _axis_of(name: str) -> tuple[int | None, str]:
    m = _AXIS.match(name)
    return (int(m.group(1)), m.group(2)) if m else (None, name)


def _color(axis: int | None, i: int) -> str:
    return COLORS[((axis or 0) - 1) % len(COLORS)] if axis else COLORS[i % len(COLORS)]


def _segments(values: np.ndarray) -> list[tuple[int, int, int]]:
    """(start, end, value) runs of equal values."""
    if not len(values):
        return []
    change = np.flatnonzero(np.diff(values)) + 1
    starts = np.concatenate([[0], change])
    ends = np.concatenate([change, [len(values)]])
    return [(int(a), int(b), int(values[a])) for a, b in zip(starts, ends, strict=True)]


def layout(rec: Any) -> tuple[list, list, list]:
    """(value panels, bands, bit rows) of a recorder, as the plot draws them."""
    data = rec.data
    panels: dict[str, list[tuple[str, np.ndarray, str, str]]] = {}
    bands: list[tuple[str, np.ndarray, dict[int, str]]] = []
    rows: list[tuple[str, np.ndarray, str]] = []
    have_state = {_axis_of(n)[0] for n, k in zip(rec.names, rec.kinds, strict=True)
                  if k.kind == "state"}  # fmt: skip
    for i, (name, kind) in enumerate(zip(rec.names, rec.kinds, strict=True)):
        col = data[:, 1 + i]
        axis, what = _axis_of(name)
        color = _color(axis, i)
        if kind.kind == "value":
            group = next((g for g, members in GROUPS if axis and what in members), None)
            if group is None:
                group = f"{name}" + (f" ({kind.unit})" if kind.unit else "")
            panels.setdefault(group, []).append((name, col, color, STYLE.get(what, "-")))
        elif kind.kind == "state":
            bands.append((f"{name}", col.astype(np.int64), STATE_NAMES))
        elif kind.kind == "mode":
            bands.append((f"{name} (6061h)", col.astype(np.int64), MODE_NAMES))
        else:  # bits
            words = col.astype(np.int64)
            if kind.bits is SW_BITS and axis not in have_state:
                states = np.array([state_of(int(w)) for w in words], dtype=np.int64)
                bands.append((f"{name.replace('.sw', '')} CiA-402 state", states, STATE_NAMES))
            width = max(kind.width, 1)
            for bit in range(width):
                on = (words >> bit & 1) == 1
                if not on.any():
                    continue
                label = (kind.bits or {}).get(bit, f"bit {bit}")
                rows.append((f"{name} {bit}: {label}" if width > 1 else f"{name}: {label}", on,
                             color))  # fmt: skip
    return list(panels.items()), bands, rows


def _with_units(rec: Any, group: str, lines: list) -> str:
    """A panel's label with the units of its lines ("position (pulse, counts)")."""
    if "(" in group:
        return group
    unit_of = dict(zip(rec.names, (k.unit for k in rec.kinds), strict=True))
    units = list(dict.fromkeys(u for name, *_ in lines if (u := unit_of.get(name))))
    return f"{group} ({', '.join(units)})" if units else group


def plot_recorder(rec: Any, path: Path, title: str) -> Path:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    t = rec.data[:, 0]
    panels, bands, rows = layout(rec)
    heights = (
        [2.2] * len(panels)
        + ([0.45 * len(bands)] if bands else [])
        + ([0.26 * len(rows) + 0.3] if rows else [])
    )
    if not heights:
        heights = [1.0]
    n_events = len(rec.events)
    fig, axes = plt.subplots(
        len(heights), 1, sharex=True, squeeze=False,
        figsize=(11, sum(heights) + 1.4 + 0.12 * min(n_events, 12)),
        gridspec_kw={"height_ratios": heights},
    )  # fmt: skip
    axes = [a[0] for a in axes]
    k = 0
    for group, lines in panels:
        ax = axes[k]
        k += 1
        for name, col, color, style in lines:
            if name.endswith(".err"):
                plot_noisy(ax, t, col, color, name)
                continue
            # the planned position on top of the encoder (thinner, dashed): both stay visible
            # where they agree, which is most of the time
            planned = name.endswith((".prf", ".vel"))
            ax.plot(
                t, col, color=color, ls=style, lw=1.0 if planned else 2.2,
                alpha=1.0 if planned else 0.45, zorder=3 if planned else 2, label=name,
            )  # fmt: skip
        ax.set_ylabel(_with_units(rec, group, lines), fontsize=8)
        ax.legend(loc="upper left", bbox_to_anchor=(1.005, 1.0), fontsize=7, frameon=False)
        ax.grid(alpha=0.3)
    if bands:
        ax = axes[k]
        k += 1
        for j, (_label, values, names) in enumerate(bands):
            y = len(bands) - 1 - j
            span = max(float(t[-1] - t[0]), 1e-9) if len(t) else 1.0
            for a, b, v in _segments(values):
                text = names.get(v, str(v))
                color = STATE_COLORS.get(text, COLORS[v % len(COLORS)] if v >= 0 else "white")
                x0 = t[a] if a < len(t) else t[-1]
                x1 = t[b - 1] if b - 1 < len(t) else t[-1]
                ax.axvspan(x0, x1, ymin=(y + 0.1) / len(bands), ymax=(y + 0.9) / len(bands),
                           color=color, alpha=0.8, lw=0)  # fmt: skip
                if (x1 - x0) > 0.06 * span:  # room for the name: write it in the band
                    ax.text((x0 + x1) / 2, y + 0.5, text, ha="center", va="center", fontsize=7)
        ax.set_ylim(0, len(bands))
        ax.set_yticks([len(bands) - 1 - j + 0.5 for j in range(len(bands))])
        ax.set_yticklabels([b[0] for b in bands], fontsize=7)
    if rows:
        ax = axes[k]
        for j, (_label, on, color) in enumerate(rows):
            y = len(rows) - 1 - j
            ax.fill_between(t, y, y + 0.7 * on, step="post", color=color, alpha=0.75, lw=0)
            ax.axhline(y, color="0.85", lw=0.5)
        ax.set_ylim(-0.2, len(rows))
        ax.set_yticks([len(rows) - 1 - j + 0.35 for j in range(len(rows))])
        ax.set_yticklabels([r[0] for r in rows], fontsize=7)
    for ax in axes:
        for ms, _text in rec.events:
            ax.axvline(ms, color="tab:red", lw=0.6, alpha=0.5)
    _event_labels(axes[0], rec.events, t)
    axes[-1].set_xlabel("controller time (ms)")
    fig.suptitle(title, fontsize=10)
    fig.tight_layout()
    fig.savefig(path, dpi=100)
    plt.close(fig)
    return path


def _event_labels(ax: Any, events: list[tuple[float, str]], t: np.ndarray) -> None:
    """Event texts above the panel, each in the first row where it does not overlap."""
    if not events:
        return
    span = max(float(t[-1] - t[0]), 1e-9) if len(t) else 1.0
    ends: list[float] = []  # per row: where its last label ends (data units)
    for ms, text in sorted(events):
        width = 0.011 * span * len(text)  # about 7 pt characters on an 11 inch figure
        row = next((r for r, end in enumerate(ends) if ms > end), len(ends))
        if row == len(ends):
            ends.append(ms + width)
        else:
            ends[row] = ms + width
        ax.annotate(text, (ms, 1.0), xycoords=("data", "axes fraction"),
                    xytext=(2, 2 + 9 * row), textcoords="offset points", fontsize=7,
                    color="tab:red", ha="left", va="bottom")  # fmt: skip
