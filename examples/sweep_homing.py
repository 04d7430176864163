"""A homing sweep: does homing find the switch on every machine we ship?

Run it over the grid beside it (1,000 machine variants, one worker process per CPU):

    gtecat sweep sweep_homing.py --grid sweep_homing.toml -o results.parquet
    gtecat sweep report results.parquet

Each case: the manual's example 5-2 homing sequence on axis 1, with the case's homing
method and speed, on a machine whose home switch edge and encoder index phase vary within
their tolerance. The application's requirement: homed (status 3), the home point on the
switch edge for method 19 (on the start position for method 35), within 2.5 s.
"""

from ctypes import byref, c_double, c_short, c_ulong

AXIS = 1
TIME_BUDGET_MS = 2500


def check(gt, rc):
    if rc != 0:
        raise RuntimeError(gt.GTE_GetLastError())


def scenario(gt, case):
    method, speed = case["method"], case["speed"]
    start = c_double()
    check(gt, gt.GTE_GetMachinePos(AXIS, byref(start)))
    check(gt, gt.GT_AxisOn(AXIS))
    check(gt, gt.GT_SetHomingMode(AXIS, 6))  # manual example 5-2
    check(gt, gt.GT_SetEcatHomingPrm(AXIS, method, speed, speed / 10, 400000, 0, 0))
    t0 = c_ulong()
    check(gt, gt.GT_GetClock(byref(t0)))
    check(gt, gt.GT_StartEcatHoming(AXIS))
    status = c_short()
    for _ in range(10_000):  # one poll per millisecond, like a 1 ms PLC task
        check(gt, gt.GT_GetEcatHomingStatus(AXIS, byref(status)))
        if status.value & 1:
            break
        gt.GTE_Wait(1)
    t1 = c_ulong()
    check(gt, gt.GT_GetClock(byref(t1)))
    check(gt, gt.GT_SetHomingMode(AXIS, 8))
    end = c_double()
    check(gt, gt.GTE_GetMachinePos(AXIS, byref(end)))
    # where the home point should be: the switch's edge, or where the axis stood (method 35)
    edge = case.get("machine.axis.1.home_switch.0.0", 100000)
    expected = edge if method == 19 else start.value
    error = end.value - expected
    homing_ms = t1.value - t0.value
    return {
        "status": status.value,
        "home_pos": end.value,
        "error_counts": error,
        "homing_ms": homing_ms,
        "ok": status.value == 3 and abs(error) <= 1 and homing_ms <= TIME_BUDGET_MS,
    }
