"""The program runtime: instruction rate, interleaving, GT_Delay, bindings, faults, GT calls."""

from __future__ import annotations

import ctypes

import pytest

from gtecat.programs import fixed
from gtecat.programs.threads import Fault, RuntimeRefusal, ThreadState

LOOP = """\
int n;
int count;
int f()
{
    int i;
    int cc;
    i = 0;
top:
    i = i + 1;
    cc = i < n;
    if(cc) goto top;
    count = count + 1;
    return i;
}
"""


def loop_instructions(n: int) -> int:
    return 1 + 3 * n + 2  # i = 0; n x (add, compare, jump); count++; return


@pytest.mark.parametrize(("n", "speed"), [(1000, 100), (333, 100), (50, 7), (1000, 1000)])
def test_a_busy_loop_costs_controller_time_at_the_instruction_rate(host, n, speed):
    h = host(LOOP, speed=speed)
    h.set_g("n", n)
    h.start()
    need = loop_instructions(n)
    ms = -(-need // speed)  # ceil: the thread ends in its ms-th cycle
    h.ms(ms - 1)
    assert h.rt.status(0).run == 1
    h.ms(1)
    st = h.rt.status(0)
    assert (st.run, st.error, st.result) == (0, 0, n)
    assert h.rt.executed == need


def test_fractional_rates_carry_over_while_running(host):
    h = host(LOOP, speed=2.5)
    h.set_g("n", 3)  # 12 instructions: 2.5 per ms -> ends in the 5th ms
    h.start()
    assert [h.ms() for _ in range(5)] == [2, 3, 2, 3, 2]


def test_threads_share_the_rate_round_robin_and_interleave(host):
    src = """\
int trace[8];
int k;
int f(int me)
{
    trace[k] = me;
    k = k + 1;
    trace[k] = me;
    k = k + 1;
    return 0;
}
"""
    h = host(src, speed=100)
    f = h.program.functions[0]
    for t in (0, 1):
        h.rt.bind(t, f.id, t)
        h.rt.pages[t][0] = 10 + t  # parameter "me" on each thread's page
        h.rt.run(t)
    h.ms()
    # one instruction each in turn: both write trace[0] (1 last), both step k, both
    # write trace[2]: the 10.2 note's interleaving
    assert h.garr("trace") == [11, 0, 11, 0, 0, 0, 0, 0]
    assert h.g("k") == 4


def test_read_modify_write_across_instructions_loses_updates_an_atomic_one_does_not(host):
    src = """\
int shared;
int atomic;
int f()
{
    int t;
    int i;
    int cc;
    i = 0;
top:
    t = shared;
    t = t + 1;
    shared = t;
    atomic = atomic + 1;
    i = i + 1;
    cc = i < 100;
    if(cc) goto top;
    return 0;
}
"""
    h = host(src)
    f = h.program.functions[0]
    for t in (0, 1):
        h.rt.bind(t, f.id, t)
        h.rt.run(t)
    h.until_idle()
    assert h.g("atomic") == 200  # one instruction: never interleaved (10.2 note)
    assert h.g("shared") == 100  # lockstep interleaving: every update of one thread lost


def test_gt_delay_sleeps_in_controller_time_while_others_run(host):
    src = """\
int woke;
int ticks;
int sleeper()
{
    GT_Delay(10);
    woke = 1;
    return 0;
}
int counter()
{
top:
    ticks = ticks + 1;
    goto top;
}
"""
    h = host(src, speed=10)
    h.start(0, "sleeper")
    h.start(1, "counter")
    h.ms(10)
    assert h.g("woke") == 0 and h.rt.status(0).run == 1
    h.ms(1)
    assert h.g("woke") == 1 and h.rt.status(0).run == 0
    assert h.g("ticks") > 40


def test_pause_resume_stop(host):
    h = host(LOOP, speed=10)
    h.set_g("n", 100)
    h.start()
    h.ms(2)
    h.rt.pause(0)
    assert h.rt.status(0).run == 2
    before = h.rt.executed
    h.ms(5)
    assert h.rt.executed == before
    h.rt.run(0)  # resumes where it stood
    assert h.rt.status(0).run == 1
    h.until_idle()
    assert h.rt.status(0).result == 100 and h.g("count") == 1
    h.start()  # a finished thread starts again from the top (its locals kept)
    h.ms(1)
    h.rt.stop(0)
    assert h.rt.status(0).run == 0
    with pytest.raises(RuntimeRefusal) as e:
        h.rt.pause(0)
    assert e.value.code == 1


def test_binding_rules(host):
    h = host(LOOP + "int g2()\n{\n    return 2;\n}\n")
    rt = h.rt
    with pytest.raises(RuntimeRefusal) as e:
        rt.run(5)
    assert e.value.code == 1 and "not bound" in str(e.value)
    rt.bind(0, 0, 0)
    with pytest.raises(RuntimeRefusal) as e:
        rt.bind(1, 0, 0)  # page 0 serves thread 0
    assert e.value.code == 1 and "page 0 belongs to thread 0" in str(e.value)
    rt.bind(1, 0, 1)  # one function on several threads
    with pytest.raises(RuntimeRefusal) as e:
        rt.bind(2, 7, 2)
    assert e.value.code == 7
    h.set_g("n", 1000)
    rt.run(0)
    with pytest.raises(RuntimeRefusal) as e:
        rt.bind(0, 1, 0)  # running: no new function
    assert e.value.code == 1
    with pytest.raises(RuntimeRefusal) as e:
        rt.run(0)
    assert "already running" in str(e.value)
    rt.stop(0)
    rt.bind(0, 1, 5)  # rebinding frees page 0
    rt.bind(2, 0, 0)


def test_runtime_faults_stop_the_thread_with_error_and_line(host):
    src = """\
int arr[3];
int k;
int divide(int b)
{
    int a;
    a = 10;
    a = a / b;
    return a;
}
int index()
{
    int v;
    v = arr[k];
    return v;
}
"""
    h = host(src)
    h.start(0, "divide")
    h.until_idle()
    st = h.rt.status(0)
    assert (st.run, st.error, st.line) == (0, Fault.DIVISION_BY_ZERO, 7)
    assert "line 7 (divide): division by zero" == h.rt.reason(0)
    h.set_g("k", 3)
    h.start(1, "index")
    h.until_idle()
    st = h.rt.status(1)
    assert (st.error, st.line) == (Fault.INDEX_OUT_OF_RANGE, 13)
    assert "index 3 out of range 0..2" in h.rt.reason(1)


def test_gt_calls_get_c_values_and_write_back_what_the_call_wrote(host):
    src = """\
double pos[3];
int sts;
int clk;
double prm[4];
int rtn;
int f()
{
    GT_SetVel(2, 0.5);
    GT_SetPos(1, -5);
    GT_Stop(0xFFFFFFFF, 0);
    GT_GetPrfPos(1, &pos[1], 2, &clk);
    rtn = GT_GetSts(3, &sts, 1, 0);
    GT_SetTrapPrm(1, prm);
    GT_GetTrapPrm(1, prm);
    return 0;
}
"""

    def get_prf_pos(args):
        _profile, values, count, clock = args
        assert count == 2 and len(values) == 2  # the room from pos[1] to the end
        values[0], values[1] = 1.25, -3.5
        clock[0] = 4_000_000_000  # unsigned long: an int holds its bit pattern
        return 0

    def get_sts(args):
        args[1][0] = 0x400
        assert args[3] is None  # 0 for an optional pointer: NULL
        return 0

    def set_trap(args):
        s = args[1]
        assert (s.acc, s.dec, s.velStart, s.smoothTime) == (0.5, 0.25, 0.0, 3)
        return 0

    def get_trap(args):
        s = args[1]
        s.acc, s.dec, s.velStart, s.smoothTime = 1.0, 2.0, 0.125, 25
        return 0

    h = host(
        src,
        answers={
            "GT_GetPrfPos": get_prf_pos,
            "GT_GetSts": get_sts,
            "GT_SetTrapPrm": set_trap,
            "GT_GetTrapPrm": get_trap,
        },
    )
    for k, v in enumerate((0.5, 0.25, 0.0, 3.0)):
        h.set_g("prm", fixed.from_float(v), k)
    h.start()
    h.until_idle()
    assert h.rt.status(0).error == 0, h.rt.reason(0)
    names = [c[0] for c in h.calls]
    assert names[:3] == ["GT_SetVel", "GT_SetPos", "GT_Stop"]
    assert h.calls[0][1] == (2, 0.5)
    assert h.calls[1][1] == (1, -5)
    assert h.calls[2][1] == (0xFFFFFFFF, 0)  # a mask: the bit pattern, as C converts it
    assert [fixed.to_float(w) for w in h.garr("pos")] == [0.0, 1.25, -3.5]
    assert h.g("clk") == fixed.wrap32(4_000_000_000)
    assert h.g("sts") == 0x400 and h.g("rtn") == 0
    assert [fixed.to_float(w) for w in h.garr("prm")] == [1.0, 2.0, 0.125, 25.0]
    assert isinstance(h.calls[3][1][1], ctypes.Array)


def test_a_gt_call_returning_non_zero_stops_the_thread(host):
    src = "int f()\n{\n    GT_SetVel(99, 1.0);\n    return 1;\n}\n"
    h = host(src, answers={"GT_SetVel": lambda args: 7})
    h.start()
    h.until_idle()
    st = h.rt.status(0)
    assert (st.run, st.error, st.line, st.result) == (0, 7, 3, 0.0)
    assert "GT_SetVel returned 7: refused" in h.rt.reason(0)


def test_a_double_result_outside_16_16_is_a_fault(host):
    src = "double p;\nint f()\n{\n    GT_GetPrfPos(1, &p, 1, 0);\n    return 0;\n}\n"

    def big(args):
        args[1][0] = 100000.0
        return 0

    h = host(src, answers={"GT_GetPrfPos": big})
    h.start()
    h.until_idle()
    assert h.rt.status(0).error == Fault.VALUE_OUT_OF_RANGE
    assert "outside the motion-program double range" in h.rt.reason(0)


def test_set_data_page_switches_the_locals(host):
    src = """\
int seen;
int f()
{
    int x;
    x = 1;
    GT_SetDataPage(7);
    seen = x;
    return 0;
}
"""
    h = host(src)
    h.rt.pages[7][0] = 42
    h.start(0, page=3)
    h.until_idle()
    assert h.g("seen") == 42 and h.rt.pages[3][0] == 1
    assert h.rt.page_owner[7] == 0
    h.rt.bind(1, 0, 4)
    h.rt.pages[4][0] = 0
    h.rt.run(1)  # page 7 stays thread 0's until thread 0 runs again or is rebound
    h.until_idle()
    assert h.rt.status(1).error == Fault.PAGE_TAKEN


def test_variables_by_id_and_count(host):
    h = host("int a[10];\ndouble d;\nint f(int p)\n{\n    return p;\n}\n")
    rt = h.rt
    a = rt.variable(None, "a")
    rt.set_values(-1, a.address + 4, 0, "a", [1, 2, 3, 4, 5, 6])
    assert h.garr("a") == [0, 0, 0, 0, 1, 2, 3, 4, 5, 6]
    assert rt.get_values(-1, a.address + 8, 0, "a", 2) == [5.0, 6.0]
    with pytest.raises(RuntimeRefusal) as e:
        rt.get_values(-1, a.address + 8, 0, "a", 3)
    assert e.value.code == 7 and "runs past a" in str(e.value)
    d = rt.variable(None, "d")
    rt.set_values(-1, d.address, 1, "d", [0.1])
    assert rt.get_values(-1, d.address, 1, "d", 1) == [6554 / 65536]
    with pytest.raises(RuntimeRefusal):
        rt.set_values(-1, d.address, 1, "d", [40000.0])
    with pytest.raises(RuntimeRefusal):
        rt.get_values(-1, d.address, 0, "d", 1)  # dataType says int
    p = rt.variable("f", "p")
    rt.set_values(5, p.address, 0, "p", [7.4])
    assert rt.pages[5][p.address] == 7
    with pytest.raises(RuntimeRefusal):
        rt.variable("f", "nope")
    with pytest.raises(RuntimeRefusal):
        rt.function_id("nope")


def test_download_resets_everything(host):
    h = host("int g = 5;\nint f()\n{\ntop:\n    goto top;\n}\n")
    assert h.g("g") == 5
    h.start()
    h.ms(1)
    h.rt.globals[0] = 9
    h.rt.download(h.program)
    assert h.g("g") == 5 and h.rt.status(0).run == 0
    assert h.rt.threads[0].function is None and not h.rt.page_owner
    assert h.rt.threads[0].state is ThreadState.IDLE
