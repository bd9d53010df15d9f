"""The page's web server (aiohttp, on its own thread and event loop): GET / is the page,
GET /updates is its WebSocket of updates, POST /stop is the STOP button. Nothing else.

Bound to loopback unless the user names another address; then every request must carry the
token printed at start (?token= on the page's address; the page passes it on).
"""

from __future__ import annotations

import asyncio
import contextlib
import hmac
import ipaddress
import json
import secrets
import threading
import time
from collections.abc import Awaitable, Callable
from importlib import resources

from aiohttp import WSMsgType, web

from host.errors import HostError
from host.view.feed import ViewFeed

STOP_REASON = "STOP pressed in the view"


def parse_address(text: str) -> tuple[str, int]:
    """[HOST:]PORT (HOST 127.0.0.1 when left out, PORT 0 = a free one; [::1]:PORT for IPv6)."""
    host, sep, port = text.rpartition(":")
    if not sep:
        host, port = "", text
    host = host.strip("[]") or "127.0.0.1"
    try:
        number = int(port)
    except ValueError:
        raise HostError(f"--view must be [HOST:]PORT, got {text!r}") from None
    if not 0 <= number <= 65535:
        raise HostError(f"--view port must be 0..65535, got {number}")
    return host, number


def is_loopback(host: str) -> bool:
    if host == "localhost":
        return True
    try:
        return ipaddress.ip_address(host).is_loopback
    except ValueError:
        return False


class ViewServer:
    """Serves the page for feed on host:port; on_stop(reason) is the STOP button (None: the
    page has no STOP, as when only a camera is watched). A token is made, and required, when
    host is not a loopback address."""

    def __init__(self, feed: ViewFeed, host: str = "127.0.0.1", port: int = 0,
                 on_stop: Callable[[str], None] | None = None) -> None:
        self.feed, self.host, self.port, self.on_stop = feed, host, port, on_stop
        self.token = None if is_loopback(host) else secrets.token_urlsafe(18)
        self.stops = 0  # STOP presses accepted
        self.connections: list[dict[str, float]] = []  # per page: updates, bytes, seconds
        self._sockets: set[web.WebSocketResponse] = set()
        self._loop = asyncio.new_event_loop()
        self._runner: web.AppRunner | None = None
        self._thread = threading.Thread(target=self._loop.run_forever, name="view-server",
                                        daemon=True)

    @property
    def url(self) -> str:
        host = f"[{self.host}]" if ":" in self.host else self.host
        query = f"?token={self.token}" if self.token else ""
        return f"http://{host}:{self.port}/{query}"

    def app(self) -> web.Application:
        app = web.Application(middlewares=[self._guard])
        app.router.add_get("/", self._page)
        app.router.add_get("/updates", self._updates)
        app.router.add_post("/stop", self._stop)
        app.on_shutdown.append(self._close_pages)
        return app

    # ------------------------------------------------------------------------ life

    def start(self) -> ViewServer:
        self._thread.start()
        try:
            asyncio.run_coroutine_threadsafe(self._start(), self._loop).result(timeout=10)
        except OSError as e:
            self.close()
            raise HostError(f"--view cannot listen on {self.host}:{self.port}: "
                            f"{e.strerror or e}") from None
        return self

    async def _start(self) -> None:
        self._runner = web.AppRunner(self.app(), access_log=None, handle_signals=False)
        await self._runner.setup()
        site = web.TCPSite(self._runner, self.host, self.port)
        await site.start()
        self.port = site._server.sockets[0].getsockname()[1]  # type: ignore[union-attr]

    def close(self) -> None:
        """Let the pages have the last step (up to a second), then close them and stop."""
        deadline = time.monotonic() + 1.0
        while time.monotonic() < deadline and any(
                c["open"] and c["seq"] < self.feed.latest_seq for c in self.connections):
            time.sleep(0.02)
        if self._runner is not None and self._thread.is_alive():
            future = asyncio.run_coroutine_threadsafe(self._runner.cleanup(), self._loop)
            with contextlib.suppress(Exception):  # closing anyway; pages see the socket go
                future.result(timeout=5)
        if self._thread.is_alive():
            self._loop.call_soon_threadsafe(self._loop.stop)
            self._thread.join(timeout=5)
        self._runner = None

    def __enter__(self) -> ViewServer:
        return self.start()

    def __exit__(self, *exc: object) -> None:
        self.close()

    async def _close_pages(self, app: web.Application) -> None:
        """The run is over: tell the pages (they say so), rather than leave them waiting."""
        for ws in list(self._sockets):
            await ws.close(message=b"the run has ended")

    # ------------------------------------------------------------------------ handlers

    @web.middleware
    async def _guard(self, request: web.Request,
                     handler: Callable[[web.Request], Awaitable[web.StreamResponse]]
                     ) -> web.StreamResponse:
        """The token (when one is needed) on every request; STOP only from the page's own
        origin, so another site open in the same browser cannot press it."""
        if self.token is not None:
            given = request.query.get("token") or request.headers.get("X-View-Token") or ""
            if not hmac.compare_digest(given.encode(), self.token.encode()):
                raise web.HTTPForbidden(text="a token is needed: use the address printed at "
                                             "start\n")
        if request.method == "POST":
            origin = request.headers.get("Origin")
            if origin is not None and origin != f"{request.scheme}://{request.host}":
                raise web.HTTPForbidden(text="STOP comes from the page only\n")
        return await handler(request)

    async def _page(self, request: web.Request) -> web.Response:
        page = resources.files("host.view").joinpath("page.html").read_text(encoding="utf-8")
        return web.Response(text=page, content_type="text/html",
                            headers={"Cache-Control": "no-store"})

    async def _stop(self, request: web.Request) -> web.Response:
        if self.on_stop is None:
            raise web.HTTPConflict(text="nothing to stop: no robot is driven\n")
        self.on_stop(STOP_REASON)
        self.stops += 1
        return web.json_response({"stopping": True, "reason": STOP_REASON})

    async def _updates(self, request: web.Request) -> web.WebSocketResponse:
        """Sends an update each time the page asks ("next"), once a newer one exists: a JSON
        text message, then its pictures as binary messages."""
        ws = web.WebSocketResponse(heartbeat=10)
        await ws.prepare(request)
        stats = {"updates": 0.0, "bytes": 0.0, "seconds": 0.0, "seq": 0, "open": True}
        self.connections.append(stats)
        self._sockets.add(ws)
        t0, seq, t_last = time.monotonic(), 0, -1e300
        self.feed.watch(True)
        try:
            async for msg in ws:
                if msg.type != WSMsgType.TEXT or msg.data != "next":
                    continue  # the page asks for updates and nothing else
                update = None
                while update is None and not ws.closed:
                    update = await asyncio.to_thread(self.feed.wait_update, seq, 0.5)
                if update is None:
                    break
                seq = update.seq
                samples = self.feed.samples_since(t_last)
                if samples:
                    t_last = samples[-1][0]
                elapsed = time.monotonic() - t0
                state = dict(update.state, samples=samples, page={
                    "updates_per_s": stats["updates"] / elapsed if elapsed > 0 else None,
                    "bytes_per_s": stats["bytes"] / elapsed if elapsed > 0 else None},
                    can_stop=self.on_stop is not None)
                text = json.dumps(state, allow_nan=False)
                try:
                    await ws.send_str(text)
                    for image in update.images:
                        await ws.send_bytes(image)
                except ConnectionResetError:  # the page went away meanwhile
                    break
                stats["updates"] += 1
                stats["bytes"] += len(text) + sum(len(i) for i in update.images)
                stats["seconds"] = time.monotonic() - t0
                stats["seq"] = seq
        finally:
            self._sockets.discard(ws)
            stats["open"] = False
            self.feed.watch(False)
        return ws
