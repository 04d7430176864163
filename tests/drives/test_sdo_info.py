"""SDO Information (ETG.1000.6 5.6.3) from the SDO server, without an ESC in between."""

from __future__ import annotations

import struct

from hypothesis import given
from hypothesis import strategies as st

from gtecat.drives.coe import CoeService, build_coe
from gtecat.drives.od import Access, DataType, ObjectDictionary, PdoDir
from gtecat.drives.sdo_server import SdoServer


def big_od(n: int) -> ObjectDictionary:
    od = ObjectDictionary()
    for k in range(n):
        od.add_var(0x2000 + k, f"Parameter {k}", DataType.UINT16, pdo=PdoDir.TX if k % 3 else 0)
    od.add_var(0x1008, "Device name", DataType.VISIBLE_STRING, Access.CONST, default="EL4002")
    return od


def od_list(server: SdoServer, list_type: int = 1) -> tuple[list[bytes], list[int]]:
    req = build_coe(CoeService.SDO_INFORMATION, struct.pack("<BBHH", 1, 0, 0, list_type), counter=1)
    messages = [server.handle(req)]
    while (nxt := server.next_message()) is not None:
        messages.append(nxt)
    data = b"".join(m[12 : 6 + struct.unpack_from("<H", m)[0]] for m in messages)
    assert struct.unpack_from("<H", data)[0] == list_type
    return messages, list(struct.unpack(f"<{len(data) // 2 - 1}H", data[2:]))


@given(st.integers(0, 400), st.sampled_from([32, 48, 128, 256, 1486]))
def test_fragments_reassemble_to_the_whole_list(n: int, size: int) -> None:
    od = big_od(n)
    server = SdoServer(od, mailbox_size=size)
    messages, indices = od_list(server)
    assert indices == sorted(o.index for o in od)
    for k, m in enumerate(messages):
        assert len(m) <= size
        left = struct.unpack_from("<H", m, 10)[0]
        assert left == len(messages) - 1 - k and bool(m[8] & 0x80) == (left > 0)
        assert (struct.unpack_from("<H", m)[0] - 6) % 2 == 0  # whole words per fragment


def test_txpdo_list_and_a_new_request_drops_the_rest() -> None:
    server = SdoServer(big_od(200), mailbox_size=64)
    _, tx = od_list(server, 3)
    assert tx == [0x2000 + k for k in range(200) if k % 3]
    req = build_coe(CoeService.SDO_INFORMATION, struct.pack("<BBHH", 1, 0, 0, 1), counter=2)
    server.handle(req)
    up = build_coe(CoeService.SDO_REQUEST, struct.pack("<BHB4x", 0x40, 0x1008, 0), counter=3)
    answer = server.handle(up)
    assert struct.unpack_from("<H", answer, 6)[0] >> 12 == CoeService.SDO_RESPONSE
    assert server.next_message() is None


def test_string_entry_describes_its_length_and_constant_access() -> None:
    server = SdoServer(big_od(1))
    body = struct.pack("<BBHHBB", 5, 0, 0, 0x1008, 0, 0x78)
    answer = server.handle(build_coe(CoeService.SDO_INFORMATION, body, counter=1))
    index, sub, vinfo, dtype, bits, access = struct.unpack_from("<HBBHHH", answer, 12)
    assert (index, sub, dtype, bits, access) == (0x1008, 0, 0x0009, 48, 0x0007)
    assert vinfo == 0x08  # only the unit: a string has no default/min/max here
    length = struct.unpack_from("<H", answer)[0]
    assert answer[26 : 6 + length] == b"Device name"  # after the 4-byte unit type
