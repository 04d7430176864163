"""The manual's examples 4-3, 6-1, 7-1, 7-2, 9-1 and 11-2 as scripts (examples/), with the
shapes of their figures checked (7-2, 7-4, 9-2, 11-2)."""

from __future__ import annotations

import importlib.util
import math
import sys

import numpy as np
import pytest

from tests.conftest import EXAMPLES
from tests.gtecat.controller.motion.reference import Trapezoid

SERVO, MOVING, ARRIVED, POS_LIMIT = 1 << 9, 1 << 10, 1 << 11, 1 << 5


def example(name: str):
    """examples/<name>.py as a module (examples/ is not a package)."""
    if name not in sys.modules:
        spec = importlib.util.spec_from_file_location(name, EXAMPLES / f"{name}.py")
        assert spec is not None and spec.loader is not None
        mod = importlib.util.module_from_spec(spec)
        sys.modules[name] = mod  # dataclasses look their module up while the class is built
        spec.loader.exec_module(mod)
    return sys.modules[name]


def test_example_4_3_configuration_takes_effect_with_clrsts():
    r = example("example_4_3_init").run(clock="lockstep")
    assert r["errors"] == []
    assert r["after_reset"] == POS_LIMIT  # standing on the positive switch
    assert r["after_lmts_off"] == POS_LIMIT  # latched
    assert r["after_clr_sts"] == 0
    assert r["after_axis_on"] == SERVO


def test_example_6_1_reads_flags_positions_and_mode():
    r = example("example_6_1_status").run(clock="lockstep")
    assert r["errors"] == []
    assert r["before"] == {"servo": False, "motion": False, "mode": "Trap"}
    scans = r["scans"]
    assert scans[0]["motion"] and scans[0]["servo"] and scans[0]["acc"] == 0.5
    assert not scans[-1]["motion"] and scans[-1]["pos"] == 2000
    assert max(s["vel"] for s in scans) == 20
    assert {s["mode"] for s in scans} == {"Trap"}
    # 2000 pulses at 20 pulse/ms, acc = dec = 0.5: 40 + 60 + 40 ms
    assert sum(1 for s in scans if s["motion"]) == 139


def test_example_7_1_matches_the_smoothed_trapezoid_sample_by_sample():
    r = example("example_7_1_trap").run(clock="lockstep")
    assert r["errors"] == []
    t = np.array(r["t"], dtype=float)
    pos = np.array(r["pos"])
    assert np.array_equal(t, np.arange(len(t)))  # one scan per cycle in lockstep
    ref = Trapezoid.plan(50000, 50, 0.25, 0.125)
    np.testing.assert_allclose(pos, ref.smoothed_exact(t, 25.0), atol=1e-7)
    assert t[-1] == 1325 and pos[-1] == 50000  # figure 7-2: 1300 ms + smoothTime
    vel = np.array(r["vel"])
    assert vel.max() == pytest.approx(50) and np.sum(vel > 50 - 1e-9) == pytest.approx(700, abs=26)


def test_example_7_1_in_the_auto_clock_keeps_its_shape():
    r = example("example_7_1_trap").run(clock="auto")
    assert r["errors"] == [] and r["pos"][-1] == 50000
    assert max(r["vel"]) == pytest.approx(50)
    assert 1320 <= r["t"][-1] - r["t"][0] <= 1335


@pytest.mark.long
def test_example_7_2_speed_up_to_100_then_down_to_50():
    r = example("example_7_2_jog").run(clock="lockstep")
    assert r["errors"] == []
    vel = np.array(r["vel"])
    k = r["update_at"]
    assert r["pos"][k - 1] > 100000 >= r["pos"][k - 2]  # the scan after it passed 100000
    up = vel[: k + 1]
    assert up.max() == pytest.approx(100)
    assert np.argmax(up >= 100 - 1e-9) == 1600  # 100 / 0.0625
    assert np.all(np.diff(up[:1601]) == pytest.approx(0.0625))
    down = vel[k:]
    assert np.argmax(down <= 50 + 1e-9) == 800  # (100 - 50) / 0.0625
    assert np.all(down[800:] == pytest.approx(50))


def test_example_9_1_stops_just_past_the_soft_limit_with_bit_5():
    r = example("example_9_1_soft_limit").run(clock="lockstep")
    assert r["errors"] == []
    pos = np.array(r["pos"])
    sts = np.array(r["sts"])
    past = pos > 20000
    first = int(np.argmax(past))
    assert not np.any(sts[:first] & POS_LIMIT)  # never before the limit
    assert np.all(sts[first:] & POS_LIMIT)  # set in the cycle that passed it, and latched
    v = pos[first] - pos[first - 1]
    assert pos[-1] == pytest.approx(pos[first] + v * v / 2000, abs=v)  # decAbruptStop 1000
    assert 20000 < pos[-1] < 20000 + 52
    stopped = r["stopped"]
    assert stopped <= first + 2 and np.all(pos[stopped:] == pos[-1])
    assert not np.any(sts[stopped:] & MOVING)


@pytest.mark.long
def test_example_11_2_y_starts_after_x_is_in_position():
    r = example("example_11_2_in_position").run(clock="lockstep")
    assert r["errors"] == []
    sts_x = np.array(r["stsX"])
    vel_y = np.array(r["velY"])
    k = r["y_started_scan"]
    x_arrived = int(np.argmax((sts_x & ARRIVED) != 0))
    x_stopped = int(np.argmax((sts_x & MOVING) == 0))
    assert 0 < x_stopped <= x_arrived < k  # X planned stop, then in position, then Y
    assert k == x_arrived + 1  # the program sees the flag one scan later
    assert np.all(vel_y[:k] == 0) and vel_y[k + 1] > 0
    # X: 10000 at 10 pulse/ms, acc 1, dec 0.5 -> 1015 ms
    assert x_stopped == math.ceil(Trapezoid.plan(10000, 10, 1, 0.5).duration)
    assert r["posX"][-1] == 10000 and r["posY"][-1] == 20000
    assert r["stsY"][-1] & ARRIVED
