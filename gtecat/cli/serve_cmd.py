"""gtecat serve --eni FILE [--machine FILE] --iface IFACE: slaves on a real wire.

Builds the virtual slaves of the ENI exactly as the emulated backend does (same drives,
same machine description), puts them behind software ESCs and answers EtherCAT frames on
IFACE until Ctrl-C or SIGTERM.  Any master (SOEM/pysoem, TwinCAT, IgH, acontis) on the
other end of the wire sees a chain of real-looking slaves.  Needs root or CAP_NET_RAW.

While it runs, the ps verb lists it (its id is in the ready line); the fault verbs
(inject, list, clear, with --attach ID) then break its chain at runtime, and the states
verb shows its slaves' AL states.

examples:
  gtecat serve --eni manual_fig5_2.eni --iface veth1
  gtecat serve --eni Gecat.eni --machine machine.toml --iface enp3s0 --duration 60
  gtecat serve --eni Gecat.eni --iface veth1 --fault link_loss.toml
  gtecat fault inject link_down after_slave=1 --attach 5120   (another terminal)
"""

from __future__ import annotations

import argparse
import json
import logging
import os
import signal
import sys
from collections.abc import Callable
from pathlib import Path
from types import FrameType

from .. import scheduling
from . import output

log = logging.getLogger("gtecat.wire.serve")


def add_parser(subparsers: argparse._SubParsersAction) -> argparse.ArgumentParser:
    p = subparsers.add_parser(
        "serve",
        help="serve the ENI's virtual slaves on a network interface (raw EtherCAT frames)",
        description=output.describe(__doc__),
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    _arguments(p)
    p.set_defaults(func=run)
    return p


def _arguments(p: argparse.ArgumentParser) -> None:
    p.add_argument("--eni", required=True, type=Path, help="ENI file (ETG.2100 XML or Googol INI)")
    p.add_argument("--machine", type=Path, help="machine description (TOML)")
    p.add_argument("--iface", required=True, help="network interface, e.g. one end of a veth pair")
    p.add_argument(
        "--step",
        choices=("frame", "cycle"),
        default="frame",
        help="step the slaves once per process-data frame (default) or on a timer",
    )
    p.add_argument(
        "--cycle-us",
        type=_cycle_ns,
        dest="cycle_ns",
        metavar="US",
        help="slave cycle for --step cycle, 31.25..1000000 us as in an ENI "
        "(default: the ENI's, else 1000)",
    )
    p.add_argument(
        "--sm-watchdog",
        action="store_true",
        help="an expired SM watchdog drops the slave to SAFEOP+error 001Bh (as real drives do)",
    )
    p.add_argument(
        "--wait",
        choices=("auto", "predict", "sleep", "spin"),
        default="auto",
        help="how to wait for frames: spin = spin all the time (a whole CPU; the lowest "
        "latency), predict = learn the master's cycle and spin only around the cyclic "
        "frame's due time (a fraction of a CPU), sleep = poll (a wake-up per frame, no "
        "CPU); auto (default) = spin on a machine with two CPUs or more, else predict",
    )
    p.add_argument(
        "--busy-poll",
        action="store_true",
        help="the same as --wait spin",
    )
    p.add_argument(
        "--rt-priority",
        type=_rt_priority,
        default="auto",
        metavar="N|auto|off",
        help="SCHED_FIFO priority N (1-99); auto (default) takes priority "
        f"{AUTO_RT_PRIORITY} where the system permits it (root or CAP_SYS_NICE) and says so "
        "in the ready line, else runs normally with a warning; off never asks",
    )
    p.add_argument(
        "--cpu",
        type=int,
        metavar="N",
        help="run on CPU N only (keep the master's busy loop on another CPU: sharing one "
        "costs a context switch per frame)",
    )
    p.add_argument("--duration", type=_positive(float), help="stop after this many seconds")
    p.add_argument(
        "--stats-json",
        type=Path,
        help="write counters and latency here on exit (and on SIGUSR1, which also "
        "starts the latency records afresh: time one phase of a run)",
    )
    p.add_argument(
        "--foe-file",
        action="append",
        default=[],
        metavar="NAME=PATH",
        help="offer PATH as file NAME for FoE reads on every slave with a mailbox (repeatable)",
    )
    p.add_argument(
        "--pcap",
        type=Path,
        metavar="FILE",
        help="write every frame received and answered to FILE (classic pcap, for Wireshark)",
    )
    p.add_argument(
        "--fault",
        action="append",
        default=[],
        type=Path,
        metavar="FILE",
        help="arm the [[fault]] tables of FILE (TOML; repeatable): the same faults as on the "
        "emulated bus, in the slaves' time since the server started (a machine "
        "description's own [[fault]] tables are armed too)",
    )
    p.add_argument("-v", "--verbose", action="store_true", help="log what the slaves do")


def _cycle_ns(text: str) -> int:
    """An argparse type: a cycle in microseconds, in the ENI's range -> nanoseconds."""
    from gtecat.eni.limits import RangeError, cycle_ns_from_us

    try:
        return cycle_ns_from_us(text, "the cycle")
    except RangeError as exc:
        raise argparse.ArgumentTypeError(str(exc)) from None


def _positive(kind: type[int] | type[float]):
    """An argparse type: a number greater than 0 (argparse names the option in its error)."""

    def parse(text: str) -> int | float:
        try:
            value = kind(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"{text!r} is not a number") from None
        if not value > 0:  # also refuses nan
            raise argparse.ArgumentTypeError(f"{text} is not greater than 0")
        return value

    parse.__name__ = kind.__name__
    return parse


def _writable(path: Path, option: str) -> None:
    """Fail now, in one line, for a file that cannot be written at the end of the run."""
    from gtecat.eni.errors import GtecatError

    probe = path.with_name(path.name + ".tmp")
    try:
        probe.touch()
        probe.unlink()
    except OSError as exc:
        raise GtecatError(f"{option} {path}: {exc.strerror or exc}") from None


def build_chain(
    eni: Path,
    machine: Path | None = None,
    *,
    watchdog_trips: bool = False,
    clock: Callable[[], int] | None = None,
):
    # -> tuple[Chain, EniConfig]
    """The ENI's slaves behind ESCs (what ``serve`` puts on the wire), each with the SII
    the ENI describes (SM layout, mailbox, product name: :mod:`gtecat.drives.esc.sii_eni`);
    ``clock``: the ESCs' time in ns (default the monotonic clock; a test's virtual one)."""
    from gtecat.drives.esc import Chain
    from gtecat.drives.esc.sii_eni import sii_for
    from gtecat.drives.machine import MachineDescription, load_machine
    from gtecat.eni.layout import build_layout
    from gtecat.eni.reader import read_eni
    from gtecat.master.factory import build_slaves

    config = read_eni(eni)
    layout = build_layout(config)
    desc = load_machine(machine) if machine else MachineDescription()
    slaves = build_slaves(layout, desc)
    sii = [sii_for(slave, s) for slave, s in zip(slaves, config.slaves, strict=True)]
    kw = {} if clock is None else {"clock": clock}
    chain = Chain(slaves, sii=sii, watchdog_trips=watchdog_trips, **kw)
    return chain, config


AUTO_RT_PRIORITY = scheduling.AUTO_RT_PRIORITY


def _rt_priority(text: str) -> int | str:
    """``--rt-priority``: a number 1-99, ``auto`` or ``off`` (0 is off too)."""
    try:
        return scheduling.parse_priority(text)
    except ValueError as exc:
        raise argparse.ArgumentTypeError(str(exc)) from None


def take_scheduling(rt: int | str, wait_given: str, cpu: int | None) -> tuple[int | None, str]:
    """The real-time priority ``serve`` runs under and words for the ready line.

    ``auto``: a server that answers frames must not wait behind other work on a busy host
    (a master drops an answer later than its timeout, SOEM's is 2 ms). It asks for
    SCHED_FIFO; where the system refuses, it runs normally and warns. It does not pin itself
    to a CPU (``--cpu`` does): a real-time task takes whichever CPU it wakes on from normal
    work, and the kernel moves it to another when one real-time task already runs there, which
    it cannot do for a pinned one - two servers pinned to one CPU at the same priority never
    preempt each other, and one answering back-to-back mailbox frames held the other's frames
    for many milliseconds (its master then configured a slave wrongly). Decision: an explicit
    ``--wait spin`` keeps normal priority under ``auto`` (a task that never sleeps under
    SCHED_FIFO is stopped by the kernel for 50 ms of every second and takes the CPU from
    everything else); the number form takes FIFO anyway, as asked."""
    taken = scheduling.take(rt, spins_forever=wait_given == "spin")
    if taken.refused:
        print(
            f"warning: running at normal priority ({taken.refused}); on a busy host answers "
            "may come later than a master's timeout: run as root or give python CAP_SYS_NICE",
            file=sys.stderr,
        )
    return taken.priority, taken.words


def preemption_words(realtime: bool) -> tuple[str, str | None]:
    """The kernel's preemption model for the ready line (``, kernel preemption none``), with a
    warning where it does not bound a real-time wake-up: under ``none`` and ``voluntary`` a
    normal task inside a system call keeps its CPU until the call ends, and a frame for the
    server waits for it, whatever the server's priority. Decision: serve does not switch the
    model itself (a boot option, ``preempt=full``, or the debugfs switch of a PREEMPT_DYNAMIC
    kernel, which changes the whole host); it says what it found."""
    from gtecat.wire.serve import UNPREEMPTIBLE, kernel_preemption

    model = kernel_preemption()
    if model is None:
        return "", None
    warning = None
    if realtime and model in UNPREEMPTIBLE:
        warning = (
            f"the kernel's preemption model is {model!r}: another program's system call "
            "can hold the server's CPU for milliseconds before it runs; boot with "
            "preempt=full (or a PREEMPT_RT kernel) for a bounded answer time"
        )
    return f", kernel preemption {model}", warning


def resolve_wait(wait: str, rt_priority: int | None = None) -> str:
    """``auto``: spin where the master keeps a CPU of its own, else predict.

    A frame answered from a spinning loop takes half the time of one answered after a
    sleep, even a predicted one: on a VM the CPU that slept runs slower for a while (p50
    13 against 28 us on the 2-vCPU machine, docs/hardware.md), and the wire's latency target is the
    spinning figure.  On one CPU a spinning server would take the master's time slices;
    under SCHED_FIFO (``--rt-priority``) the kernel stops a task that never sleeps for 50 ms
    of every second (``sched_rt_runtime_us``), so auto predicts there too.
    """
    if wait != "auto":
        return wait
    if rt_priority:
        return "predict"
    try:
        cpus = len(os.sched_getaffinity(0))
    except (AttributeError, OSError):
        cpus = os.cpu_count() or 1
    return "spin" if cpus >= 2 else "predict"


def run(args: argparse.Namespace) -> int:
    from gtecat.eni.errors import GtecatError
    from gtecat.wire.serve import WireServer, interface_is_up, pin_to_cpu

    if args.verbose:
        logging.basicConfig(level=logging.INFO, format="%(name)s: %(message)s")
    wait_given = "spin" if args.busy_poll else args.wait
    if args.cpu is not None:
        pin_to_cpu(args.cpu)
    wants_rt = args.rt_priority != "off" and not (
        args.rt_priority == "auto" and wait_given == "spin"
    )
    wait = resolve_wait(wait_given, AUTO_RT_PRIORITY if wants_rt else None)
    if wait == "spin" and wants_rt:
        print(
            "warning: a spinning server under SCHED_FIFO is stopped by the kernel for 50 ms "
            "every second (sched_rt_runtime_us); --wait predict sleeps between frames",
            file=sys.stderr,
        )
    if not Path("/sys/class/net", args.iface).exists() and Path("/sys/class/net").is_dir():
        from gtecat.eni.errors import GtecatError

        raise GtecatError(
            f"no network interface {args.iface!r}: `gtecat ifaces` lists the ones this machine has"
        )
    chain, config = build_chain(args.eni, args.machine, watchdog_trips=args.sm_watchdog)
    for spec in args.foe_file:
        name, sep, path = spec.partition("=")
        if not sep or not name:
            raise GtecatError(f"--foe-file {spec!r}: expected NAME=PATH")
        try:
            content = Path(path).read_bytes()
        except OSError as exc:
            raise GtecatError(f"--foe-file {spec!r}: {exc.strerror}") from None
        for esc in chain.escs:
            if esc.slave.has_mailbox:
                esc.foe.files[name] = content
    cycle_ns = args.cycle_ns or config.cycle_time_ns or 1_000_000
    if interface_is_up(args.iface) is False:
        print(f"warning: interface {args.iface} is down", file=sys.stderr)
    from gtecat.master.pcap import PcapWriter

    if args.stats_json:
        _writable(args.stats_json, "--stats-json")
    try:
        pcap = PcapWriter(args.pcap) if args.pcap else None
    except OSError as exc:
        raise GtecatError(f"--pcap {args.pcap}: {exc.strerror or exc}") from None
    server = WireServer(
        chain,
        args.iface,
        step_mode=args.step,
        cycle_ns=cycle_ns,
        wait=wait,
        pcap=pcap,
    )
    from gtecat.inspect.serve import ServeHost

    host = ServeHost(server, config, eni=args.eni, iface=args.iface, say=_sayer(server))
    _arm_faults(args, host)
    # the scheduling last, once everything that can fail has been checked; given back at
    # the end (a program that calls serve in-process keeps its own)
    before = scheduling.snapshot()
    rt, sched_words = take_scheduling(args.rt_priority, wait_given, args.cpu)
    words, warning = preemption_words(rt is not None)
    sched_words += words
    if warning:  # said right after the ready line (the first line is the ready line)
        server.early_messages.append(f"warning: {warning}")
    if rt is None and wants_rt and wait == "predict" and args.wait == "auto":
        wait = server.wait = resolve_wait("auto", None)
    if rt is not None:
        from gtecat.wire.serve import LINGER_RT_NS

        server.linger_ns = LINGER_RT_NS  # a real-time spin holds the CPU against the master

    def _stop(signum: int, _frame: FrameType | None) -> None:
        server.stop.set()

    old = {s: signal.signal(s, _stop) for s in (signal.SIGINT, signal.SIGTERM)}

    def _write_stats(report: dict[str, object]) -> None:
        if args.stats_json:
            tmp = args.stats_json.with_name(args.stats_json.name + ".tmp")
            try:
                tmp.write_text(json.dumps(report, indent=2) + "\n")
                tmp.replace(args.stats_json)
            except OSError as exc:  # the folder went away during the run: say so, go on
                print(f"warning: --stats-json {args.stats_json}: {exc.strerror}", file=sys.stderr)

    def _snapshot(signum: int, _frame: FrameType | None) -> None:
        server.snapshot_due = True

    server.on_snapshot = _write_stats
    if hasattr(signal, "SIGUSR1"):  # kill -USR1: stats so far to --stats-json, latency anew
        old[signal.SIGUSR1] = signal.signal(signal.SIGUSR1, _snapshot)

    served = []
    endpoint = None

    def _ready() -> None:
        nonlocal endpoint
        from gtecat.inspect.serve import publish

        served.append(True)
        endpoint = publish(host)  # `gtecat ps` lists it; `gtecat fault --attach` acts on it
        names = ", ".join(f"{s.position}:{s.name}" for s in chain.slaves)
        seen = f", id {endpoint.id} (gtecat ps)" if endpoint is not None else ""
        print(
            f"gtecat serve: {len(chain)} slaves on {args.iface} ({names}), --wait {wait}, "
            f"{sched_words}{seen}; ready",
            flush=True,
        )
        server.said_ready = True
        for message in getattr(server, "early_messages", ()):
            print(f"gtecat serve: {message}", file=sys.stderr, flush=True)

    try:
        server.serve(ready=_ready, duration_s=args.duration)
    finally:
        if endpoint is not None:
            endpoint.close()
        scheduling.restore(before)
        for s, h in old.items():
            signal.signal(s, h)
        server.close()
        report = server.report()
        _write_stats(report)
        lat = report["latency"]
        if served:  # a server that never started has nothing to report
            steal = report.get("host_steal_percent")
            print(
                f"gtecat serve: stopped after {report['elapsed_s']} s, "
                f"{report['sent']} frames answered, {report['chain']['dropped']} dropped, "
                f"latency p50 {lat.get('p50_us', 0):.1f} us, p99 {lat.get('p99_us', 0):.1f} us, "
                f"{lat.get('over_1ms', 0)} over 1 ms"
                + (f" (the hypervisor took {steal} % of the CPUs)" if steal else ""),
                flush=True,
            )
    return 0


def _sayer(server):
    """``gtecat serve: MESSAGE`` on stderr; said before the ready line: said right after it."""
    early: list[str] = []
    server.early_messages = early

    def say(message: str) -> None:
        if not getattr(server, "said_ready", False):
            early.append(message)
            return
        print(f"gtecat serve: {message}", file=sys.stderr, flush=True)

    return say


def _arm_faults(args: argparse.Namespace, host) -> None:
    """The machine description's and the --fault files' [[fault]] tables on the chain (the
    injector ``gtecat fault --attach`` reaches at runtime)."""
    from gtecat.drives.machine import load_machine
    from gtecat.faults import arm, load, specs_from_tables

    specs = []
    if args.machine:
        tables = load_machine(args.machine).faults
        if tables:
            specs += specs_from_tables(list(tables), str(args.machine))
    for path in args.fault:
        specs += load(path)
    if specs:
        arm(host.fault_injector(), specs)


def main(argv: list[str] | None = None) -> int:
    """Entry point for ``python -m gtecat.cli.serve_cmd`` (same options as ``gtecat serve``)."""
    from gtecat.eni.errors import GtecatError

    parser = argparse.ArgumentParser(prog="gtecat serve", description=__doc__)
    _arguments(parser)
    parser.add_argument("--debug", action="store_true", help="show tracebacks")
    args = parser.parse_args(argv)
    try:
        return run(args)
    except GtecatError as exc:
        if args.debug:
            raise
        print(f"error: {exc}", file=sys.stderr)
        return 1


if __name__ == "__main__":
    sys.exit(main())
