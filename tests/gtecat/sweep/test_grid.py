"""Grid files: crossed lists, seeded samples, stable case ids and seeds, machine overrides."""

from __future__ import annotations

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from gtecat.errors import ParameterError
from gtecat.sweep.grid import Case, case_id_of, load_grid, set_path
from tests.conftest import examples

MACHINE = """
[axis.1]
position = 40000
home_switch = [[100000, 400000]]
"""


def _grid(tmp_path, text, machine=MACHINE):
    (tmp_path / "m.toml").write_text(machine)
    p = tmp_path / "grid.toml"
    p.write_text(text)
    return load_grid(p)


def test_lists_are_crossed_and_random_keys_drawn_n_times_per_point(tmp_path):
    g = _grid(
        tmp_path,
        '[base]\neni = "manual_fig5_2"\nmachine = "m.toml"\n'
        "[grid]\nmethod = [19, 35]\nspeed = [1, 2, 3]\n"
        '[random]\nn = 4\nseed = 7\n"machine.axis.1.position" = { uniform = [0, 10] }\n',
    )
    cases = g.cases()
    assert len(cases) == 2 * 3 * 4
    assert {(c["method"], c["speed"]) for c in cases} == {
        (m, s) for m in (19, 35) for s in (1, 2, 3)
    }
    assert all(0 <= c["machine.axis.1.position"] <= 10 for c in cases)
    # the same file gives the same cases, ids and seeds (a re-run, another worker)
    again = _grid(tmp_path, (tmp_path / "grid.toml").read_text()).cases()
    assert [(c.id, c.seed, c.params) for c in again] == [(c.id, c.seed, c.params) for c in cases]
    assert len({c.id for c in cases}) == len(cases)


def test_the_eni_is_a_file_beside_the_grid_or_a_shipped_example(tmp_path):
    g = _grid(tmp_path, '[base]\neni = "manual_fig5_2"\n')
    assert g.eni == "manual_fig5_2" and b"EtherCATConfig" in g.eni_bytes
    (tmp_path / "my.eni").write_bytes(g.eni_bytes)
    assert _grid(tmp_path, '[base]\neni = "my.eni"\n').eni_bytes == g.eni_bytes
    assert len(_grid(tmp_path, '[base]\neni = "my.eni"\n').cases()) == 1  # no grid: one case


def test_machine_overrides_reach_into_tables_and_lists(tmp_path):
    g = _grid(tmp_path, '[base]\neni = "manual_fig5_2"\nmachine = "m.toml"\n')
    case = Case({"machine.axis.1.home_switch.0.0": 99000.5, "machine.axis.2.index_offset": 5})
    m = g.machine_for(case)
    assert m["axis"]["1"]["home_switch"] == [[99000.5, 400000]]
    assert m["axis"]["2"] == {"index_offset": 5}
    assert g.machine["axis"]["1"]["home_switch"] == [[100000, 400000]]  # the base is untouched
    with pytest.raises(ParameterError, match="is a list of 1; '3' is not an index"):
        g.machine_for(Case({"machine.axis.1.home_switch.3.0": 1}))


@pytest.mark.parametrize(
    ("text", "message"),
    [
        ("[grid]\nx = [1]\n", "needs eni"),
        ('[base]\neni = "nope"\n', "neither a file beside the grid nor a shipped example"),
        ('[base]\neni = "manual_fig5_2"\n[grid]\nx = []\n', "non-empty list"),
        ('[base]\neni = "manual_fig5_2"\n[random]\nx = { poisson = [1, 2] }\n', "uniform = "),
        ('[base]\neni = "manual_fig5_2"\n[random]\nx = { uniform = [2, 1] }\n', "lo <= hi"),
        ('[base]\neni = "manual_fig5_2"\n[random]\nn = 0\nx = { normal = [1, 2] }\n', "n must"),
        ('[base]\neni = "manual_fig5_2"\n[grids]\n', "unknown table"),
        ("[base\n", "not valid TOML"),
    ],
)
def test_a_wrong_grid_is_one_clear_error(tmp_path, text, message):
    with pytest.raises(ParameterError, match=message):
        _grid(tmp_path, text)


def test_find_names_a_case_by_id(tmp_path):
    g = _grid(tmp_path, '[base]\neni = "manual_fig5_2"\n[grid]\nv = [1, 2, 3]\n')
    c = g.cases()[1]
    assert g.find(c.id).params == {"v": 2}
    with pytest.raises(ParameterError, match="no case 'zzz'"):
        g.find("zzz")


values = st.one_of(st.integers(), st.floats(allow_nan=False), st.text(max_size=8), st.booleans())


@settings(max_examples=examples(60, 15))
@given(st.dictionaries(st.text(min_size=1, max_size=10), values, max_size=5))
def test_case_ids_depend_on_the_parameters_only(params):
    """Key order never changes an id; the seed follows the id."""
    reordered = dict(reversed(list(params.items())))
    assert case_id_of(params) == case_id_of(reordered)
    assert Case(params).seed == Case(reordered).seed
    assert len(case_id_of(params)) == 12


def test_set_path_refuses_to_walk_through_a_value():
    data = {"axis": {"1": {"position": 5}}}
    with pytest.raises(ParameterError, match="is a value"):
        set_path(data, "axis.1.position.x", 1, "machine.axis.1.position.x")


def test_what_would_fail_every_case_is_refused_before_any_runs(tmp_path):
    """A grid of more cases than a sweep holds is refused before it is built (it would
    fill the memory); a ``machine.*`` key or index the description refuses is named once."""
    base = '[base]\neni = "manual_fig5_2"\nmachine = "m.toml"\n'
    huge = _grid(
        tmp_path, base + "[grid]\n" + "".join(f"p{i} = {list(range(10))}\n" for i in range(9))
    )
    with pytest.raises(ParameterError, match="1,000,000,000 cases; a sweep holds at most"):
        huge.check()
    with pytest.raises(ParameterError, match="a sweep holds at most"):
        huge.cases()
    bad_key = _grid(tmp_path, base + '[grid]\n"machine.axis.1.nosuchkey" = [1]\n')
    with pytest.raises(ParameterError, match=r"\[grid\] machine.axis.1.nosuchkey = 1: .*nosuchkey"):
        bad_key.check()
    bad_index = _grid(
        tmp_path,
        base + '[random]\nn = 3\n"machine.axis.1.home_switch.5.0" = { uniform = [0, 1] }\n',
    )
    with pytest.raises(
        ParameterError, match=r"\[random\] machine.axis.1.home_switch.5.0 = .*list of 1"
    ):
        bad_index.check()
    _grid(tmp_path, base + '[grid]\n"machine.axis.1.position" = [0, 10]\n').check()  # fine


def test_a_scenario_that_does_not_compile_is_refused_at_once(tmp_path, capsys, monkeypatch):
    from gtecat.cli.main import main

    monkeypatch.chdir(tmp_path)
    (tmp_path / "grid.toml").write_text('[base]\neni = "manual_fig5_2"\n[grid]\nx = [1, 2]\n')
    (tmp_path / "syn.py").write_text("def scenario(gt, case) return 1\n")
    (tmp_path / "none.py").write_text("x = 1\n")
    assert main(["sweep", "syn.py", "--grid", "grid.toml", "--list"]) == 1
    assert "syn.py:1:" in capsys.readouterr().err
    assert main(["sweep", "none.py", "--grid", "grid.toml", "--list"]) == 1
    assert "defines no function scenario(gt, case)" in capsys.readouterr().err
