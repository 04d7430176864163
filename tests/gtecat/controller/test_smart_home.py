"""Smart homing on a GTS card axis, every mode against closed forms of the machine.

Facts: ``../shared/reference/gts-header-facts.md`` "Smart home" (THomePrm, stages, errors,
``capturePos``, ``targetPos = capturePos + homeOffset``) and seed 002's description of the
four common modes (limit: "fast to the limit, reverse, leave it, back slowly until the
limit triggers again"; limit + home: "reverse with capture armed, search the home";
home: "fast with capture armed, return slowly to the captured position"; index: "fast
with capture armed until the index pulse, slowly to it").  The decisions the header leaves
open are :mod:`gtecat.controller.smart_home`'s docstring.

The machine: limits at -30000 / +30000 (active at or beyond), a home switch active on
[10000, 12000), an index pulse at 1234 + 5000k.  Every expected position below is computed
from those numbers by the small closed forms here (which edge a direction reaches, the
first index pulse beyond a position), never from the implementation.  The encoder reads
the machine position (no GT_ZeroPos), so a capture is a machine position.  A card latches
home and index edges in hardware: exact (within the count the encoder reads, +-1); a limit
is sampled once per cycle: within half a cycle's travel at velLow (+-5 here).
"""

from __future__ import annotations

import math
from ctypes import byref, c_long

import pytest

from gtecat import gt
from gtecat.controller.smart_home import (
    HomeError,
    HomeMode,
    HomeParams,
    HomeRefused,
    Stage,
    smart_home,
)
from gtecat.drives.machine import AxisMachine, MachineDescription
from gtecat.errors import CommandError, ParameterError

NEG, POS = -30000, 30000
LO, HI = 10000, 12000
CPR, IDX0 = 5000, 1234
START = {"below": 0, "above": 20000, "on home": 11000, "on -limit": -30200, "on +limit": 30200}
VEL_HIGH, VEL_LOW, ACC = 80.0, 8.0, 4.0
OFFSET = 500
#: a sampled edge: within half a cycle's travel at velLow (1 ms cycle), and the count
SAMPLED = VEL_LOW / 2 + 1
EXACT = 1


def machine(start: float, **kw) -> MachineDescription:
    geometry = dict(
        position=start,
        counts_per_rev=CPR,
        index_offset=IDX0,
        negative_limit=NEG,
        positive_limit=POS,
        home_switch=((LO, HI),),
    )
    geometry.update(kw)
    return MachineDescription({1: AxisMachine(**geometry), 2: AxisMachine()})


@pytest.fixture(autouse=True)
def _closed():
    gt.GT_Close()
    yield
    gt.GT_Close()


def open_card(start: float, axes: int = 1, **kw):
    assert (
        gt.GT_Open(card=f"gts:{axes}", machine=machine(start, **kw), clock="lockstep", log="") == 0
    )
    for a in range(1, axes + 1):
        assert gt.GT_AxisOn(a) == 0, gt.GTE_GetLastError()
    return gt.GTE_Controller()


def params(**kw) -> HomeParams:
    base = dict(velHigh=VEL_HIGH, velLow=VEL_LOW, acc=ACC, dec=ACC, homeOffset=OFFSET)
    base.update(kw)
    return HomeParams(**base)


def home_run(ctl, prm: HomeParams, axis: int = 1, timeout_ms: float = 120_000):
    """Start, run to the end; returns (home, stages seen, flags seen in GT_GetSts)."""
    home = smart_home(ctl, axis)
    home.start(prm)
    stages = [home.status.stage]
    flags = 0
    sts = c_long()

    def done() -> bool:
        nonlocal flags
        if home.status.stage != stages[-1]:
            stages.append(home.status.stage)
        gt.GT_GetSts(axis, byref(sts))
        flags |= sts.value
        return not home.running

    assert ctl.clock.run_until(done, timeout_ms), f"still homing at stage {home.status.stage}"
    return home, stages, flags


# --- closed forms ------------------------------------------------------------------------
def limit(d: int) -> int:
    return POS if d > 0 else NEG


def home_edge(d: int, edge: int) -> int:
    """Moving in ``d``, the switch [LO, HI) is reached at LO (d > 0) or HI (d < 0); edge 0
    captures where it is reached, edge 1 where it is left (capture module docstring)."""
    reached, left = (LO, HI) if d > 0 else (HI, LO)
    return reached if edge == 0 else left


def index_beyond(x: float, d: int) -> int:
    """The first index pulse strictly beyond ``x`` in direction ``d``."""
    k = (x - IDX0) / CPR
    n = math.floor(k) + 1 if d > 0 else math.ceil(k) - 1
    return IDX0 + n * CPR


def on_limit(start: float, d: int) -> bool:
    return start >= POS if d > 0 else start <= NEG


def index_search(start: float, d: int) -> int:
    """Mode 30: the first index in ``d``; if that is past the limit, the search turns at the
    limit (or where it stands on it) and takes the first index the other way."""
    first = index_beyond(start, d)
    if (first - limit(d)) * d < 0 and not on_limit(start, d):
        return first
    turn = start if on_limit(start, d) else limit(d)
    return index_beyond(turn, -d)


def expected(mode: int, d: int, start: float, edge: int = 0, idx: int = 1) -> tuple[float, float]:
    """(capturePos, tolerance) of a homing run from ``start``."""
    if mode == HomeMode.LIMIT:
        return limit(d), SAMPLED
    if mode == HomeMode.LIMIT_HOME:
        return home_edge(-d, edge), EXACT
    if mode == HomeMode.LIMIT_INDEX:
        return index_beyond(limit(d), idx), EXACT
    if mode == HomeMode.LIMIT_HOME_INDEX:
        return index_beyond(home_edge(-d, edge), idx), EXACT
    if mode == HomeMode.HOME:
        return home_edge(d, edge), EXACT
    if mode == HomeMode.HOME_INDEX:
        return index_beyond(home_edge(d, edge), idx), EXACT
    if mode == HomeMode.INDEX:
        return index_search(start, d), EXACT
    if mode == HomeMode.FORCED_HOME:
        return home_edge(d, 0), SAMPLED  # sampled: active in d, inactive again going back
    return index_beyond(home_edge(d, 0), idx), EXACT  # FORCED_HOME_INDEX


ALL = tuple(START)
TWO = ("below", "above")
CASES = [
    # (mode, moveDir, edge, indexDir, starts)
    (10, -1, 0, 1, ALL),
    (10, 1, 0, 1, TWO),
    (11, -1, 0, 1, TWO),
    (11, 1, 1, 1, TWO),
    (12, -1, 0, 1, ALL),
    (12, 1, 0, -1, TWO),
    (13, -1, 0, 1, TWO),
    (13, 1, 0, -1, TWO),
    (20, 1, 0, 1, ALL),
    (20, -1, 0, 1, ALL),
    (20, 1, 1, 1, (*TWO, "on home")),
    (20, -1, 1, 1, (*TWO, "on home")),
    (22, 1, 0, 1, ALL),
    (22, 1, 0, -1, TWO),
    (22, -1, 0, 1, TWO),
    (30, 1, 0, 1, ALL),
    (30, -1, 0, 1, ALL),
    (40, 1, 0, 1, ALL),
    (40, -1, 0, 1, TWO),
    (41, 1, 0, -1, (*TWO, "on home")),
]


@pytest.mark.parametrize(
    ("mode", "d", "edge", "idx", "where"),
    [(m, d, e, i, w) for m, d, e, i, starts in CASES for w in starts],
)
@pytest.mark.sample(8)
def test_every_mode_lands_on_the_closed_form(mode, d, edge, idx, where):
    start = START[where]
    ctl = open_card(start)
    offset = -d * OFFSET  # away from the limit the limit modes end next to
    prm = params(mode=mode, moveDir=d, edge=edge, indexDir=idx, homeOffset=offset)
    home, stages, _ = home_run(ctl, prm)
    st = home.status
    assert (st.run, st.stage, st.error) == (0, Stage.END, HomeError.NONE), home.reason
    want, tol = expected(mode, d, start, edge, idx)
    assert abs(st.capturePos - want) <= tol, (st.capturePos, want)
    assert st.targetPos == st.capturePos + offset
    res = home.res
    assert res.profile.planner.pos == st.targetPos  # stands there, in Trap mode
    assert res.profile.planner.done and res.profile.mode == 0
    assert abs(res.encoder.pos - st.targetPos) <= 1  # not zeroed: the encoder reads it
    assert stages[-2:] == [Stage.GO_HOME, Stage.END]


# --- stages and limit flags --------------------------------------------------------------
def test_limit_mode_reports_its_stages_and_the_limit_flag_it_raised_is_gone_at_the_end():
    ctl = open_card(START["below"])
    _, stages, flags = home_run(ctl, params(mode=10, moveDir=-1, escapeStep=1000))
    assert stages == [
        Stage.START,
        Stage.SEARCH_LIMIT,
        Stage.SEARCH_LIMIT_STOP,
        Stage.SEARCH_LIMIT_ESCAPE,
        Stage.SEARCH_LIMIT_RETURN,
        Stage.SEARCH_LIMIT_RETURN_STOP,
        Stage.GO_HOME,
        Stage.END,
    ]
    assert flags & (1 << 6)  # the search raised the negative limit flag (seed 002 clears it)
    sts = c_long()
    gt.GT_GetSts(1, byref(sts))
    assert not sts.value & (1 << 6) and sts.value & (1 << 9)  # cleared (cause gone), servo on


def test_limit_home_index_mode_goes_through_home_return_and_index():
    ctl = open_card(START["above"])
    _, stages, _ = home_run(ctl, params(mode=13, moveDir=-1, indexDir=1))
    assert stages == [
        Stage.START,
        Stage.SEARCH_LIMIT,
        Stage.SEARCH_LIMIT_STOP,
        Stage.SEARCH_HOME,
        Stage.SEARCH_HOME_RETURN,
        Stage.SEARCH_INDEX,
        Stage.GO_HOME,
        Stage.END,
    ]


def test_limit_mode_with_limits_off_stops_on_the_input_itself():
    ctl = open_card(START["above"])
    assert gt.GT_LmtsOff(1) == 0
    home, _, flags = home_run(ctl, params(mode=10, moveDir=-1))
    assert home.status.error == 0
    assert abs(home.status.capturePos - NEG) <= SAMPLED
    assert not flags & (1 << 6)  # the limit check is off: no flag, the search stopped itself


def test_escape_repeats_while_the_limit_is_still_active():
    ctl = open_card(START["on -limit"])  # 200 counts inside the switch
    home, _, _ = home_run(ctl, params(mode=10, moveDir=-1, escapeStep=50))
    assert home.status.error == 0 and abs(home.status.capturePos - NEG) <= SAMPLED


def test_smooth_time_changes_the_moves_not_the_positions():
    ctl = open_card(START["above"])
    home, _, _ = home_run(ctl, params(mode=22, moveDir=1, smoothTime=30))
    assert home.status.capturePos == index_beyond(LO, 1)
    assert home.status.targetPos == index_beyond(LO, 1) + OFFSET


def test_trigger_index_of_the_axis_itself_is_the_same_as_minus_one():
    ctl = open_card(START["below"], axes=2)
    home, _, _ = home_run(ctl, params(mode=20, moveDir=1, triggerIndex=1))
    assert home.status.capturePos == LO


def test_trigger_index_of_another_axis_watches_that_axis():
    ctl = open_card(START["below"], axes=2)  # axis 2 stands still, off every switch
    home, _, _ = home_run(ctl, params(mode=20, moveDir=1, triggerIndex=2, searchHomeDistance=15000))
    assert home.status.error == HomeError.NO_HOME


# --- errors ------------------------------------------------------------------------------
def test_not_trap_mode_off_and_alarm_are_refused_with_their_errors():
    ctl = open_card(START["below"])
    home = smart_home(ctl, 1)
    assert gt.GT_PrfPt(1) == 0  # (a Jog is taken over: test_home_calls)
    with pytest.raises(HomeRefused) as e:
        home.start(params())
    assert e.value.error == HomeError.NOT_TRAP_MODE
    assert (home.status.run, home.status.error) == (0, HomeError.NOT_TRAP_MODE)
    assert gt.GT_PrfTrap(1) == 0
    assert gt.GT_AxisOff(1) == 0
    with pytest.raises(HomeRefused) as e:
        home.start(params())
    assert e.value.error == HomeError.DISABLE
    assert gt.GT_AxisOn(1) == 0
    gt.GTE_Slave(0).channel(0).inject_fault("alarm")
    ctl.clock.advance(5)
    with pytest.raises(HomeRefused) as e:
        home.start(params())
    assert e.value.error == HomeError.ALARM


def test_unknown_mode_is_home_mode_error():
    ctl = open_card(START["below"])
    home = smart_home(ctl, 1)
    with pytest.raises(HomeRefused) as e:
        home.start(params(mode=15))
    assert e.value.error == HomeError.HOME_MODE == home.status.error


@pytest.mark.parametrize(
    "bad",
    [
        dict(moveDir=0),
        dict(indexDir=2),
        dict(edge=2),
        dict(velHigh=0.0),
        dict(velLow=-1.0),
        dict(acc=0.0),
        dict(smoothTime=51),
        dict(triggerIndex=3),
        dict(searchHomeDistance=-1),
        dict(mode=10, escapeStep=0),
        dict(mode=12, moveDir=1, indexDir=1),
        dict(mode=40, triggerIndex=17),
    ],
)
def test_parameters_out_of_range_are_refused(bad):
    ctl = open_card(START["below"])
    home = smart_home(ctl, 1)
    with pytest.raises(ParameterError):
        home.start(params(**bad))
    assert home.status.stage == Stage.IDLE and not home.running


def test_a_second_go_home_while_homing_is_refused():
    ctl = open_card(START["below"])
    home = smart_home(ctl, 1)
    home.start(params())
    ctl.clock.advance(10)
    with pytest.raises(CommandError):
        home.start(params())
    assert home.running


def _start_and_run(ctl, prm, ms: float):
    home = smart_home(ctl, 1)
    home.start(prm)
    ctl.clock.advance(ms)
    assert home.running and home.status.stage == Stage.SEARCH_HOME
    return home


def _finish(ctl, home):
    assert ctl.clock.run_until(lambda: not home.running, 5000)
    return home.status


def test_gt_stop_during_the_search_is_stop_error_and_run_drops_once_standing():
    ctl = open_card(START["below"])
    home = _start_and_run(ctl, params(mode=20), 60)
    assert gt.GT_Stop(1, 0) == 0
    ctl.clock.advance(1)
    assert home.status.run == 1  # still braking
    st = _finish(ctl, home)
    assert (st.run, st.stage, st.error) == (0, Stage.SEARCH_HOME, HomeError.STOP)
    assert home.res.profile.planner.done


def test_axis_off_during_the_search_is_disable_error():
    ctl = open_card(START["below"])
    home = _start_and_run(ctl, params(mode=20), 60)
    assert gt.GT_AxisOff(1) == 0
    assert _finish(ctl, home).error == HomeError.DISABLE


def test_drive_alarm_during_the_search_is_alarm_error():
    ctl = open_card(START["below"])
    home = _start_and_run(ctl, params(mode=20), 60)
    gt.GTE_Slave(0).channel(0).inject_fault("alarm")
    assert _finish(ctl, home).error == HomeError.ALARM


def test_another_motion_command_during_homing_is_stage_error():
    ctl = open_card(START["below"])
    home = _start_and_run(ctl, params(mode=20), 60)
    assert gt.GT_SetVel(1, 5.0) == 0 and gt.GT_SetPos(1, -5000) == 0
    assert gt.GT_Update(1) == 0
    assert _finish(ctl, home).error == HomeError.STAGE


def test_no_home_within_the_search_distance():
    ctl = open_card(START["below"])
    home, _, _ = home_run(ctl, params(mode=20, searchHomeDistance=5000))
    assert home.status.error == HomeError.NO_HOME
    assert home.res.profile.planner.pos == pytest.approx(5000)


def test_no_home_switch_between_the_limits():
    ctl = open_card(START["below"], home_switch=())
    home, _, _ = home_run(ctl, params(mode=20))
    assert (home.status.error, home.status.stage) == (HomeError.NO_HOME, Stage.SEARCH_HOME)


def test_no_index_pulse_at_all():
    ctl = open_card(START["below"], index_offset=None)
    home, _, _ = home_run(ctl, params(mode=30))
    assert (home.status.error, home.status.stage) == (HomeError.NO_INDEX, Stage.SEARCH_INDEX)


def test_no_index_within_the_search_distance():
    ctl = open_card(START["below"])  # next index beyond the home edge 10000: 11234
    home, _, _ = home_run(ctl, params(mode=22, searchIndexDistance=1000))
    assert home.status.error == HomeError.NO_INDEX


def test_a_home_offset_into_the_limit_ends_in_a_stage_error():
    ctl = open_card(START["below"])
    home, _, _ = home_run(ctl, params(mode=10, moveDir=1, homeOffset=500))
    assert (home.status.error, home.status.stage) == (HomeError.STAGE, Stage.GO_HOME)


def test_gt_reset_ends_a_homing_and_restores_the_defaults():
    ctl = open_card(START["below"])
    home = _start_and_run(ctl, params(mode=20, velHigh=12.5), 60)
    assert gt.GT_Reset() == 0
    ctl.clock.advance(5)
    assert not home.running
    assert home.params == HomeParams() and home.status.stage == Stage.IDLE


def test_gt_stop_while_the_search_stops_at_the_limit_ends_the_homing():
    """GT_Stop in stage 11 (the axis braking at the limit it found, a stop of the search's
    own): the homing ends with the stop error there, and the axis does not move again."""
    ctl = open_card(START["below"])
    home = smart_home(ctl, 1)
    home.start(params(mode=10, moveDir=-1, escapeStep=1000))
    assert ctl.clock.run_until(lambda: home.status.stage == Stage.SEARCH_LIMIT_STOP, 60_000)
    assert gt.GT_Stop(1, 0) == 0
    st = _finish(ctl, home)
    assert (st.run, st.stage, st.error) == (0, Stage.SEARCH_LIMIT_STOP, HomeError.STOP)
    here = home.res.profile.planner.pos
    ctl.clock.advance(500)
    assert home.res.profile.planner.pos == here and home.res.profile.planner.done
