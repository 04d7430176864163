"""What the frame faults do to an answered frame on the wire (``gtecat serve``'s frame hook),
without a network: the injector's :meth:`~gtecat.faults.injector.Injector.frame` on frames
built here.  (``tests/gtecat/wire/test_faults_wire.py`` runs them against a real master.)"""

from __future__ import annotations

import struct

from gtecat.drives.esc import Command, Datagram, decode_frame, encode_frame
from gtecat.faults import Injector, WireBus, kinds


class _Chain:
    process_data = True
    slaves: list = []  # noqa: RUF012


def _frame(wkc: int = 3, index: int = 7, command: int = Command.LRW, adp: int = 0) -> bytearray:
    return bytearray(encode_frame([Datagram(command, adp, 0, bytes(8), index, wkc)]))


def test_frame_faults_on_answered_frames() -> None:
    inj = Injector(WireBus(_Chain()))  # type: ignore[arg-type]
    inj.add(kinds.DropResponses(count=2))
    buf = _frame()
    assert inj.frame(buf, len(buf), 0) == 0 and inj.frame(buf, len(buf), 0) == 0
    assert inj.frame(buf, len(buf), 0) == len(buf)  # spent: answered again
    inj.tick()
    assert inj.entries == []
    inj.add(kinds.FrameTruncate(bytes=5))
    assert inj.frame(buf, len(buf), 0) == len(buf) - 5
    inj.add(kinds.FrameWrongIndex())
    buf = _frame(index=7)
    inj.frame(buf, len(buf), 0)
    assert decode_frame(buf).datagrams[0].index == 7 ^ 0x80
    first, second = _frame(wkc=1), _frame(wkc=2)
    inj.frame(first, len(first), 0)
    inj.add(kinds.FrameReplay())
    n = inj.frame(second, len(second), 0)
    assert decode_frame(second[:n]).datagrams[0].wkc == 1  # the previous answer again


def test_wkc_offset_by_command_and_logical_area() -> None:
    inj = Injector(WireBus(_Chain()))  # type: ignore[arg-type]
    inj.add(kinds.WkcOffset(offset=-1, command="LRW", area=(0, 4)))
    lrw = _frame(wkc=3)
    inj.frame(lrw, len(lrw), 0)
    assert decode_frame(lrw).datagrams[0].wkc == 2
    brd = _frame(wkc=3, command=Command.BRD)
    inj.frame(brd, len(brd), 0)
    assert decode_frame(brd).datagrams[0].wkc == 3  # another command: untouched
    far = bytearray(encode_frame([Datagram(Command.LRW, 0x10, 0, bytes(8), 1, 3)]))
    far_addr = struct.unpack_from("<I", far, 18)[0]
    assert far_addr == 0x10  # logical bytes 16.. of the image: outside [0, 4)
    inj.frame(far, len(far), 0)
    assert decode_frame(far).datagrams[0].wkc == 3


def test_only_cyclic_frames_are_hit() -> None:
    chain = _Chain()
    chain.process_data = False
    inj = Injector(WireBus(chain))  # type: ignore[arg-type]
    inj.add(kinds.DropResponses(count=1))
    buf = _frame()
    assert inj.frame(buf, len(buf), 0) == len(buf)  # a register read at bring-up passes
