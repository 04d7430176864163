"""SdoClient against misbehaving slaves: scripted fake mailboxes, not our own SdoServer.

Every bad answer must end in an :class:`SdoAbort` with a fitting CiA 301 code, after a
bounded number of exchanges, and the client aborts the transfer at the slave when it
gives up (ETG.1000.6 5.6.2.7).
"""

from __future__ import annotations

import math
import struct
from collections.abc import Callable, Iterable

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from gtecat.drives.abort import SdoAbort, SdoAbortCode
from gtecat.drives.coe import (
    MIN_SEGMENT_DATA,
    CoeHeader,
    CoeService,
    MailboxType,
    SdoClient,
    build_abort,
    build_coe,
    build_mailbox,
    parse_mailbox,
)
from tests.conftest import examples

IDX, SUB = 0x2000, 0
ADDR = struct.pack("<HB", IDX, SUB)


# --- reply builders (ETG.1000.6 5.6.2) ---------------------------------------------------
def response(sdo: bytes) -> bytes:
    return build_coe(CoeService.SDO_RESPONSE, sdo, counter=1)


def normal_upload(total: int, first: bytes = b"", addr: bytes = ADDR) -> bytes:
    """Initiate upload response, normal transfer, size indicated."""
    return response(bytes([0x41]) + addr + struct.pack("<I", total) + first)


def expedited_upload(data: bytes, addr: bytes = ADDR, cmd: int | None = None) -> bytes:
    if cmd is None:
        cmd = 0x43 | (4 - len(data)) << 2
    return response(bytes([cmd]) + addr + data.ljust(4, b"\x00"))


def upload_segment(toggle: bool, data: bytes, *, last: bool = False, unused: int = 0) -> bytes:
    cmd = toggle << 4 | unused << 1 | last
    return response(bytes([cmd]) + data)


def download_answer(addr: bytes = ADDR) -> bytes:
    return response(bytes([0x60]) + addr + bytes(4))


def download_segment_answer(toggle: bool) -> bytes:
    return response(bytes([0x20 | toggle << 4]) + bytes(7))


class FakeSlave:
    """Answers from a script, then from ``then(request)`` (default: no answer)."""

    def __init__(
        self,
        script: Iterable[bytes | None] = (),
        then: Callable[[bytes], bytes | None] | None = None,
    ) -> None:
        self.script = list(script)
        self.then = then
        self.sent: list[bytes] = []

    def __call__(self, message: bytes) -> bytes | None:
        self.sent.append(message)
        if _is_abort(message):
            return None  # an abort request is not answered
        if self.script:
            return self.script.pop(0)
        return self.then(message) if self.then else None

    @property
    def requests(self) -> list[bytes]:
        return [m for m in self.sent if not _is_abort(m)]

    @property
    def aborts(self) -> list[tuple[int, int, int]]:
        """(index, subindex, code) of every abort request the client sent."""
        return [struct.unpack_from("<HBI", m, 9) for m in self.sent if _is_abort(m)]


def _is_abort(message: bytes) -> bool:
    mbx = parse_mailbox(message)
    coe = CoeHeader.parse(mbx.data[:2])
    return coe.service == CoeService.SDO_REQUEST and mbx.data[2] == 0x80


def request_toggle(message: bytes) -> bool:
    return bool(message[8] & 0x10)


def expect_abort(call: Callable[[], object], code: int, detail: str = "") -> SdoAbort:
    with pytest.raises(SdoAbort) as e:
        call()
    assert e.value.code == code, str(e.value)
    assert detail in str(e.value)
    return e.value


# --- endless segmented uploads --------------------------------------------------------
@pytest.mark.parametrize("first", [b"", bytes(112)])
def test_endless_empty_segments_time_out_at_once(first: bytes) -> None:
    slave = FakeSlave(
        [normal_upload(1000, first)], lambda m: upload_segment(request_toggle(m), b"")
    )
    expect_abort(
        lambda: SdoClient(slave).upload(IDX, SUB),
        SdoAbortCode.SDO_PROTOCOL_TIMED_OUT,
        "no progress",
    )
    assert len(slave.requests) == 2
    assert slave.aborts == [(IDX, SUB, SdoAbortCode.SDO_PROTOCOL_TIMED_OUT)]


def test_endless_padded_segments_stop_at_the_announced_size() -> None:
    """7 zero bytes with seg_size 7 but not last: counted as data, so it overruns."""
    slave = FakeSlave(
        [normal_upload(1000, bytes(112))],
        lambda m: upload_segment(request_toggle(m), bytes(7), unused=7),
    )
    expect_abort(
        lambda: SdoClient(slave).upload(IDX, SUB), SdoAbortCode.SDO_PROTOCOL_TIMED_OUT, "announced"
    )
    assert len(slave.requests) == 1 + math.ceil(888 / 7)
    assert len(slave.aborts) == 1


@pytest.mark.parametrize(("total", "seg"), [(200, 50), (20, 7), (112 + 119, 119)])
def test_segments_past_the_announced_size_time_out(total: int, seg: int) -> None:
    first = bytes(min(total, 112) - 1) if total > 112 else b""
    slave = FakeSlave(
        [normal_upload(total, first)], lambda m: upload_segment(request_toggle(m), bytes(seg))
    )
    err = expect_abort(
        lambda: SdoClient(slave).upload(IDX, SUB),
        SdoAbortCode.SDO_PROTOCOL_TIMED_OUT,
        f"{total} announced",
    )
    assert "is not the last" in err.detail
    n_segments = (total - len(first)) // seg + 1
    assert len(slave.requests) == 1 + n_segments
    assert slave.aborts == [(IDX, SUB, SdoAbortCode.SDO_PROTOCOL_TIMED_OUT)]


def test_too_many_tiny_segments_time_out() -> None:
    total = 700
    slave = FakeSlave([normal_upload(total)], lambda m: upload_segment(request_toggle(m), b"x"))
    expect_abort(
        lambda: SdoClient(slave).upload(IDX, SUB),
        SdoAbortCode.SDO_PROTOCOL_TIMED_OUT,
        "no last segment after",
    )
    assert len(slave.requests) == 1 + math.ceil(total / MIN_SEGMENT_DATA) + 1


def test_an_announced_size_beyond_max_size_is_refused_before_any_segment() -> None:
    slave = FakeSlave(
        [normal_upload(0xFFFFFFFF)], lambda m: upload_segment(request_toggle(m), b"x")
    )
    expect_abort(lambda: SdoClient(slave).upload(IDX, SUB), SdoAbortCode.OUT_OF_MEMORY)
    assert len(slave.requests) == 1
    assert slave.aborts == [(IDX, SUB, SdoAbortCode.OUT_OF_MEMORY)]
    small = FakeSlave([normal_upload(101)])
    expect_abort(lambda: SdoClient(small, max_size=100).upload(IDX, SUB), 0x05040005, "101")


def test_tiny_segments_within_the_bound_still_work() -> None:
    """A slave sending short (non-conforming) segments is tolerated while it makes progress."""
    payload = bytes(range(30))
    chunks = [payload[k : k + 5] for k in range(0, 30, 5)]
    script = [normal_upload(30)] + [
        upload_segment(bool(k & 1), c, last=k == len(chunks) - 1) for k, c in enumerate(chunks)
    ]
    assert SdoClient(FakeSlave(script)).upload(IDX, SUB) == payload


def test_last_segment_with_a_length_mismatch() -> None:
    for data in (bytes(10), bytes(30)):
        slave = FakeSlave([normal_upload(20), upload_segment(False, data, last=True)])
        expect_abort(lambda s=slave: SdoClient(s).upload(IDX, SUB), SdoAbortCode.LENGTH_MISMATCH)
        assert len(slave.aborts) == 1


# --- malformed replies --------------------------------------------------------------------
def mbx_error(payload: bytes) -> bytes:
    return build_mailbox(payload, counter=1, mbx_type=MailboxType.ERR)


MALFORMED: list[tuple[str, bytes, int, str]] = [
    # ConstError: the error reply's "service" word is not 0x0001
    ("error reply service 2", mbx_error(b"\x02\x00\x04\x00"), 0x08000000, "service 0x0002"),
    ("error reply short", mbx_error(b"\x01\x00"), 0x08000000, "2 bytes"),
    ("error reply empty", mbx_error(b""), 0x08000000, "0 bytes"),
    ("error reply unknown", mbx_error(b"\x01\x00\x99\x00"), 0x08000000, "0x0099"),
    ("error reply known", mbx_error(b"\x01\x00\x06\x00"), 0x08000000, "SIZE_TOO_SHORT"),
    ("under a header", b"\x0a\x00\x00", 0x08000000, "shorter than its header"),
    ("cut short", normal_upload(5, b"abcde")[:-3], 0x08000000, "mailbox header says"),
    ("FoE", build_mailbox(b"\x00\x30" + bytes(8), counter=1, mbx_type=MailboxType.FOE), 0x08000000,
     "mailbox type 4"),
    ("CoE without SDO", build_mailbox(b"\x00\x30", counter=1), 0x08000000, "no SDO frame"),
    ("CoE emergency", build_coe(CoeService.EMERGENCY, bytes(8), counter=1), 0x08000000,
     "EMERGENCY"),
    ("CoE service 15", build_coe(15, bytes(8), counter=1), 0x08000000, "service 15"),  # type: ignore[arg-type]
    ("SDO request, not abort", build_coe(CoeService.SDO_REQUEST, b"\x43" + ADDR + bytes(4),
     counter=1), 0x08000000, "SDO_REQUEST"),
    ("short abort", build_coe(CoeService.SDO_REQUEST, b"\x80\x00\x20", counter=1), 0x08000000,
     "abort frame of 3 bytes"),
    ("short initiate", response(b"\x43\x00\x20"), 0x08000000, "3 bytes, 8 expected"),
    ("wrong index", expedited_upload(b"\x01", addr=struct.pack("<HB", 0x2001, 0)), 0x08000000,
     "answer is for 0x2001:00"),
    ("wrong subindex", expedited_upload(b"\x01", addr=struct.pack("<HB", IDX, 3)), 0x08000000,
     "answer is for 0x2000:03"),
    ("download answer", download_answer(), 0x05040001, "not INITIATE_UPLOAD"),
    ("segment answer", upload_segment(False, bytes(7)), 0x05040001, "not INITIATE_UPLOAD"),
    ("scs 5", response(b"\xa0" + ADDR + bytes(4)), 0x05040001, "0xA0"),
    ("abort with reserved bits", response(b"\x81" + ADDR + bytes(4)), 0x05040001, "0x81"),
]  # fmt: skip


#: replies that are wrong for a segment request too (the rest are right-looking initiates)
MALFORMED_ANYWHERE = MALFORMED[:13]


def cases(table: list[tuple[str, bytes, int, str]]) -> list[object]:
    return [pytest.param(*m[1:], id=m[0]) for m in table]


@pytest.mark.parametrize(("reply", "code", "detail"), cases(MALFORMED))
def test_malformed_initiate_upload_answer(reply: bytes, code: int, detail: str) -> None:
    slave = FakeSlave([reply])
    expect_abort(lambda: SdoClient(slave).upload(IDX, SUB), code, detail)
    assert len(slave.requests) == 1
    assert slave.aborts == [(IDX, SUB, code)]


@pytest.mark.parametrize(("reply", "code", "detail"), cases(MALFORMED_ANYWHERE))
def test_malformed_segment_answers(reply: bytes, code: int, detail: str) -> None:
    up = FakeSlave([normal_upload(200, bytes(112)), reply])
    expect_abort(lambda: SdoClient(up).upload(IDX, SUB), code, detail)
    down = FakeSlave([download_answer(), reply])
    expect_abort(lambda: SdoClient(down).download(IDX, SUB, bytes(200)), code, detail)
    assert len(up.aborts) == len(down.aborts) == 1


def test_upload_segment_with_the_wrong_toggle_or_specifier() -> None:
    slave = FakeSlave([normal_upload(200, bytes(112)), upload_segment(True, bytes(88), last=True)])
    expect_abort(lambda: SdoClient(slave).upload(IDX, SUB), 0x05030000, "segment 1 has toggle 1")
    slave = FakeSlave(
        [
            normal_upload(300, bytes(112)),
            upload_segment(False, bytes(100)),
            upload_segment(False, b""),
        ]
    )
    expect_abort(lambda: SdoClient(slave).upload(IDX, SUB), 0x05030000, "segment 2")
    slave = FakeSlave([normal_upload(200, bytes(112)), normal_upload(200, bytes(88))])
    expect_abort(lambda: SdoClient(slave).upload(IDX, SUB), 0x05040001, "not UPLOAD_SEGMENT")
    assert slave.aborts == [(IDX, SUB, 0x05040001)]


def test_download_answers_with_the_wrong_toggle_specifier_or_object() -> None:
    big = bytes(400)  # 112 in the initiate, then 3 segments
    slave = FakeSlave([download_answer(), download_segment_answer(True)])
    expect_abort(lambda: SdoClient(slave).download(IDX, SUB, big), 0x05030000, "segment 1")
    slave = FakeSlave([download_answer(), download_segment_answer(False), download_answer()])
    expect_abort(lambda: SdoClient(slave).download(IDX, SUB, big), 0x05040001, "DOWNLOAD_SEGMENT")
    slave = FakeSlave([download_answer(struct.pack("<HB", 0x6040, 0))])
    expect_abort(lambda: SdoClient(slave).download(IDX, SUB, b"\x01"), 0x08000000, "0x6040:00")
    slave = FakeSlave([expedited_upload(b"\x01")])
    expect_abort(lambda: SdoClient(slave).download(IDX, SUB, b"\x01"), 0x05040001)
    slave = FakeSlave([download_answer(), download_segment_answer(False)])  # then silence
    expect_abort(lambda: SdoClient(slave).download(IDX, SUB, big), 0x05040000, "no answer")
    assert slave.aborts == [(IDX, SUB, 0x05040000)]
    assert len(slave.requests) == 3


def test_complete_access_answers_are_checked_too() -> None:
    ca_sub1 = struct.pack("<HB", 0x1C12, 1)
    slave = FakeSlave([expedited_upload(b"\x01\x00\x00\x16", addr=struct.pack("<HB", 0x1C12, 0))])
    expect_abort(lambda: SdoClient(slave).upload(0x1C12, 1, True), 0x08000000, "0x1C12:00")
    slave = FakeSlave([normal_upload(6, b"\x01\x00\x00\x16\x00\x00", addr=ca_sub1)])
    assert SdoClient(slave).upload(0x1C12, 1, complete_access=True) == b"\x01\x00\x00\x16\x00\x00"
    assert slave.requests[0][8] & 0x10  # the request asked for complete access
    slave = FakeSlave([normal_upload(300, bytes(112), addr=ca_sub1)], lambda m: None)
    expect_abort(lambda: SdoClient(slave).upload(0x1C12, 1, True), 0x05040000)
    assert slave.aborts == [(0x1C12, 1, 0x05040000)]
    slave = FakeSlave([download_answer(ca_sub1), download_segment_answer(True)])
    expect_abort(lambda: SdoClient(slave).download(0x1C12, 1, bytes(300), True), 0x05030000)


# --- aborts both ways ----------------------------------------------------------------------
def test_a_slave_abort_is_not_answered_with_an_abort() -> None:
    abort = build_coe(CoeService.SDO_REQUEST, build_abort(IDX, SUB, 0x06010002), counter=1)
    slave = FakeSlave([normal_upload(300, bytes(112)), abort])
    expect_abort(lambda: SdoClient(slave).upload(IDX, SUB), 0x06010002)
    assert slave.aborts == [] and len(slave.sent) == 2


def test_the_abort_request_bytes() -> None:
    slave = FakeSlave(
        [normal_upload(300, bytes(112), struct.pack("<HB", 0x6041, 2))]
    )  # then silence
    client = SdoClient(slave)
    expect_abort(lambda: client.upload(0x6041, 2), 0x05040000)
    # CoE service 2 carries the abort (ETG.1000.6 Table 40), with the next counter
    assert slave.sent[-1] == bytes.fromhex(
        "0a00 0000 00 33 0020 80 4160 02 00000405".replace(" ", "")
    )
    assert client.counter == 3


def test_a_failing_abort_request_does_not_hide_the_abort(caplog: pytest.LogCaptureFixture) -> None:
    def transfer(message: bytes) -> bytes | None:
        if _is_abort(message):
            raise OSError("link down")
        return None

    expect_abort(lambda: SdoClient(transfer).upload(IDX, SUB), 0x05040000, "no answer")
    assert "link down" in caplog.text


# --- properties: any reply gives data or SdoAbort, after a bounded number of exchanges --------
@st.composite
def replies(draw: st.DrawFn) -> bytes:
    kind = draw(st.sampled_from(["raw", "mailbox", "sdo", "sdo", "sdo"]))
    if kind == "raw":
        return draw(st.binary(max_size=40))
    if kind == "mailbox":
        body = draw(st.binary(max_size=20))
        mtype = draw(st.integers(0, 15))
        message = build_mailbox(body, counter=1, mbx_type=mtype)  # type: ignore[arg-type]
        return message[: draw(st.integers(0, len(message)))] if draw(st.booleans()) else message
    service = draw(st.sampled_from([2, 3, 3, 3, 1, 8, 0, 15]))
    cmd = draw(st.integers(0, 255))
    addr = ADDR if draw(st.booleans()) else draw(st.binary(min_size=3, max_size=3))
    tail = draw(st.binary(max_size=130))
    sdo = bytes([cmd]) + addr + tail if draw(st.booleans()) else bytes([cmd]) + tail
    return build_coe(service, sdo, counter=draw(st.integers(0, 7)))  # type: ignore[arg-type]


def run_service(client: SdoClient, service: int, ca: bool, size: int) -> None:
    try:
        if service == 0:
            assert isinstance(client.upload(IDX, SUB, complete_access=ca), bytes)
        else:
            client.download(IDX, SUB, bytes(size), complete_access=ca)
    except SdoAbort as e:
        assert isinstance(e.code, int)


@settings(max_examples=examples(400, 50), deadline=None)
@given(
    st.lists(replies() | st.none(), max_size=12),
    st.integers(0, 1),
    st.booleans(),
    st.integers(0, 600),
)
def test_any_replies_give_data_or_an_abort(
    script: list[bytes | None], service: int, ca: bool, size: int
) -> None:
    slave = FakeSlave(script)
    run_service(SdoClient(slave), service, ca, size)
    assert len(slave.requests) <= len(script) + 1  # then silence: one timeout
    assert len(slave.aborts) <= 1


MAX = 2048


@settings(max_examples=examples(200, 30), deadline=None)
@given(
    st.integers(0, 2**32 - 1),
    st.binary(max_size=112),
    st.lists(st.tuples(st.integers(0, 20), st.booleans(), st.integers(0, 7)), min_size=1),
    st.booleans(),
)
def test_an_endless_segment_stream_always_ends(
    total: int, first: bytes, pattern: list[tuple[int, bool, int]], flip: bool
) -> None:
    """The slave never stops answering segment requests (toggle echoed, unless ``flip``)."""
    count = [0]

    def segment(message: bytes) -> bytes:
        n, last, unused = pattern[count[0] % len(pattern)]
        count[0] += 1
        toggle = request_toggle(message) ^ (flip and count[0] % 5 == 0)
        return upload_segment(toggle, bytes(n), last=last and count[0] > 3, unused=unused)

    slave = FakeSlave([normal_upload(total, first)], segment)
    try:
        data = SdoClient(slave, max_size=MAX).upload(IDX, SUB)
        assert len(data) == total
    except SdoAbort as e:
        assert len(slave.aborts) == 1 and slave.aborts[0][2] == e.code
    assert len(slave.requests) <= math.ceil(MAX / MIN_SEGMENT_DATA) + 2


@settings(max_examples=examples(200, 30), deadline=None)
@given(replies(), st.integers(0, 1), st.booleans(), st.integers(0, 600))
def test_one_reply_repeated_for_ever_ends(reply: bytes, service: int, ca: bool, size: int) -> None:
    slave = FakeSlave(then=lambda _m: reply)
    run_service(SdoClient(slave, max_size=MAX), service, ca, size)
    bound = math.ceil(MAX / MIN_SEGMENT_DATA) + 2 if service == 0 else math.ceil(size / 119) + 1
    assert len(slave.requests) <= bound
