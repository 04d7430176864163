"""``gtecat example [NAME [-o DIR]]``: the examples that come with gtecat.

Without NAME, lists them. With NAME, writes that example's files into DIR (default
``./NAME``): its ENI, the topology it was written from, a machine description, a script
and the output the script prints (``SCRIPT.expected.txt``). The scripts find their files
beside themselves, so a copied example runs from any folder, with nothing else installed.

Examples:

  gtecat example                        list the examples
  gtecat example manual_fig5_2 -o .     the tutorials' bus, into the current folder
  gtecat example example_5_2            manual example 5-2 (homing) into ./example_5_2
"""

from __future__ import annotations

import argparse
import tomllib
from dataclasses import dataclass
from importlib import resources
from importlib.resources.abc import Traversable
from pathlib import Path, PurePosixPath

from ..errors import ParameterError
from . import output


@dataclass(frozen=True, slots=True)
class Example:
    name: str
    about: str
    files: tuple[str, ...]  # paths inside the examples folder
    script: str | None

    @property
    def expected(self) -> str | None:
        """The script's expected output, ``SCRIPT.expected.txt`` beside it."""
        if self.script is None:
            return None
        name = str(PurePosixPath(self.script).with_suffix("")) + ".expected.txt"
        return name if _root().joinpath(name).is_file() else None

    def all_files(self) -> tuple[str, ...]:
        return (*self.files, self.expected) if self.expected else self.files


def _root() -> Traversable:
    """The examples shipped inside the package (``gtecat/examples``)."""
    return resources.files("gtecat") / "examples"


def examples() -> dict[str, Example]:
    """Every shipped example by name, in the order of ``index.toml``."""
    index = tomllib.loads(_root().joinpath("index.toml").read_text(encoding="utf-8"))
    return {
        name: Example(name, t["about"], tuple(t["files"]), t.get("script"))
        for name, t in index.items()
    }


def find(name: str) -> Example:
    """The example called ``name``, or the only one whose name starts with it."""
    table = examples()
    if name in table:
        return table[name]
    hits = [e for n, e in table.items() if n.startswith(name)]
    if len(hits) == 1:
        return hits[0]
    if hits:
        raise ParameterError(
            f"example {name!r} is ambiguous: {', '.join(e.name for e in hits)}; give the full name"
        )
    raise ParameterError(
        f"no example called {name!r}; `gtecat example` lists them (e.g. manual_fig5_2)"
    )


def read_bytes(path: str) -> bytes:
    """The content of a shipped example file (``path`` inside the examples folder)."""
    return _root().joinpath(path).read_bytes()


def role(path: str, text: str | None = None) -> str:
    """What a file of an example is, for the listing."""
    p = PurePosixPath(path)
    if p.name.endswith(".expected.txt"):
        return "expected output"
    if p.suffix == ".eni":
        return "ENI"
    if p.suffix == ".cfg":
        return "controller configuration (GT_LoadConfig)"
    if p.suffix in (".py", ".toml") and text is None:
        text = _root().joinpath(path).read_text(encoding="utf-8")
    if p.suffix in (".py", ".cpp", ".c"):
        if p.suffix == ".py" and text is not None and "def scenario(" in text:
            return "sweep scenario (gtecat sweep)"
        return "script" if p.suffix == ".py" else "C/C++ program"
    if p.suffix == ".toml":
        assert text is not None
        if "[base]" in text:
            return "sweep grid (gtecat sweep --grid)"
        return "topology (gtecat eni new)" if "[[slave]]" in text else "machine description"
    return "file"


def write(example: Example, out: Path, *, force: bool = False) -> list[Path]:
    """Copy ``example``'s files into ``out`` (flat); refuse to overwrite a different file."""
    plan = []
    for rel in example.all_files():
        data = _root().joinpath(rel).read_bytes()
        dest = out / PurePosixPath(rel).name
        if dest.is_dir():
            raise ParameterError(f"{dest} is a folder; choose another folder with -o DIR")
        if dest.exists() and not force and dest.read_bytes() != data:
            raise ParameterError(
                f"{dest} exists and differs from the example's; "
                "use --force to overwrite it, or -o DIR for another folder"
            )
        plan.append((dest, data))
    out.mkdir(parents=True, exist_ok=True)
    for dest, data in plan:
        if not dest.exists() or dest.read_bytes() != data:
            dest.write_bytes(data)
    return [dest for dest, _ in plan]


def add_parser(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser(
        "example",
        help="list the shipped examples, or write one into a folder",
        description=output.describe(__doc__),
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    p.add_argument("name", nargs="?", help="example to write (a unique prefix is enough)")
    p.add_argument("-o", "--output", metavar="DIR", help="folder to write into (default: ./NAME)")
    p.add_argument("--force", action="store_true", help="overwrite files that differ")
    output.add_json(p)
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    if not args.name:
        table = examples()
        rows = [
            {
                "name": e.name,
                "about": e.about,
                "files": [{"file": PurePosixPath(f).name, "role": role(f)} for f in e.all_files()],
                "script": PurePosixPath(e.script).name if e.script else None,
            }
            for e in table.values()
        ]
        if args.json:
            output.print_json(rows)
            return 0
        output.print_table(rows, [("name", "name"), ("about", "about")])
        print("\ngtecat example NAME [-o DIR] writes one into a folder (default ./NAME)")
        return 0
    example = find(args.name)
    out = Path(args.output) if args.output else Path(example.name)
    written = write(example, out, force=args.force)
    if args.json:
        output.print_json(
            {"name": example.name, "folder": str(out), "files": [str(p) for p in written]}
        )
        return 0
    shown = "./" if str(out) == "." else f"{out}/"
    print(f"wrote {len(written)} files to {shown}: {example.about}")
    width = max(len(p.name) for p in written)
    for p, rel in zip(written, example.all_files(), strict=True):
        print(f"  {p.name:<{width}}  {role(rel)}")
    cd = "" if str(out) == "." else f"cd {out} && "
    grid = next(
        (p for p, r in zip(written, example.all_files(), strict=True) if "grid" in role(r)), None
    )
    scenario = next(
        (p for p, r in zip(written, example.all_files(), strict=True) if "scenario" in role(r)),
        None,
    )
    if example.script and example.script.endswith(".py"):
        print(f"next: {cd}python3 {PurePosixPath(example.script).name}")
    elif grid and scenario:
        print(f"next: {cd}gtecat sweep {scenario.name} --grid {grid.name}")
    else:
        eni = next((p.name for p in written if p.suffix == ".eni"), None)
        if eni:
            print(f"next: {cd}gtecat map {eni}")
    return 0
