"""Machine description (DESIGN.md "Machine description"): levels, exact edges, index pulses."""

import pytest

from gtecat.drives.machine import AxisMachine, MachineError, load_machine, machine_from_dict


def test_levels_and_defaults():
    m = AxisMachine(negative_limit=-100, positive_limit=100, home_switch=((10, 20),))
    assert m.negative_limit_active(-100) and not m.negative_limit_active(-99.5)
    assert m.positive_limit_active(100) and not m.positive_limit_active(99)
    assert m.home_active(10) and m.home_active(19.9) and not m.home_active(20)
    assert not AxisMachine().home_active(0)
    assert AxisMachine().travel == (-1e12, 1e12)


def test_index_positions_repeat_every_revolution():
    m = AxisMachine(index_offset=250, counts_per_rev=1000)
    assert m.index_positions(0, 2500) == [250, 1250, 2250]
    assert m.index_positions(2500, 0) == [2250, 1250, 250]
    assert m.index_positions(250, 1249) == []  # half-open: start excluded
    assert m.index_positions(-900, -700) == [-750]


def test_toml_loading(tmp_path):
    f = tmp_path / "m.toml"
    f.write_text(
        "[axis.1]\nposition = 5\nnegative_limit = -10\npositive_limit = 10\n"
        "home_switch = [[1, 2], [4, 6]]\nprobe1 = [3, 4]\n"
    )
    d = load_machine(f)
    a = d.axis(1)
    assert a.position == 5 and a.home_switch == ((1, 2), (4, 6)) and a.probe1 == ((3, 4),)
    assert d.axis(2) == AxisMachine()


@pytest.mark.parametrize(
    "table, match",
    [
        ({"axis": {"1": {"speed": 3}}}, "unknown key"),
        ({"axis": {"0": {}}}, "numbered from 1"),
        ({"axis": {"1": {"negative_limit": 5, "positive_limit": 1}}}, "below"),
        ({"axis": {"1": {"home_switch": [[3, 1]]}}}, "low < high"),
        ({"axis": {"1": {"counts_per_rev": "x"}}}, "number"),
        # a misspelt table would be ignored: refused, with the tables there are
        ({"axis": {}, "falt": {"kind": "sto"}}, r"unknown table\(s\) \[falt\]; .*\[\[fault\]\]"),
    ],
)
def test_bad_descriptions_are_refused(table, match):
    with pytest.raises(MachineError, match=match):
        machine_from_dict(table, "m.toml")


def test_missing_file(tmp_path):
    with pytest.raises(MachineError, match="not found"):
        load_machine(tmp_path / "nope.toml")


def test_a_loaded_description_carries_the_digest_of_its_bytes(tmp_path):
    import hashlib

    f = tmp_path / "m.toml"
    f.write_bytes(b"[axis.2]\nprobe2 = [[-5, 5]]\n")
    d = load_machine(f)
    assert d.digest == hashlib.sha256(f.read_bytes()).hexdigest()[:16]
    f.write_bytes(b"")
    e = load_machine(f)
    assert e.digest != d.digest and not e.axes
    assert machine_from_dict({}).digest == ""  # (not read from a file)
    assert e == machine_from_dict({}, str(f))  # (the digest is not compared)


def test_a_description_that_is_not_utf8_is_a_clear_error(tmp_path):
    f = tmp_path / "m.toml"
    f.write_bytes(b"[axis.1]\nposition = 1 # \xff\n")
    with pytest.raises(MachineError, match="not UTF-8 text"):
        load_machine(f)
