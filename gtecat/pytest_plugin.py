"""pytest plugin: test your own GT application against the emulator.

Installed with gtecat and loaded by pytest on its own (entry point ``pytest11``). Fixtures:

``gtecat_bus``
    An opened emulated controller, lockstep clock, bus in OP (manual example 5-5 done), as a
    :class:`Bench`: ``.gt`` (the GT functions), ``.wait(ms)``, ``.field(slave)`` (a virtual
    slave's field side), ``.record(*signals)`` (a started recorder), ``.check(rc)``,
    ``.axis_on(*axes)``, ``.path`` (the test's own folder). Closed after the test.
``gtecat_eni`` / ``gtecat_machine``
    What the bus is built from: a file path, or the name of a shipped example
    (``gtecat example`` lists them), found in this order - your machine first, a shipped
    example only when you name it:

    1. the ``gtecat`` marker (``eni=`` / ``machine=``),
    2. the ``gtecat_eni`` / ``gtecat_machine`` ini options (``pytest.ini``, ``pyproject.toml``),
    3. ``GTECAT_ENI`` / ``GTECAT_MACHINE`` in the environment (as ``GT_Open`` reads them),
    4. ``Gecat.eni`` in the rootdir (beside ``pytest.ini``), as the real controller looks for
       it in its working folder; for the machine description, none;
    5. else the test errors with a message that says how to choose.

    The pytest header line names the bus and machine of the session and where they came from.
    Override either by defining a fixture of that name in your ``conftest.py``.
``gtecat_env``
    For applications that call ``GT_Open()`` themselves: the ``GTECAT_*`` environment of
    the same ENI, machine and lockstep clock, with the master log and MRAM in the test's folder.
``gtecat_field``
    ``gtecat_field(slave)``: the field side of a virtual slave (wires, sensors, faults).
``gtecat_recorder``
    A recorder of every axis's planned and actual position, following error and statusword.

Every file a controller writes (``Gecat.log``, ``Gecat.mram``, traces) goes to the test's
``tmp_path``, never the working directory, so tests run in parallel under pytest-xdist
(``-n auto``): each worker process has its own controller and each test its own folder.

``--gtecat-trace`` saves, for every failing test, a CSV and a PNG of what the recorders saw
(``gtecat-trace.csv``/``.png`` in the test's folder; ``--gtecat-trace-dir DIR`` collects them)
and adds the recent GT errors and the file paths to the failure report.

Marker: ``@pytest.mark.gtecat(eni="homing_probe", machine="machine.toml", clock="auto")``.
"""

from __future__ import annotations

import re
import sys
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any

import pytest


def _not_rewritten() -> None:
    """Leave gtecat's own modules to Python's import, not pytest's assertion rewriter.

    pytest rewrites the asserts of every module of a plugin's distribution, and that is all of
    gtecat (~350 modules) since this plugin ships with it: parsed and compiled again in every
    pytest process that has no rewritten copy cached yet (a fresh install, or
    ``PYTHONDONTWRITEBYTECODE`` set), about 14 s of CPU each.  Its modules hold no test
    asserts; this module (imported first) keeps the rewriting.  Without the hook's set (another
    pytest) nothing changes."""
    for finder in sys.meta_path:
        marked = getattr(finder, "_must_rewrite", None)
        if type(finder).__name__ == "AssertionRewritingHook" and isinstance(marked, set):
            marked.discard(__name__.partition(".")[0])


_not_rewritten()

DEFAULT_FILE = "Gecat.eni"
NO_ENI = (
    "gtecat: which bus should the tests run against? Name it in pytest.ini "
    "([pytest] gtecat_eni = path/to/your.eni, or a shipped example such as manual_fig5_2; "
    "`gtecat example` lists them), set GTECAT_ENI, or put your Gecat.eni in {rootdir}"
)
TRACE_KEY = pytest.StashKey[list]()
ERRORS_KEY = pytest.StashKey[object]()
RECORD_KEY = pytest.StashKey[Any]()
LISTENERS_KEY = pytest.StashKey[list]()
#: the ``--gtecat-check`` checker of a test, and how many of its findings were warned already
CHECK_KEY = pytest.StashKey[list]()


def _errors_seen() -> object:
    """The newest entry of the GT error ring now: a failure reports only later ones."""
    from .gt import _core

    return _core.SESSION.errors[-1] if _core.SESSION.errors else None


def _errors_since(marker: object) -> list[Any]:
    from .gt import _core

    ring = list(_core.SESSION.errors)
    for i in range(len(ring) - 1, -1, -1):
        if ring[i] is marker:
            return ring[i + 1 :]
    return ring


def pytest_addoption(parser: pytest.Parser) -> None:
    group = parser.getgroup("gtecat", "gtecat emulator")
    group.addoption(
        "--gtecat-trace",
        action="store_true",
        help="save a CSV and PNG trace of every failing test that used a gtecat fixture",
    )
    group.addoption(
        "--gtecat-trace-dir",
        metavar="DIR",
        help="also copy the traces of failing tests into DIR (one file pair per test)",
    )
    group.addoption(
        "--gtecat-check",
        action="store_true",
        help="report where a test's GT calls do what a real drive or controller punishes "
        "(check: FILE:LINE lines; gtecat run --check)",
    )
    group.addoption(
        "--gtecat-record",
        action="store_true",
        help="record the GT calls of every test that uses gtecat_bus; a failing test keeps "
        "its recording (gtecat replay FILE) beside its trace",
    )
    parser.addini("gtecat_eni", "ENI file or shipped example name for the gtecat fixtures")
    parser.addini("gtecat_machine", "machine description TOML for the gtecat fixtures")


def pytest_configure(config: pytest.Config) -> None:
    # a test run opens many short controllers: none publishes an inspection endpoint (gtecat
    # ps, gtecat panel) unless the run asks for it with GTECAT_INSPECT=1
    import os

    os.environ.setdefault("GTECAT_INSPECT", "0")
    config.addinivalue_line(
        "markers",
        "gtecat(eni=None, machine=None, clock='lockstep'): the bus the gtecat fixtures build",
    )


def _marker(request: pytest.FixtureRequest, key: str) -> Any:
    m = request.node.get_closest_marker("gtecat")
    return None if m is None else m.kwargs.get(key)


def _resolve(value: Any, kind: str, tmp_path: Path, rootdir: Path) -> Any:
    """A path (relative to the rootdir when not found here) or an example name -> a file."""
    if value is None or not isinstance(value, str | Path):
        return value  # None, or a machine description as a dict / object
    p = Path(value)
    for candidate in (p, rootdir / p):
        if candidate.is_file():
            return candidate.resolve()
    if p.suffix in ("", ".eni", ".toml") and p.parent == Path("."):
        from .cli import example_cmd

        try:
            example = example_cmd.find(p.stem)
        except Exception:
            example = None
        if example is not None:
            folder = tmp_path / "example"
            written = example_cmd.write(example, folder)
            want = ".eni" if kind == "eni" else ".toml"
            for f in written:
                if f.suffix == want and (kind == "eni" or "[[slave]]" not in f.read_text()):
                    return f
    raise pytest.UsageError(
        f"gtecat: {kind} {value!r} is neither a file nor a shipped example "
        "(`gtecat example` lists them)"
    )


def _session_choice(config: pytest.Config, kind: str) -> tuple[Any, str]:
    """(value, where it came from) for the whole session: ini option, environment,
    ``Gecat.eni`` in the rootdir; (None, "") when nothing names one."""
    import os

    ini = config.getini(f"gtecat_{kind}")
    if ini:
        return ini, f"gtecat_{kind} in {_ini_name(config)}"
    env = os.environ.get(f"GTECAT_{kind.upper()}", "").strip()
    if env:
        return env, f"GTECAT_{kind.upper()}"
    if kind == "eni":
        default = config.rootpath / DEFAULT_FILE
        if default.is_file():
            return default, f"{DEFAULT_FILE} in the rootdir"
    return None, ""


def _ini_name(config: pytest.Config) -> str:
    return config.inipath.name if config.inipath is not None else "the ini file"


def _choice(request: pytest.FixtureRequest, kind: str) -> Any:
    marked = _marker(request, kind)
    if marked:
        return marked
    return _session_choice(request.config, kind)[0]


@pytest.fixture
def gtecat_eni(request: pytest.FixtureRequest, tmp_path: Path) -> Path:
    """The ENI of the bus: marker, ini option ``gtecat_eni``, ``GTECAT_ENI``, ``Gecat.eni``
    in the rootdir; an error that says how to choose when none names one."""
    value = _choice(request, "eni")
    if value is None:
        pytest.fail(NO_ENI.format(rootdir=request.config.rootpath), pytrace=False)
    return _resolve(value, "eni", tmp_path, request.config.rootpath)


@pytest.fixture
def gtecat_machine(request: pytest.FixtureRequest, tmp_path: Path) -> Any:
    """The machine description: marker, ini option ``gtecat_machine``, ``GTECAT_MACHINE``,
    else none (no switches, no probe marks)."""
    return _resolve(_choice(request, "machine"), "machine", tmp_path, request.config.rootpath)


def pytest_report_header(config: pytest.Config) -> list[str]:
    """One line: the bus and machine the gtecat fixtures use, and where each came from."""
    eni, eni_from = _session_choice(config, "eni")
    machine, machine_from = _session_choice(config, "machine")
    bus = f"bus {eni} ({eni_from})" if eni is not None else "bus: none chosen (see gtecat_eni)"
    mach = f"machine {machine} ({machine_from})" if machine is not None else "no machine file"
    return [f"gtecat: {bus}, {mach}; a gtecat marker overrides them per test"]


def _clock(request: pytest.FixtureRequest) -> str:
    return _marker(request, "clock") or "lockstep"


@pytest.fixture
def gtecat_env(
    request: pytest.FixtureRequest,
    gtecat_eni: Path,
    gtecat_machine: Any,
    tmp_path: Path,
    monkeypatch: pytest.MonkeyPatch,
) -> dict[str, str]:
    """``GTECAT_*`` for an application that calls ``GT_Open()`` itself."""
    for k in ("GTECAT_BACKEND", "GTECAT_IFACE", "GTECAT_BUS", "GTECAT_CONTROLLER"):
        monkeypatch.delenv(k, raising=False)
    env = {
        "GTECAT_ENI": str(gtecat_eni),
        "GTECAT_CLOCK": _clock(request),
        "GTECAT_LOG": str(tmp_path / "Gecat.log"),
        "GTECAT_MRAM": str(tmp_path / "Gecat.mram"),
    }
    if isinstance(gtecat_machine, Path):
        env["GTECAT_MACHINE"] = str(gtecat_machine)
    else:
        monkeypatch.delenv("GTECAT_MACHINE", raising=False)
    for k, v in env.items():
        monkeypatch.setenv(k, v)
    request.node.stash[TRACE_KEY] = []  # no recorders, but the GT errors go into a failure
    request.node.stash[ERRORS_KEY] = _errors_seen()
    yield env
    from . import gt

    gt._core.close_all()  # an application that forgot (every card): the next test starts clean


class Bench:
    """An opened emulated controller and what a test needs around it."""

    def __init__(self, gt: Any, path: Path, eni: Path, machine: Any) -> None:
        self.gt = gt
        self.path = path
        self.eni = eni
        self.machine = machine
        self.recorders: list[Any] = []

    @property
    def ctl(self) -> Any:
        """The Python controller underneath the GT calls (``GTE_Controller()``)."""
        return self.gt.GTE_Controller()

    def check(self, rc: int) -> None:
        """Fail the test with the GT reason unless ``rc`` is 0."""
        if rc != 0:
            raise AssertionError(self.gt.GTE_GetLastError() or f"returned {rc}")

    def wait(self, ms: float) -> None:
        """Let ``ms`` of controller time pass (cycles run)."""
        self.check(self.gt.GTE_Wait(ms))

    def run_until(self, predicate: Callable[[], bool], timeout_ms: float = 10_000) -> float:
        """Cycle until ``predicate()``; the controller ms it took. Fails on the timeout."""
        t0 = self.now_ms()
        while not predicate():
            if self.now_ms() - t0 >= timeout_ms:
                raise AssertionError(f"not reached within {timeout_ms} ms of controller time")
            self.wait(1)
        return self.now_ms() - t0

    def now_ms(self) -> float:
        return self.ctl.clock.now_ns / 1e6

    def field(self, slave: int) -> Any:
        """The field side of virtual slave ``slave`` (``GTE_Slave``)."""
        return self.gt.GTE_Slave(slave)

    def axis_on(self, *axes: int) -> None:
        for axis in axes:
            self.check(self.gt.GT_AxisOn(axis))

    def record(self, *signals: str) -> Any:
        """A recorder of ``signals`` (``gtecat run --help`` names them), started now."""
        from .controller.recorder import Recorder

        rec = Recorder(self.ctl, list(signals)).start()
        self.recorders.append(rec)
        return rec

    def axes(self) -> int:
        return len(self.ctl.require_master().layout.axes)


def _bring_up(gt: Any, bench: Bench) -> None:
    from ctypes import byref, c_short

    bench.check(gt.GT_InitEcatComm())
    status = c_short()
    for _ in range(10_000):
        if gt.GT_IsEcatReady(byref(status)) == 0 and status.value == 1:
            break
        gt.GTE_Wait(1)
    else:
        raise AssertionError("the emulated bus did not reach OP in 10 s: " + gt.GTE_GetLastError())
    bench.check(gt.GT_StartEcatComm())


@pytest.fixture
def gtecat_bus(
    request: pytest.FixtureRequest,
    gtecat_eni: Path,
    gtecat_machine: Any,
    tmp_path: Path,
    monkeypatch: pytest.MonkeyPatch,
) -> Iterator[Bench]:
    """An opened emulated controller in the lockstep clock, bus in OP; closed afterwards."""
    from . import gt

    for k in ("GTECAT_BACKEND", "GTECAT_IFACE", "GTECAT_BUS", "GTECAT_CONTROLLER"):
        monkeypatch.delenv(k, raising=False)
    gt._core.close_all()
    machine = str(gtecat_machine) if isinstance(gtecat_machine, Path) else gtecat_machine
    listeners: list[Any] = []
    if request.config.getoption("gtecat_record"):
        from .faults.record import Recorder

        rec = Recorder(tmp_path / "gtecat-recording.jsonl", {"test": request.node.nodeid})
        listeners.append(rec.start())
        request.node.stash[RECORD_KEY] = rec
    checker = None
    if request.config.getoption("gtecat_check"):
        import io

        from .faults.checks import Checker

        checker = Checker(io.StringIO()).start()  # its findings: warnings, at the end
        listeners.append(checker)
        request.node.stash[CHECK_KEY] = [checker, 0]
    request.node.stash[LISTENERS_KEY] = listeners
    rc = gt.GT_Open(
        eni=str(gtecat_eni),
        machine=machine,
        clock=_clock(request),
        log=str(tmp_path / "Gecat.log"),
        mram=str(tmp_path / "Gecat.mram"),
    )
    if rc != 0:
        raise AssertionError(gt.GTE_GetLastError())
    bench = Bench(gt, tmp_path, gtecat_eni, gtecat_machine)
    request.node.stash[TRACE_KEY] = bench.recorders
    request.node.stash[ERRORS_KEY] = _errors_seen()
    try:
        _bring_up(gt, bench)
        if request.config.getoption("gtecat_trace"):
            per_axis = ("prf", "enc", "err", "sw")
            bench.record(
                *(f"axis{a}.{s}" for a in range(1, bench.axes() + 1) for s in per_axis), "faults"
            )
        yield bench
    finally:
        for rec in bench.recorders:
            rec.stop()
        gt._core.close_all()  # every card the test opened
        for listener in listeners:
            listener.stop()
        if checker is not None:  # what the closing found (the test's own: at its end)
            seen = request.node.stash.get(CHECK_KEY, [checker, 0])
            _warn_findings(checker.findings[seen[1] :])


def _warn_findings(findings: list[Any]) -> None:
    """The checks' findings as pytest warnings at the application's file and line: pytest
    shows them in its warnings summary, from every worker of an xdist run too (printed to
    the test's stderr they were captured and shown only with ``-s`` or ``-rA``).  Where the
    warnings filter makes them errors (``-W error::...GtecatCheckWarning``), one
    GtecatCheckWarning raised with every finding, one per line."""
    import warnings

    from .faults.checks import GtecatCheckWarning

    raised: list[str] = []
    for f in findings:
        try:
            warnings.warn_explicit(str(f), GtecatCheckWarning, f.file, f.line)
        except GtecatCheckWarning as e:
            raised.append(str(e))
    if raised:
        raise GtecatCheckWarning("\n".join(raised))


@pytest.hookimpl(hookwrapper=True)
def pytest_runtest_call(item: pytest.Item) -> Iterator[None]:
    """A ``--gtecat-check`` test's findings are warned as its call ends, in the call itself:
    turned into errors by the warnings filter, they fail the test (not its teardown); a
    test that failed anyway has them warned at its teardown."""
    outcome = yield
    seen = item.stash.get(CHECK_KEY, None)
    if seen is None or outcome.excinfo is not None:
        return
    checker, done = seen
    seen[1] = len(checker.findings)
    from .faults.checks import GtecatCheckWarning

    try:
        _warn_findings(checker.findings[done:])
    except GtecatCheckWarning as e:
        force = getattr(outcome, "force_exception", None)
        if force is None:  # (pluggy before 1.1: raised from the wrapper)
            raise
        force(e)


@pytest.fixture
def gtecat_faults(gtecat_bus: Bench) -> Iterator[Any]:
    """The fault vocabulary on the test's bus: ``gtecat_faults.inject("drive_fault", axis=1,
    code=0x2310, at_ms=500)``, ``.clear()``, ``.listing()``, ``.script([...])``; every fault
    is cleared at the end of the test."""
    import types

    from . import faults

    ctl = gtecat_bus.ctl
    face = types.SimpleNamespace(
        inject=lambda kind, **values: faults.inject(kind, ctl=ctl, **values),
        clear=lambda ident=None: faults.clear(ident, ctl=ctl),
        listing=lambda: faults.listing(ctl=ctl),
        script=lambda steps: faults.script(steps, ctl=ctl),
        describe=faults.describe,
    )
    yield face
    if ctl.master is not None and ctl.master.opened:
        faults.clear(ctl=ctl)


@pytest.fixture
def gtecat_field(gtecat_bus: Bench) -> Callable[[int], Any]:
    """``gtecat_field(slave)``: a virtual slave's field side (wires, sensors, faults)."""
    return gtecat_bus.field


@pytest.fixture
def gtecat_recorder(gtecat_bus: Bench) -> Any:
    """Every axis's planned/actual position, following error and statusword, every cycle."""
    n = gtecat_bus.axes()
    return gtecat_bus.record(
        *(f"axis{a}.{s}" for a in range(1, n + 1) for s in ("prf", "enc", "err", "sw"))
    )


def _safe(nodeid: str) -> str:
    return re.sub(r"[^A-Za-z0-9_.-]+", "_", nodeid).strip("_")[:150]


@pytest.hookimpl(hookwrapper=True)
def pytest_runtest_makereport(item: pytest.Item, call: pytest.CallInfo[None]) -> Iterator[None]:
    outcome = yield
    report = outcome.get_result()
    if report.when != "call" or not report.failed:
        return
    recording = item.stash.get(RECORD_KEY, None)
    if recording is not None:
        recording.stop()
        path = recording.write()
        lines = [f"gtecat replay {path}"]
        extra = item.config.getoption("gtecat_trace_dir")
        if extra:  # beside the traces copied there
            import shutil

            out = Path(extra)
            out.mkdir(parents=True, exist_ok=True)
            copy = shutil.copy(path, out / (_safe(item.nodeid) + ".gtrec.jsonl"))
            lines.append(f"gtecat replay {copy}")
        report.sections.append(("gtecat recording", "\n".join(lines)))
    recorders = item.stash.get(TRACE_KEY, None)
    if recorders is None:
        return
    errors = _errors_since(item.stash.get(ERRORS_KEY, None))[-5:]
    if errors:
        report.sections.append(
            (
                "gtecat: recent GT errors",
                "\n".join(f"[{e.clock_ms} ms] {e.function} returned {e.code}: {e.reason}"
                          for e in errors),
            )
        )  # fmt: skip
    if not item.config.getoption("gtecat_trace"):
        return
    lines = []
    folder = Path(getattr(item, "funcargs", {}).get("tmp_path") or ".")
    extra = item.config.getoption("gtecat_trace_dir")
    for i, rec in enumerate(r for r in recorders if r.n):
        stem = folder / ("gtecat-trace" if i == 0 else f"gtecat-trace-{i}")
        paths = [rec.to_csv(stem.with_suffix(".csv")), rec.plot(stem.with_suffix(".png"),
                 title=item.nodeid)]  # fmt: skip
        if extra:
            import shutil

            out = Path(extra)
            out.mkdir(parents=True, exist_ok=True)
            base = _safe(item.nodeid) + ("" if i == 0 else f"-{i}")
            paths += [Path(shutil.copy(p, out / (base + p.suffix))) for p in paths[:2]]
        lines.append(f"{rec.n} cycles of {', '.join(rec.names)}:")
        lines += [f"  {p}" for p in paths]
    log = folder / "Gecat.log"
    if log.is_file():
        lines.append(f"master log: {log}")
    if lines:
        report.sections.append(("gtecat trace", "\n".join(lines)))
