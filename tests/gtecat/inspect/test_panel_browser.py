"""gtecat panel in a real browser (Debian's chromium, headless, driven by Selenium).

One panel brings up the figure 5-2 bus (manual 5.2.2.4) with --control, a second one
attaches to it read-only; one browser tab shows either page (a second window cost the
browser a renderer of its own).  What the page shows is compared with the endpoint's own
readings (the GT readers) and the scope's CSV with a recorder of the test's own.  Set
GTECAT_PANEL_SHOTS=DIR to save screenshots (the docs' pictures).
"""

from __future__ import annotations

import csv
import io
import itertools
import os
import subprocess
import sys
import time
import urllib.error
import urllib.request
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest

from gtecat.inspect import client, runtime

from .conftest import FIG5_2

pytestmark = pytest.mark.xdist_group("panel_browser")
CHROMIUM, DRIVER = "/usr/bin/chromium", "/usr/bin/chromedriver"
# the two omnibox popups Chromium preloads (web pages of their own, a renderer: half a second
# of CPU at each start) are of no use to a headless browser
ARGS = (
    "--headless --no-sandbox --disable-gpu --no-first-run --disable-background-networking "
    "--disable-component-update --disable-sync --window-size=1300,1700 "
    "--disable-features=WebUIOmniboxPopup,WebUIOmniboxAimPopup"
).split()
SIGNALS = [f"axis{a}.{s}" for a in (1, 2) for s in ("prf", "enc", "err", "vel")]


def _wait(pred: Any, timeout: float = 10.0, what: str = "") -> Any:
    deadline = time.monotonic() + timeout
    while True:
        v = pred()
        if v:
            return v
        if time.monotonic() > deadline:
            raise AssertionError(f"timed out waiting for {what or pred}")
        time.sleep(0.05)


def _start_panel(args: list[str], env: dict[str, str]) -> tuple[subprocess.Popen, str]:
    p = subprocess.Popen(
        [sys.executable, "-m", "gtecat", "panel", *args],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        env=env,
    )
    line = p.stdout.readline() if p.stdout else ""
    if "http://" not in line:
        p.kill()
        raise AssertionError(f"panel did not start: {line}{p.stderr.read() if p.stderr else ''}")
    return p, line[line.index("http://") :].strip()


@pytest.fixture(scope="module")
def panels(tmp_path_factory: pytest.TempPathFactory) -> Iterator[dict[str, Any]]:
    for need in (CHROMIUM, DRIVER):
        if not Path(need).exists():
            pytest.skip("needs Chromium: apt-get install chromium chromium-driver")
    pytest.importorskip("selenium", reason="needs selenium (the test extra)")
    pytest.importorskip("aiohttp", reason="needs aiohttp (the panel extra)")
    run = tmp_path_factory.mktemp("run")
    run.chmod(0o700)
    saved = {k: os.environ.get(k) for k in ("XDG_RUNTIME_DIR", "GTECAT_INSPECT")}
    os.environ.update(XDG_RUNTIME_DIR=str(run), GTECAT_INSPECT="1")
    env = dict(os.environ, GTECAT_LOG="")
    procs = []
    try:
        p1, url1 = _start_panel(["--eni", str(FIG5_2), "--control", "--port", "0"], env)
        procs.append(p1)
        (ep,) = runtime.endpoints()
        p2, url2 = _start_panel(["--attach", ep.id, "--port", "0"], env)
        procs.append(p2)
        yield {"control": url1, "readonly": url2, "socket": ep.socket}
    finally:
        for p in procs:
            p.terminate()
        for p in procs:
            try:
                p.wait(5)
            except subprocess.TimeoutExpired:
                p.kill()
        for k, v in saved.items():
            if v is None:
                os.environ.pop(k, None)
            else:
                os.environ[k] = v


@pytest.fixture(scope="module")
def chromium(panels: dict[str, Any]) -> Iterator[Any]:
    from selenium import webdriver
    from selenium.webdriver.chrome.options import Options
    from selenium.webdriver.chrome.service import Service

    o = Options()
    o.binary_location = CHROMIUM
    for a in ARGS:
        o.add_argument(a)
    d = webdriver.Chrome(service=Service(DRIVER), options=o)
    try:
        yield d
    finally:
        d.quit()


def _show(d: Any, url: str) -> Any:
    """``d`` showing the page at ``url``, live (loaded only when another one is shown)."""
    if d.current_url != url:
        d.get(url)
    ready = "return !!(window.gtecat && gtecat.ready && gtecat.snap)"
    _wait(lambda: d.execute_script(ready), 20, "the page")
    return d


@pytest.fixture
def browser(chromium: Any, panels: dict[str, Any]) -> Any:
    """The module's browser on the --control panel's page."""
    return _show(chromium, panels["control"])


@pytest.fixture(scope="module")
def endpoint_conn(panels: dict[str, Any]) -> Iterator[client.Attached]:
    with client.Attached(panels["socket"]) as c:
        yield c


def _shot(d: Any, name: str, element: str | None = None) -> None:
    where = os.environ.get("GTECAT_PANEL_SHOTS")
    if not where:
        return
    Path(where).mkdir(parents=True, exist_ok=True)
    if element:
        d.find_element("id", element).screenshot(str(Path(where) / name))
    else:
        d.save_screenshot(str(Path(where) / name))


def _click(d: Any, element: Any) -> None:
    """Click ``element`` scrolled to the middle of the window: Selenium scrolls it only just
    into view, where the page's sticky title bar can cover it (it did after a test further
    down the page had scrolled it, in another order of the tests)."""
    d.execute_script("arguments[0].scrollIntoView({block: 'center'})", element)
    element.click()


def _axis_value(d: Any, axis: int, field: str) -> str:
    return d.execute_script(
        f'return document.querySelector(\'[data-axis="{axis}"] [data-field="{field}"]\')'
        ".textContent"
    )


def test_the_page_shows_the_slaves_of_figure_5_2_in_op(browser: Any) -> None:
    rows = browser.execute_script(
        "return [...document.querySelectorAll('#slaves tbody tr')]"
        ".map(r => [...r.cells].map(c => c.textContent))"
    )
    assert [r[1] for r in rows] == ["GTHD 0", "GTHD 1", "IO 2", "IO 3"]
    assert [r[2] for r in rows] == ["OP"] * 4
    assert [r[5] for r in rows] == ["0 + 16", "16 + 16", "32 + 4", "36 + 4"]  # GT raw regions
    # the GT raw offset beside each entry: slave 1's 6041h at 22 (manual figure 5-2)
    cells = browser.execute_script(
        "return [...document.querySelectorAll('#entries tbody tr')]"
        ".map(r => [...r.cells].map(c => c.textContent))"
    )
    s1 = {(r[0], r[2]): r for r in cells}
    assert s1[("1", "0x6041:00")][7] == "22" and s1[("1", "0x6040:00")][7] == "16"
    _shot(browser, "panel.png")


def test_a_trap_move_updates_the_position(browser: Any, endpoint_conn: client.Attached) -> None:
    def axis2() -> dict[str, Any]:
        snap = endpoint_conn.call("snapshot")
        return dict(zip(snap["axis_fields"], snap["axes"][1], strict=True))

    # 1000 counts on from where the module's other tests left axis 2, once it is at rest
    # (a jog they stopped may still be slowing down): the move takes as long in any order,
    # half a second at 2 pulse/ms, about a dozen of the page's snapshots
    _wait(lambda: not axis2()["sts"] & 0x400, 20, "axis 2 at rest")  # table 6-2 bit 10
    at_rest = endpoint_conn.call("snapshot")["cycles"]
    target = round(axis2()["prf_pos"]) + 1000
    _wait(
        lambda: browser.execute_script("return gtecat.snap.cycles") >= at_rest,
        10,
        "the page at rest",
    )
    before = _axis_value(browser, 2, "prf")
    card = browser.find_element("css selector", '[data-axis="2"]')
    for cls, value in (("trap-pos", str(target)), ("trap-vel", "2"), ("trap-acc", "0.5")):
        box = card.find_element("class name", cls)
        box.clear()
        box.send_keys(value)
    browser.execute_script(  # what the page shows, sampled in the page every 20 ms
        "window.seen = new Set(); window.tick = setInterval(() => seen.add(document"
        '.querySelector(\'[data-axis="2"] [data-field="prf"]\').textContent), 20)'
    )
    _click(browser, card.find_element("class name", "trap-go"))
    _wait(lambda: _axis_value(browser, 2, "prf") == str(target), 10, "the target")
    shown = browser.execute_script("clearInterval(tick); return [...seen]")
    assert len([v for v in shown if v not in (before, str(target))]) >= 3  # it moved
    _shot(browser, "panel-axes.png", "axes")
    assert axis2()["prf_pos"] == float(target)


def test_the_scope_csv_holds_every_sample_the_recorder_took(
    browser: Any, endpoint_conn: client.Attached
) -> None:
    # the signals put in their box by a script: typed, their 79 characters cost the browser
    # a third of a second (a key event each); the box's value is what the page reads either way
    box = browser.find_element("id", "scope-signals")
    browser.execute_script("arguments[0].value = arguments[1]", box, ",".join(SIGNALS))
    tid = endpoint_conn.call("trace_start", SIGNALS)  # the test's own recorder
    _click(browser, browser.find_element("id", "scope-start"))
    endpoint_conn.call("jog", 2, -20.0)
    _wait(lambda: browser.execute_script("return gtecat.scope.rows.length") > 300, 15, "samples")
    _click(browser, browser.find_element("id", "scope-stop"))
    _wait(lambda: browser.execute_script("return !gtecat.scope.running"), 5, "the stop")
    endpoint_conn.call("stop", 2)
    _shot(browser, "panel-scope.png", "scope")
    ours = endpoint_conn.call("trace_read", tid, 0)["rows"]
    endpoint_conn.call("trace_stop", tid)
    text = browser.execute_script("return gtecat.scopeCsv()")
    table = list(csv.reader(io.StringIO(text)))
    assert table[0] == ["time_ms", *SIGNALS]
    page = [[float(v) for v in r] for r in table[1:]]
    times = [r[0] for r in page]
    steps = {round(b - a, 6) for a, b in itertools.pairwise(times)}
    assert steps == {1.0}  # one row per 1 ms cycle: none dropped, none decimated
    by_time = {r[0]: r[1:] for r in ours}
    common = [r for r in page if r[0] in by_time]
    assert len(common) > 300
    assert all(r[1:] == by_time[r[0]] for r in common)
    assert any(r[SIGNALS.index("axis2.vel") + 1] != 0 for r in common)  # it saw the jog


def test_jog_moves_with_control_and_does_nothing_read_only(
    browser: Any, panels: dict[str, Any], endpoint_conn: client.Attached
) -> None:
    """The module's last test in the browser: it leaves the read-only page in the tab (the
    control page loaded again would cost the browser another page)."""

    def axis1() -> dict[str, Any]:
        snap = endpoint_conn.call("snapshot")
        return dict(zip(snap["axis_fields"], snap["axes"][0], strict=True))

    before = axis1()["prf_pos"]
    card = browser.find_element("css selector", '[data-axis="1"]')
    _click(browser, card.find_element("class name", "jog-plus"))
    _wait(lambda: axis1()["prf_pos"] > before + 100, 10, "the jog")
    _click(browser, card.find_element("class name", "stop"))
    _wait(lambda: not axis1()["sts"] & 0x400, 20, "axis 1 at rest")  # table 6-2 bit 10
    # the read-only panel's page: no jog buttons, and a jog sent anyway is refused
    _show(browser, panels["readonly"])
    assert not browser.find_element("css selector", '[data-axis="1"] .jog-plus').is_displayed()
    before = axis1()["prf_pos"]
    err = browser.execute_async_script(
        "const done = arguments[0];"
        "gtecat.ask('jog', 1, 50).then(() => done('accepted'), (e) => done(String(e)));"
    )
    assert "read-only" in err
    # this page updates too, and over the 300 cycles it sees go by the refused jog moves
    # nothing (waited for by the snapshots' own cycle count: the page's count of snapshots
    # starts again every second, and a loaded machine may deliver none for a while)
    seen = browser.execute_script("return gtecat.snap.cycles")
    _wait(
        lambda: browser.execute_script("return gtecat.snap.cycles") >= seen + 300,
        10,
        "the read-only page's next snapshots",
    )
    assert axis1()["prf_pos"] == before


def test_a_request_without_the_token_gets_403(panels: dict[str, Any]) -> None:
    url = panels["readonly"]
    base = url[: url.index("?")]
    for path in ("", "static/panel.js", "ws", "scope.csv"):
        with pytest.raises(urllib.error.HTTPError) as e:
            urllib.request.urlopen(base + path, timeout=5)
        assert e.value.code == 403
    with pytest.raises(urllib.error.HTTPError) as e:
        urllib.request.urlopen(base + "?token=wrong", timeout=5)
    assert e.value.code == 403
    with urllib.request.urlopen(url, timeout=5) as r:
        assert r.status == 200 and b"gtecat panel" in r.read()


@pytest.mark.long
def test_faults_from_the_panel(browser: Any, endpoint_conn: client.Attached) -> None:
    """The fourth way in: a fault typed as on the command line, injected, listed, cleared."""
    spec = browser.find_element("id", "fault-spec")
    spec.clear()
    spec.send_keys("drive_fault axis=1 code=0x2310 after_ms=100000")
    _click(browser, browser.find_element("id", "fault-inject"))
    _wait(lambda: "fault" in browser.find_element("id", "fault-msg").text, 10, "the injection")
    listed = endpoint_conn.call("fault_list")
    assert [f["kind"] for f in listed] == ["drive_fault"] and listed[0]["state"] == "armed"
    _wait(lambda: "0x2310" in browser.find_element("id", "fault-table").text, 10, "the list")
    _click(browser, browser.find_element("id", "fault-clear"))
    _wait(lambda: endpoint_conn.call("fault_list") == [], 10, "the clear")
