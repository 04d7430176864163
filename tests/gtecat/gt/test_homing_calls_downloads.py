"""GT_SetEcatHomingPrm's five SDO downloads (manual entry 103): each one a download of its
own, the first the drive refuses ending the call with its abort and the ones after it not
sent, as a master sends them one by one."""

from __future__ import annotations

from ctypes import byref, c_ubyte, c_uint32
from typing import Any

import pytest

from gtecat import gt
from gtecat.drives.coe import advance_counter
from gtecat.drives.sdo_server import SdoServer
from gtecat.gt import _core

from .conftest import bring_up

_OBJECTS = ((0x6098, 0), (0x6099, 1), (0x6099, 2), (0x609A, 0), (0x607C, 0))


def _upload(index: int, subindex: int) -> int:
    data, size = (c_ubyte * 4)(), c_uint32()
    assert gt.GT_EcatSDOUpload(0, index, subindex, data, 4, byref(size)) == 0
    return int.from_bytes(bytes(data)[: size.value], "little", signed=index == 0x607C)


def test_a_refusal_in_the_middle_stops_the_downloads_after_it(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    served: list[tuple[int, bool]] = []
    serve = SdoServer.download_values_in_process

    def spy(self: SdoServer, items: Any, al_state: Any) -> Any:
        n, abort = serve(self, items, al_state)
        served.append((n, abort is not None))
        return n, abort

    monkeypatch.setattr(SdoServer, "download_values_in_process", spy)
    bring_up(clock="lockstep")
    assert gt.GT_AxisOn(1) == 0 and gt.GT_SetHomingMode(1, 6) == 0
    backend = _core.SESSION.controllers[1].master.backend
    drive = backend.slaves[0]
    drive.od.find(0x609A, 0).high = 100_000  # this drive's homing acceleration: at most this
    before = {key: _upload(*key) for key in _OBJECTS}
    client, server = backend._clients[0].counter, drive.sdo.counter

    assert gt.GT_SetEcatHomingPrm(1, 34, 50_000, 5_000, 150_000, 77, 0) == 1
    assert served == [(4, True)]  # (in one go, unframed, on this bus)
    reason = gt.GTE_GetLastError()
    assert "writing 150000 to 0x609A:00 failed" in reason and "(0x06090031)" in reason
    # four downloads sent, the fourth refused: both sides counted four messages
    assert backend._clients[0].counter == advance_counter(client, 4)
    assert drive.sdo.counter == advance_counter(server, 4)
    after = {key: _upload(*key) for key in _OBJECTS}
    assert after[0x6098, 0] == 34 and after[0x6099, 1] == 50_000 and after[0x6099, 2] == 5_000
    assert after[0x609A, 0] == before[0x609A, 0] and after[0x607C, 0] == before[0x607C, 0] == 0
    assert gt.GT_StartEcatHoming(1) == 1  # the parameters were not (all) set

    assert gt.GT_SetEcatHomingPrm(1, 34, 50_000, 5_000, 90_000, 77, 0) == 0
    assert served[-1] == (5, False)
    assert _upload(0x609A, 0) == 90_000 and _upload(0x607C, 0) == 77
