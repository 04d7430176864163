"""A session with a fault to record and replay: 12 axes, 60 virtual seconds of Trap moves,
the status of each axis polled every 10 ms; an overcurrent on axis 5 at 20 s for 200 ms; the
application clears it (GT_ClrSts, GT_AxisOn) and goes on.  Its replay should run about as fast
as the same session's without the fault (``--no-fault``)::

    gtecat record -o fault.gtrec -- python tools/fault_session.py
    /usr/bin/time gtecat replay fault.gtrec
"""

import sys
from ctypes import byref, c_long, c_short
from pathlib import Path

from gtecat import faults, gt

ENI = str(Path(__file__).resolve().parents[1] / "examples" / "twelve_axes.eni")
assert gt.GT_Open(eni=ENI, clock="auto", log="") == 0
assert gt.GT_InitEcatComm() == 0
st = c_short()
while gt.GT_IsEcatReady(byref(st)) == 0 and st.value != 1:
    gt.GTE_Wait(1)
gt.GT_StartEcatComm()
gt.GT_Reset()
for a in range(1, 13):
    gt.GT_AxisOn(a)
gt.GTE_Wait(50)
if "--no-fault" not in sys.argv:
    faults.inject("drive_fault", axis=5, code=0x2310, at_ms=20000, duration_ms=200)
prm = gt.TTrapPrm()
prm.acc = prm.dec = 0.5
target = {a: 0 for a in range(1, 13)}
t = c_long()
s = c_long()
recovered = 0
while True:
    gt.GT_GetClock(byref(t))
    if t.value >= 60000:
        break
    for a in range(1, 13):
        gt.GT_GetSts(a, byref(s))
        if s.value & 2:
            gt.GT_ClrSts(a, 1)
            gt.GT_AxisOn(a)
            recovered += 1
        elif not s.value & 0x400 and s.value & 0x200:
            target[a] = 20000 if target[a] <= 0 else -20000
            gt.GT_PrfTrap(a)
            gt.GT_SetTrapPrm(a, byref(prm))
            gt.GT_SetPos(a, target[a])
            gt.GT_SetVel(a, 50)
            gt.GT_Update(1 << (a - 1))
    gt.GTE_Wait(10)
print("recovered", recovered)
gt.GT_Close()
