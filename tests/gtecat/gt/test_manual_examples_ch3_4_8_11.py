"""The manual's examples 3-1, 4-1, 4-2, 8-1 and 11-1, written as printed, on the emulated bus.

Each test carries one example's PLC program call for call, in the manual's order,
translated the way ctypes code for the vendor DLL reads: ``ADR(x)`` -> ``byref(x)``,
a literal ``0`` pointer stays ``0``, ``DWORD``/``long *`` -> ``c_long``, ``LREAL``
arrays -> ``c_double * n``, ``POINTER TO STRING`` -> ``c_char_p``.  Around the
program, a test sets up what the example assumes (bus up, a machine) and checks
what the manual says the example achieves.  The same programs are shipped as
``examples/example_3_1_return_codes.py``, ``example_4_1_enc_sns.py``,
``example_4_2_lmts_off.py``, ``example_8_1_encoder.py`` and ``example_11_1_version.py``;
the last test runs those scripts.
"""

from __future__ import annotations

import importlib.util
import re
import sys
from ctypes import byref, c_char_p, c_double, c_long, create_string_buffer

import pytest

from gtecat import gt
from gtecat.drives.machine import AxisMachine, MachineDescription
from tests.conftest import EXAMPLES
from tests.gtecat.gt.conftest import bring_up

CLOCKS = pytest.mark.parametrize("clock", ["lockstep", "auto"])
ALARM, MERROR, POS_LIMIT, NEG_LIMIT = 1 << 1, 1 << 4, 1 << 5, 1 << 6
SMOOTH_STOP, ABRUPT_STOP, SERVO, MOVING = 1 << 7, 1 << 8, 1 << 9, 1 << 10
ERROR_BITS = ALARM | MERROR | POS_LIMIT | NEG_LIMIT | SMOOTH_STOP | ABRUPT_STOP
# table 11-3: "aaa bbbbbb ccc dddddd", a string of 18 characters (the digits)
TABLE_11_3 = re.compile(rb"\d{3} ?\d{6} ?\d{3} ?\d{6}")


# --- what the examples stand on -------------------------------------------------------------
def status(axis: int) -> int:
    sts = c_long()
    assert gt.GT_GetSts(axis, byref(sts), 1, None) == 0, gt.GTE_GetLastError()
    return sts.value


def prf_pos(axis: int) -> float:
    v = c_double()
    assert gt.GT_GetPrfPos(axis, byref(v), 1, None) == 0, gt.GTE_GetLastError()
    return v.value


def enc_pos(axis: int) -> float:
    v = c_double()
    assert gt.GT_GetEncPos(axis, byref(v), 1, None) == 0, gt.GTE_GetLastError()
    return v.value


def start_trap(axis: int, distance: int, vel: float = 10) -> None:
    """A Trap move of ``distance`` pulses from where the profile stands (manual 7.2)."""
    assert gt.GT_AxisOn(axis) == 0, gt.GTE_GetLastError()
    assert gt.GT_PrfTrap(axis) == 0, gt.GTE_GetLastError()
    prm = gt.TTrapPrm()
    assert gt.GT_GetTrapPrm(axis, byref(prm)) == 0
    prm.acc, prm.dec = 1, 1
    assert gt.GT_SetTrapPrm(axis, byref(prm)) == 0, gt.GTE_GetLastError()
    assert gt.GT_SetPos(axis, round(prf_pos(axis)) + distance) == 0, gt.GTE_GetLastError()
    assert gt.GT_SetVel(axis, vel) == 0, gt.GTE_GetLastError()


def wait_stopped(*axes: int, limit_ms: int = 10_000) -> None:
    """Until bit 10 falls on every axis; bounded (a PLC would scan for ever)."""
    for _ in range(limit_ms):
        gt.GTE_Wait(1)
        if not any(status(a) & MOVING for a in axes):
            return
    raise AssertionError(f"axes {axes} still moving after {limit_ms} ms")


# --- example 3-1 ----------------------------------------------------------------------------
ERR_INFO: list[str] = []


def commandhandler(command: str, error: int) -> int:
    """FUNCTION commandhandler of example 3-1 (errInfo kept in ERR_INFO for the test)."""
    errInfo = ""
    if error != 0:
        errInfo = command + " = "
        errInfo = errInfo + str(error)
        ERR_INFO.append(errInfo)
    return 0  # the ST function never assigns its INT result


@CLOCKS
def test_example_3_1_gtn_getsts_return_value_checked(clock):
    """Example 3-1: ``rtn:= GT_GetSts(1,1,ADR(sts),1,0); commandhandler('GT_GetSts',rtn);``.

    Five arguments, the title says "GTN 指令": core 1 (EtherCAT), axis 1, count 1,
    pClock 0 - ``GTN_GetSts`` through ctypes.
    """
    bring_up(clock=clock)
    ERR_INFO.clear()
    sts = c_long()  # sts: DWORD (long *pSts)
    rtn = gt.GTN_GetSts(1, 1, byref(sts), 1, 0)
    commandhandler("GT_GetSts", rtn)  # check the return value
    assert rtn == 0, gt.GTE_GetLastError()
    assert ERR_INFO == []  # the handler builds no errInfo for 0 (table 3-1: success)
    assert sts.value & (ERROR_BITS | SERVO | MOVING) == 0  # a fresh bus: off, still, no flag
    assert sts.value == status(1)  # the GTN twin reads the same word as GT_GetSts(1, ...)

    # The handler's other branch: a command that fails reports "<command> = <code>".
    rtn = gt.GTN_GetSts(1, 99, byref(sts), 1, 0)
    commandhandler("GT_GetSts", rtn)
    assert rtn == 7 and ERR_INFO == ["GT_GetSts = 7"]  # table 3-1: parameter error
    # Read as the core-less GT_GetSts, the five printed arguments are a parameter error
    # (return code, not an exception).
    assert gt.GT_GetSts(1, 1, byref(sts), 1, 0) == 7


# --- example 4-1 ----------------------------------------------------------------------------
@CLOCKS
def test_example_4_1_enc_sns_reverses_encoder_1_only(clock):
    """Example 4-1: ``rtn:= GT_EncSns(16#01);`` - encoder 1 reversed, the others not."""
    bring_up(clock=clock)
    assert gt.GT_Reset() == 0
    gt.GTE_Wait(1)

    rtn = gt.GT_EncSns(0x01)
    assert rtn == 0, gt.GTE_GetLastError()

    prf0 = {a: prf_pos(a) for a in (1, 2)}
    enc0 = {a: enc_pos(a) for a in (1, 2)}
    for axis in (1, 2):
        start_trap(axis, 1000)
    assert gt.GT_Update(0b11) == 0, gt.GTE_GetLastError()
    wait_stopped(1, 2)
    gt.GTE_Wait(5)
    assert {a: prf_pos(a) - prf0[a] for a in (1, 2)} == {1: 1000, 2: 1000}
    # table 4-3: bit 0 = Enc1 counts the other way; Enc2 (bit 1 = 0) as before
    assert {a: enc_pos(a) - enc0[a] for a in (1, 2)} == {1: -1000, 2: 1000}
    assert status(1) & ERROR_BITS == 0 and status(2) & ERROR_BITS == 0


# --- example 4-2 ----------------------------------------------------------------------------
@CLOCKS
def test_example_4_2_lmts_off_disables_axis_1_limit_alarm(clock):
    """Example 4-2: ``rtn:= GT_LmtsOff(1, -1);`` - axis 1's limit alarm no longer counts.

    Axis 1 stands on its positive limit switch (example_4_3_machine.toml).  With the
    limits watched, GT_ClrSts cannot clear bit 5; after the example it can (the flag is
    latched, 9.2), and the axis moves on toward the switch.
    """
    bring_up(clock=clock, machine=str(EXAMPLES / "example_4_3_machine.toml"))
    assert gt.GT_Reset() == 0
    gt.GTE_Wait(1)
    assert status(1) & POS_LIMIT
    assert gt.GT_ClrSts(1, 1) == 0
    gt.GTE_Wait(1)
    assert status(1) & POS_LIMIT  # default: limits valid ("默认的限位报警是有效的")

    rtn = gt.GT_LmtsOff(1, -1)  # limit alarm off
    assert rtn == 0, gt.GTE_GetLastError()

    assert gt.GT_ClrSts(1, 1) == 0
    gt.GTE_Wait(10)
    assert status(1) & (POS_LIMIT | NEG_LIMIT) == 0
    start_trap(1, 1000)
    assert gt.GT_Update(1) == 0, gt.GTE_GetLastError()  # toward the (ignored) switch
    wait_stopped(1)
    assert prf_pos(1) == 205000 + 1000
    assert status(1) & (ERROR_BITS | MOVING) == 0


# --- example 8-1 ----------------------------------------------------------------------------
EIGHT_AXES = MachineDescription(axes={n: AxisMachine(position=1000.0 * n) for n in range(1, 9)})


@CLOCKS
def test_example_8_1_reads_eight_encoders(clock):
    """Example 8-1: ``GT_GetEncPos(1, ADR(enc), 8,0); GT_GetEncVel(1, ADR(vel), 8,0);``.

    Eight encoders: the twelve-axis bus, mechanics of axis n at n·1000 counts.
    """
    bring_up("twelve_axes.eni", clock=clock, machine=EIGHT_AXES)
    assert gt.GT_Reset() == 0
    gt.GTE_Wait(1)

    enc = (c_double * 8)()  # enc: ARRAY [0..7] OF LREAL
    vel = (c_double * 8)()  # vel: ARRAY [0..7] OF LREAL
    rtn = gt.GT_GetEncPos(1, byref(enc), 8, 0)  # the positions of 8 encoders
    assert rtn == 0, gt.GTE_GetLastError()
    rtn = gt.GT_GetEncVel(1, byref(vel), 8, 0)  # the speeds of 8 encoders
    assert rtn == 0, gt.GTE_GetLastError()
    assert list(enc) == [1000.0 * n for n in range(1, 9)]  # "总线上反馈的实际编码器增量值"
    assert list(vel) == [0.0] * 8

    start_trap(1, 5000, vel=10)
    assert gt.GT_Update(1) == 0, gt.GTE_GetLastError()
    gt.GTE_Wait(200)  # constant speed by now
    rtn = gt.GT_GetEncPos(1, byref(enc), 8, 0)
    assert rtn == 0, gt.GTE_GetLastError()
    rtn = gt.GT_GetEncVel(1, byref(vel), 8, 0)
    assert rtn == 0, gt.GTE_GetLastError()
    assert 1000 < enc[0] < 6000 and list(enc)[1:] == [1000.0 * n for n in range(2, 9)]
    assert vel[0] == pytest.approx(10) and list(vel)[1:] == [0.0] * 7


def test_example_8_1_as_printed_on_the_figure_5_2_bus():
    bring_up(clock="lockstep")
    enc = (c_double * 8)()
    vel = (c_double * 8)()
    rtn_pos = gt.GT_GetEncPos(1, byref(enc), 8, 0)
    rtn_vel = gt.GT_GetEncVel(1, byref(vel), 8, 0)
    # the count rule (resources.axis_span): encoders 3..8 exist without a drive and read 0
    assert (rtn_pos, rtn_vel) == (0, 0), gt.GTE_GetLastError()
    assert list(enc)[2:] == [0.0] * 6 and list(vel)[2:] == [0.0] * 6


# --- example 11-1 ---------------------------------------------------------------------------
@CLOCKS
def test_example_11_1_reads_the_firmware_version(clock):
    """Example 11-1: ``rtn:= GT_GetVersion(ADR(pVersion)); firmwareVersion:=pVersion^;``."""
    bring_up(clock=clock)
    pVersion = c_char_p()  # pVersion: POINTER TO STRING
    rtn = gt.GT_GetVersion(byref(pVersion))  # read the version
    firmwareVersion = pVersion.value
    assert rtn == 0, gt.GTE_GetLastError()
    assert firmwareVersion is not None and TABLE_11_3.fullmatch(firmwareVersion)


def test_example_11_1_version_string_has_the_form_of_table_11_3():
    """The same read through entry 78's ``char *pVersion`` (a caller's buffer)."""
    bring_up(clock="lockstep")
    buf = create_string_buffer(64)
    assert gt.GT_GetVersion(buf) == 0, gt.GTE_GetLastError()
    assert TABLE_11_3.fullmatch(buf.value), buf.value


# --- the scripts ----------------------------------------------------------------------------
def example(name: str):
    """examples/<name>.py as a module (examples/ is not a package)."""
    if name not in sys.modules:
        spec = importlib.util.spec_from_file_location(name, EXAMPLES / f"{name}.py")
        assert spec is not None and spec.loader is not None
        mod = importlib.util.module_from_spec(spec)
        sys.modules[name] = mod
        spec.loader.exec_module(mod)
    return sys.modules[name]


@pytest.mark.parametrize(
    "name",
    [
        "example_3_1_return_codes",
        "example_4_1_enc_sns",
        "example_4_2_lmts_off",
        "example_8_1_encoder",
        "example_11_1_version",
    ],
)
def test_example_scripts_succeed(name, capsys):
    assert example(name).main() == 0, capsys.readouterr().out
