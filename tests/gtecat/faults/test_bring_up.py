"""A machine description's ``[[fault]]`` tables are armed before the bring-up: its InitCmds
(SDOs) meet a mailbox fault and count toward an ``on_sdo`` trigger, with the frames captured
(``pcap``) or not; a fault that starts at once otherwise still starts once the bus is up."""

from __future__ import annotations

from ctypes import byref, c_short, c_ubyte, c_uint32
from pathlib import Path

import pytest

from gtecat import gt
from gtecat.eni.reader import read_eni
from tests.conftest import EXAMPLES

ENI = EXAMPLES / "manual_fig5_2.eni"
ABORT = 0x06010000


def _bring_up_sdos(index: int) -> int:
    """The SDOs to ``index`` of slave 0 in the ENI's CoE InitCmds."""
    cmds = read_eni(ENI).slaves[0].init_cmds
    return sum(1 for c in cmds if c.index == index)


def _open(tmp: Path, n: int, pcap: bool, extra: str = "") -> int:
    machine = tmp / f"m{n}{pcap}.toml"
    machine.write_text(
        f'[[fault]]\nkind = "mailbox_abort"\nslave = 0\nindex = 0x1C12\ncode = {ABORT:#x}\n'
        f"on_sdo = [0, 0x1C12, {n}]\n{extra}"
    )
    kw = {"pcap": str(tmp / f"{n}.pcap")} if pcap else {}
    gt.GT_Close()
    assert gt.GT_Open(eni=str(ENI), machine=str(machine), clock="lockstep", log="", **kw) == 0
    return gt.GT_InitEcatComm()


@pytest.mark.parametrize("pcap", [False, True], ids=["no capture", "pcap"])
def test_the_nth_sdo_counts_the_bring_up_and_its_fault_fails_it(tmp_path: Path, pcap: bool):
    n = _bring_up_sdos(0x1C12)
    assert n >= 2
    assert _open(tmp_path, n, pcap) == 1  # the bring-up's last SDO to 0x1C12
    err = gt.GTE_GetLastError()
    assert "slave 0" in err and "InitCmd PS 0x1C12:00" in err and f"{ABORT:#010x}" in err.lower()


def test_past_the_bring_up_the_application_meets_it_and_at_once_waits_for_the_bus(
    tmp_path: Path,
):
    at_once = '[[fault]]\nkind = "drive_fault"\naxis = 1\ncode = 0x2310\n'
    assert _open(tmp_path, _bring_up_sdos(0x1C12) + 1, False, at_once) == 0
    ready = c_short()
    for _ in range(100):
        if gt.GT_IsEcatReady(byref(ready)) == 0 and ready.value == 1:
            break
        gt.GTE_Wait(1)
    assert ready.value == 1
    ab = c_uint32()
    rc = gt.GT_EcatSDODownload(0, 0x1C12, 0, (c_ubyte * 1)(0), 1, byref(ab))
    assert (rc, ab.value) == (1, ABORT)
    from gtecat import faults

    assert {f["kind"]: f["state"] for f in faults.listing()}["drive_fault"] == "active"


def test_only_the_slaves_a_fault_concerns_take_their_sdos_framed(tmp_path: Path):
    """A mailbox fault or an ``on_sdo`` trigger of one slave puts that slave's SDOs through
    the injector (framed, counted, faulted); the other slaves' expedited SDOs go to their SDO
    servers unframed, as on a bus without faults; a fault injected later is seen at once."""
    from gtecat import faults
    from gtecat.gt._core import SESSION

    assert _open(tmp_path, _bring_up_sdos(0x1C12) + 1, False) == 0
    slaves = SESSION.controllers[1].backend.slaves
    mailboxes = [s.mailbox for s in slaves if s.has_mailbox]
    assert len(mailboxes) >= 2
    assert [m.sdo_server_only for m in mailboxes[:2]] == [False, True]
    # a trigger counting the SDOs of slave 1 (the fault itself acts on an axis): framed
    ident = faults.inject("drive_fault", axis=1, code=0x2310, on_sdo=[1, 0x1018, 2])
    assert [m.sdo_server_only for m in mailboxes[:2]] == [False, False]
    value, size, ab = (c_ubyte * 4)(), c_uint32(), c_uint32()
    for _ in range(2):
        assert gt.GT_EcatSDOUpload(1, 0x1018, 1, value, 4, byref(size), byref(ab)) == 0
    assert any(e["id"] == ident and e["state"] == "active" for e in faults.listing())
    faults.clear(ident)
    assert [m.sdo_server_only for m in mailboxes[:2]] == [False, True]
    # a mailbox fault of slave 1 injected now: its next SDO meets it
    faults.inject("mailbox_abort", slave=1, index=0x1018, code=ABORT)
    assert mailboxes[1].sdo_server_only is False
    assert gt.GT_EcatSDOUpload(1, 0x1018, 1, value, 4, byref(size), byref(ab)) == 1
    assert ab.value == ABORT
