"""ENI -> virtual slaves: kinds chosen from the mapping, vendor InitCmd objects adopted."""

from __future__ import annotations

from dataclasses import replace

from gtecat.drives.drive import Cia402Drive
from gtecat.drives.io_slaves import CoeIoSlave, IoSlave
from gtecat.eni.layout import build_layout
from gtecat.eni.model import InitCmd
from gtecat.eni.reader import read_eni
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
