"""Virtual IO slaves: field side, wiring, ETG.5001 modules, outputs safe below OP."""

from __future__ import annotations

import pytest

from gtecat.drives.io_slaves import IoSlave
from gtecat.drives.slave import AlState, AlStatusCode
from gtecat.eni.model import Direction, Identity, Pdo, PdoEntry


def _coupler() -> IoSlave:
    rx = (
        Pdo(
            0x1600,
            Direction.OUT,
            (PdoEntry(0x7010, 1, 16, "DO16", "UINT"), PdoEntry(0x7030, 1, 16, "AO1", "INT")),
        ),
    )
    tx = (
        Pdo(
            0x1A00,
            Direction.IN,
            (PdoEntry(0x6000, 1, 16, "DI16", "UINT"), PdoEntry(0x6020, 1, 16, "AI1", "INT")),
        ),
    )
    s = IoSlave(0, "coupler", Identity(1, 2), rx_pdos=rx, tx_pdos=tx)
    for st in (AlState.PREOP, AlState.SAFEOP, AlState.OP):
        assert s.request_state(st) == AlStatusCode.NO_ERROR
    return s


def test_outputs_reach_the_field_only_in_op():
    s = _coupler()
    s.rx[:] = b"\x34\x12\xff\xff"
    s.step(0, 1_000_000)
    assert s.get_output(0x7010, 1) == 0x1234 and s.get_output(0x7030, 1) == -1
    s.request_state(AlState.SAFEOP)
    s.step(0, 1_000_000)
    assert s.get_output(0x7010, 1) == 0  # safe state below OP (ETG.1000.6)


def test_inputs_and_wires():
    s = _coupler()
    s.set_input(0x6020, 1, -300)
    s.wire_objects((0x7010, 1), (0x6000, 1))
    s.rx[0:2] = b"\x0f\x00"
    s.step(0, 1_000_000)
    assert bytes(s.tx) == b"\x0f\x00" + (-300).to_bytes(2, "little", signed=True)


def test_modules_grouped_by_etg5001_index():
    s = _coupler()
    groups = {n: sorted(p.index for p in pts) for n, pts in s.modules().items()}
    assert groups == {0: [0x6000], 1: [0x7010], 2: [0x6020], 3: [0x7030]}


def test_unmapped_objects_and_bad_bits_are_clear_errors():
    s = _coupler()
    with pytest.raises(KeyError, match="maps no input 0x6010:01"):
        s.set_input(0x6010, 1, 1)
    with pytest.raises(ValueError, match="no output bit 32"):
        s.wire(32, 0)


def test_al_state_machine_refuses_illegal_transitions():
    s = IoSlave(0, "io", Identity(1, 2))
    assert s.request_state(AlState.OP) == AlStatusCode.INVALID_REQUESTED_STATE_CHANGE
    assert s.al_state == AlState.INIT and s.al_error
    assert s.request_state(AlState.BOOT) == AlStatusCode.BOOTSTRAP_NOT_SUPPORTED
    assert s.request_state(AlState.PREOP) == AlStatusCode.NO_ERROR and not s.al_error
    s.expected_sizes = (8, 0)  # the master expects an output byte the slave doesn't map
    assert s.request_state(AlState.SAFEOP) == AlStatusCode.INVALID_OUTPUT_CONFIGURATION
    assert s.al_state == AlState.PREOP


def test_coe_io_slave_sdo_reads_the_process_data_of_mapped_objects():
    """ETG.5001: a module's mapped 0x7000/0x6000 objects are its process data, by SDO too."""
    from gtecat.drives.abort import SdoAbort, SdoAbortCode
    from gtecat.drives.coe import SdoClient
    from gtecat.drives.io_slaves import CoeIoSlave

    ref = _coupler()
    s = CoeIoSlave(0, "coupler", Identity(1, 2), rx_pdos=ref.rx_pdos, tx_pdos=ref.tx_pdos)
    for st in (AlState.PREOP, AlState.SAFEOP, AlState.OP):  # PS recomputes the layout
        assert s.request_state(st) == AlStatusCode.NO_ERROR
    sdo = SdoClient(s.mailbox)
    s.rx[:] = b"\x34\x12\xfb\xff"  # the master's outputs: DO16 0x1234, AO1 -5
    s.set_input(0x6000, 1, 0xBEEF)
    s.step(0, 1_000_000)
    assert sdo.upload(0x7010, 1) == b"\x34\x12"
    assert sdo.upload(0x7030, 1) == b"\xfb\xff"
    assert sdo.upload(0x6000, 1) == b"\xef\xbe"
    sdo.download(0x7010, 1, b"\x01\x00")  # an output set by SDO is what the slave then holds
    assert sdo.upload(0x7010, 1) == b"\x01\x00" and s.rx[:2] == b"\x01\x00"
    with pytest.raises(SdoAbort) as err:
        sdo.download(0x6000, 1, b"\x00\x00")  # inputs are read-only
    assert err.value.code == SdoAbortCode.WRITE_OF_READ_ONLY


def test_settled_means_another_step_changes_nothing():
    """The controller runs cycles many at a time only while every IO slave is settled."""
    s = _coupler()
    s.wire_objects((0x7010, 1), (0x6000, 1))
    s.rx[0:2] = b"\x0f\x00"
    assert not s.settled()  # the outputs have not reached the field yet
    s.step(0, 1_000_000)
    assert s.settled()
    before = (bytes(s.field_outputs), bytes(s.field_inputs), bytes(s.tx))
    s.step(0, 1_000_000)
    assert (bytes(s.field_outputs), bytes(s.field_inputs), bytes(s.tx)) == before
    s.set_input(0x6020, 1, 7)  # the field changed: the next step sends it
    assert not s.settled()
    s.step(0, 1_000_000)
    assert s.settled()
    s.request_state(AlState.SAFEOP)
    assert not s.settled()  # only in OP
