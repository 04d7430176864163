"""The endpoint reads the master, not the emulator: the same operations on the pysoem
backend (driven by the fake SOEM of the backend's own tests, no NIC needed)."""

from __future__ import annotations

from types import SimpleNamespace

from gtecat.controller.inspect import BusView
from gtecat.drives.slave import AlState
from gtecat.inspect import ops
from gtecat.master.clock import Clock
from gtecat.master.masterlog import MasterLog

from ..master.backends.test_pysoem_backend import bring_up, make_bus


def _ctl() -> SimpleNamespace:
    master, backend, devices, _lines = make_bus()
    backend.check_interval_ms = 1
    bring_up(master)
    clock = Clock(lambda: None, cycle_ns=1_000_000)
    ctl = SimpleNamespace(
        master=master,
        backend=backend,
        devices=devices,
        axes={},
        resources={},
        bank=None,
        clock=clock,
        reset_ns=0,
        log=MasterLog(),
        options=SimpleNamespace(eni="bus.eni", clock="realtime", backend="pysoem"),
    )
    return ctl


def _run(ctl: SimpleNamespace, n: int, t0: int) -> None:
    for k in range(n):
        ctl.master.cycle(t0 + k * 1_000_000, 1_000_000)


def test_snapshot_and_layout_on_pysoem_read_the_master() -> None:
    ctl = _ctl()
    ctx = SimpleNamespace(ctl=ctl, kind="python", homing={})
    lay = ops.layout(ctx)
    assert lay["emulated"] is False  # the page offers no field side
    assert [s["name"] for s in lay["slaves"]] == ["IO A", "Bits B", "Bits C", "IO D"]
    snap = ops.snapshot(ctx)
    assert snap["states"] == [int(AlState.OP)] * 4
    assert snap["wkc"] == snap["expected"] == ctl.backend.expected_wkc()
    assert len(bytes.fromhex(snap["image"])) == lay["outputs_bytes"] + lay["inputs_bytes"]


def test_a_state_asked_on_pysoem_holds_until_op_is_asked() -> None:
    """The master keeps the request (Master.held, which SOEM's check_and_recover also
    skips) and OP brings the slave back with the master's own walk."""
    ctl = _ctl()
    rows = BusView(ctl).states(2, "PREOP")
    assert rows[0]["state"] == "PREOP" and ctl.master.held == {2: AlState.PREOP}
    _run(ctl, 40, 100_000_000)
    assert ctl.devices[2].vs.al_state == AlState.PREOP
    BusView(ctl).states(2, "OP")
    _run(ctl, 40, 200_000_000)
    assert ctl.devices[2].vs.al_state == AlState.OP and not ctl.master.held
