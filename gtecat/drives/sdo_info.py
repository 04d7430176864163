"""The slave side of the CoE SDO Information service (ETG.1000.6 5.6.3).

A master lists a slave's object dictionary with three requests:

* Get OD List (5.6.3.3): the indices of all objects, of those mappable into an
  RxPDO or a TxPDO, of those stored for device replacement or the startup
  parameters; list type 0 gives the length of each list.
* Get Object Description (5.6.3.5): data type, maximum subindex, object code
  and name of one index.
* Get Entry Description (5.6.3.6): data type, bit length, access rights per AL
  state and PDO mappability, optionally unit, default, minimum and maximum, and
  the name of one entry.

An answer longer than one mailbox is sent in fragments, each a mailbox message
of its own whose header counts the fragments still to come (``Incomplete`` set
on all but the last).  The master sends no request between fragments: the
slave puts the next one into its send mailbox as soon as the master has read
the previous one, so :meth:`SdoInformation.handle` returns every fragment and
the caller hands them out one at a time.

Every refusal is an SDO Info Error request carrying the CiA 301 abort code
(object does not exist 06020000h, subindex does not exist 06090011h, unknown
opcode 05040001h).  Names are Latin-1 with no terminator: a master derives a
name's length from the mailbox length (SOEM does), so nothing pads them.
"""

from __future__ import annotations

import logging

from gtecat.drives.abort import SdoAbort, SdoAbortCode
from gtecat.drives.coe import (
    COE_HEADER_SIZE,
    MAILBOX_HEADER_SIZE,
    SDO_INFO_HEADER_SIZE,
    EntryDescription,
    EntryDescriptionRequest,
    ObjectDescription,
    OdListType,
    SdoInfoError,
    SdoInfoHeader,
    SdoInfoOpcode,
    ValueInfo,
)
from gtecat.drives.od import ObjectDictionary, OdObject, PdoDir, Variable

log = logging.getLogger(__name__)

#: the longest name an answer carries (SOEM keeps 40 characters, TwinCAT shows more)
MAX_NAME = 80


class SdoInformation:
    """Answer SDO Information requests from one object dictionary."""

    def __init__(self, od: ObjectDictionary) -> None:
        self.od = od

    def handle(self, body: bytes) -> tuple[SdoInfoOpcode, list[bytes]]:
        """One request (the bytes after the CoE header) -> (opcode, fragment payloads).

        Each payload is the SDO Information data of one fragment; the caller frames
        them (:func:`gtecat.drives.coe.build_sdo_info`) with ``fragments_left`` counting down.
        """
        if len(body) < SDO_INFO_HEADER_SIZE:
            return _error(SdoAbortCode.GENERAL_ERROR)
        header = SdoInfoHeader.parse(body[:SDO_INFO_HEADER_SIZE])
        data = body[SDO_INFO_HEADER_SIZE:]
        opcode = header.op.opcode
        try:
            if opcode == SdoInfoOpcode.GET_OD_LIST_REQUEST:
                return SdoInfoOpcode.GET_OD_LIST_RESPONSE, [self._od_list(data)]
            if opcode == SdoInfoOpcode.GET_OBJECT_DESCRIPTION_REQUEST:
                return SdoInfoOpcode.GET_OBJECT_DESCRIPTION_RESPONSE, [self._object(data)]
            if opcode == SdoInfoOpcode.GET_ENTRY_DESCRIPTION_REQUEST:
                return SdoInfoOpcode.GET_ENTRY_DESCRIPTION_RESPONSE, [self._entry(data)]
        except SdoAbort as err:
            return _error(err.code)
        except Exception:
            log.exception("SDO Information request (opcode %d) failed inside the slave", opcode)
            return _error(SdoAbortCode.GENERAL_ERROR)
        return _error(SdoAbortCode.COMMAND_SPECIFIER_INVALID)

    # --- the three services -------------------------------------------------------
    def lists(self) -> dict[OdListType, list[int]]:
        """Lists 1..5 of Get OD List, indices ascending."""
        objects = sorted(self.od, key=lambda o: o.index)

        def mappable(obj: OdObject, direction: PdoDir) -> bool:
            return any(v.pdo & direction for v in obj.subs.values())

        return {
            OdListType.ALL: [o.index for o in objects],
            OdListType.RXPDO_MAPPABLE: [o.index for o in objects if mappable(o, PdoDir.RX)],
            OdListType.TXPDO_MAPPABLE: [o.index for o in objects if mappable(o, PdoDir.TX)],
            OdListType.DEVICE_REPLACEMENT: [],
            OdListType.STARTUP: [],
        }

    def _od_list(self, data: bytes) -> bytes:
        if len(data) < 2:
            raise SdoAbort(SdoAbortCode.GENERAL_ERROR, 0, 0, "Get OD List without a list type")
        list_type = int.from_bytes(data[:2], "little")
        lists = self.lists()
        if list_type == OdListType.LENGTHS:
            values = [len(lists[t]) for t in sorted(lists)]
        else:
            try:
                values = lists[OdListType(list_type)]
            except ValueError:
                raise SdoAbort(
                    SdoAbortCode.VALUE_RANGE_EXCEEDED, 0, 0, f"list type {list_type}"
                ) from None
        return list_type.to_bytes(2, "little") + b"".join(v.to_bytes(2, "little") for v in values)

    def _object(self, data: bytes) -> bytes:
        if len(data) < 2:
            raise SdoAbort(SdoAbortCode.GENERAL_ERROR, 0, 0, "Get Object Description without index")
        index = int.from_bytes(data[:2], "little")
        obj = self.od.obj(index)
        return ObjectDescription.build(
            {
                "index": index,
                "data_type": obj.data_type,
                "max_subindex": obj.max_subindex,
                "object_code": int(obj.code),
                "name": _name(obj.name),
            }
        )

    def _entry(self, data: bytes) -> bytes:
        if len(data) < 4:
            raise SdoAbort(SdoAbortCode.GENERAL_ERROR, 0, 0, "short Get Entry Description")
        req = EntryDescriptionRequest.parse(data[:4])
        var = self.od.variable(req.index, req.subindex)
        asked = ValueInfo(req.value_info & 0x78)
        given, extra = _value_info(var, asked)
        return EntryDescription.build(
            {
                "index": req.index,
                "subindex": req.subindex,
                "value_info": int(given),
                "data_type": int(var.data_type),
                "bit_length": var.bit_length,
                "object_access": int(var.object_access),
                "rest": extra + _name(var.name),
            }
        )


def fragments(payload: bytes, mailbox_size: int) -> list[bytes]:
    """Split one answer into fragment payloads that each fit the slave's send mailbox.

    Fragments hold an even number of bytes (a master reading index lists takes
    whole words from each fragment).
    """
    room = mailbox_size - MAILBOX_HEADER_SIZE - COE_HEADER_SIZE - SDO_INFO_HEADER_SIZE
    room -= room % 2
    if room <= 0:
        raise ValueError(f"a mailbox of {mailbox_size} bytes cannot carry SDO Information")
    return [payload[i : i + room] for i in range(0, len(payload), room)] or [b""]


def _error(code: int) -> tuple[SdoInfoOpcode, list[bytes]]:
    return SdoInfoOpcode.SDO_INFO_ERROR_REQUEST, [SdoInfoError.build({"code": int(code)})]


def _name(text: str) -> bytes:
    return text.encode("latin-1", "replace")[:MAX_NAME]


def _value_info(var: Variable, asked: ValueInfo) -> tuple[ValueInfo, bytes]:
    """The optional parts the master asked for that this entry has, in their wire order."""
    given, out = ValueInfo(0), bytearray()
    if asked & ValueInfo.UNIT_TYPE:
        given |= ValueInfo.UNIT_TYPE
        out += bytes(4)  # no unit (ETG.1004 unit 0)
    if var.info.is_string:
        return given, bytes(out)
    low = var.low if var.low is not None else var.info.low
    high = var.high if var.high is not None else var.info.high
    if asked & ValueInfo.DEFAULT_VALUE and var.getter is None:
        given |= ValueInfo.DEFAULT_VALUE
        out += var.encode(var.value)
    if asked & ValueInfo.MINIMUM_VALUE and low is not None:
        given |= ValueInfo.MINIMUM_VALUE
        out += var.encode(low)
    if asked & ValueInfo.MAXIMUM_VALUE and high is not None:
        given |= ValueInfo.MAXIMUM_VALUE
        out += var.encode(high)
    return given, bytes(out)
