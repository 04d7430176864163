"""The ENI writer writes as it makes: the text of a tree writer, a slave at a time."""

from __future__ import annotations

import hashlib
import xml.etree.ElementTree as ET
from pathlib import Path
from typing import Any

import pytest
from hypothesis import HealthCheck, given, settings

from gtecat.eni import writer
from gtecat.eni.topology import build_config, load_topology
from gtecat.eni.writer import HEADER, write_eni, write_eni_file, write_eni_to
from tests.conftest import examples
from tests.eni.test_properties import topologies
from tools.gen_axes_eni import axes_config

#: SHA-256 of what the writer gave for generated buses (drives, 6060h/6061h mapped) when it
#: built an ElementTree and indented it before writing: the text has not changed a byte,
#: except where the cyclic commands no longer fit one Ethernet frame: 129 drives without
#: 6060h/6061h (774 output and 1,290 input bytes, 2,090 bytes of datagrams) now has two
#: frames, the LWR and the input bytes 0..689 (1,490 bytes), then the rest of the inputs
TREE_WRITER = {
    (1, True): "1258c665c999bfd13e67671d31fbfb6c9ff96b7c1f8c46af953ef39f8514da06",
    (2, False): "588ce82c0f75ee35405ee58e08b0a469248ddc45295e98b5bebe00b5bbb843e6",
    (3, True): "feda0d6d5f562a566e3f7fc667975124f075ba72238916b47a0c5ed3264bc6e7",
    (64, True): "6ea5e5a67c30c1b3b146c873216f2884f46d7a0c95c1bc3eeec758fb9b1a347f",
    (129, False): "ec71b7ae6bfa2a81dd306e305a36f65ddab003438f5b80046cd5d60b2d7c70cc",
}


def tree_text(text: str) -> str:
    """``text`` from ``<Config>`` on, read into an ElementTree, indented and written by it as
    the writer once wrote (the root's start tag aside: read, its ``xmlns:xsi`` is a
    namespace, which ElementTree writes first)."""
    root = ET.fromstring(text)
    ET.indent(root, space="  ")
    tree = ET.tostring(root, encoding="unicode") + "\n"
    return tree[tree.index("<Config>") :]


@pytest.mark.parametrize(("n", "modes"), list(TREE_WRITER))
def test_generated_buses_are_the_tree_writers_bytes(n: int, modes: bool) -> None:
    text = write_eni(axes_config(n, modes=modes))
    assert hashlib.sha256(text.encode()).hexdigest() == TREE_WRITER[n, modes]


def test_examples_are_laid_out_as_elementtree_lays_them_out(examples_dir: Path) -> None:
    tomls = [t for t in sorted(examples_dir.glob("*.toml")) if t.with_suffix(".eni").exists()]
    assert len(tomls) >= 3
    for t in tomls:
        text = write_eni(load_topology(t))
        assert text.startswith(HEADER), t.name
        assert text[text.index("<Config>") :] == tree_text(text), t.name


class Sink:
    def __init__(self) -> None:
        self.pieces: list[str] = []

    def write(self, text: str) -> int:
        self.pieces.append(text)
        return len(text)


def test_text_leaves_a_slave_at_a_time() -> None:
    cfg = axes_config(40)
    sink = Sink()
    write_eni_to(cfg, sink)
    text = "".join(sink.pieces)
    assert text == write_eni(cfg)
    assert len(sink.pieces) > 40 and max(map(len, sink.pieces)) < len(text) / 20


def test_a_failure_leaves_no_half_written_file(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    cfg = axes_config(3)
    made = []

    def failing(s: object, bases: object) -> object:
        if made:
            raise RuntimeError("disk gone")
        made.append(s)
        return real(s, bases)

    real = writer.slave_cmds
    monkeypatch.setattr(writer, "slave_cmds", failing)
    path = tmp_path / "bus.eni"
    with pytest.raises(RuntimeError, match="disk gone"):
        write_eni_file(cfg, path)
    assert not path.exists()
    monkeypatch.undo()
    write_eni_file(cfg, path)
    assert path.read_text(encoding="utf-8") == write_eni(cfg)


@settings(max_examples=examples(60, 8), deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(topologies())
def test_any_topology_is_laid_out_as_elementtree_lays_it_out(topo: dict[str, Any]) -> None:
    # names of any letters, digits, punctuation and symbols: escaped as ElementTree escapes them
    text = write_eni(build_config(topo, "topo.toml"))
    assert text[text.index("<Config>") :] == tree_text(text)
