"""The encoder resource of a bus axis (manual 4.3.2, 8.2): counting 6064h or 607Ah."""

from __future__ import annotations

from hypothesis import given
from hypothesis import strategies as st

from gtecat.controller.encoder import Encoder

int32 = st.integers(-(1 << 31), (1 << 31) - 1)


def test_first_sample_takes_the_drive_value_then_counts_increments():
    e = Encoder(1.0)
    e.sample(1000, 1.0)
    assert e.pos == 1000 and e.vel == 0
    e.sample(1010, 1.0)
    assert (e.pos, e.vel, e.acc) == (1010, 10, 10)
    e.sample(1030, 0.5)
    assert (e.pos, e.vel, e.acc) == (1020, 10, 0)


def test_sense_reverses_without_a_jump_and_set_pos_redefines():
    e = Encoder(1.0)
    e.sample(0, 1.0)
    e.sample(100, 1.0)
    e.sense = -1
    e.sample(150, 1.0)
    assert e.pos == 50
    e.set_pos(-7)
    e.sample(160, 1.0)
    assert e.pos == -17


def test_inactive_encoder_is_frozen_and_rebase_takes_the_drive_value():
    e = Encoder(2.0)
    e.sample(0, 1.0)
    e.active = False
    e.sample(500, 1.0)
    assert e.pos == 0
    e.active = True
    e.sample(520, 1.0)
    assert e.pos == 20 and e.vel == 10  # 20 pulses in a 2 ms cycle
    e.rebase(-3, 0.25)
    assert e.pos == -0.75


@given(st.lists(int32, min_size=2, max_size=50), st.integers(0, 8))
def test_counting_is_exact_and_survives_the_32_bit_wrap(raws, scale):
    unit = 1.0 / (1 << scale)
    e = Encoder(1.0)
    total = 0
    for i, r in enumerate(raws):
        e.sample(r, unit)
        if i:
            d = (r - raws[i - 1] + (1 << 31)) % (1 << 32) - (1 << 31)
            total += d
    assert e.pos == (raws[0] + total) * unit
