"""The controller's protocol, spoken by a test client built from the same plans as libgts."""

from __future__ import annotations

import ctypes
import math
import random
import socket
import struct

import pytest

from gtecat import gt
from gtecat.gt import _core
from gtecat.gt.table import SCALARS
from gtecat.native import cdecl, protocol
from gtecat.native.server import Server
from tests.conftest import examples

from .conftest import FIG5_2
from .wire_client import WireClient


@pytest.fixture
def served(tmp_path):
    """This process's gt session, bus up, served on a socket."""
    gt.GT_Close()
    assert gt.GT_Open(eni=str(FIG5_2), clock="lockstep", log="") == 0
    assert gt.GT_InitEcatComm() == 0
    gt.GTE_Wait(50)
    address = f"unix:{tmp_path}/s.sock"
    with Server(address, wall_floor=False) as server:
        yield server, address
    gt.GT_Close()


def test_calls_before_gt_open_return_minus_1(served):
    _, address = served
    c = WireClient(address)
    rc, blocks, text = c.call("GT_GetSts", 1, 8, 1, None)
    assert rc == -1
    assert "GT_Open" in text
    assert c.call("GT_Open", 0, 1)[0] == 0  # attaches to the open controller
    rc, blocks, _ = c.call("GT_GetSts", 1, 8, 1, None)
    assert rc == 0 and len(blocks) == 1
    assert c.call("GTN_Close", core=2)[0] == 7  # no core 2: nothing is closed
    assert c.call("GT_GetSts", 1, 8, 1, None)[0] == 0
    assert c.call("GTN_Open", 0, 1, core=3)[0] == 7
    assert c.call("GT_Close")[0] == 0
    assert c.call("GT_GetSts", 1, 8, 1, None)[0] == -1
    c.close()


def test_a_library_of_another_table_is_refused(served):
    _, address = served
    c = WireClient(address, digest="0123456789abcdef")
    assert c.hello_status == 1
    assert "another gtecat" in c.hello_text
    with pytest.raises((ConnectionError, OSError)):
        c.call("GT_Open", 0, 1)  # calls before a good hello close the connection


def test_a_malformed_request_closes_only_that_connection(served):
    _, address = served
    good = WireClient(address)
    assert good.call("GT_Open", 0, 1)[0] == 0
    bad = socket.socket(socket.AF_UNIX, protocol.SOCKET_TYPE)
    bad.settimeout(5)
    bad.connect(address[5:])
    bad.sendall(struct.pack("<I", 3) + b"\x07xx")
    assert bad.recv(10) == b""  # closed
    assert good.call("GT_GetSts", 1, 8, 1, None)[0] == 0


def test_out_bytes_the_call_does_not_write_come_back_unchanged(served):
    _, address = served
    c = WireClient(address)
    c.call("GT_Open", 0, 1)
    target = b"\xee" * 8
    rc, blocks, _ = c.call("GT_EcatSDOUpload", 0, 0x6041, 0, target, 8, 8, 8)
    assert rc == 0
    data, size, abort = blocks
    assert abort == bytes(8)
    assert struct.unpack("<Q", size)[0] == 2
    assert data[2:] == b"\xee" * 6  # only the object's 2 bytes were written


def test_size_unknown_pointer_gets_what_the_call_wrote(served):
    _, address = served
    c = WireClient(address)
    c.call("GT_Open", 0, 1)
    rc, blocks, _ = c.call("GT_GetEcatAxisPdoData", 1, 0x6064, "?")
    assert rc == 0
    assert len(blocks[0]) == 4  # 6064h is a DINT


def test_several_clients_are_served_in_turn(served):
    _, address = served
    clients = [WireClient(address) for _ in range(4)]
    for c in clients:
        assert c.call("GT_Open", 0, 1)[0] == 0
    assert clients[0].call("GT_SetEcatRawData", 32, 1, b"\x42")[0] == 0
    for c in clients:
        rc, blocks, _ = c.call("GT_GetEcatRawData", 32, 1, 1)
        assert (rc, blocks[0]) == (0, b"\x42")


# --- the same codes as Python ---------------------------------------------------------------
_SKIP = {
    "GT_Open", "GT_Close", "GT_Reset", "GT_InitEcatComm", "GT_TerminateEcatComm",
    "GT_LoadConfig", "GTE_Wait", "GTE_UnplugSlave", "GTE_ReplugSlave", "GT_EcatIOSynch",
    "GT_SetCardNo", "GT_SetCore",  # the session's own: every later call would address another
}  # fmt: skip
_INTS = (0, 1, 2, -1, 3, 99, 40000, 1 << 31, -(1 << 33))
_REALS = (0.0, 1.5, -3.0, math.nan, math.inf, 1e300)


def _elem(ctype: str):
    if ctype in SCALARS:
        return getattr(ctypes, SCALARS[ctype][0])
    return cdecl.structure(ctype)


def _case(plan, rnd: random.Random):
    """(python args, wire args) for one random call."""
    counts = {a.count_arg for a in plan.args if a.count_arg >= 0}
    scalars = []
    for i, a in enumerate(plan.args):
        if a.kind is protocol.Kind.INT:
            scalars.append(rnd.choice((0, 1, 2, -1)) if i in counts else rnd.choice(_INTS))
        elif a.kind is protocol.Kind.DOUBLE:
            scalars.append(rnd.choice(_REALS))
        else:
            scalars.append(None)
    py, wire = [], []
    for a, v in zip(plan.args, scalars, strict=True):
        if a.kind in (protocol.Kind.INT, protocol.Kind.DOUBLE):
            if a.kind is protocol.Kind.INT and a.param.ctype in SCALARS:
                _, lo, hi, _ = SCALARS[a.param.ctype]
                if a.param.ctype in ("short", "unsigned short", "unsigned char", "char"):
                    v = max(lo, min(hi, v))  # C narrows to the type before the call
            py.append(v)
            wire.append(v)
            continue
        if rnd.random() < 0.15:
            py.append(None)
            wire.append(None)
            continue
        if a.kind is protocol.Kind.TEXT:
            py.append(b"x.cfg")
            wire.append(b"x.cfg\0")
            continue
        if a.kind is protocol.Kind.OUT_ANY:  # memory of the prototype's type (7 otherwise)
            py.append((_elem(a.param.ctype) * max(1, 8 // ctypes.sizeof(_elem(a.param.ctype))))())
            wire.append("?")
            continue
        n = scalars[a.count_arg] if a.count_arg >= 0 else a.count
        n = max(int(n), 0)
        elem = _elem(a.param.ctype)
        py.append((elem * max(n, 1))() if n else (elem * 0)())
        wire.append(ctypes.sizeof(elem) * n)
    return py, wire


@pytest.mark.long
def test_bad_input_gets_the_python_codes(served):
    _, address = served
    c = WireClient(address)
    c.call("GT_Open", 0, 1)
    rnd = random.Random(13)
    checked = 0
    for plan in protocol.plans():
        if plan.name in _SKIP or plan.unsupported:
            continue
        fn = _core.REGISTRY.get(plan.name)
        if fn is None:  # declared in the table, not implemented yet
            continue
        for _ in range(examples(12, 4)):  # cases per function: all 12 under GTECAT_LONG
            py, wire = _case(plan, rnd)
            want = fn(*py)
            got, _, text = c.call(plan.name, *wire)
            assert got == want, (plan.name, py, wire, text, gt.GTE_GetLastError())
            checked += 1
            if plan.proto.gtn:
                core = rnd.choice((1, 1, 0, 2, -5))
                want = _core.REGISTRY["GTN_" + plan.name[3:]](core, *py)
                got, _, text = c.call("GTN_" + plan.name[3:], *wire, core=core)
                assert got == want, ("GTN", core, plan.name, py, wire, text)
    assert checked > 1000


def test_a_call_that_cannot_travel_checks_its_arguments_first_as_python_does(served):
    """GT_Compile's TCompileInfo holds pointers (it cannot travel: 1), but a NULL where the
    prototype needs memory is 7 first, the same code the Python function gives."""
    _, address = served
    c = WireClient(address)
    assert c.call("GT_Open", 0, 1)[0] == 0
    size = ctypes.sizeof(gt.TCompileInfo)
    rc, _, text = c.call("GT_Compile", None, size)
    assert rc == 7 and "pFileName is NULL" in text
    rc, _, text = c.call("GT_Compile", b"prog.c\0", None)
    assert rc == 7 and "pWrongInfo is NULL" in text
    assert gt.GT_Compile("prog.c", None) == 7  # what Python says
    rc, _, text = c.call("GT_Compile", b"prog.c\0", size)
    assert rc == 1 and "pointers" in text
    c.close()


def test_a_long_wait_of_one_client_lets_the_others_in_between_its_slices(served):
    """GTE_Wait runs its time in slices; between them the server answers the other clients
    (a client's day-long wait must not hold everyone for the hours it takes to compute).

    The bus runs the wait's cycles many at a time: 30 s of controller time can pass in a few
    milliseconds, before the other client's first call arrives.  So the first look between
    two slices waits (a bounded while) until the other client's call is in the socket; from
    there on the server must answer it inside the wait, however fast the slices run."""
    import threading

    server, address = served
    waiter, other = WireClient(address), WireClient(address)
    assert waiter.call("GT_Open", 0, 1)[0] == 0 and other.call("GT_Open", 0, 1)[0] == 0
    started, sent, done = threading.Event(), threading.Event(), threading.Event()
    looks, answered_during = [0], [0]
    serve_others = server._serve_others

    def between_slices() -> None:
        looks[0] += 1
        if not started.is_set():
            started.set()
            sent.wait(10)  # the other client's call is in the socket (or the test fails below)
        calls = server.calls
        serve_others()
        answered_during[0] += server.calls - calls  # (counted here: the wait runs meanwhile)

    class _Sock:  # the other client's socket, saying when a request has been sent
        def __init__(self, sock: socket.socket) -> None:
            self._sock = sock

        def sendall(self, data: bytes) -> None:
            self._sock.sendall(data)
            sent.set()

        def __getattr__(self, name: str):
            return getattr(self._sock, name)

    server._serve_others = between_slices  # (what the server gives the wait as its hook)
    result: list[int] = []

    def wait_long() -> None:
        result.append(waiter.call("GTE_Wait", 30_000.0)[0])  # 300 slices of 100 ms
        done.set()

    t = threading.Thread(target=wait_long)
    t.start()
    try:
        assert started.wait(10), "the wait never reached its first slice's end"
        other.sock = _Sock(other.sock)
        for _ in range(2000):
            if done.is_set():
                break
            assert other.call("GT_GetSts", 1, 8, 1, None)[0] == 0
    finally:
        sent.set()
        t.join(60)
    assert result == [0]
    assert answered_during[0] > 0  # the other client was answered while the wait ran
    assert looks[0] == 299  # a look at the others between every two slices


def test_the_socket_is_its_owners_and_its_folder_is_checked(served, tmp_path):
    """The socket is 0600; a socket folder another user could enter or own is refused with
    the reason (whoever made it first could take the controller's address over)."""
    import os
    import stat

    from gtecat.native import transport

    _, address = served
    assert stat.S_IMODE(os.stat(address[len("unix:") :]).st_mode) == 0o600
    mine = transport.private_dir(tmp_path / "run" / "gtecat-me")
    assert stat.S_IMODE(mine.stat().st_mode) == 0o700
    shared = tmp_path / "shared"
    shared.mkdir()
    shared.chmod(0o777)
    with pytest.raises(ValueError, match="open to other users"):
        transport.private_dir(shared)
    (tmp_path / "file").write_text("x")
    with pytest.raises(ValueError, match="not a folder"):
        transport.private_dir(tmp_path / "file")
    if os.getuid() == 0:  # root can make a folder another user owns
        theirs = tmp_path / "theirs"
        theirs.mkdir(mode=0o700)
        os.chown(theirs, 65534, 65534)
        with pytest.raises(ValueError, match="belongs to uid 65534"):
            transport.private_dir(theirs)
