"""``gtecat panel``: a local web page over a running gtecat's inspection endpoint.

One aiohttp application (HTTP and websockets in one dependency, the ``panel`` extra)
serves the page (plain HTML/CSS/JS shipped in the package: no CDN, works offline) and one
websocket per browser.  The server holds three connections to the endpoint: one receives
:func:`~gtecat.inspect.ops.snapshot` pushed at :data:`RATE_HZ` and sends each to every
browser, one reads the scope's recorder while it runs, one runs what a browser asks
(layout, log, object dictionary, and with ``--control`` the commands of
:data:`gtecat.inspect.ops.CONTROL`).  Any number of browsers share the one subscription,
so a second browser costs the watched application nothing more.

Security: binds 127.0.0.1; every request (page, assets, websocket) must carry the random
token of the printed URL (``?token=``) or the cookie the page sets, else 403; the Host
header must name this machine's loopback (a web page elsewhere cannot reach it through a
DNS name).  Read-only unless ``--control``: the server refuses a command, whatever the page
sends.

The scope records with :class:`gtecat.controller.recorder.Recorder` in the watched
process, every cycle, and the page receives every row: the drawing decimates (min/max per
pixel), the CSV export holds every sample.
"""

from __future__ import annotations

import asyncio
import contextlib
import json
import secrets
import threading
from dataclasses import dataclass, field
from importlib import resources
from typing import Any

from ..errors import BusError, ParameterError
from .client import Attached
from .ops import CONTROL

#: snapshots per second sent to the browsers
RATE_HZ = 25
#: what a browser may ask without --control
READ_OPS = frozenset(
    {
        "info",
        "layout",
        "log",
        "slaves",
        "pdos",
        "sdos",
        "sdo_upload",
        "sdo_entry",
        "data",
        "fault_list",
    }
)
CONTROL_OPS = CONTROL | {"sdo_write", "set_input"}
#: scope rows kept for the page at most (about 10 minutes at 1 ms)
SCOPE_MAX_ROWS = 600_000


@dataclass
class PanelState:
    """What the panel server shares between its poll thread and the browsers."""

    token: str
    control: bool
    poll: Attached  # the snapshots' subscription
    command: Attached  # what browsers ask
    scope: Attached  # the scope's recorder (its traces belong to this connection)
    title: str = ""
    #: each browser's websocket -> its queue of messages (one writer each keeps the order)
    clients: dict[Any, asyncio.Queue[str]] = field(default_factory=dict)
    last: str = ""  # the last snapshot message sent (a new browser starts with it)
    scope_id: int | None = None
    scope_names: list[str] = field(default_factory=list)
    scope_next: int = 0
    scope_rows: int = 0
    polls: int = 0
    lock: threading.Lock = field(default_factory=threading.Lock)
    stop: threading.Event = field(default_factory=threading.Event)
    #: why the watched gtecat stopped answering ("" while it answers)
    gone: str = ""


def _asset(name: str) -> bytes:
    return resources.files("gtecat.inspect").joinpath("web", name).read_bytes()


CONTENT_TYPES = {
    ".html": "text/html; charset=utf-8",
    ".js": "text/javascript; charset=utf-8",
    ".css": "text/css; charset=utf-8",
}


def make_app(state: PanelState) -> Any:
    from aiohttp import WSMsgType, web

    @web.middleware
    async def guard(request: web.Request, handler: Any) -> web.StreamResponse:
        host = request.host.rsplit(":", 1)[0].strip("[]")
        if host not in ("127.0.0.1", "localhost", "::1"):
            return web.Response(status=403, text="forbidden: not a loopback host name\n")
        given = request.query.get("token") or request.cookies.get("gtecat_token", "")
        if not secrets.compare_digest(given.encode(), state.token.encode()):
            return web.Response(status=403, text="forbidden: this page needs its token\n")
        resp = await handler(request)
        if request.query.get("token"):
            resp.set_cookie("gtecat_token", state.token, httponly=True, samesite="Strict")
        return resp

    async def page(request: web.Request) -> web.Response:
        html = _asset("index.html").decode().replace("{{TOKEN}}", state.token)
        return web.Response(
            text=html, content_type="text/html", headers={"Cache-Control": "no-store"}
        )

    async def static(request: web.Request) -> web.Response:
        name = request.match_info["name"]
        suffix = name[name.rfind(".") :]
        if "/" in name or suffix not in CONTENT_TYPES:
            raise web.HTTPNotFound()
        try:
            body = _asset(name)
        except FileNotFoundError:
            raise web.HTTPNotFound() from None
        return web.Response(body=body, headers={"Content-Type": CONTENT_TYPES[suffix]})

    async def scope_csv(request: web.Request) -> web.Response:
        """The scope's samples as the recorder holds them (every cycle since its start)."""
        tid = state.scope_id
        if tid is None:
            return web.Response(status=404, text="no scope running\n")
        data = await asyncio.to_thread(_call, state, state.scope, "trace_read", tid, 0)
        lines = [",".join(["time_ms", *data["names"]])]
        lines += [
            ",".join(f"{v:.6g}" if i else f"{v:.3f}" for i, v in enumerate(r)) for r in data["rows"]
        ]
        return web.Response(text="\n".join(lines) + "\n", content_type="text/csv")

    async def ws(request: web.Request) -> web.WebSocketResponse:
        sock = web.WebSocketResponse(heartbeat=20)
        await sock.prepare(request)
        hello = {
            "type": "hello",
            "control": state.control,
            "title": state.title,
            "rate_hz": RATE_HZ,
            "scope": {"names": state.scope_names} if state.scope_id is not None else None,
        }
        await sock.send_str(json.dumps(hello))
        queue: asyncio.Queue[str] = asyncio.Queue()
        if state.last:
            queue.put_nowait(state.last)
        state.clients[sock] = queue

        async def writer() -> None:
            while True:
                await sock.send_str(await queue.get())

        task = asyncio.create_task(writer())
        try:
            async for msg in sock:
                if msg.type != WSMsgType.TEXT:
                    continue
                reply = await asyncio.to_thread(_browser_request, state, msg.data)
                queue.put_nowait(json.dumps(reply))
        finally:
            state.clients.pop(sock, None)
            task.cancel()
        return sock

    app = web.Application(middlewares=[guard])
    app.router.add_get("/", page)
    app.router.add_get("/static/{name}", static)
    app.router.add_get("/scope.csv", scope_csv)
    app.router.add_get("/ws", ws)
    return app


def _call(state: PanelState, conn: Attached, op: str, *args: Any) -> Any:
    return conn.call(op, *args)


def _browser_request(state: PanelState, text: str) -> dict[str, Any]:
    """One request of a page: {"id", "op", "args"} -> {"type": "reply", "id", ...}."""
    rid = None
    try:
        msg = json.loads(text)
        rid = msg.get("id")
        op = str(msg.get("op", ""))
        args = list(msg.get("args") or [])
        if op in CONTROL_OPS and not state.control:
            raise ParameterError(
                f"{op}: this panel is read-only (start it with --control to change the machine)"
            )
        if op == "scope_start":
            result = _scope_start(state, [str(a) for a in args[0]])
        elif op == "scope_stop":
            result = _scope_stop(state)
        elif op == "sdo_write":
            result = _sdo_write(state, *args)
        elif op in READ_OPS or op in CONTROL_OPS:
            result = state.command.call(op, *args)
        else:
            raise ParameterError(f"the panel does not offer {op!r}")
        return {"type": "reply", "id": rid, "ok": True, "result": result}
    except Exception as e:
        return {"type": "reply", "id": rid, "ok": False, "error": str(e) or type(e).__name__}


def _sdo_write(
    state: PanelState, slave: int, index: int, sub: int, text: str, type_name: str
) -> Any:
    from ..cli.bus_cmd import FROM_DICTIONARY, _encode

    kind = FROM_DICTIONARY.get(str(type_name))
    if kind is None:
        raise ParameterError(f"cannot write a {type_name} from the panel (give a number type)")
    data = _encode(str(text), kind)
    return state.command.call("sdo_download", int(slave), int(index), int(sub), data.hex())


def _scope_start(state: PanelState, names: list[str]) -> dict[str, Any]:
    if not names:
        raise ParameterError("pick at least one signal")
    with state.lock:
        if state.scope_id is not None:
            with contextlib.suppress(BusError):
                state.scope.call("trace_stop", state.scope_id)
        state.scope_id = state.scope.call("trace_start", names)
        state.scope_names = names
        state.scope_next = 0
        state.scope_rows = 0
    msg = json.dumps({"type": "scope_start", "names": names})
    _broadcast(state, msg)
    return {"names": names}


def _scope_stop(state: PanelState) -> dict[str, Any]:
    with state.lock:
        tid, state.scope_id = state.scope_id, None
        if tid is not None:
            _scope_read(state, tid)  # the last rows first
            with contextlib.suppress(BusError):
                state.scope.call("trace_stop", tid)
    _broadcast(state, json.dumps({"type": "scope_stop", "rows": state.scope_rows}))
    return {"rows": state.scope_rows}


def _scope_read(state: PanelState, tid: int) -> None:
    data = state.scope.call("trace_read", tid, state.scope_next)
    rows = data["rows"]
    if rows:
        state.scope_next += len(rows)
        state.scope_rows += len(rows)
        _broadcast(state, json.dumps({"type": "scope", "rows": rows}))


_LOOP: asyncio.AbstractEventLoop | None = None


def _broadcast(state: PanelState, text: str) -> None:
    """``text`` to every browser, in order (each browser's queue, from any thread)."""
    loop = _LOOP
    if loop is None:
        return
    for queue in list(state.clients.values()):
        loop.call_soon_threadsafe(queue.put_nowait, text)


def poll_loop(state: PanelState) -> None:
    """Snapshots pushed by the endpoint at RATE_HZ, to every browser."""
    try:
        for snap in state.poll.subscribe("snapshot", 1000 / RATE_HZ):
            if state.stop.is_set():
                return
            snap["type"] = "snap"
            state.last = json.dumps(snap, separators=(",", ":"))
            state.polls += 1
            _broadcast(state, state.last)
    except (BusError, OSError, ValueError) as e:
        state.gone = str(e) or type(e).__name__
        _broadcast(state, json.dumps({"type": "gone", "error": state.gone}))
        state.stop.set()


def scope_loop(state: PanelState) -> None:
    """The scope's new rows, while it runs, at RATE_HZ (from the recorder in the watched
    process: every cycle's sample)."""
    period = 1.0 / RATE_HZ
    while not state.stop.wait(period):
        try:
            with state.lock:
                if state.scope_id is not None:
                    _scope_read(state, state.scope_id)
        except BusError:
            return


def serve(socket_path: str, *, control: bool, port: int, title: str, ready: Any = None) -> str:
    """Run the panel until interrupted or until the watched gtecat ends; ``ready(url)`` is
    called once it listens.  Returns why the watched gtecat stopped answering ("" when
    the panel was interrupted)."""
    from aiohttp import web

    global _LOOP
    state = PanelState(
        token=secrets.token_urlsafe(18),
        control=control,
        poll=Attached(socket_path),
        command=Attached(socket_path),
        scope=Attached(socket_path),
        title=title,
    )

    async def main() -> None:
        global _LOOP
        _LOOP = asyncio.get_running_loop()
        runner = web.AppRunner(make_app(state), access_log=None)
        await runner.setup()
        site = web.TCPSite(runner, "127.0.0.1", port)
        await site.start()
        real_port = site._server.sockets[0].getsockname()[1]  # type: ignore[union-attr]
        for loop in (poll_loop, scope_loop):
            threading.Thread(target=loop, args=(state,), daemon=True).start()
        url = f"http://127.0.0.1:{real_port}/?token={state.token}"
        if ready is not None:
            ready(url)
        try:
            # woken by the event itself (a thread waits on it), not by looking every 0.2 s:
            # the panel ends as soon as it is asked to or the watched gtecat ends
            await _LOOP.run_in_executor(None, state.stop.wait)
        finally:
            state.stop.set()  # cancelled (Ctrl-C): the waiting thread ends too
            for sock in list(state.clients):
                with contextlib.suppress(Exception):
                    await sock.close()
            await runner.cleanup()

    try:
        asyncio.run(main())
    finally:
        _LOOP = None
        state.stop.set()
        for conn in (state.poll, state.command, state.scope):
            conn.close()
    return state.gone


__all__ = ["RATE_HZ", "PanelState", "make_app", "serve"]
