"""ENI -> virtual slaves: what the emulated bus (and ``gtecat serve``) puts on the wire.

A slave that maps a CiA-402 controlword/statusword pair per channel becomes a
:class:`drives.drive.Cia402Drive` with one channel per GT axis (its mechanics
from the machine description, by GT axis number); every other slave becomes a
:class:`drives.io_slaves.IoSlave` driven by its mapping.  The drives' initial
PDO mapping is what the ENI lists; the ENI's CoE InitCmds are then applied by
the master through the mailbox, as on a real bus.
"""

from __future__ import annotations

from drives.io_slaves import IoSlave
from drives.machine import MachineDescription
from drives.slave import VirtualSlave
from eni.layout import Layout


def build_slave(
    layout: Layout, position: int, machine: MachineDescription | None = None
) -> VirtualSlave:
    machine = machine or MachineDescription()
    sl = layout.slaves[position]
    cfg = layout.config.slaves[position]
    if sl.channels:
        from drives.drive import Cia402Drive

        channels = max(sl.channels) + 1
        by_channel = dict(zip(sl.channels, sl.axes, strict=True))
        machines = [
            machine.axis(by_channel[k]) if k in by_channel else machine.axis(0)
            for k in range(channels)
        ]
        return Cia402Drive(
            cfg.position,
            cfg.name,
            cfg.identity,
            rx_pdos=cfg.rx_pdos,
            tx_pdos=cfg.tx_pdos,
            channels=channels,
            machines=machines,
        )
    return IoSlave(cfg.position, cfg.name, cfg.identity, rx_pdos=cfg.rx_pdos, tx_pdos=cfg.tx_pdos)


def build_slaves(layout: Layout, machine: MachineDescription | None = None) -> list[VirtualSlave]:
    """One virtual slave per ENI slave, in bus order."""
    return [build_slave(layout, i, machine) for i in range(len(layout.slaves))]
