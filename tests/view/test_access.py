"""Access to the live view: loopback needs no token; any other address makes a token that the
page, its updates and STOP all require; STOP is the only action, and only from the page."""

from __future__ import annotations

import asyncio
import urllib.error
import urllib.request

import aiohttp
import pytest

from host.errors import HostError
from host.view import ViewFeed, ViewServer, parse_address
from host.view.server import STOP_REASON


@pytest.fixture
def started():
    """start(host) -> a running server on loopback whose STOP presses land in `stops`; a
    non-loopback host is only the address the user named (the test rebinds it to 127.0.0.1,
    it never leaves loopback)."""
    made = []

    def start(host: str = "127.0.0.1") -> tuple[ViewServer, list[str]]:
        stops: list[str] = []
        feed = ViewFeed()
        server = ViewServer(feed, host, 0, stops.append)
        server.host = "127.0.0.1"
        made.append((server, feed))
        return server.start(), stops

    yield start
    for server, feed in made:
        server.close()
        feed.close()


def request(url: str, method: str = "GET", headers: dict | None = None) -> int:
    req = urllib.request.Request(url, method=method, headers=headers or {})
    try:
        with urllib.request.urlopen(req, timeout=5) as r:
            return r.status
    except urllib.error.HTTPError as e:
        return e.code


def base(server: ViewServer) -> str:
    return f"http://127.0.0.1:{server.port}"


@pytest.mark.parametrize("host", ["127.0.0.1", "127.0.0.2", "::1", "localhost"])
def test_loopback_needs_no_token(host):
    assert ViewServer(ViewFeed(), host).token is None


@pytest.mark.parametrize("host", ["0.0.0.0", "192.168.1.20", "robot-pc.local", "::"])
def test_any_other_address_makes_a_token(host):
    a, b = ViewServer(ViewFeed(), host), ViewServer(ViewFeed(), host)
    assert a.token and len(a.token) >= 20 and a.token != b.token
    assert a.url.endswith(f"/?token={a.token}")


def test_page_and_stop_on_loopback(started):
    server, stops = started()
    assert request(base(server) + "/") == 200
    assert request(base(server) + "/stop", "POST") == 200
    assert stops == [STOP_REASON]


def test_token_is_required_for_page_updates_and_stop(started):
    server, stops = started("0.0.0.0")
    url = base(server)
    assert request(url + "/") == 403
    assert request(url + "/?token=wrong") == 403
    assert request(url + "/stop", "POST") == 403
    assert request(url + "/stop?token=wrong", "POST") == 403
    assert stops == []
    assert request(url + f"/?token={server.token}") == 200
    assert request(url + "/stop", "POST", {"X-View-Token": server.token}) == 200
    assert stops == [STOP_REASON]

    async def updates(query: str) -> int:
        async with aiohttp.ClientSession() as s:
            try:
                async with s.ws_connect(url + "/updates" + query) as ws:
                    await ws.close()
                    return 101
            except aiohttp.WSServerHandshakeError as e:
                return e.status

    assert asyncio.run(updates("")) == 403
    assert asyncio.run(updates(f"?token={server.token}")) == 101


def test_stop_is_the_only_action(started):
    server, stops = started()
    routes = {(r.method, r.resource.canonical) for r in server.app().router.routes()}
    assert routes == {("GET", "/"), ("HEAD", "/"), ("GET", "/updates"), ("HEAD", "/updates"),
                      ("POST", "/stop")}
    url = base(server)
    assert request(url + "/stop") == 405  # a link or a prefetch cannot press it
    assert request(url + "/", "POST") == 405
    for path in ("/drive", "/config", "/stop/", "/updates/x"):
        assert request(url + path, "POST") in (404, 405)
    # another site open in the same browser cannot press it either
    assert request(url + "/stop", "POST", {"Origin": "http://evil.example"}) == 403
    assert stops == []

    async def talk() -> None:  # the page's socket takes "next" and nothing else
        async with aiohttp.ClientSession() as s:
            async with s.ws_connect(url + "/updates") as ws:
                for text in ("stop", '{"drive": [500, 500]}', "STOP"):
                    await ws.send_str(text)
                await ws.send_bytes(b"stop")
                await asyncio.sleep(0.2)

    asyncio.run(talk())
    assert stops == [] and server.stops == 0


def test_no_stop_when_nothing_is_driven():
    feed = ViewFeed(can_stop=False)
    with ViewServer(feed, "127.0.0.1", 0, None) as server:
        assert request(base(server) + "/stop", "POST") == 409
    feed.close()


def test_view_address():
    assert parse_address("8080") == ("127.0.0.1", 8080)
    assert parse_address("0.0.0.0:8080") == ("0.0.0.0", 8080)
    assert parse_address("[::1]:0") == ("::1", 0)
    assert parse_address(":9000") == ("127.0.0.1", 9000)
    for bad in ("host:port", "70000", ""):
        with pytest.raises(HostError):
            parse_address(bad)
