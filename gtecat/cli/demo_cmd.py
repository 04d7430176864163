"""``gtecat demo``: the manual's figure 5-2 bus, brought up and exercised through ``GT_*``.

What it shows, in a few readable lines: the bring-up of manual example 5-5,
a ``GT_SetEcatRawData`` write at the manual's offset (5.2.2.4) reaching an IO
slave's outputs, and the wired input coming back through ``GT_GetEcatRawData``.
When the drive layer is present it goes on with the axes (enable, home,
probe, a Trap move) and writes ``demo.csv`` and ``demo.png``.
"""

from __future__ import annotations

import argparse
import time
from ctypes import byref, c_short, c_ulong, c_ushort
from importlib import resources
from pathlib import Path

from gtecat.eni.topology import parse_topology
from gtecat.eni.writer import write_eni_file

from ..errors import BusError


def add_parser(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser(
        "demo",
        help="run the figure 5-2 demo (bus, IO, axes) and plot it",
        epilog="examples:\n"
        "  gtecat demo                        demo.png, demo.csv, Gecat.log here\n"
        "  gtecat demo --out run1 --no-plot   only the CSV and the log, in ./run1",
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    p.add_argument("--out", default=".", help="folder for demo.eni, demo.csv, demo.png, Gecat.log")
    p.add_argument("--no-plot", action="store_true", help="skip demo.png")
    p.set_defaults(func=run)


def demo_files(out: Path) -> tuple[Path, Path]:
    """Write the demo ENI (from the packaged topology) and machine description into ``out``."""
    data = resources.files("gtecat") / "data"
    out.mkdir(parents=True, exist_ok=True)
    eni = out / "demo.eni"
    write_eni_file(
        parse_topology(data.joinpath("demo_topology.toml").read_text(), "demo_topology.toml"), eni
    )
    machine = out / "demo_machine.toml"
    machine.write_text(data.joinpath("demo_machine.toml").read_text())
    return eni, machine


def say(gt, text: str) -> None:
    """One log entry, stamped with the controller clock (GT_GetClock)."""
    clock = c_ulong()
    gt.GT_GetClock(byref(clock))
    print(f"[{clock.value:>6} ms] {text}", flush=True)


def _entry(gt, first: str, *more: str) -> None:
    say(gt, "\n".join([first, *(" " * 12 + m for m in more)]))


def _check(gt, rc: int, what: str) -> None:
    if rc != 0:
        raise BusError(f"{what} returned {rc}: {gt.GTE_GetLastError()}")


def run(args: argparse.Namespace) -> int:
    from gtecat import gt

    out = Path(args.out)
    eni, machine = demo_files(out)
    wall = time.perf_counter()
    gt.GT_Close()
    _check(
        gt, gt.GT_Open(eni=str(eni), machine=str(machine), log=str(out / "Gecat.log")), "GT_Open"
    )
    print(
        "gtecat demo: the manual's figure 5-2 bus (2 servo drives, 2 IO slaves), emulated.\n"
        "Each entry: [controller time] what happened, then the GT calls and their return "
        "codes (0 = ok).",
        flush=True,
    )
    try:
        _entry(gt, f"GT_Open = 0: ENI {eni}, machine {machine}")
        _check(gt, gt.GT_InitEcatComm(), "GT_InitEcatComm")
        status, polls = c_short(), 0
        while True:
            rc = gt.GT_IsEcatReady(byref(status))
            polls += 1
            if rc == 0 and status.value == 1:
                break
            if polls > 100_000:
                raise BusError("the bus never reached OP: " + gt.GTE_GetLastError())
        _check(gt, gt.GT_StartEcatComm(), "GT_StartEcatComm")
        n, axes = c_short(), c_short()
        gt.GT_GetEcatSlaves(byref(n))
        gt.GT_GetMcEcatAxisNum(byref(axes))
        _entry(
            gt,
            f"bus up: {n.value} slaves in OP, {axes.value} EtherCAT axes (manual example 5-5)",
            f"GT_InitEcatComm = 0; GT_IsEcatReady reported 1 after {polls} polls; "
            "GT_StartEcatComm = 0",
        )

        io = gt.GTE_Slave(2)
        for bit in range(16):
            io.wire(bit, bit)  # a wire from each output terminal to the same input terminal
        word = c_ushort(0x1234)
        _check(gt, gt.GT_SetEcatRawData(32, 2, byref(word)), "GT_SetEcatRawData")
        gt.GT_EcatIOSynch()
        _entry(
            gt,
            "raw data: 0x1234 written at GT raw offset 32, IO slave 2's outputs (manual 5.2.2.4)",
            f"GT_SetEcatRawData(32, 2, 0x{word.value:04X}) = 0; slave 2 drives "
            f"0x7000:01 = 0x{io.get_output(0x7000, 1):02X}, "
            f"0x7000:02 = 0x{io.get_output(0x7000, 2):02X}",
        )
        gt.GTE_Wait(2)
        back = c_ushort()
        _check(gt, gt.GT_GetEcatRawData(34, 2, byref(back)), "GT_GetEcatRawData")
        _entry(
            gt,
            "raw data: the outputs, wired to slave 2's inputs, read back at offset 34",
            f"GT_GetEcatRawData(34, 2) = 0: 0x{back.value:04X}",
        )
        bad = gt.GT_SetEcatRawData(34, 2, byref(word))
        _entry(
            gt,
            "raw data: a write to input bytes is refused and changes nothing",
            f"GT_SetEcatRawData(34, 2) = {bad}: "
            + gt.GTE_GetLastError().split(": ", 1)[1].split(";")[0],
        )
        try:
            from . import demo_axes
        except ImportError:
            demo_axes = None
        problems: list[str] = []
        if demo_axes is not None:
            problems = demo_axes.run(gt, say, out, plot=not args.no_plot).problems()
        virtual = gt.GTE_Controller().clock.now_ns / 1e9
    finally:
        gt.GT_Close()
    print(
        f"done: {virtual:.2f} s of controller time in {time.perf_counter() - wall:.2f} s; "
        f"master log {out / 'Gecat.log'}"
    )
    if problems:
        raise BusError("the demo did not go as planned: " + "; ".join(problems))
    return 0
