"""ENI -> virtual slaves: what the emulated bus (and ``gtecat serve``) puts on the wire.

A slave that maps a CiA-402 controlword/statusword pair per channel becomes a
:class:`gtecat.drives.drive.Cia402Drive` with one channel per GT axis (its mechanics
from the machine description, by GT axis number); every other slave becomes a
:class:`gtecat.drives.io_slaves.IoSlave` driven by its mapping (a
:class:`gtecat.drives.io_slaves.CoeIoSlave` when the ENI gives it a mailbox).  The drives' initial
PDO mapping is what the ENI lists; the ENI's CoE InitCmds are then applied by
the master through the mailbox, as on a real bus.
"""

from __future__ import annotations

from gtecat.drives.io_slaves import CoeIoSlave, IoSlave
from gtecat.drives.machine import MachineDescription
from gtecat.drives.slave import VirtualSlave
from gtecat.eni.layout import Layout
from gtecat.eni.model import InitCmd


def build_slave(
    layout: Layout, position: int, machine: MachineDescription | None = None
) -> VirtualSlave:
    machine = machine or MachineDescription()
    sl = layout.slaves[position]
    cfg = layout.config.slaves[position]
    if sl.channels:
        from gtecat.drives.drive import Cia402Drive

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
    cls = CoeIoSlave if cfg.mailbox else IoSlave
    return cls(cfg.position, cfg.name, cfg.identity, rx_pdos=cfg.rx_pdos, tx_pdos=cfg.tx_pdos)


#: the manufacturer-specific objects (ETG.1000.6 5.6.7.4.1, the CoE object dictionary's areas)
MANUFACTURER = (0x2000, 0x5FFF)


def adopt_init_cmd_objects(slave: VirtualSlave, cmds: tuple[InitCmd, ...]) -> list[str]:
    """Give a virtual slave the objects its ENI's CoE InitCmds write but it lacks.

    An ENI made for a real device configures that device's own parameters
    (vendor objects such as 0x8000:xx settings).  The virtual slave takes them
    as plain read-write parameters of the written size, so the bring-up works
    and an SDO upload reads the value back; the slave's behaviour ignores them.
    Mapping and assignment objects are never invented, nor a subindex of an object the
    slave has outside the manufacturer-specific range 0x2000-0x5FFF (a communication or
    profile object as its profile defines it, such as 0x607D with subindices 1 and 2): a
    write to one it lacks aborts as on a real slave (0x06090011), and the bring-up reports
    the InitCmd with the slave and the abort code.  Returns what was added.
    """
    od = getattr(slave, "od", None)
    if od is None:
        return []
    from gtecat.drives.od import Access, DataType, ObjectCode, OdObject, Variable

    added = []
    sizes = {1: DataType.UINT8, 2: DataType.UINT16, 4: DataType.UINT32, 8: DataType.UINT64}
    for cmd in cmds:
        if cmd.upload or 0x1600 <= cmd.index < 0x1C00 or cmd.index in (0x1C12, 0x1C13):
            continue
        sub = 0 if cmd.complete_access else cmd.subindex
        if od.find(cmd.index, sub) is not None:
            continue
        if cmd.index in od.objects and not MANUFACTURER[0] <= cmd.index <= MANUFACTURER[1]:
            continue  # the profile's object, whole: the slave's SDO server aborts the write
        dtype = sizes.get(len(cmd.data), DataType.OCTET_STRING)
        default: object = 0 if dtype != DataType.OCTET_STRING else bytes(len(cmd.data))
        var = Variable(
            cmd.index,
            sub,
            f"0x{cmd.index:04X}:{sub:02X} (from the ENI)",
            dtype,
            Access.RW,
            default=default,
        )
        obj = od.objects.get(cmd.index)
        if obj is None:
            code = ObjectCode.VAR if sub == 0 else ObjectCode.RECORD
            obj = od.add_object(OdObject(cmd.index, var.name, code))
            if sub:
                obj.add(
                    Variable(
                        cmd.index, 0, "Number of entries", DataType.UINT8, Access.RO, default=sub
                    )
                )
        elif 0 in obj.subs and sub > 0 and obj.subs[0].getter is None:
            obj.subs[0].value = max(int(obj.subs[0].value), sub)
        obj.add(var)
        added.append(f"0x{cmd.index:04X}:{sub:02X}")
    return added


def build_slaves(layout: Layout, machine: MachineDescription | None = None) -> list[VirtualSlave]:
    """One virtual slave per ENI slave, in bus order."""
    slaves = [build_slave(layout, i, machine) for i in range(len(layout.slaves))]
    for slave, cfg in zip(slaves, layout.config.slaves, strict=True):
        adopt_init_cmd_objects(slave, cfg.init_cmds)
    return slaves
