"""Manual example 4-3, "initialise the controller's configuration", against the emulator.

    python example_4_3_init.py

GT_Reset, the alarm and the limit switches of axis 1 switched off, GT_ClrSts so
that the configuration takes effect ("通过指令配置控制器之后，用户必须调用指令
GT_ClrSts 更新状态，使得配置生效", 4.5.3), then GT_AxisOn.

The machine (``example_4_3_machine.toml``) leaves axis 1 standing on its positive
limit switch: after GT_Reset the status word shows bit 5; it stays set after
GT_LmtsOff (a latched flag) and goes with GT_ClrSts, because its cause - an
enabled, active switch - is gone.
"""

from __future__ import annotations

import sys
from ctypes import byref, c_long, c_short
from pathlib import Path

from gtecat import gt

HERE = Path(__file__).resolve().parent
ENI = HERE / "manual_fig5_2.eni"
MACHINE = HERE / "example_4_3_machine.toml"
LOG: list[str] = []


def commandhandler(command: str, rtn: int) -> None:
    """The manual's error hook: record every non-zero return with its reason."""
    if rtn != 0:
        LOG.append(gt.GTE_GetLastError() or f"{command} = {rtn}")


def status(axis: int) -> int:
    sts = c_long()
    gt.GT_GetSts(axis, byref(sts), 1, None)
    return sts.value


def plc_prg(trace: dict[str, int]) -> None:
    """Example 4-3 (one pass), with the status word read between the steps."""
    rtn = gt.GT_Reset()  # reset the system
    commandhandler("GT_Reset", rtn)
    gt.GTE_Wait(1)  # one cycle: the flags see the machine again
    trace["after_reset"] = status(1)
    rtn = gt.GT_AlarmOff(1)  # axis 1's alarm invalid
    commandhandler("GT_AlarmOff", rtn)
    rtn = gt.GT_LmtsOff(1, -1)  # axis 1's positive and negative limits invalid
    commandhandler("GT_LmtsOff", rtn)
    trace["after_lmts_off"] = status(1)
    rtn = gt.GT_ClrSts(1, 1)  # update the status after configuring
    commandhandler("GT_ClrSts", rtn)
    trace["after_clr_sts"] = status(1)
    rtn = gt.GT_AxisOn(1)  # axis 1 servo on
    commandhandler("GT_AxisOn", rtn)
    trace["after_axis_on"] = status(1)


def bring_up(**options: object) -> None:
    """Manual example 5-5: open, initialise, wait until the bus is ready, start."""
    options.setdefault("log", "")
    options.setdefault("machine", str(MACHINE))
    commandhandler("GT_Open", gt.GT_Open(eni=str(ENI), **options))
    commandhandler("GT_InitEcatComm", gt.GT_InitEcatComm())
    ready = c_short()
    for _ in range(10_000):
        if gt.GT_IsEcatReady(byref(ready)) == 0 and ready.value == 1:
            break
        gt.GTE_Wait(1)
    commandhandler("GT_StartEcatComm", gt.GT_StartEcatComm())


def run(**options: object) -> dict[str, object]:
    LOG.clear()
    gt.GT_Close()
    bring_up(**options)
    try:
        trace: dict[str, int] = {}
        plc_prg(trace)
        return {**trace, "errors": list(LOG)}
    finally:
        gt.GT_Close()


def main() -> int:
    r = run()
    for key in ("after_reset", "after_lmts_off", "after_clr_sts", "after_axis_on"):
        print(f"{key:15s} status 0x{r[key]:04X}")
    for line in r["errors"]:
        print("error:", line)
    ok = not r["errors"] and r["after_clr_sts"] & (1 << 5) == 0 and r["after_axis_on"] & (1 << 9)
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
