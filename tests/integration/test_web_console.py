#!/usr/bin/python3
"""`motwin serve --web`: the console's HTTP files and its JSON protocol over a WebSocket, spoken by
a script (python3-websocket) as docs/web-console.md describes it, checked against what a TMCL host
on the same serve sees over TCP."""

import os
import sys

sys.dont_write_bytecode = True  # no __pycache__ in the source tree
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

import motwin_harness as mh  # noqa: E402
from motwin_harness import TcpClient, TempDir, check, check_equal, run_tests  # noqa: E402
import web_harness as wh  # noqa: E402

MAX_CURRENT = 11  # TMCM-1636 axis parameter: 0..60000 mA, RWEX


def test_http_files_and_loopback(motwin):
    with TempDir() as state, wh.WebServer(motwin, state).start() as server:
        # Bound to 127.0.0.1 only (7F000001 in /proc/net/tcp's byte order).
        check_equal(wh.listening_addresses(server.web_port), ["0100007F"], "listening address of --web 127.0.0.1:0")
        status, content_type, body = wh.http_get(server.url("/"))
        check_equal(status, 200, "GET /")
        check(content_type.startswith("text/html"), f"GET / content type {content_type!r}")
        check(b"app.js" in body, "the page loads app.js")
        for path in ("/app.js", "/style.css", "/vendor/uPlot.iife.min.js"):
            status, _, body = wh.http_get(server.url(path))
            check_equal(status, 200, f"GET {path}")
            check(len(body) > 0, f"GET {path} is empty")
        check_equal(wh.http_get(server.url("/nothing-here"))[0], 404, "GET of an unknown path")
        check_equal(wh.http_get(server.url("/../CMakeLists.txt"))[0], 404, "GET outside the page")
        check_equal(wh.http_get(server.url("/favicon.ico"))[0], 204, "GET /favicon.ico")
        server.stop()


def test_parameters_through_the_modules_checks(motwin):
    wh.require_websocket()
    with TempDir() as state, wh.WebServer(motwin, state).start() as server, \
            TcpClient(server.tcp_port) as tmcl, server.console() as console:
        listing = console.ask("list")
        check_equal(listing["ok"], True, "list")
        module = listing["modules"][0]
        check_equal((module["name"], module["protocol"], module["motors"]), ("tmcm-1636", "tmcl", 1),
                    "the listed module")
        row = next(p for p in module["sections"][0]["parameters"] if p["number"] == MAX_CURRENT)
        check_equal((row["min"], row["max"], row["unit"], row["access"]), (0, 60000, "mA", "RWEX"), "row of AP 11")

        before = tmcl.gap(MAX_CURRENT)
        check_equal(console.ask("get", module=0, kind="axis", number=MAX_CURRENT, axis=0)["value"], before,
                    "get = GAP over TCP")
        # Out of range: the module's own status, and nothing changes.
        reply = console.ask("set", module=0, kind="axis", number=MAX_CURRENT, axis=0, value=60001)
        check_equal((reply["ok"], reply["status"]), (False, 4), "set 60001: status 4 (invalid value)")
        check_equal(tmcl.gap(MAX_CURRENT), before, "AP 11 after a refused set")
        # Read-only: refused by the module.
        reply = console.ask("set", module=0, kind="axis", number=0, axis=0, value=1)
        check(reply["ok"] is False and reply["status"] != 100, f"set of read-only AP 0: {reply!r}")
        # In range: a TMCL host sees the new value.
        reply = console.ask("set", module=0, kind="axis", number=MAX_CURRENT, axis=0, value=1500)
        check_equal((reply["ok"], reply["status"]), (True, 100), "set 1500")
        check_equal(tmcl.gap(MAX_CURRENT), 1500, "AP 11 over TCP after the console set it")
        # And a TMCL host's change shows in the console.
        tmcl.sap(MAX_CURRENT, 1700)
        check_equal(console.ask("get", module=0, number=MAX_CURRENT)["value"], 1700, "get after SAP over TCP")

        reply = console.ask("tmcl", module=0, text="SAP 11, 0, 1800")
        check_equal((reply["ok"], reply["instruction"]), (True, "SAP 11, 0, 1800"), "tmcl SAP")
        check_equal(tmcl.gap(MAX_CURRENT), 1800, "AP 11 after the console's SAP")
        check_equal(console.ask("tmcl", module=0, text="136 0")["version"], "1636V109", "version string")
        check_equal(console.ask("store", module=0, number=MAX_CURRENT)["status"], 100, "store (STAP)")
        server.stop()


MAX_VELOCITY = 4  # TMCM-3216 TMCL axis parameter, per motor: 0..16777215 pps


def test_three_motors(motwin):
    """The TMCM-3216's TMCL firmware: AP 4 of each motor through the console's `axis` field, checked
    against GAP/SAP of the same motor over TMCL/TCP; a motor beyond the last refused."""
    wh.require_websocket()
    with TempDir() as state, wh.WebTmcm3216TmclServer(motwin, state).start() as server, \
            TcpClient(server.tcp_port) as tmcl, server.console() as console:
        module = console.ask("list")["modules"][0]
        check_equal((module["name"], module["protocol"], module["firmware"], module["motors"]),
                    ("tmcm-3216", "tmcl", "3216V100", 3), "the listed module")
        before = [tmcl.gap(MAX_VELOCITY, motor) for motor in range(3)]
        # The console writes motor 2; a TMCL host reads it there, motors 0 and 1 as they were.
        reply = console.ask("set", module=0, kind="axis", number=MAX_VELOCITY, axis=2, value=12345)
        check_equal((reply["ok"], reply["status"]), (True, 100), "set AP 4 of motor 2")
        check_equal([tmcl.gap(MAX_VELOCITY, motor) for motor in range(3)], [before[0], before[1], 12345],
                    "GAP 4 of motors 0..2 over TCP after the console's set")
        # A TMCL host writes motor 1; the console reads it there.
        tmcl.sap(MAX_VELOCITY, 23456, motor=1)
        check_equal([console.ask("get", module=0, number=MAX_VELOCITY, axis=motor)["value"] for motor in range(3)],
                    [before[0], 23456, 12345], "get of AP 4 of motors 0..2 after SAP 4, 1 over TCP")
        # Subscribed per motor: each item echoes its axis and has its motor's value.
        reply = console.ask("subscribe", rate_hz=25, items=[
            {"module": 0, "kind": "axis", "number": MAX_VELOCITY, "axis": motor} for motor in range(3)])
        check_equal(reply["ok"], True, "subscribe to AP 4 of each motor")
        values = console.next_update()["values"]
        check_equal([(v["axis"], v["value"]) for v in values], [(0, before[0]), (1, 23456), (2, 12345)],
                    "the update's values per motor")
        console.ask("unsubscribe")
        # Motor 3: the console refuses it, naming the motors; the firmware answers a host status 4.
        reply = console.ask("set", module=0, number=MAX_VELOCITY, axis=3, value=1)
        check_equal((reply["ok"], reply.get("error")),
                    (False, '"axis": no motor 3 on tmcm-3216 (3 motors: 0..2)'), "set of motor 3")
        check_equal(tmcl.request(mh.GAP, MAX_VELOCITY, 3).status, 4, "GAP 4, 3 over TCP: invalid value")
        server.stop()


def test_subscription_updates(motwin):
    wh.require_websocket()
    with TempDir() as state, wh.WebServer(motwin, state).start() as server, \
            TcpClient(server.tcp_port) as tmcl, server.console() as console:
        reply = console.ask("subscribe", rate_hz=25, items=[{"module": 0, "kind": "axis", "number": MAX_CURRENT},
                                                          {"module": 0, "kind": "global", "number": 77, "bank": 0}])
        check_equal((reply["ok"], reply["items"]), (True, 2), "subscribe")
        times = []
        for _ in range(10):
            update = console.next_update()
            check_equal(len(update["values"]), 2, "values per update")
            check_equal(update["values"][0]["number"], MAX_CURRENT, "first item")
            check("value" in update["values"][1], f"second item has a value: {update!r}")
            times.append(update["sim_time_us"])
        check(all(b > a for a, b in zip(times, times[1:])), f"simulated time advances: {times!r}")
        # A change by a TMCL host arrives in a later update.
        tmcl.sap(MAX_CURRENT, 2222)
        for _ in range(50):
            if console.next_update()["values"][0].get("value") == 2222:
                break
        else:
            raise mh.TestFailure("the subscribed value never showed the SAP over TCP")
        check_equal(console.ask("unsubscribe")["ok"], True, "unsubscribe")
        server.stop()


def test_garbage_leaves_connection_and_module_intact(motwin):
    wh.require_websocket()
    with TempDir() as state, wh.WebServer(motwin, state).start() as server, \
            TcpClient(server.tcp_port) as tmcl, server.console() as console:
        for garbage in ("{not json", "[1, 2, 3]", "\u00ff\u0000", "{\"id\": 5}", "{\"id\": 6, \"op\": 7}"):
            console.send_text(garbage)
        replies = [console._receive_one(wh.REPLY_TIMEOUT) for _ in range(5)]
        check(all(r["ok"] is False and r["error"] for r in replies), f"error replies to garbage: {replies!r}")
        check_equal([r["id"] for r in replies], [None, None, None, 5, 6], "ids of the error replies")
        check_equal(console.ask("fly")["ok"], False, "unknown op")
        console.send_text(bytes(range(256)), opcode=wh.websocket.ABNF.OPCODE_BINARY)
        check_equal(console._receive_one(wh.REPLY_TIMEOUT)["ok"], False, "binary frame")
        # The session and the module still work.
        check_equal(console.ask("get", module=0, number=MAX_CURRENT)["ok"], True, "get after garbage")
        check_equal(tmcl.gap(MAX_CURRENT), console.ask("get", module=0, number=MAX_CURRENT)["value"], "TMCL over TCP after garbage on the console")
        server.stop()


def test_token_and_non_loopback(motwin):
    wh.require_websocket()
    with TempDir() as state:
        refused = mh.Server(motwin, state, extra_args=["--web", "0.0.0.0:0"])
        check_equal(refused.start_expect_failure(), 2, "--web 0.0.0.0 without a token")
        check("--web-token" in refused.stderr_text(), f"the error names --web-token: {refused.stderr_text()!r}")
        with wh.WebServer(motwin, state, extra_args=["--web-token", "s3cret"]).start() as server:
            for query in ("", "?token=wrong"):
                try:
                    server.console(query).close()
                except wh.websocket.WebSocketException:
                    pass
                else:
                    raise mh.TestFailure(f"a WebSocket with {query!r} was accepted")
            with server.console("?token=s3cret") as console:
                check_equal(console.ask("list")["ok"], True, "list with the token")
            server.stop()


def test_canopen_node(motwin):
    wh.require_websocket()
    with TempDir() as state, wh.WebCanServer(motwin, state).start() as server, server.console() as console:
        module = console.ask("list")["modules"][0]
        check_equal((module["protocol"], module["node_id"]), ("canopen", 1), "the listed node")
        check_equal(console.ask("get", module=0, index=0x1008, sub=0)["text"], "TMCM-3216", "1008 by SDO")
        reply = console.ask("set", module=0, index=0x1000, sub=0, value=1)
        check_equal((reply["ok"], reply["abort"]), (False, "0x06010002"), "write of read-only 1000")
        check_equal(console.ask("sdo_write", module=0, index=0x1017, sub=0, value=20)["ok"], True, "1017 = 20 ms")
        check_equal(console.ask("nmt", module=0, command="start")["ok"], True, "NMT start")
        for _ in range(200):
            if console.ask("list")["modules"][0].get("nmt_state") == "operational":
                break
            console.ask("get", module=0, index=0x1017)  # a round trip: time passes
        else:
            raise mh.TestFailure("the node never reported operational by heartbeat")
        check_equal(console.ask("nmt_state")["nodes"], [{"module": 0, "node_id": 1, "nmt_state": "operational"}],
                    "nmt_state: the state without the tables")
        server.stop()


if __name__ == "__main__":
    run_tests([test_http_files_and_loopback, test_parameters_through_the_modules_checks, test_three_motors,
               test_subscription_updates,
               test_garbage_leaves_connection_and_module_intact, test_token_and_non_loopback, test_canopen_node])
