"""ENI -> virtual slaves: kinds chosen from the mapping, vendor InitCmd objects adopted."""

from __future__ import annotations

from dataclasses import replace

import pytest

from gtecat.drives.drive import Cia402Drive
from gtecat.drives.io_slaves import CoeIoSlave, IoSlave
from gtecat.eni.layout import build_layout
from gtecat.eni.model import InitCmd
from gtecat.eni.reader import read_eni
from gtecat.errors import StateError
from gtecat.master.backends.emulated import EmulatedBackend
from gtecat.master.bus import Master
from gtecat.master.factory import build_slaves
from tests.conftest import EXAMPLES


def test_kinds_follow_the_mapping_and_the_mailbox(shared_fixtures):
    kinds = [type(s) for s in build_slaves(build_layout(read_eni(EXAMPLES / "manual_fig5_4.eni")))]
    assert kinds == [CoeIoSlave]  # the coupler has a mailbox
    fig = build_slaves(build_layout(read_eni(EXAMPLES / "manual_fig5_2.eni")))
    assert [type(s) for s in fig] == [Cia402Drive, Cia402Drive, IoSlave, IoSlave]
    acontis = read_eni(shared_fixtures / "eni" / "acontis_training_slaves.xml")
    master = Master(build_layout(acontis), EmulatedBackend(), op_delay_cycles=0)
    master.open()  # CoE InitCmds with complete access on the CoE IO slaves
    master.cycle(0, 1_000_000)  # the OP request follows the first cycle in SAFEOP
    master.cycle(1_000_000, 1_000_000)
    assert master.ready


def test_vendor_objects_written_by_init_cmds_are_adopted():
    cfg = read_eni(EXAMPLES / "manual_fig5_2.eni")
    extra = (
        InitCmd(("PS",), 0x2010, 3, (500).to_bytes(2, "little"), comment="vendor gain"),
        InitCmd(("PS",), 0x6065, 0, (1234).to_bytes(4, "little"), comment="FE window"),
    )
    s0 = replace(cfg.slaves[0], init_cmds=cfg.slaves[0].init_cmds + extra)
    cfg = replace(cfg, slaves=(s0, *cfg.slaves[1:]))
    layout = build_layout(cfg)
    backend = EmulatedBackend()
    master = Master(layout, backend, op_delay_cycles=0)
    master.open()
    assert master.sdo_upload(0, 0x2010, 3) == (500).to_bytes(2, "little")
    assert master.sdo_upload(0, 0x6065, 0) == (1234).to_bytes(4, "little")  # a real object
    assert "0x2010:03" in backend.slaves[0].od.find(0x2010, 3).name


def test_a_missing_subindex_of_a_profile_object_fails_the_bring_up():
    """0x607D (software position limit) has subindices 1 and 2: an InitCmd writing 0x607D:07
    aborts as on a real slave, and the bring-up names the slave, the command and the code;
    a manufacturer-specific object the slave lacks is still adopted."""
    cfg = read_eni(EXAMPLES / "manual_fig5_2.eni")
    bad = InitCmd(("PS",), 0x607D, 7, (1).to_bytes(4, "little"), comment="no such subindex")
    vendor = InitCmd(("PS",), 0x2FFF, 0, b"\x01", comment="vendor switch")
    s0 = replace(cfg.slaves[0], init_cmds=(*cfg.slaves[0].init_cmds, vendor, bad))
    master = Master(build_layout(replace(cfg, slaves=(s0, *cfg.slaves[1:]))), EmulatedBackend())
    with pytest.raises(StateError) as e:
        master.open()
    assert e.value.slave == 0
    assert "slave 0" in str(e.value) and "InitCmd PS 0x607D:07" in str(e.value)
    assert "0x06090011" in str(e.value) and master.error == str(e.value)
    assert master.backend.slaves[0].od.find(0x607D, 7) is None
    assert master.backend.slaves[0].od.find(0x2FFF, 0) is not None
