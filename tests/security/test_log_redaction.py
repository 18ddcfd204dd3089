"""Issue 33, finding 13: log redaction is judged on the decoded query. `GET /login?tok%65n=<token>`
logged in (the server decodes the name) while the access log kept the token (the filter matched
the raw text `token=`). Now no query value of /login reaches the log, and elsewhere no value of a
parameter whose decoded name is a secret."""

from __future__ import annotations

import socket
import time
from collections.abc import Iterator

import httpx
import pytest

from server.api.redaction import redact
from tests.api.conftest import LabServer, start_server, stop_server
from tests.waiting import wait_until


@pytest.fixture(scope="module")
def lab(tmp_path_factory) -> Iterator[LabServer]:
    server = start_server(tmp_path_factory.mktemp("redaction"), {"ROBODOJO_SANDBOX_POOL": "0"})
    yield server
    stop_server(server)


def login_lines(server: LabServer) -> list[str]:
    return [line for line in server.output if "/login" in line or "/live" in line]


def test_an_encoded_token_name_logs_in_and_its_value_is_not_logged(lab):
    _, token = lab.new_user("encoded")
    before = len(login_lines(lab))
    # The name spelt three ways the server decodes to `token`: each one logs in.
    for query in (f"tok%65n={token}", f"%74oken={token}", f"%74%6F%6B%65%6E={token}"):
        answer = httpx.get(f"{lab.url}/login?{query}", follow_redirects=False, timeout=10)
        assert answer.status_code == 303, (query, answer.text)  # the attack did log in
    lines = wait_until(
        lambda: (found := login_lines(lab)[before:]) and len(found) >= 3 and found,
        10,
        "the access log wrote the three logins",
    )
    log = "\n".join(lines)
    assert token not in log, log
    assert log.count("/login?token=***") == 3, log  # written as the server read it


@pytest.mark.parametrize(
    "query",
    [
        "next={value}",  # any parameter of /login, not only the token
        "{value}",  # a token pasted without a name
        "t+oken={value}",  # a name with a `+` (a space, decoded): not plain, still hidden
        "a=1;token={value}",  # `;` between parameters
        "%2574oken={value}",  # encoded twice
        "x'={value}",  # a quote in the query does not end what is read of it
        "tok%65n=%0a{value}",  # an encoded new line before the value
    ],
)
def test_no_query_value_of_login_reaches_the_log(lab, query):
    value = f"SeCrEt{time.monotonic_ns()}"
    before = len(login_lines(lab))
    httpx.get(f"{lab.url}/login?{query.format(value=value)}", timeout=10)
    lines = wait_until(lambda: login_lines(lab)[before:], 10, "the access log wrote the request")
    assert value not in "\n".join(lab.output), lines


def test_a_websocket_token_under_an_encoded_name_is_not_logged(lab):
    secret = f"WsSecret{time.monotonic_ns()}"
    port = int(lab.url.rsplit(":", 1)[1])
    with socket.create_connection(("127.0.0.1", port), timeout=10) as sock:
        sock.sendall(
            f"GET /api/runs/nope/live?t%6Fken={secret}&x=1 HTTP/1.1\r\nHost: x\r\n"
            "Upgrade: websocket\r\nConnection: Upgrade\r\nSec-WebSocket-Version: 13\r\n"
            "Sec-WebSocket-Key: dGhlIHNhbXBsZSBub25jZQ==\r\n\r\n".encode()
        )
        sock.recv(1000)
    wait_until(
        lambda: any("/api/runs/nope/live?" in line for line in lab.output),
        10,
        "the error log wrote the websocket's path",
    )
    log = "\n".join(lab.output)
    assert secret not in log
    assert "/api/runs/nope/live?token=***&x=1" in log, log[-2000:]


def test_redaction_keeps_what_is_not_secret():
    assert redact('127.0.0.1:5 - "GET /api/runs?page=2&state=failed HTTP/1.1" 200') == (
        '127.0.0.1:5 - "GET /api/runs?page=2&state=failed HTTP/1.1" 200'
    )
    assert redact("/api/runs/r1/live?access_%74oken=abc&view=3") == (
        "/api/runs/r1/live?access_token=***&view=3"
    )
    assert redact("/login?next=%2Fadmin&%0aFORGED=1") == "/login?next=***&***=***"
    assert redact("/log%69n/?token=abc") == "/log%69n/?token=***"
