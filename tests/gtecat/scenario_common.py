"""One machine scenario that runs unchanged on every backend (issue 7, deliver 5).

:func:`run` drives a whole bus through the ``GT_*`` API only, the way a user's
application does (manual examples 5-1 to 5-5): bring-up, inventory, GT raw data
and EtherCAT IO offsets, SDO (values and abort codes), servo enable, and - when
those GT functions exist - homing, touch probe and a Trap move.  It returns a
plain dict of what it observed: settled values and return codes only, never
times, so the same ENI and machine give the same dict on the emulated backend
(virtual clock) and on the pysoem backend against ``gtecat serve`` on a veth
pair (realtime clock); free-text reasons are kept under ``_`` keys, which
:func:`comparable` drops.  Everything it needs comes from the ENI (slave regions,
axes, mailboxes), so it also runs on an ENI it has never seen.

The backend is chosen by the caller's ``GT_Open`` options (or the ``GTECAT_*``
environment); this module never names one.  Run it by hand::

    GTECAT_BACKEND=pysoem GTECAT_IFACE=eth1 GTECAT_CLOCK=realtime \\
        python -m tests.gtecat.scenario_common --eni Gecat.eni [--machine m.toml]

It imports nothing of pysoem.
"""

from __future__ import annotations

import argparse
import json
import sys
from collections.abc import Callable
from ctypes import byref, c_long, c_short, c_ubyte, c_uint32, c_ushort
from typing import Any

#: controller milliseconds a settling loop may wait (virtual or wall time)
SETTLE_MS = 3000
#: sentinel for a step whose GT functions this build does not have
SKIPPED = "skipped: GT function not available"


def _call(gt: Any, name: str, *args: Any) -> int | None:
    fn = getattr(gt, name, None)
    return None if fn is None else int(fn(*args))


def _has(gt: Any, *names: str) -> bool:
    return all(hasattr(gt, n) for n in names)


def wait_until(gt: Any, pred: Callable[[], bool], ms: int = SETTLE_MS, step_ms: int = 2) -> bool:
    """Poll ``pred`` while letting controller time pass (GTE_Wait: any clock mode)."""
    waited = 0
    while not pred():
        if waited >= ms:
            return False
        gt.GTE_Wait(step_ms)
        waited += step_ms
    return True


def _raw(gt: Any, offset: int, size: int) -> tuple[int, str]:
    buf = (c_ubyte * max(size, 1))()
    rc = gt.GT_GetEcatRawData(offset, size, buf)
    return rc, bytes(buf)[:size].hex()


def _u(buf: Any, n: int) -> int:
    return int.from_bytes(bytes(buf)[:n], "little")


# --- steps ----------------------------------------------------------------------------------
def bring_up(gt: Any, r: dict[str, Any]) -> bool:
    """Manual example 5-5: init, wait for GT_IsEcatReady, start, reset."""
    r["init"] = gt.GT_InitEcatComm()
    if r["init"] != 0:
        r["_init_reason"] = gt.GTE_GetLastError()
        return False
    status = c_short()
    r["ready"] = wait_until(gt, lambda: gt.GT_IsEcatReady(byref(status)) == 0 and status.value == 1)
    r["start"] = gt.GT_StartEcatComm()
    r["reset"] = gt.GT_Reset()
    return bool(r["ready"])


def inventory(gt: Any, r: dict[str, Any]) -> list[dict[str, Any]]:
    n, axes, length = c_short(), c_short(), c_long()
    gt.GT_GetEcatSlaves(byref(n))
    gt.GT_GetMcEcatAxisNum(byref(axes))
    gt.GT_GetEcatPdoLength(byref(length))
    r["slaves"], r["axes"], r["pdo_length"] = n.value, axes.value, length.value
    infos = []
    for k in range(n.value):
        info = gt.TSlaveInfo()
        rc = gt.GT_GetEcatSlaveInfo(k, byref(info))
        infos.append(
            {
                "rc": rc,
                "vendor": info.vendorId,
                "product": info.productCode,
                "revision": info.revisionNo,
                "state": info.state,
                "axisCount": info.axisCount,
                "firstAxis": info.firstAxis,
                "outputBytes": info.outputBytes,
                "inputBytes": info.inputBytes,
                "pdoOffset": info.pdoOffset,
                "name": info.name.decode(errors="replace"),
            }
        )
    r["slave_info"] = infos
    return infos


def raw_data(gt: Any, r: dict[str, Any], infos: list[dict[str, Any]]) -> None:
    """Each slave's region read through the GT raw view and through GT_EcatIOReadInput."""
    out = []
    for k, s in enumerate(infos):
        size = s["outputBytes"] + s["inputBytes"]
        rc, raw = _raw(gt, s["pdoOffset"], size)
        buf = (c_ubyte * max(size, 1))()
        rc_io = gt.GT_EcatIOReadInput(k, 0, size, buf)
        out.append({"rc": rc, "rc_io": rc_io, "same_bytes": raw == bytes(buf)[:size].hex()})
    r["raw_regions"] = out
    total = r["pdo_length"]
    r["raw_past_end"] = _raw(gt, max(total - 1, 0), 2)[0]
    one = (c_ubyte * 1)(0xFF)
    first_in = next((s["pdoOffset"] + s["outputBytes"] for s in infos if s["inputBytes"]), None)
    if first_in is not None:  # writing an input byte is refused, nothing changes
        before = _raw(gt, first_in, 1)
        r["raw_write_input"] = gt.GT_SetEcatRawData(first_in, 1, one)
        r["raw_input_unchanged"] = _raw(gt, first_in, 1) == before


def io(gt: Any, r: dict[str, Any], infos: list[dict[str, Any]]) -> None:
    """Write a pattern to every IO slave's outputs; read the region back (manual 5.2.2.5)."""
    res = []
    for k, s in enumerate(infos):
        n = s["outputBytes"]
        if s["axisCount"] or not n:
            continue
        pattern = bytes((0x5A + 0x11 * i + k) & 0xFF for i in range(n))
        buf = (c_ubyte * n)(*pattern)
        rc_w = gt.GT_EcatIOWriteOutput(k, 0, n, buf)
        rc_bit = gt.GT_EcatIOBitWriteOutput(k, 0, 0, 1)
        gt.GT_EcatIOSynch()
        gt.GTE_Wait(5)
        back = (c_ubyte * (n + s["inputBytes"]))()
        rc_r = gt.GT_EcatIOReadInput(k, 0, n + s["inputBytes"], back)
        rc_raw, raw = _raw(gt, s["pdoOffset"], n)
        past = gt.GT_EcatIOWriteOutput(k, n, 1, (c_ubyte * 1)())  # an input byte or past end
        res.append(
            {
                "slave": k,
                "write": rc_w,
                "bit": rc_bit,
                "read": rc_r,
                "raw_rc": rc_raw,
                "outputs": bytes(back)[:n].hex(),
                "inputs": bytes(back)[n:].hex(),
                "raw_matches": raw == bytes(back)[:n].hex(),
                "write_past_outputs": past,
            }
        )
    r["io"] = res


def sdo(gt: Any, r: dict[str, Any], mailbox: list[int], drives: list[int]) -> None:
    """Identity upload, a missing object and a read-only object: values and abort codes."""
    res = []
    for k in mailbox:
        data, size, abort = (c_ubyte * 4)(), c_long(), c_uint32()
        rc = gt.GT_EcatSDOUpload(k, 0x1018, 1, data, 4, byref(size), byref(abort))
        item = {"slave": k, "1018:01": [rc, _u(data, 4), size.value, abort.value]}
        rc = gt.GT_EcatSDOUpload(k, 0x2FFF, 0x7F, data, 4, byref(size), byref(abort))
        item["2FFF:7F"] = [rc, abort.value]
        if k in drives:
            sw = (c_ubyte * 2)(0x06, 0x00)
            rc = gt.GT_EcatSDODownload(k, 0x6041, 0, sw, 2, byref(abort))
            item["6041:00 write"] = [rc, abort.value]
            mode = (c_ubyte * 1)(8)
            rc = gt.GT_EcatSDODownload(k, 0x6060, 0, mode, 1, byref(abort))
            item["6060:00 write"] = [rc, abort.value]
            back = (c_ubyte * 1)()
            rc = gt.GT_EcatSDOUpload(k, 0x6060, 0, back, 1, byref(size), byref(abort))
            item["6060:00 read"] = [rc, back[0], abort.value]
        res.append(item)
    r["sdo"] = res


def _statusword(gt: Any, axis: int) -> int:
    buf = (c_ubyte * 2)()
    if gt.GT_GetEcatAxisPdoData(axis, 0x6041, buf) != 0:
        return -1
    return _u(buf, 2)


def _enc(gt: Any, axis: int) -> int | None:
    pos = c_long()
    return pos.value if gt.GT_GetEcatEncPos(axis, byref(pos)) == 0 else None


def enable(gt: Any, r: dict[str, Any], axes: int) -> None:
    res = []
    for a in range(1, axes + 1):
        rc = gt.GT_AxisOn(a)
        on = wait_until(gt, lambda a=a: _statusword(gt, a) & 0x6F == 0x27)
        res.append({"axis": a, "rc": rc, "enabled": on, "enc": _enc(gt, a)})
    r["enable"] = res


def home(gt: Any, r: dict[str, Any], axes: int, switches: dict[int, bool]) -> None:
    """Manual example 5-2: method 19 (home switch) where the machine has one, else 37.

    Method 19 travels to the switch edge, so an armed probe window on the way is
    crossed; method 37 homes on the current position (no switch needed, any ENI).
    """
    if not _has(
        gt,
        "GT_SetHomingMode",
        "GT_SetEcatHomingPrm",
        "GT_StartEcatHoming",
        "GT_GetEcatHomingStatus",
    ):
        r["home"] = SKIPPED
        return
    res = []
    for a in range(1, axes + 1):
        st = c_short()
        method = 19 if switches.get(a) else 37
        rcs = [
            gt.GT_SetHomingMode(a, 6),
            gt.GT_SetEcatHomingPrm(a, method, 200_000, 20_000, 2_000_000, 1000, 0),
            gt.GT_StartEcatHoming(a),
        ]
        done = wait_until(
            gt,
            lambda a=a, st=st: (
                gt.GT_GetEcatHomingStatus(a, byref(st)) == 0 and st.value in (3, 4, 5)
            ),
        )
        rcs.append(gt.GT_SetHomingMode(a, 8))
        res.append(
            {
                "axis": a,
                "method": method,
                "rc": rcs,
                "done": done,
                "status": st.value,
                "enc": _enc(gt, a),
            }
        )
    r["home"] = res


def trap_move(gt: Any, r: dict[str, Any], axes: int, distance: int = 20000) -> None:
    """A Trap move of ``distance`` pulses on every axis, waited until the profile stops."""
    if not _has(
        gt,
        "GT_PrfTrap",
        "GT_SetTrapPrm",
        "GT_SetPos",
        "GT_SetVel",
        "GT_Update",
        "GT_GetSts",
        "TTrapPrm",
    ):
        r["trap"] = SKIPPED
        return
    res = []
    starts = {a: _enc(gt, a) or 0 for a in range(1, axes + 1)}
    for a in range(1, axes + 1):  # every axis prepared, then one GT_Update starts them all
        prm = gt.TTrapPrm()
        prm.acc, prm.dec, prm.velStart, prm.smoothTime = 0.5, 0.5, 0, 0
        rcs = [
            gt.GT_PrfTrap(a),
            gt.GT_SetTrapPrm(a, byref(prm)),
            gt.GT_SetPos(a, starts[a] + distance),
            gt.GT_SetVel(a, 50),
        ]
        res.append({"axis": a, "rc": rcs})
    r["trap_update"] = gt.GT_Update((1 << axes) - 1)
    sts = c_long()
    stopped = wait_until(
        gt,
        lambda: all(
            gt.GT_GetSts(a, byref(sts)) == 0 and not sts.value & 0x400 for a in range(1, axes + 1)
        ),
        ms=20_000,
    )
    # the drives follow the last set-point: waited for (bounded), not a fixed 20 ms, which a
    # wire on a loaded machine (frames late, cycles lost) did not always give them
    wait_until(gt, lambda: all(_enc(gt, a) == starts[a] + distance for a in starts))
    for item in res:
        a = item["axis"]
        item["stopped"] = stopped
        item["moved"] = (_enc(gt, a) or 0) - starts[a]
    r["trap"] = res


def probe_arm(gt: Any, r: dict[str, Any], axes: int) -> None:
    """Manual example 5-3: probe 1, rising edge, continuous (armed before homing moves)."""
    if not _has(gt, "GT_SetTouchProbeFunction", "GT_GetTouchProbeStatus"):
        r["probe_arm"] = SKIPPED
        return
    r["probe_arm"] = [gt.GT_SetTouchProbeFunction(a, 0x0013) for a in range(1, axes + 1)]


def probe_read(gt: Any, r: dict[str, Any], axes: int) -> None:
    """What probe 1 captured (the window edge crossed while homing), then disarm."""
    if not _has(gt, "GT_SetTouchProbeFunction", "GT_GetTouchProbeStatus"):
        r["probe"] = SKIPPED
        return
    res = []
    for a in range(1, axes + 1):
        sts, v = c_ushort(), [c_long() for _ in range(4)]
        rc = gt.GT_GetTouchProbeStatus(a, byref(sts), *(byref(x) for x in v))
        captured = bool(sts.value & 0x0002)
        res.append(
            {
                "axis": a,
                "rc": rc,
                "enabled": bool(sts.value & 0x0001),
                "captured": captured,
                "rise1": v[0].value if captured else None,
                "off": gt.GT_SetTouchProbeFunction(a, 0),
            }
        )
    r["probe"] = res


def disable(gt: Any, r: dict[str, Any], axes: int) -> None:
    r["axis_off"] = [_call(gt, "GT_AxisOff", a) for a in range(1, axes + 1)]


# --- the scenario -----------------------------------------------------------------------------
def run(
    gt: Any | None = None, *, eni: str, machine: str | None = None, **open_options: Any
) -> dict[str, Any]:
    """Open, run every step, close; the observations as a dict (same on every backend)."""
    if gt is None:
        from gtecat import gt as gt_module

        gt = gt_module
    from gtecat.eni.layout import build_layout
    from gtecat.eni.reader import read_eni

    layout = build_layout(read_eni(eni))
    switches: dict[int, bool] = {}
    if machine:
        from gtecat.drives.machine import load_machine

        desc = load_machine(machine)
        switches = {a.axis: bool(desc.axis(a.axis).home_switch) for a in layout.axes}
    mailbox = [s.position for s in layout.config.slaves if s.mailbox]
    drives = [s.position for s in layout.slaves if s.axes]
    r: dict[str, Any] = {}
    gt.GT_Close()
    open_options.setdefault("log", "")
    r["open"] = gt.GT_Open(eni=eni, machine=machine, **open_options)
    try:
        if r["open"] != 0 or not bring_up(gt, r):
            r["_reason"] = gt.GTE_GetLastError()
            return r
        infos = inventory(gt, r)
        raw_data(gt, r, infos)
        io(gt, r, infos)
        sdo(gt, r, mailbox, drives)
        axes = r["axes"]
        enable(gt, r, axes)
        probe_arm(gt, r, axes)
        home(gt, r, axes, switches)
        probe_read(gt, r, axes)
        trap_move(gt, r, axes)
        disable(gt, r, axes)
        r["terminate"] = gt.GT_TerminateEcatComm()
    finally:
        gt.GT_Close()
    return r


def comparable(result: dict[str, Any]) -> dict[str, Any]:
    """The observations without the free-text reasons (keys starting with ``_``).

    Codes and values must match between backends; a reason's wording may not.
    """
    return {k: v for k, v in result.items() if not k.startswith("_")}


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--eni", required=True)
    ap.add_argument("--machine")
    args = ap.parse_args(argv)
    print(json.dumps(run(eni=args.eni, machine=args.machine), indent=1))
    return 0


if __name__ == "__main__":
    sys.exit(main())
