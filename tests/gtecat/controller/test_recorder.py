"""The recorder (issue 2 item 6): chosen image variables every cycle into a numpy buffer."""

from __future__ import annotations

from ctypes import byref, c_ushort

import numpy as np
import pytest

from gtecat import gt
from gtecat.controller.recorder import Recorder
from gtecat.errors import ParameterError
from tests.gtecat.gt.conftest import bring_up


@pytest.fixture(autouse=True)
def _closed():
    gt.GT_Close()
    yield
    gt.GT_Close()


@pytest.mark.long
def test_records_every_cycle_what_the_bus_carried(tmp_path):
    bring_up()
    ctl = gt.GTE_Controller()
    io = gt.GTE_Slave(2)
    for bit in range(8):
        io.wire(bit, bit)
    rec = Recorder(ctl, ["2:0x7000:1", "2:0x6000:1", "axis1.sw"]).start()
    n0 = ctl.clock.cycles
    for v in range(1, 6):
        gt.GT_SetEcatRawData(32, 1, byref(c_ushort(v)))
        gt.GTE_Wait(1)
    gt.GTE_Wait(3)
    rec.stop()
    assert rec.n == ctl.clock.cycles - n0  # one row per cycle
    assert list(rec.column("2:0x7000:1")[-1:]) == [5]
    # the input follows the output one cycle later (the wire is read at the next step)
    out, inp = rec.column("2:0x7000:1"), rec.column("2:0x6000:1")
    assert set(inp[1:]) <= set(out[:-1]) | {0}
    assert rec.data[1, 0] - rec.data[0, 0] == pytest.approx(1.0)
    csv_file = rec.to_csv(tmp_path / "t.csv")
    assert csv_file.read_text().splitlines()[0] == "time_ms,2:0x7000:1,2:0x6000:1,axis1.sw"
    png = rec.plot(tmp_path / "t.png")
    assert png.stat().st_size > 1000


def test_unknown_signal_is_a_clear_error():
    bring_up()
    with pytest.raises(ParameterError, match="maps no 0x7000:09"):
        Recorder(gt.GTE_Controller(), ["2:0x7000:9"])
    with pytest.raises(ParameterError, match="unknown signal"):
        Recorder(gt.GTE_Controller(), ["nonsense"])


@pytest.mark.long
def test_the_trace_plot_shows_the_planned_position_over_the_encoder_with_units(
    tmp_path, monkeypatch
):
    import matplotlib.figure

    figures = []
    monkeypatch.setattr(matplotlib.figure.Figure, "savefig", lambda f, *a, **k: figures.append(f))
    bring_up()
    rec = Recorder(gt.GTE_Controller(), ["axis1.prf", "axis1.enc", "axis1.err"]).start()
    gt.GTE_Wait(20)
    rec.stop()
    rec.plot(tmp_path / "t.png")
    axes = figures[0].axes
    pos = next(a for a in axes if a.get_ylabel().startswith("position"))
    assert pos.get_ylabel() == "position (pulse, counts)"  # planned in pulses, encoder counts
    lines = {ln.get_label(): ln for ln in pos.get_lines()}
    assert lines["axis1.prf"].get_zorder() > lines["axis1.enc"].get_zorder()
    assert lines["axis1.prf"].get_linewidth() < lines["axis1.enc"].get_linewidth()


def test_a_signal_toggling_every_cycle_is_drawn_as_a_band_and_its_mean():
    """The following error of a moving axis toggles by a count (set-point rounding): drawn
    sample by sample it fills the panel like a solid block; the envelope shows 0..1, mean 0.5."""
    from gtecat.controller.trace_plot import envelope

    t = np.arange(20_000.0)
    y = (np.arange(20_000) % 2).astype(float)
    tb, lo, hi, mean = envelope(t, y, bins=100)
    assert len(tb) == 100 and set(lo) == {0.0} and set(hi) == {1.0}
    assert np.allclose(mean, 0.5)
    short = envelope(t[:50], y[:50], bins=100)  # few samples: drawn as they are
    assert np.array_equal(short[3], y[:50])
