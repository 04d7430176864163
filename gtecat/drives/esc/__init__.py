"""Virtual slaves on a real wire: the EtherCAT slave controller (ESC) in software.

A chain of :class:`~gtecat.drives.esc.chain.Chain` ESCs answers EtherCAT frames the
way a line of real slaves does: datagrams addressed by position, station
address, broadcast or logical address (FMMUs), working counters by the rules
of ETG.1000.4, the register space of ETG.1000.4 Table 31 with its SII EEPROM,
sync managers (mailbox and buffered) and the basic DC registers.  Behind the
sync managers sit the same :class:`~gtecat.drives.slave.VirtualSlave` objects the
in-process backend uses.

Modules: :mod:`.frames` (the wire format), :mod:`.sii` (EEPROM content),
:mod:`.registers` (one ESC), :mod:`.chain` (a line of ESCs processing a frame).
"""

from gtecat.eni.ethercat import Command

from .chain import Chain, ChainStats
from .frames import Datagram, FrameError, decode_frame, encode_frame
from .registers import Esc
from .sii import SiiInfo, build_sii, parse_sii, sii_info_for

__all__ = [
    "Chain",
    "ChainStats",
    "Command",
    "Datagram",
    "Esc",
    "FrameError",
    "SiiInfo",
    "build_sii",
    "decode_frame",
    "encode_frame",
    "parse_sii",
    "sii_info_for",
]
