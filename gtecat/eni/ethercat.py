"""EtherCAT protocol numbers (ETG.1000.4, ETG.1000.6) that both layers name.

An ENI's register InitCmds (:mod:`gtecat.eni.register_cmds`) are datagrams to ESC registers
that move slaves between AL states; the virtual ESCs (:mod:`gtecat.drives.esc`) decode the same
commands and answer the same registers.  ``eni`` is the lower layer, so the numbers live
here and ``drives`` imports them.
"""

from __future__ import annotations

from enum import IntEnum

#: Ethernet II header (destination, source, EtherType); no VLAN tag (masters send none)
ETH_HEADER_LEN = 14
#: the EtherCAT frame header: length 11 bits, reserved 1, type 4 (ETG.1000.4 5.3)
ECAT_HEADER_LEN = 2
#: a datagram's header (Cmd, Idx, ADP, ADO, Len/R/C/M, IRQ) and its working counter (5.4)
DATAGRAM_HEADER_LEN = 10
WKC_LEN = 2
#: an Ethernet frame carries at most 1500 bytes (1514 without FCS): the EtherCAT header and
#: its datagrams
MAX_ECAT_LEN = 1498


class Command(IntEnum):
    """Datagram commands (ETG.1000.4 5.4: Table 14 is APRD, the other commands follow it)."""

    NOP = 0
    APRD = 1
    APWR = 2
    APRW = 3
    FPRD = 4
    FPWR = 5
    FPRW = 6
    BRD = 7
    BWR = 8
    BRW = 9
    LRD = 10
    LWR = 11
    LRW = 12
    ARMW = 13
    FRMW = 14


class AlState(IntEnum):
    """EtherCAT application-layer states (ETG.1000.6 5.3.2; register 0x0130 low nibble)."""

    NONE = 0
    INIT = 1
    PREOP = 2
    BOOT = 3
    SAFEOP = 4
    OP = 8


class Reg(IntEnum):
    """Register addresses (ETG.1000.4 Table 31)."""

    TYPE = 0x0000
    REVISION = 0x0001
    BUILD = 0x0002
    FMMU_COUNT = 0x0004
    SM_COUNT = 0x0005
    RAM_SIZE = 0x0006
    PORT_DESCRIPTOR = 0x0007
    FEATURES = 0x0008
    STATION_ADDRESS = 0x0010
    STATION_ALIAS = 0x0012
    DL_CONTROL = 0x0100
    DL_ALIAS = 0x0103
    DL_STATUS = 0x0110
    AL_CONTROL = 0x0120
    AL_STATUS = 0x0130
    AL_STATUS_CODE = 0x0134
    PDI_CONTROL = 0x0140
    ESC_CONFIG = 0x0141
    EVENT_MASK = 0x0200
    AL_EVENT_MASK = 0x0204
    EVENT_REQUEST = 0x0210
    AL_EVENT_REQUEST = 0x0220
    RX_ERROR = 0x0300
    WD_DIVIDER = 0x0400
    WD_TIME_PDI = 0x0410
    WD_TIME_PD = 0x0420
    WD_STATUS_PD = 0x0440
    WD_COUNTER_PD = 0x0442
    EEPROM_CONFIG = 0x0500
    EEPROM_PDI_ACCESS = 0x0501
    EEPROM_CONTROL = 0x0502
    EEPROM_ADDRESS = 0x0504
    EEPROM_DATA = 0x0508
    FMMU0 = 0x0600
    SM0 = 0x0800
    DC_RECEIVE_TIME0 = 0x0900
    DC_RECEIVE_TIME1 = 0x0904
    DC_SYSTEM_TIME = 0x0910
    DC_RECEIVE_TIME_PU = 0x0918
    DC_SYSTEM_OFFSET = 0x0920
    DC_SYSTEM_DELAY = 0x0928
    DC_SYSTEM_DIFF = 0x092C
    DC_SPEED_COUNT = 0x0930
    DC_FILTER_DEPTH = 0x0934
    DC_CYCLIC_CONTROL = 0x0980
    DC_ACTIVATION = 0x0981
    DC_START_TIME = 0x0990
    DC_SYNC0_CYCLE = 0x09A0
    DC_SYNC1_CYCLE = 0x09A4


class EepromStatus:
    """Bits of 0502h (ETG.1000.4 Table 48)."""

    WRITE_ENABLE = 0x0001
    READ_8_BYTES = 0x0040
    TWO_ADDRESS_BYTES = 0x0080
    CMD_READ = 0x0100
    CMD_WRITE = 0x0200
    CMD_RELOAD = 0x0400
    CMD_MASK = 0x0700
    CHECKSUM_ERROR = 0x0800
    LOAD_ERROR = 0x1000
    ACK_ERROR = 0x2000
    WRITE_ENABLE_ERROR = 0x4000
    BUSY = 0x8000
    ERROR_MASK = 0x7800
