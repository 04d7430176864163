"""Shared test fixtures: where the real-tool configuration files live."""

from __future__ import annotations

import contextlib
import gc
import os
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest

# No test depends on the wall clock's speed: hypothesis's deadline is off in every profile (a
# loaded CI machine must not fail an example for being slow). CI runs the property tests with
# a fixed derandomised seed (reproducible, never flaky); developers' runs keep exploring.
#: GTECAT_LONG=1 runs the long campaigns (fuzzers over the whole function table, wide sweeps)
#: in full; the default run keeps a small, bounded, seeded version of each so that the suite
#: fits its 2-CPU machine.
LONG = bool(os.environ.get("GTECAT_LONG"))

# A property test that names no example count runs hypothesis's 100 under GTECAT_LONG=1 and
# 25 in the default run (the suite's CPU budget, docs/performance.md).
_EXAMPLES = 100 if LONG else 25


def _hypothesis_profiles() -> None:
    """The profiles above, loaded in each process that runs tests (pytest_configure: before
    the test modules are imported).  The controller of a pytest-xdist run runs none and
    does not import hypothesis (a third of a second)."""
    from hypothesis import settings

    settings.register_profile("dev", deadline=None, max_examples=_EXAMPLES)
    settings.register_profile("ci", derandomize=True, deadline=None, max_examples=_EXAMPLES)
    settings.load_profile("ci" if os.environ.get("CI") else "dev")


# The cyclic collector of a test process runs its youngest generation every 5,000 allocations
# net, not 700: the suite makes buses, drives and hypothesis examples by the million, most of
# which die young by reference counting, and each young pass also ages the survivors toward
# the full passes over the whole process (every test module, the collected items, hypothesis):
# 4.6 -> 3.1 s of collector time in the GT, drive and controller tests.  Child processes
# (the programs, controllers and CLIs the tests start) keep Python's default.
gc.set_threshold(5000, 10, 10)


def _hypothesis_not_rewritten() -> None:
    """pytest rewrites the asserts of every module of a plugin's distribution, hypothesis's
    included (its pytest plugin): ~90 modules of hypothesis's own internal checks, whose
    failures are never ours to explain, ~0.5 s of CPU in every pytest process on a fresh
    machine (nothing cached).  Unmarked here, before hypothesis is imported; with a pytest
    whose internals differ, it is rewritten as before.  Hypothesis's own plugins (another
    package's, e.g. trio's, which imports trio) are not loaded in the test processes."""
    import sys

    os.environ.setdefault("HYPOTHESIS_NO_PLUGINS", "1")
    if "hypothesis" in sys.modules:
        return
    for finder in sys.meta_path:
        marked = getattr(finder, "_must_rewrite", None)
        if isinstance(marked, set) and "hypothesis" in marked:
            marked.discard("hypothesis")
            cache = getattr(finder, "_marked_for_rewrite_cache", None)
            if isinstance(cache, dict):
                cache.clear()


_hypothesis_not_rewritten()


def examples(long: int, default: int) -> int:
    """A property test's ``max_examples``: ``long`` under GTECAT_LONG=1, else ``default``."""
    return long if LONG else default


def campaign_seed() -> int:
    """The seed of a sampled campaign: ``GTECAT_SEED`` when set, 0 under ``CI`` (the same
    sample every run), else a fresh one per run (developers' runs cover the rest over time;
    a failure names its seed)."""
    env = os.environ.get("GTECAT_SEED")
    if env:
        return int(env)
    if os.environ.get("CI"):
        return 0
    run = os.environ.get("PYTEST_XDIST_TESTRUNUID")  # the same in every worker of one run
    if run:
        return int(run[:8], 16)
    return int.from_bytes(os.urandom(4), "little")


#: why the default run skips a ``@pytest.mark.long`` test
LONG_REASON = (
    "a longer check: GTECAT_LONG=1 runs it (the default run is the suite's quick share, about "
    "a minute and a half of CPU)"
)


def _long_and_sampled(items: list[pytest.Item]) -> None:
    """The default run's share of the longer checks (docs/performance.md, the test suite).

    ``@pytest.mark.long`` or ``@pytest.mark.long("what it runs")``: skipped unless
    ``GTECAT_LONG=1``, the skip saying what it would have run.  ``@pytest.mark.sample(k)`` on
    a parametrized test: the default run keeps ``k`` of its cases, chosen by
    :func:`campaign_seed` (the same ones on every CI run, others on each developer's run),
    and skips the rest saying so; ``GTECAT_LONG=1`` runs every case.  Skips are marks added at
    collection, so every xdist worker collects the same items."""
    if LONG:
        return
    import random

    families: dict[tuple[str, str], list[pytest.Item]] = {}
    for item in items:
        if (mark := item.get_closest_marker("long")) is not None:
            what = f" ({mark.args[0]})" if mark.args else ""
            item.add_marker(pytest.mark.skip(reason=LONG_REASON + what))
        elif item.get_closest_marker("sample") is not None:
            key = (item.nodeid.split("::")[0], getattr(item, "originalname", item.name))
            families.setdefault(key, []).append(item)
    seed = campaign_seed()
    rng = random.Random(seed)
    for (_, name), family in sorted(families.items()):
        keep = int(family[0].get_closest_marker("sample").args[0])
        if keep >= len(family):
            continue
        family.sort(key=lambda i: i.name)
        kept = set(rng.sample(range(len(family)), keep))
        for n, item in enumerate(family):
            if n not in kept:
                item.add_marker(
                    pytest.mark.skip(
                        reason=f"sampled out: the default run takes {keep} of the {len(family)} "
                        f"cases of {name} (seed {seed}); GTECAT_LONG=1 runs all"
                    )
                )


def pytest_xdist_make_scheduler(config, log):  # type: ignore[no-untyped-def]
    """``--dist loadgroup`` hands out work by module: the tests of one ``xdist_group``
    together (as loadgroup does), every other test with the rest of its module.

    loadgroup alone makes each ungrouped test a unit of its own, and its controller counts
    every worker's pending units after each report (about 3 s of CPU for the suite's ~3,000
    tests, growing with the square); by module there are ~200 units, and a module's
    module-scoped fixtures are built on one worker instead of on each."""
    if getattr(config.option, "dist", None) != "loadgroup":
        return None
    from xdist.scheduler import LoadGroupScheduling

    class ByModuleOrGroup(LoadGroupScheduling):
        def _split_scope(self, nodeid: str) -> str:
            if "@" in nodeid:
                return nodeid.rsplit("@", 1)[-1]
            return nodeid.split("::", 1)[0]

    return ByModuleOrGroup(config, log)


@pytest.hookimpl(trylast=True)
def pytest_collection_modifyitems(config, items):  # type: ignore[no-untyped-def]
    """The default run's longer checks (:func:`_long_and_sampled`), then the xdist groups.

    ``--dist loadgroup`` (pyproject's addopts) keeps the tests of one ``xdist_group`` on one
    worker, so a module's expensive fixture (a demo run, compiled programs, a panel and its
    browser) is built once.  pytest-xdist marks them by appending ``@group`` to the nodeid
    through an attribute that pytest 9.2 no longer reads (its nodeid is structured now):
    without this the groups were split over the workers and each built the fixture."""
    _long_and_sampled(items)
    if not getattr(config.option, "loadgroup", False):  # set in xdist workers
        return
    try:
        from _pytest.nodeid import NodeId
    except ImportError:  # an older pytest: xdist's own marking works
        return
    for item in items:
        names = {
            str(m.args[0] if m.args else m.kwargs.get("name", "default"))
            for m in item.iter_markers("xdist_group")
        }
        suffix = "@" + "_".join(sorted(names))
        if names and not item.nodeid.endswith(suffix) and hasattr(item, "_id"):
            item._id = NodeId.parse(item.nodeid + suffix)


ROOT = Path(__file__).resolve().parent.parent
EXAMPLES = ROOT / "examples"
# ../shared/fixtures beside the checkout (CI clones main with shared/ beside it)
SHARED_FIXTURES = ROOT.parent / "shared" / "fixtures"


def is_setting(name: str) -> bool:
    """Whether environment variable ``name`` is a gtecat setting a test clears to run a
    process on the defaults (``GTECAT_*``), the cache folder excepted: it says where gtecat
    keeps what it builds, not how it runs, so the test's process builds where the run does
    (a run given its own folder writes nothing into the user's)."""
    return name.startswith("GTECAT_") and name != "GTECAT_CACHE_DIR"


def needs_fixture(what: object) -> str:
    """The skip reason of a test that reads the vendors' sample files: they are not shipped
    with gtecat (a repository checkout keeps them in a fixtures folder beside it)."""
    return (
        f"needs the vendors' sample files, which gtecat does not ship ({what} not found: these "
        "tests read them from the folder shared/fixtures beside the checkout)"
    )


@pytest.fixture
def shared_fixtures() -> Path:
    if not SHARED_FIXTURES.is_dir():
        pytest.skip(needs_fixture(SHARED_FIXTURES))
    return SHARED_FIXTURES


@pytest.fixture
def examples_dir() -> Path:
    return EXAMPLES


# GTECAT_CPU_REPORT=FILE: every process of the run (each xdist worker, the controller) appends
# one line per test to FILE.<worker>: the CPU seconds (user+sys, its own and its waited-for
# children's) that the test's setup, call and teardown cost, and one line for the process's
# fixed cost (interpreter, imports, collection) before its first test. The suite's budget
# (docs/performance.md) is kept with it.
_CPU_REPORT = os.environ.get("GTECAT_CPU_REPORT")


def _cpu_now() -> float:
    import resource

    own = resource.getrusage(resource.RUSAGE_SELF)
    kids = resource.getrusage(resource.RUSAGE_CHILDREN)
    return own.ru_utime + own.ru_stime + kids.ru_utime + kids.ru_stime


if _CPU_REPORT:
    _cpu_first = [True]

    def _cpu_write(line: str) -> None:
        worker = os.environ.get("PYTEST_XDIST_WORKER", "main")
        with open(f"{_CPU_REPORT}.{worker}", "a") as f:
            f.write(line + "\n")

    @pytest.hookimpl(hookwrapper=True)
    def pytest_runtest_protocol(item, nextitem):  # type: ignore[no-untyped-def]
        start = _cpu_now()
        if _cpu_first[0]:
            _cpu_first[0] = False
            _cpu_write(f"{start:.3f}\t<process start, imports, collection>")
        yield
        _cpu_write(f"{_cpu_now() - start:.3f}\t{item.nodeid}")

    def pytest_collection_finish(session):  # type: ignore[no-untyped-def]
        _cpu_write(f"{_cpu_now():.3f}\t<collected>")

    def pytest_sessionfinish(session, exitstatus):  # type: ignore[no-untyped-def]
        _cpu_write(f"{_cpu_now():.3f}\t<process total>")


@pytest.fixture(scope="module", autouse=True)
def _no_controller_left_open():
    """After each module: every card and core it left open in this process is closed.

    ``GT_Close`` closes the current card only (as on the vendor's library), so a module
    whose clients opened a second card through a controller of this process would hand
    it to the next module, whose ``GT_Open(controller=...)`` is then refused."""
    yield
    import sys

    core = sys.modules.get("gtecat.gt._core")
    if core is not None and core.SESSION.all_controllers():
        core.close_all()


def pytest_sessionstart(session: pytest.Session) -> None:
    """The bank's compiled cycle is built (once per machine, on an empty cache) before the
    first test of each process that runs tests.  An application's first run does not wait
    for that build - its bank runs numpy meanwhile - so the tests that count the compiled
    cycles would otherwise depend on when the build ends."""
    if os.environ.get("PYTEST_XDIST_WORKER") is None and getattr(
        session.config.option, "numprocesses", None
    ):
        return  # the controller of a pytest-xdist run runs no test
    from gtecat.controller import bank_kernel

    if bank_kernel.wanted() != "numpy":
        bank_kernel.library()


@pytest.hookimpl(hookwrapper=True)
def pytest_collection(session: pytest.Session) -> Iterator[None]:
    """The collection imports every test module, rewriting its asserts on a fresh checkout
    (CI's every run): with :func:`faster_rewriter` and the cyclic collector paused.

    In one process (the default, ``-n 0``) nothing rewrites ahead (:func:`_rewrite_ahead`
    runs in a pytest-xdist controller), so this process rewrites the ~290 modules itself:
    ~8 s of CPU with pytest's own location pass, most of a cold run's extra cost.  The
    rewriting makes and drops ASTs by the million, none of them in a cycle; the collector
    found nothing in them and walked the growing process (gtecat, hypothesis, the test
    modules) again and again: ~1.2 s of CPU.  It runs as before once the collection ends."""
    paused = gc.isenabled()
    gc.disable()
    try:
        from _pytest.assertion import rewrite

        faster = faster_rewriter(rewrite) if hasattr(rewrite, "traverse_node") else None
    except ImportError:
        faster = None
    try:
        with faster or contextlib.nullcontext():
            yield
    finally:
        if paused:
            gc.enable()


def pytest_configure(config: pytest.Config) -> None:
    """The controller of a pytest-xdist run rewrites the test modules' asserts and compiles
    the package once, before its workers start (:func:`_rewrite_ahead`,
    :func:`_compile_ahead`); a process that runs tests loads the hypothesis profiles."""
    if os.environ.get("PYTEST_XDIST_WORKER") is None and getattr(
        config.option, "numprocesses", None
    ):
        _rewrite_ahead(config)
        _compile_ahead()
    else:
        _hypothesis_profiles()


def _compile_ahead() -> None:
    """Write the byte code of the package's modules that have none cached.

    The tests import the package from the checkout; in a fresh one (CI) each worker found
    no byte code and compiled every module it imports at the same time as the other (~1 s
    of CPU each).  Compiled here once, they read it."""
    import compileall
    import sys

    if sys.dont_write_bytecode:
        return
    try:
        compileall.compile_dir(ROOT / "gtecat", quiet=2)
    except OSError:
        return


def _rewrite_ahead(config: pytest.Config) -> None:
    """Write the rewritten byte code of every test module and conftest that has none cached.

    pytest rewrites a test module's asserts when it first imports it and caches the result
    beside it; in a fresh checkout (CI) every worker found no cache and did the same ~10 s of
    rewriting at once, as each collects every module.  Done here once, the workers read it.
    Uses pytest's own rewriter (the same code and cache files as an import); with another
    pytest whose internals differ, or no writable cache, the workers rewrite as before."""
    import sys

    if sys.dont_write_bytecode:
        return
    try:
        from _pytest.assertion import rewrite
        from _pytest.assertion.rewrite import assertstate_key

        state = config.stash[assertstate_key]
        with faster_rewriter(rewrite):  # half the rewriting's CPU (see there)
            for fn in sorted(ROOT.joinpath("tests").rglob("*.py")):
                if not (fn.name.startswith("test_") or fn.name == "conftest.py"):
                    continue
                pyc = rewrite.get_cache_dir(fn) / (fn.name[:-3] + rewrite.PYC_TAIL)
                if rewrite._read_pyc(fn, pyc) is not None or not rewrite.try_makedirs(pyc.parent):
                    continue
                source_hash, co = rewrite._rewrite_test(fn, config)
                rewrite._write_pyc(state, co, source_hash, pyc)
    except (ImportError, AttributeError, KeyError, TypeError, OSError, SyntaxError):
        return


_LOCATION = ("lineno", "col_offset", "end_lineno", "end_col_offset")


@contextlib.contextmanager
def faster_rewriter(rewrite: Any) -> Iterator[None]:
    """pytest's assert rewriter (module ``rewrite``) with its last pass done in one loop.

    After rewriting an assert, pytest walks every new statement recursively (one generator per
    node) and gives each node without a line number the assert's location with
    ``ast.copy_location``: most of a fresh checkout's ~10 s of rewriting.  Here the walk is
    one loop that sets those attributes itself, exactly as ``copy_location`` would (the same
    attributes, only on nodes that have them, only where no line number is set), and hands
    pytest's loop nothing left to do.  It does not go down into the assert's own nodes, which
    the new statements take up unchanged: the parser located them and everything below them
    (every test module of the suite comes out the same, locations included, as with pytest's
    pass).  Outside an assert the original walk is used."""
    import ast

    cls = rewrite.AssertionRewriter
    visit, walk = cls.visit_Assert, rewrite.traverse_node
    asserts: list[Any] = []

    def visit_assert(self: Any, assert_: Any) -> Any:
        asserts.append((assert_, {id(n) for n in ast.walk(assert_)}))
        try:
            return visit(self, assert_)
        finally:
            asserts.pop()

    def traverse_node(node: Any) -> Any:
        if not asserts:
            return walk(node)
        source, original = asserts[-1]
        where = [
            (a, v)
            for a in _LOCATION
            if (v := getattr(source, a, None)) is not None
            or (a.startswith("end_") and hasattr(source, a))
        ]
        node_type, stack = ast.AST, [node]
        while stack:
            n = stack.pop()
            if id(n) in original:
                continue  # the assert's own node: located by the parser, and all below it
            if getattr(n, "lineno", None) is None:
                attributes = n._attributes
                for a, v in where:
                    if a in attributes:
                        setattr(n, a, v)
            for field in n._fields:
                value = getattr(n, field, None)
                if value.__class__ is list:
                    stack.extend(x for x in value if isinstance(x, node_type))
                elif isinstance(value, node_type):
                    stack.append(value)
        return ()

    cls.visit_Assert, rewrite.traverse_node = visit_assert, traverse_node
    try:
        yield
    finally:
        cls.visit_Assert, rewrite.traverse_node = visit, walk
