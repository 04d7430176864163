"""CoordSystem.run takes the cycles inside a segment many at a time (numpy, or the compiled
segment of bank_crd): every sample, speed and state bit for bit those of the scalar cycle
(CoordSystem.step, then each axis taking its slot's sample)."""

from __future__ import annotations

import pytest

from gtecat.controller import bank_crd
from gtecat.controller.crd import CoordSystem, CrdParams, Line, make_arc
from gtecat.controller.crd.path import CCW, CW
from gtecat.controller.crd.system import AxisSlot, Delay, Motion

CYCLE_MS = 0.4  # not a power of two: the path time rounds at every addition


def _system(override: float, dims: int, even_time: int) -> CoordSystem:
    c = CoordSystem(1, lambda: CYCLE_MS)
    profile = tuple(k + 1 if k < dims else 0 for k in range(8))
    c.prm = CrdParams(dims, profile, 300.0, 3.0, even_time=even_time)
    c.slots = [AxisSlot(c, k, 10.0 * k + 0.3) for k in range(dims)]
    c.origin = [-7.1 * k + 0.1 for k in range(dims)]
    c.override = override
    return c


def _line(c: CoordSystem, to: tuple[float, ...], vel: float, acc: float, vel_end: float) -> None:
    c.push(Motion(Line(c.tail(0), to), vel, acc, vel_end), 0)


def _arc(
    c: CoordSystem, to: tuple[float, ...], centre: tuple[float, float], d: int, vel: float
) -> None:
    axis3 = 2 if len(to) > 2 else None
    c.push(Motion(make_arc(c.tail(0), to, centre, (0, 1), d, axis3), vel, 0.7, vel), 0)


def _fill(c: CoordSystem) -> None:
    dims = len(c.slots)
    z = (0.0,) * (dims - 2)
    _line(c, (1000.3, 0.7, *z), 17.0, 0.45, 9.0)  # ends moving into the next
    _line(c, (1000.3, 333.3, *z), 25.5, 1.3, 25.5)  # several speeds, a cruise
    _arc(c, (1500.3, 833.3, *(5.0,) * (dims - 2)), (1000.3, 833.3), CW, 12.0)
    c.push(Motion(Line(c.tail(0), c.tail(0)), 5.0, 1.0, 5.0), 0)  # no length: skipped
    _line(c, (1400.0, 700.0, *z), 3.0, 0.05, 0.0)  # decelerates from the arc's speed
    c.push(Delay(3.7), 0)
    _arc(c, (1400.0, 700.0, *z), (1300.0, 700.0), CCW, 30.0)  # a full turn
    _line(c, (1400.1, 700.05, *z), 40.0, 2.0, 0.0)  # a triangle, a few cycles
    _line(c, (0.0, 0.0, *z), 60.0, 0.9, 0.0)


def _scalar(c: CoordSystem) -> tuple[list, list, list]:
    samples, speeds, states = [], [], []
    while c.running:
        c.step()
        samples.append([s.step() for s in c.slots])
        speeds.append(c.speed)
        states.append(c.state())
    return samples, speeds, states


def _bits(x: object) -> object:
    if isinstance(x, float):
        return x.hex()
    if isinstance(x, (list, tuple)):
        return [_bits(y) for y in x]
    return x


@pytest.fixture(params=["numpy", "compiled"])
def segment(request: pytest.FixtureRequest) -> object:
    if request.param == "numpy":
        return None
    lib, reason = bank_crd.library()
    if lib is None:
        pytest.skip(f"the compiled segment did not build here: {reason}")
    return bank_crd.CrdFill(lib).segment


@pytest.mark.parametrize(
    ("override", "dims", "even_time", "table"),
    [(1.0, 2, 0, 32), (0.7, 2, 0, 32), (1.6, 3, 5, 32), (1.3, 2, 0, 7), (0.0, 2, 0, 32)],
)
def test_run_matches_the_scalar_cycles_bit_for_bit(
    override, dims, even_time, table, segment
) -> None:
    ref, got = _system(override, dims, even_time), _system(override, dims, even_time)
    _fill(ref)
    _fill(got)
    ref.start(0)
    got.start(0)
    want = _scalar(ref) if override else None
    if not override:  # the path stands: as many scalar cycles as the run takes
        want = ([], [], [])
        for _ in range(3 * table):
            ref.step()
            want[0].append([s.step() for s in ref.slots])
            want[1].append(ref.speed)
            want[2].append(ref.state())
    samples: list = []
    speeds: list[float] = []
    marks: list = []
    cycles = 0
    while got.running and cycles < len(want[0]):
        run_marks: list = []
        out, end = got.run(table, speeds, run_marks, segment)
        m = end + 1 if end >= 0 else table
        marks.extend((cycles + j, st) for j, st in run_marks)
        for j in range(m):
            samples.append([tuple(out[q, k, j].item() for q in range(3)) for k in range(dims)])
        cycles += m
    assert _bits(samples) == _bits(want[0])
    assert _bits(speeds) == _bits(want[1])
    assert _bits(got.state()) == _bits(want[2][-1])
    assert len(marks) >= (8 if override else 0)  # the cycles a segment ends in, at least
    for j, st in marks:
        assert _bits(st) == _bits(want[2][j]), f"cycle {j}"
    assert (got.t, got.s, got.segments_done) == (ref.t, ref.s, ref.segments_done)
    if override:
        assert not got.running and samples[-1] == want[0][-1]
