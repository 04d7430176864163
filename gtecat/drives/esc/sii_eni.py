"""The SII a virtual slave shows, with what an ETG.2100 ENI says about the real device.

A master that reads a slave's SII rather than the ENI (SOEM, KickCAT, ebpfcat) must find the
device's own layout: the sync managers where the device has them (an EL2008's output SM is
the digital output register 0F00h, an EL1809's inputs are SM0, an EL4002's SM3 sits at
1180h), the mailbox where the ENI puts it, and the product it is. The ENI reader
(:mod:`gtecat.eni.xml_reader`) reads those facts into :class:`gtecat.eni.model.Slave`
(``sync_managers``, ``mailbox_layout``, ``product_revision``); :func:`sii_for` applies them
to the SII the slave would otherwise get (:func:`gtecat.drives.esc.sii.sii_info_for`). The
same SII serves ``gtecat serve`` and the in-process ``gtecat sii read``.

A Googol INI file states none of it: its slaves keep the default layout.
"""

from __future__ import annotations

import dataclasses
import re

from gtecat.eni.model import Direction, SyncManager
from gtecat.eni.model import Slave as EniSlave

from ..slave import VirtualSlave
from .sii import SM_CONTROL_MBX_IN, SM_CONTROL_MBX_OUT, SiiInfo, SmConfig, SmType, sii_info_for

_SM_TYPE = {Direction.OUT: SmType.OUTPUTS, Direction.IN: SmType.INPUTS}


def product_name(name: str, product_revision: str | None) -> str:
    """What the device calls itself in 1008h: ``EL2008`` for ``EL2008-0000-0018`` or
    ``Term 2 (EL2008)``, else the ENI's name of the slave."""
    if product_revision:
        return product_revision.split("-")[0].strip() or name
    found = re.search(r"\(([^()]+)\)\s*$", name)
    return found.group(1).strip() if found else name


def _sm_length(slave: VirtualSlave, sm: SyncManager, sms: tuple[SyncManager, ...]) -> int:
    """Bytes of one process-data SM: the PDOs assigned to it, else the whole direction."""
    direction = sm.direction
    pdos = getattr(slave, "rx_pdos" if direction == Direction.OUT else "tx_pdos", ()) or ()
    rx_bits, tx_bits = slave.pdo_sizes()
    total = rx_bits if direction == Direction.OUT else tx_bits
    same = [s for s in sms if s.direction == sm.direction and s.enable]
    if len(same) > 1 and any(p.sm is not None for p in pdos):
        total = sum(p.bit_len for p in pdos if p.sm == sm.number)
    elif same and same[0] is not sm:
        total = 0  # one direction, one buffer: the first enabled SM of the type carries it
    return (total + 7) // 8 if sm.enable else 0


def sii_for(slave: VirtualSlave, eni: EniSlave | None) -> SiiInfo:
    """The slave's SII with the SM layout, mailbox and name the ENI states.

    Also makes the slave's SDO server segment to the ENI's mailbox size and its
    1008h name the product.
    """
    mbx = eni.mailbox_layout if eni is not None else None
    sdo = getattr(slave, "sdo", None)
    if mbx is not None and sdo is not None:
        sdo.mailbox_size = min(mbx.out_length, mbx.in_length)
    if eni is not None:
        od = getattr(slave, "od", None)
        name = od.find(0x1008, 0) if od is not None else None
        if name is not None and name.getter is None:
            name.value = product_name(eni.name, eni.product_revision)
    info = sii_info_for(slave)
    if eni is None or not (eni.sync_managers or mbx):
        return info
    by_number: dict[int, SmConfig] = {}
    if info.has_mailbox:
        out = (mbx.out_start, mbx.out_length) if mbx else info.rx_mailbox
        inp = (mbx.in_start, mbx.in_length) if mbx else info.tx_mailbox
        by_number[0] = SmConfig(out[0], out[1], SM_CONTROL_MBX_OUT, 1, SmType.MAILBOX_OUT)
        by_number[1] = SmConfig(inp[0], inp[1], SM_CONTROL_MBX_IN, 1, SmType.MAILBOX_IN)
    if eni.sync_managers:
        for sm in eni.sync_managers:
            length = _sm_length(slave, sm, eni.sync_managers)
            by_number[sm.number] = SmConfig(
                sm.start, length, sm.control, int(sm.enable), _SM_TYPE[sm.direction]
            )
    else:  # the ENI places the mailbox only: process data SMs as the default puts them
        for sm in info.sync_managers:
            if sm.type in (SmType.OUTPUTS, SmType.INPUTS):
                by_number[max(by_number, default=-1) + 1] = sm
    unused = SmConfig(0, 0, 0, 0, SmType.UNUSED)
    layout = tuple(by_number.get(n, unused) for n in range(max(by_number) + 1))
    return dataclasses.replace(
        info,
        sync_managers=layout,
        rx_mailbox=(by_number[0].start, by_number[0].length) if info.has_mailbox else (0, 0),
        tx_mailbox=(by_number[1].start, by_number[1].length) if info.has_mailbox else (0, 0),
    )
