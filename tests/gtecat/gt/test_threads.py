"""An application whose threads call GT functions at once (a polling thread beside the one
that moves, as HMIs are written): the calls are serialised per controller, as the vendor's
library serialises its callers' threads, so the axis bank's cycles, claims and releases of
one thread never interleave with another's; every call answers with its code."""

from __future__ import annotations

import sys
import threading
from ctypes import byref, c_long, c_short

from gtecat import gt
from gtecat.gt import _core
from tests.conftest import EXAMPLES

from .conftest import bring_up


def test_a_polling_thread_beside_coordinated_motion() -> None:
    bring_up(
        "homing_probe.eni",
        machine=str(EXAMPLES / "homing_probe_machine.toml"),
        clock="auto",
        bank="on",
    )
    try:
        assert gt.GT_AxisOn(1) == 0 and gt.GT_AxisOn(2) == 0
        bad: list[tuple[str, int, str]] = []
        done = threading.Event()

        def poll() -> None:
            x, r = c_long(), c_short()
            while not done.is_set():
                for name, rc in (
                    ("GT_GetSts", gt.GT_GetSts(1, byref(x))),
                    ("GT_CrdStatus", gt.GT_CrdStatus(1, byref(r), byref(x))),
                ):
                    if rc not in (0, 1):  # (1: no parameters yet, the table's refusal)
                        bad.append((name, rc, gt.GTE_GetLastError()))

        def move() -> None:
            try:
                for _ in range(12):
                    q = gt.TCrdPrm()
                    q.dimension, q.synVelMax, q.synAccMax = 2, 50.0, 1.0
                    q.profile[0], q.profile[1] = 1, 2
                    for name, rc in (
                        ("GT_SetCrdPrm", gt.GT_SetCrdPrm(1, byref(q))),
                        ("GT_LnXY", gt.GT_LnXY(1, 2000, 1000, 30.0, 0.5, 0)),
                        ("GT_CrdStart", gt.GT_CrdStart(1, 0)),
                        *(("GTE_Wait", gt.GTE_Wait(1)) for _ in range(20)),
                        ("GT_Stop", gt.GT_Stop(3, 0)),
                    ):
                        if rc not in (0, 1):  # (1: a system still running refuses)
                            bad.append((name, rc, gt.GTE_GetLastError()))
            finally:
                done.set()

        threads = [threading.Thread(target=poll), threading.Thread(target=move)]
        was = sys.getswitchinterval()
        sys.setswitchinterval(2e-6)  # (the threads take turns often: many interleavings)
        try:
            for t in threads:
                t.start()
            for t in threads:
                t.join(timeout=60)
        finally:
            sys.setswitchinterval(was)
        assert not any(t.is_alive() for t in threads)
        assert not bad, bad[:3]
        internal = [e for e in _core.SESSION.errors if "internal error" in e.reason]
        assert not internal, internal[:3]
    finally:
        gt.GT_Close()
