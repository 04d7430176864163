"""Table 6-2 bits and the in-position timer of GT_SetAxisBand (manual 6.3.1, 11.7)."""

from __future__ import annotations

from hypothesis import given
from hypothesis import strategies as st

from gtecat.controller.axis_status import BLOCKING, LATCHED, AxisStatus, InPosition

MS = 1_000_000


def test_bit_numbers_are_table_6_2():
    assert [int(f).bit_length() - 1 for f in AxisStatus] == [1, 4, 5, 6, 7, 8, 9, 10, 11]
    assert not LATCHED & (AxisStatus.SERVO_ON | AxisStatus.MOVING | AxisStatus.ARRIVED)
    assert not BLOCKING & (AxisStatus.POSITIVE_LIMIT | AxisStatus.NEGATIVE_LIMIT)


def test_off_by_default():
    b = InPosition()
    for k in range(10):
        b.update(k * MS, True, 0.0)
    assert not b.enabled and not b.arrived


def test_hold_time_in_250_us_units_counted_in_whole_cycles():
    b = InPosition()
    b.set(10, 5)  # 1.25 ms
    b.update(0, True, 3.0)
    b.update(1 * MS, True, -10.0)  # the band edge is inside
    assert not b.arrived
    b.update(2 * MS, True, 0.0)
    assert b.arrived
    b.update(3 * MS, True, 10.5)  # out of the band: cleared at once
    assert not b.arrived
    b.update(4 * MS, False, 0.0)  # the profile moves
    assert not b.arrived


@given(
    st.lists(st.tuples(st.booleans(), st.floats(-30, 30)), min_size=1, max_size=40),
    st.integers(0, 12),
)
def test_arrived_iff_in_band_and_standing_for_the_hold_time(samples, time):
    b = InPosition()
    b.set(20, time)
    run = 0
    for k, (standing, err) in enumerate(samples):
        b.update(k * MS, standing, err)
        ok = standing and abs(err) <= 20
        run = run + 1 if ok else 0
        assert b.arrived == (ok and (run - 1) * MS >= time * 250_000)
