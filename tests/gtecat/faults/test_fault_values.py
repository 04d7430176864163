"""Every value of every fault kind and trigger is range-checked, the same through each way in
(Python ``faults.inject``, a machine TOML's ``[[fault]]`` tables, ``gtecat fault inject``);
``gtecat run --check`` names the call that changed a mode and exits 3 on findings."""

from __future__ import annotations

import dataclasses
import textwrap
from pathlib import Path

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from gtecat import faults, gt
from gtecat.cli.main import main
from gtecat.errors import ParameterError
from gtecat.faults import FaultSpecError
from gtecat.faults.kinds import KINDS, fault_from_dict, field_range
from gtecat.faults.triggers import trigger_from_dict
from tests.conftest import EXAMPLES

#: what each kind needs besides the value under test (in range)
_NEEDS = {"axis": 1, "slave": 0, "after_slave": 0, "switch": "home", "bit": 0}
#: (kind, field, lowest, highest) for every integer value of every kind
INT_FIELDS = [
    (kind, f.name, *rng)
    for kind, cls in KINDS.items()
    for f in dataclasses.fields(cls)
    if (rng := field_range(kind, f.name)) is not None
]


def _table(kind: str, name: str, value: object) -> dict[str, object]:
    cls = KINDS[kind]
    needed = {
        f.name: _NEEDS[f.name]
        for f in dataclasses.fields(cls)
        if f.default is dataclasses.MISSING and f.name != name
    }
    return {"kind": kind, **needed, name: value}


def test_every_integer_value_has_a_range() -> None:
    ints = {
        (kind, f.name)
        for kind, cls in KINDS.items()
        for f in dataclasses.fields(cls)
        if str(f.type).startswith("int")
    }
    assert ints <= {(k, n) for k, n, _, _ in INT_FIELDS}


def test_an_integer_of_any_type_is_an_integer_and_a_bool_none() -> None:
    """NumPy integers are integers, as 1.0 and "1" are (TOML, JSON and the command line
    give those); a bool of either kind is a yes-or-no value only."""
    import numpy as np

    for axis in (np.int64(2), np.uint8(2), 2.0, "2", np.float32(2)):
        assert fault_from_dict({"kind": "drive_fault", "axis": axis}).axis == 2
        assert type(fault_from_dict({"kind": "drive_fault", "axis": axis}).axis) is int
    for axis in (True, np.True_, 2.5, np.float64("nan")):
        with pytest.raises(FaultSpecError, match="axis must be an integer"):
            fault_from_dict({"kind": "drive_fault", "axis": axis})
    on = {"kind": "switch_stuck", "axis": 1, "switch": "home", "value": np.True_}
    assert fault_from_dict(on).value == 1
    spec = faults.spec_from_dict({"kind": "sto", "axis": 1, "after": np.int64(3)})
    assert spec.after == 3 and type(spec.after) is int


@settings(max_examples=40)
@given(
    which=st.sampled_from(INT_FIELDS),
    past=st.integers(min_value=1, max_value=2**40),
    below=st.booleans(),
    as_text=st.sampled_from(["int", "dec", "hex"]),
)
def test_a_value_out_of_range_is_refused(which, past: int, below: bool, as_text: str) -> None:
    kind, name, lo, hi = which
    v = lo - past if below else hi + past
    raw: object = v
    if as_text == "dec":
        raw = str(v)
    elif as_text == "hex":
        raw = f"-0x{-v:X}" if v < 0 else f"0x{v:X}"
    with pytest.raises(FaultSpecError) as e:
        fault_from_dict(_table(kind, name, raw), "m.toml [[fault]] #1")
    msg = str(e.value)
    assert "\n" not in msg and msg.startswith("m.toml [[fault]] #1: ")
    assert name in msg and "out of range" in msg
    # the class itself refuses it too (faults.inject(DriveFault(...)))
    with pytest.raises(FaultSpecError):
        KINDS[kind](**{k: x for k, x in _table(kind, name, v).items() if k != "kind"})
    # the edges are taken
    for edge in (lo, hi):
        fault_from_dict(_table(kind, name, edge))


_KEYS = (
    "count code index subindex value area switch at_ms on_sdo when_position after_cycles "
    "duration_ms after at_homing offset"
).split()
_JUNK = st.one_of(
    st.none(),
    st.booleans(),
    st.integers(),
    st.floats(allow_nan=True, allow_infinity=True),
    st.text(max_size=8),
    st.lists(st.integers(), max_size=4),
    st.dictionaries(st.text(max_size=3), st.integers(), max_size=2),
)


@settings(max_examples=40)
@given(
    kind=st.sampled_from(sorted(KINDS)),
    key=st.sampled_from(_KEYS),
    value=_JUNK,
)
def test_any_value_is_taken_or_refused_with_the_modules_error(kind, key, value) -> None:
    table = _table(kind, "-", None)
    table.pop("-")
    table[key] = value
    try:
        spec = faults.spec_from_dict(table)
    except FaultSpecError as e:
        assert "\n" not in str(e)
    else:
        spec.describe()


@pytest.mark.parametrize(
    ("values", "words"),
    [
        ({"kind": "mailbox_abort", "slave": 0, "index": 0x6060, "code": -1}, "code -0x1"),
        ({"kind": "mailbox_abort", "slave": 0, "code": "0x1FFFFFFFF"}, "0x00000000..0xFFFFFFFF"),
        ({"kind": "mailbox_abort", "slave": 0, "index": 0x1FFFF}, "index 0x1FFFF"),
        ({"kind": "mailbox_abort", "slave": 0, "subindex": 256}, "subindex 256"),
        ({"kind": "switch_stuck", "axis": 1, "switch": "home", "value": 7}, "value 7"),
        ({"kind": "drop_responses", "count": -2}, "count -2"),
        ({"kind": "drop_responses", "on_sdo": "0,0x6060"}, "on_sdo needs 3 values"),
        ({"kind": "drop_responses", "on_sdo": [0, 0x6060, 0]}, "on_sdo: n 0"),
        ({"kind": "drop_responses", "on_sdo": [0, 0x10000, 1]}, "on_sdo: index 0x10000"),
        ({"kind": "drop_responses", "when_position": [0, 5]}, "when_position: axis 0"),
        ({"kind": "drop_responses", "at_ms": "nan"}, "at_ms must be a finite"),
        ({"kind": "drop_responses", "after_cycles": 1.5}, "after_cycles must be a whole"),
        ({"kind": "drop_responses", "duration_ms": -1}, "duration_ms -1"),
        ({"axis": 1}, "kind is missing"),
    ],
)
def test_the_refusals_name_the_value_and_its_range(values: dict, words: str) -> None:
    with pytest.raises(FaultSpecError, match=words.replace("(", r"\(").replace(".", r"\.")):
        faults.spec_from_dict(values)


def test_the_triggers_refuse_too() -> None:
    with pytest.raises(FaultSpecError, match="slave 70000"):
        trigger_from_dict({"on_sdo": [70000, 0x6060, 1]})
    assert (
        trigger_from_dict({"on_sdo": "0,0x6060,2"}).describe()
        == "on the 2nd SDO to 0x6060 of slave 0"
    )


def test_the_command_line_refuses_before_it_connects(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["fault", "inject", "mailbox_abort", "slave=0", "index=0x6060", "code=-1"]) == 1
    err = capsys.readouterr().err
    assert "code -0x1 is out of range 0x00000000..0xFFFFFFFF" in err and "running" not in err
    assert main(["fault", "inject", "switch_stuck", "axis=2", "switch=positive", "value=7"]) == 1
    assert "value 7 is out of range 0..1" in capsys.readouterr().err
    assert main(["fault", "inject", "drop", "on_sdo=0,0x6060"]) == 1
    assert "on_sdo needs 3 values" in capsys.readouterr().err
    assert main(["fault", "kinds"]) == 0
    out = capsys.readouterr().out
    assert "code=0x08000000" in out and "code=0x2310" in out and "134217728" not in out


def _open(machine: Path | None = None) -> int:
    opts = {"machine": str(machine)} if machine else {}
    assert gt.GT_Open(eni=str(EXAMPLES / "full_servo.eni"), clock="lockstep", log="", **opts) == 0
    return gt.GT_InitEcatComm()


@pytest.mark.parametrize(
    ("table", "words"),
    [
        ('kind = "mailbox_abort"\nslave = 0\ncode = -1', "code -0x1 is out of range"),
        ('kind = "switch_stuck"\naxis = 1\nswitch = "home"\nvalue = 7', "value 7 is out of range"),
        ('kind = "link_down"\nafter_slave = 5', "link_down after slave 5: nothing follows"),
        ('kind = "drop_responses"\nafter = "nosuch"', "after='nosuch': no fault named so"),
        ("axis = 1", "the fault kind is missing"),
        # a trigger on what the bus does not have would never fire (full_servo: axis 1,
        # slaves 0..1; the IO slave has no mailbox)
        (
            'kind = "drive_fault"\naxis = 1\nwhen_position = [3, 100]',
            "when_position: no axis 3: the bus has axes 1..1",
        ),
        ('kind = "sto"\naxis = 1\nat_homing = [9, "search"]', "at_homing: no axis 9"),
        ('kind = "sto"\naxis = 1\non_sdo = [7, 0x6060, 1]', "on_sdo: no slave 7"),
        ('kind = "sto"\naxis = 1\non_sdo = [1, 0x6060, 1]', "slave 1 (IO 1) has no mailbox"),
        ('kind = "wkc_offset"\narea = [1000, 1010]', "lies past the process image"),
        # true is no axis 1 (only a yes-or-no value takes true/false)
        ('kind = "drive_fault"\naxis = true', "axis must be an integer, got True"),
    ],
)
def test_the_machine_toml_refuses_with_one_code(tmp_path: Path, table: str, words: str) -> None:
    m = tmp_path / "m.toml"
    m.write_text(f"[[fault]]\n{table}\n")
    assert _open(m) == 1
    why = gt.GTE_GetLastError()
    assert words in why and f"{m} [[fault]] #1: " in why, why


def test_two_tables_of_one_name_are_refused(tmp_path: Path) -> None:
    m = tmp_path / "m.toml"
    m.write_text('[[fault]]\nkind = "sto"\naxis = 1\nname = "a"\n' * 2)
    assert _open(m) == 1
    assert f"{m} [[fault]] #2: name 'a' names another fault already" in gt.GTE_GetLastError()


def test_a_machine_table_keeps_its_name_after_it_ended(tmp_path: Path) -> None:
    """Every bring-up arms the machine's tables again, so a fault injected under the name of
    one that has ended would stand beside it after GT_InitEcatComm: refused when injected."""
    m = tmp_path / "m.toml"
    m.write_text('[[fault]]\nkind = "brake"\naxis = 1\nduration_ms = 1\nname = "cut"\n')
    assert _open(m) == 0
    gt.GTE_Wait(5)
    assert faults.listing() == []  # (it ran and ended)
    with pytest.raises(FaultSpecError, match="name 'cut' belongs to a \\[\\[fault\\]\\] table"):
        faults.inject("sto", axis=1, name="cut", at_ms=10**8)
    assert gt.GT_InitEcatComm() == 0, gt.GTE_GetLastError()
    assert [f["kind"] for f in faults.listing()] == ["brake"]  # (the table, armed again)


def test_python_inputs_that_are_not_a_fault_are_told_so() -> None:
    """What is no fault table is refused in words, before anything is armed: booleans as
    numbers, a script that is no list of tables, a name used twice."""
    assert _open() == 0
    with pytest.raises(FaultSpecError, match="axis must be an integer, got True"):
        faults.inject("drive_fault", axis=True)
    with pytest.raises(FaultSpecError, match="slave must be an integer, got 'false'"):
        faults.inject("io_stuck", slave="false", bit=0)
    assert faults.describe({"kind": "switch_stuck", "axis": 1, "switch": "home", "value": True})
    with pytest.raises(FaultSpecError, match="a script is a list of steps"):
        faults.script("x")  # type: ignore[arg-type]
    with pytest.raises(FaultSpecError, match="step 2: a fault is a table of its values"):
        faults.script([{"kind": "sto", "axis": 1}, "link_down"])  # type: ignore[list-item]
    with pytest.raises(FaultSpecError, match=r"a fault is a table of its values.*got 3"):
        faults.describe(3)  # type: ignore[arg-type]
    assert faults.listing() == []  # (the script's first step was not armed either)
    faults.inject("sto", axis=1, at_ms=10**6, name="a")
    with pytest.raises(FaultSpecError, match="name 'a' names another fault already"):
        faults.inject("brake", axis=1, name="a")
    faults.inject("drive_fault", axis=1, at_ms=10**6)
    assert [type(f["code"]) for f in faults.listing() if "code" in f] == [int]
    faults.inject(faults.kinds.DriveFault(axis=1), at_ms=10**6)
    assert {type(f["code"]) for f in faults.listing() if "code" in f} == {int}


def test_python_inject_refuses_and_after_slave_minus_1_takes_the_whole_bus() -> None:
    assert _open() == 0
    with pytest.raises(FaultSpecError, match="code -0x1 is out of range"):
        faults.inject("mailbox_abort", slave=0, index=0x6060, code=-1)
    with pytest.raises(FaultSpecError, match="index 0x1FFFF is out of range"):
        faults.inject("mailbox_abort", slave=0, index=0x1FFFF)
    with pytest.raises(FaultSpecError, match="on_sdo needs 3 values"):
        faults.inject("mailbox_abort", slave=0, index=0x6060, on_sdo=[0, 0x6060])
    for trig, words in [
        ({"when_position": [3, 100]}, "when_position: no axis 3: the bus has axes 1..1"),
        ({"at_homing": [9, "search"]}, "at_homing: no axis 9"),
        ({"on_sdo": [7, 0x6060, 1]}, "on_sdo: no slave 7"),
    ]:
        with pytest.raises(ParameterError, match=words):
            faults.inject("drive_fault", axis=1, **trig)
    with pytest.raises(ParameterError, match=r"area \[1000, 1010\) lies past the process"):
        faults.inject("wkc_offset", area=[1000, 1010])
    assert faults.listing() == []
    fid = faults.inject("link_down", after_slave=-1)
    ids = faults.script([{"kind": "drop_responses", "after_ms": 300}])
    words = {f["id"]: f["describe"] for f in faults.listing()}
    assert "link down at the master (every slave vanishes)" in words[fid]
    assert words[ids[0]] == "the next 1 answer lost, 300 ms later" or "fault" not in words[ids[0]]
    step = faults.describe({"kind": "drop_responses", "after_ms": 300, "after": fid})
    assert step == f"the next 1 answer lost, once fault {fid} has started, 300 ms later"


MODE_SCRIPT = textwrap.dedent(
    f"""\
    from ctypes import byref, c_ubyte, c_uint32
    from gtecat import gt
    gt.GT_Open(eni={str(EXAMPLES / "manual_fig5_2.eni")!r}, clock="lockstep", log="")
    gt.GT_InitEcatComm(); gt.GTE_Wait(100); gt.GT_StartEcatComm(); gt.GT_Reset()
    gt.GT_AxisOn(2); gt.GTE_Wait(20)
    prm = gt.TTrapPrm(); prm.acc = prm.dec = 0.5
    gt.GT_PrfTrap(2); gt.GT_SetTrapPrm(2, byref(prm))
    gt.GT_SetPos(2, 500000); gt.GT_SetVel(2, 20); gt.GT_Update(2); gt.GTE_Wait(30)
    mode, ab = (c_ubyte * 1)(6), c_uint32()
    gt.GT_EcatSDODownload(1, 0x6060, 0, mode, 1, byref(ab))
    gt.GT_AxisOff(2); gt.GTE_Wait(10)
    """
)


def test_a_mode_change_names_the_sdo_call_and_the_check_exits_3(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    app = tmp_path / "mode.py"
    app.write_text(MODE_SCRIPT)
    assert main(["run", "--check", "--no-progress", str(app)]) == 3
    err = capsys.readouterr().err
    found = [x for x in err.splitlines() if "mode of operation 8 -> 6" in x]
    assert found and all(x.startswith(f"check: {app}:10: ") for x in found), err
    assert "check: 1 finding" in err
    # the script's own failure code wins over the findings'
    app.write_text(
        "from ctypes import byref, c_short\n"
        "from gtecat import gt\n"
        f"gt.GT_Open(eni={str(EXAMPLES / 'full_servo.eni')!r}, log='')\n"
        "s = c_short()\n"
        "for _ in range(200):\n"
        "    gt.GT_IsEcatReady(byref(s))\n"
        "raise SystemExit(5)\n"
    )
    assert main(["run", "--check", "--no-progress", str(app)]) == 5
    assert "GT_IsEcatReady answered not ready 200 times" in capsys.readouterr().err
