"""SDO abort codes (CiA 301 7.2.4.3.17, ETG.1000.6 Table 41) and the exception that carries one.

Every refusal of an object access ends in exactly one of these codes: the
object dictionary raises :class:`SdoAbort`, the SDO server turns it into an
abort frame, the SDO client turns the frame back into the same exception, and
the GT layer copies ``code`` into ``pAbort_code``.
"""

from __future__ import annotations

from enum import Enum, IntEnum

from gtecat.eni.errors import GtecatError


class SdoAbortCode(IntEnum):
    """CiA 301 abort codes plus the EtherCAT additions of ETG.1000.6 (0x0601000x)."""

    TOGGLE_BIT_NOT_ALTERNATED = 0x05030000
    SDO_PROTOCOL_TIMED_OUT = 0x05040000
    COMMAND_SPECIFIER_INVALID = 0x05040001
    INVALID_BLOCK_SIZE = 0x05040002
    INVALID_SEQUENCE_NUMBER = 0x05040003
    CRC_ERROR = 0x05040004
    OUT_OF_MEMORY = 0x05040005
    UNSUPPORTED_ACCESS = 0x06010000
    READ_OF_WRITE_ONLY = 0x06010001
    WRITE_OF_READ_ONLY = 0x06010002
    SUBINDEX_CANNOT_BE_WRITTEN = 0x06010003
    COMPLETE_ACCESS_NOT_SUPPORTED = 0x06010004
    OBJECT_LENGTH_EXCEEDS_MAILBOX = 0x06010005
    OBJECT_MAPPED_TO_RXPDO = 0x06010006
    OBJECT_DOES_NOT_EXIST = 0x06020000
    OBJECT_CANNOT_BE_MAPPED = 0x06040041
    PDO_LENGTH_EXCEEDED = 0x06040042
    PARAMETER_INCOMPATIBILITY = 0x06040043
    INTERNAL_INCOMPATIBILITY = 0x06040047
    HARDWARE_ERROR = 0x06060000
    LENGTH_MISMATCH = 0x06070010
    LENGTH_TOO_HIGH = 0x06070012
    LENGTH_TOO_LOW = 0x06070013
    SUBINDEX_DOES_NOT_EXIST = 0x06090011
    VALUE_RANGE_EXCEEDED = 0x06090030
    VALUE_TOO_HIGH = 0x06090031
    VALUE_TOO_LOW = 0x06090032
    MAX_LESS_THAN_MIN = 0x06090036
    GENERAL_ERROR = 0x08000000
    CANNOT_TRANSFER = 0x08000020
    CANNOT_TRANSFER_LOCAL_CONTROL = 0x08000021
    CANNOT_TRANSFER_DEVICE_STATE = 0x08000022
    NO_OBJECT_DICTIONARY = 0x08000023
    NO_DATA_AVAILABLE = 0x08000024


#: The wording of CiA 301 / ETG.1000.6 for each code (what a user sees in a reason).
ABORT_TEXT: dict[SdoAbortCode, str] = {
    SdoAbortCode.TOGGLE_BIT_NOT_ALTERNATED: "toggle bit not alternated",
    SdoAbortCode.SDO_PROTOCOL_TIMED_OUT: "SDO protocol timed out",
    SdoAbortCode.COMMAND_SPECIFIER_INVALID: "client/server command specifier not valid or unknown",
    SdoAbortCode.INVALID_BLOCK_SIZE: "invalid block size",
    SdoAbortCode.INVALID_SEQUENCE_NUMBER: "invalid sequence number",
    SdoAbortCode.CRC_ERROR: "CRC error",
    SdoAbortCode.OUT_OF_MEMORY: "out of memory",
    SdoAbortCode.UNSUPPORTED_ACCESS: "unsupported access to an object",
    SdoAbortCode.READ_OF_WRITE_ONLY: "attempt to read a write-only object",
    SdoAbortCode.WRITE_OF_READ_ONLY: "attempt to write a read-only object",
    SdoAbortCode.SUBINDEX_CANNOT_BE_WRITTEN: (
        "subindex cannot be written, SI0 must be 0 for write access"
    ),
    SdoAbortCode.COMPLETE_ACCESS_NOT_SUPPORTED: (
        "complete access not supported for objects of variable length"
    ),
    SdoAbortCode.OBJECT_LENGTH_EXCEEDS_MAILBOX: "object length exceeds mailbox size",
    SdoAbortCode.OBJECT_MAPPED_TO_RXPDO: "object mapped to RxPDO, SDO download blocked",
    SdoAbortCode.OBJECT_DOES_NOT_EXIST: "object does not exist in the object dictionary",
    SdoAbortCode.OBJECT_CANNOT_BE_MAPPED: "object cannot be mapped to the PDO",
    SdoAbortCode.PDO_LENGTH_EXCEEDED: (
        "number and length of the objects to be mapped would exceed PDO length"
    ),
    SdoAbortCode.PARAMETER_INCOMPATIBILITY: "general parameter incompatibility",
    SdoAbortCode.INTERNAL_INCOMPATIBILITY: "general internal incompatibility in the device",
    SdoAbortCode.HARDWARE_ERROR: "access failed due to a hardware error",
    SdoAbortCode.LENGTH_MISMATCH: (
        "data type does not match, length of service parameter does not match"
    ),
    SdoAbortCode.LENGTH_TOO_HIGH: "data type does not match, length of service parameter too high",
    SdoAbortCode.LENGTH_TOO_LOW: "data type does not match, length of service parameter too low",
    SdoAbortCode.SUBINDEX_DOES_NOT_EXIST: "subindex does not exist",
    SdoAbortCode.VALUE_RANGE_EXCEEDED: "value range of parameter exceeded",
    SdoAbortCode.VALUE_TOO_HIGH: "value of parameter written too high",
    SdoAbortCode.VALUE_TOO_LOW: "value of parameter written too low",
    SdoAbortCode.MAX_LESS_THAN_MIN: "maximum value is less than minimum value",
    SdoAbortCode.GENERAL_ERROR: "general error",
    SdoAbortCode.CANNOT_TRANSFER: "data cannot be transferred or stored to the application",
    SdoAbortCode.CANNOT_TRANSFER_LOCAL_CONTROL: (
        "data cannot be transferred or stored to the application because of local control"
    ),
    SdoAbortCode.CANNOT_TRANSFER_DEVICE_STATE: (
        "data cannot be transferred or stored to the application"
        " because of the present device state"
    ),
    SdoAbortCode.NO_OBJECT_DICTIONARY: (
        "object dictionary dynamic generation fails or no object dictionary"
    ),
    SdoAbortCode.NO_DATA_AVAILABLE: "no data available",
}


def abort_text(code: int) -> str:
    """The standard wording of ``code``, or ``unknown abort code`` for a vendor code."""
    try:
        return ABORT_TEXT[SdoAbortCode(code)]
    except ValueError:
        return "unknown abort code"


class SdoAbort(GtecatError):
    """An SDO transfer refused with a CiA 301 abort code.

    ``str(err)`` reads ``0x6040:00: attempt to write a read-only object
    (0x06010002)`` plus the detail when one is given.  ``code`` stays an
    ``int`` subclass so vendor codes outside :class:`SdoAbortCode` survive a
    round trip through the wire.
    """

    def __init__(self, code: int, index: int, subindex: int, detail: str = "") -> None:
        try:
            self.code: int = SdoAbortCode(code)
        except ValueError:
            self.code = int(code)
        self.index = index
        self.subindex = subindex
        self.detail = detail
        text = f"0x{index:04X}:{subindex:02X}: {abort_text(code)} (0x{int(code):08X})"
        if detail:
            text += f": {detail}"
        super().__init__(text)


class MailboxFailure(Enum):
    """How an SDO transfer ends without an abort frame from the slave (what the master saw)."""

    #: the request got no answer within the master's mailbox timeout
    NO_ANSWER = "no answer"
    #: a mailbox error reply (ETG.1000.4 Table 30) instead of the SDO answer
    ERROR_REPLY = "mailbox error reply"
    #: an answer that is not the SDO answer: another mailbox type or CoE service, an SDO
    #: frame cut short, an answer for another object
    UNEXPECTED = "unexpected answer"
    #: the answer announces more data than the master takes
    TOO_BIG = "too big"


#: The abort code the master reports in ``pAbort_code`` for each, on every backend: the
#: emulated bus's SDO client (:class:`gtecat.drives.coe.SdoClient`) and the pysoem backend
#: (SOEM's outcomes) both build their :class:`SdoAbort` from this table, so an
#: application sees the same code whichever bus it runs on.
MAILBOX_FAILURE_CODES: dict[MailboxFailure, SdoAbortCode] = {
    MailboxFailure.NO_ANSWER: SdoAbortCode.SDO_PROTOCOL_TIMED_OUT,
    MailboxFailure.ERROR_REPLY: SdoAbortCode.GENERAL_ERROR,
    MailboxFailure.UNEXPECTED: SdoAbortCode.GENERAL_ERROR,
    MailboxFailure.TOO_BIG: SdoAbortCode.OUT_OF_MEMORY,
}


def mailbox_failure(
    failure: MailboxFailure, index: int, subindex: int, detail: str = ""
) -> SdoAbort:
    """The :class:`SdoAbort` the master raises for ``failure`` (:data:`MAILBOX_FAILURE_CODES`)."""
    return SdoAbort(MAILBOX_FAILURE_CODES[failure], index, subindex, detail or failure.value)
