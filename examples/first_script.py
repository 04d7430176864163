"""Bring up the manual's figure 5-2 bus, write an IO slave's outputs, try its inputs."""

from ctypes import byref, c_short, c_ubyte

from gtecat import gt

gt.GT_Open(eni="manual_fig5_2.eni")  # or GTECAT_ENI=..., default ./Gecat.eni
gt.GT_InitEcatComm()  # 0 / -8 mismatch / -9 no ENI / -10 no slaves
status = c_short()
while gt.GT_IsEcatReady(byref(status)) == 0 and status.value != 1:
    pass  # virtual time passes with every call
gt.GT_StartEcatComm()
out = (c_ubyte * 2)(0x55, 0xAA)
print(gt.GT_SetEcatRawData(32, 2, out))  # 0: slave 2's outputs (manual 5.2.2.4)
print(gt.GT_SetEcatRawData(34, 2, out))  # 7: slave 2's inputs cannot be written
print(gt.GTE_GetLastError())  # the reason for the last call's non-zero return
gt.GT_Close()
