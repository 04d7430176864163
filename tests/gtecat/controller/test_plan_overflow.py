"""An axis whose checks are off jogs past every drive count (outside check of issue 17): the
planned position beyond 2**63 counts and then beyond every float. The scalar path takes the
exact integer's low 32 bits for 607Ah; a position that is not a number has no counts, so 607Ah
holds, the axis alarms (GT_GetSts bit 1) and goes servo off, and GT_ClrSts + GT_AxisOn recover.
The bank (compiled and numpy) hands such rows to the scalar path: the same bytes, the same
codes, no warning and no internal error."""

from __future__ import annotations

import os
import re
import warnings
from ctypes import byref, c_long, c_short, c_ubyte
from pathlib import Path

import pytest

from gtecat import gt

ROOT = Path(__file__).resolve().parents[3]
STS_ALARM, STS_SERVO_ON = 1 << 1, 1 << 9
RECOVER = 220  # the cycle of GT_ClrSts + GT_AxisOn after an alarm (the jog overflows at ~180)


def _run(tmp: Path, bank: str, kernel: str, vel: float) -> tuple[list, list]:
    cfg = re.sub(r"(\[axis1\]\nactive=)1", r"\g<1>0", (ROOT / "examples" / "test.cfg").read_text())
    (tmp / "off.cfg").write_text(cfg)  # axis 1: no following-error or limit checks
    (tmp / "m.toml").write_text("[axis.1]\nfollowing_error_window = 0\n")
    os.environ["GTECAT_BANK_KERNEL"] = kernel
    try:
        rc = gt.GT_Open(
            eni=str(ROOT / "examples" / "full_servo.eni"),
            machine=str(tmp / "m.toml"),
            clock="lockstep",
            log="",
            bank=bank,
        )
    finally:
        del os.environ["GTECAT_BANK_KERNEL"]
    assert rc == 0
    codes, trace = [], []
    try:
        codes.append(gt.GT_InitEcatComm())
        ready = c_short()
        while not ready.value:
            gt.GT_IsEcatReady(byref(ready))
            gt.GTE_Wait(1)
        codes += [gt.GT_StartEcatComm(), gt.GT_LoadConfig(str(tmp / "off.cfg")), gt.GT_AxisOn(1)]
        codes.append(gt.GT_PrfJog(1))
        prm = gt.TJogPrm()
        prm.acc = prm.dec = vel
        codes += [gt.GT_SetJogPrm(1, byref(prm)), gt.GT_SetVel(1, vel), gt.GT_Update(1)]
        size = gt.GTE_Controller().layout.gt_raw_bytes
        raw, sts = (c_ubyte * size)(), c_long()
        for k in range(260):
            codes.append(gt.GTE_Wait(1))
            gt.GT_GetEcatRawData(0, size, raw)
            gt.GT_GetSts(1, byref(sts))
            trace.append((bytes(raw), sts.value))
            if k == RECOVER and sts.value & STS_ALARM:
                codes += [gt.GT_ClrSts(1), gt.GT_AxisOn(1)]
    finally:
        gt.GT_Close()
    return codes, trace


@pytest.mark.parametrize("vel", [1e17, 1e306], ids=["past 2**63 counts", "into infinity"])
def test_bank_and_scalar_agree_and_nothing_raises(tmp_path: Path, vel: float) -> None:
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # a numpy RuntimeWarning would be a defect here
        ref_codes, ref = _run(tmp_path, "off", "c", vel)
        for kernel in ("c", "numpy"):
            codes, got = _run(tmp_path, "on", kernel, vel)
            assert codes == ref_codes, kernel
            assert got == ref, kernel
    assert -7 not in ref_codes and set(ref_codes) == {0}
    stss = [s for _, s in ref]
    if vel > 1e300:  # not a number of counts: alarm and servo off, then recovered
        assert stss[RECOVER] & STS_ALARM and not stss[RECOVER] & STS_SERVO_ON
        assert stss[-1] & STS_SERVO_ON and not stss[-1] & STS_ALARM
    else:  # past 2**63 counts: 607Ah keeps taking the exact count's low 32 bits, no alarm
        assert not any(s & STS_ALARM for s in stss)
        assert len({raw[2:6] for raw, _ in ref[-20:]}) > 1  # 607Ah (axis 1) still changes
