"""The Pythonic layer under the GT calls: AxisResources, the mode framework, master sources."""

from __future__ import annotations

import pytest

from gtecat.controller.core import Controller, Options
from gtecat.controller.motion.pt import PtPlanner
from gtecat.controller.profile import PrfMode
from gtecat.controller.resources import axis_resources, position_source
from gtecat.errors import BusError, CommandError, ParameterError
from tests.conftest import EXAMPLES


@pytest.fixture
def ctl():
    c = Controller(Options(eni=str(EXAMPLES / "manual_fig5_2.eni"), clock="lockstep", log=""))
    c.init_ecat()
    c.clock.run_until(lambda: c.ready, 100)
    c.start_ecat()
    yield c
    c.close()


def enable(ctl: Controller, n: int) -> None:
    ax = ctl.axis(n)
    assert ctl.clock.run_until(ax.enable_step, 200)
    ax.sync_to_actual()
    ax.servo_on = True


def test_before_the_bus_is_up_it_is_a_bus_error():
    c = Controller(Options(eni=str(EXAMPLES / "manual_fig5_2.eni"), clock="lockstep", log=""))
    with pytest.raises(BusError):
        axis_resources(c, 1)
    c.close()


def test_any_planner_plugs_into_the_profile_slot(ctl):
    """What the PT/Gear/Follow wrappers will do: enter the mode with their planner, start it."""
    enable(ctl, 1)
    res = axis_resources(ctl, 1)
    pt = res.profile.enter(PrfMode.PT, factory=lambda: PtPlanner(cycle_ms=res.cycle_ms))
    assert isinstance(pt, PtPlanner) and res.profile.mode == PrfMode.PT
    pt.data(1000, 100)  # one normal segment: 1000 pulses in 100 ms from rest
    pt.data(2000, 200, 2)  # and a stop segment
    res.check_motion("GT_PtStart", direction=1.0)
    pt.start(0)
    ctl.clock.advance(100)
    assert res.prf_pos == pytest.approx(1000) and ctl.axis(1).prf_pos == pytest.approx(1000)
    with pytest.raises(CommandError, match="moving"):
        res.profile.enter(PrfMode.TRAP)
    with pytest.raises(CommandError, match="Trap and Jog"):
        res.check_update()
    ctl.clock.advance(150)
    assert not res.moving and res.prf_pos == 2000
    res.profile.enter(PrfMode.TRAP)
    assert res.profile.trap_target == 2000  # entering Trap: the target is where it stands
    assert res.profile.planners[PrfMode.PT] is pt  # kept for the next GT_PrfPt


def test_check_motion_refuses_toward_a_latched_limit(ctl):
    enable(ctl, 1)
    res = axis_resources(ctl, 1)
    res.safety.set_soft_limits(-1, -10)
    ctl.clock.advance(1)
    with pytest.raises(CommandError, match="positive limit"):
        res.check_motion("GT_GearStart", direction=1.0)
    res.check_motion("GT_GearStart", direction=-1.0)
    res.check_motion("GT_GearStart")  # direction unknown: only the other rules


def test_master_position_sources(ctl):
    enable(ctl, 1)
    res = axis_resources(ctl, 1)
    res.set_prf_pos(500)
    res.set_enc_pos(-20)
    assert position_source(ctl, 2, 1)() == 500  # profile
    assert position_source(ctl, 1, 1)() == -20  # encoder
    assert position_source(ctl, 3, 1, 0)() == 0  # axis planned (not synchronised yet)
    res.synch_axis_pos()
    assert position_source(ctl, 3, 1, 0)() == 500
    assert position_source(ctl, 3, 1, 1)() == -20
    with pytest.raises(ParameterError):
        position_source(ctl, 4, 1)


def test_axis_moving_property_and_reset_hook(ctl):
    enable(ctl, 1)
    ax = ctl.axis(1)
    res = ax.motion
    res.profile.trap_vel = 10
    res.profile.trap_target = 100
    res.check_update()
    res.start()
    assert ax.moving
    for hook in ctl.on_reset:
        hook(ctl)
    assert not ax.moving and not ax.servo_on and res.profile.trap_vel == 0
