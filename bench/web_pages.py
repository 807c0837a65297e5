#!/usr/bin/python3
"""Open web-console pages without a browser, for bench_web_pages (docs/benchmarks.md).

Each page opens the WebSocket sessions web/site/app.js opens with the Parameters view shown and the
Scope running, and sends what they send:
  - the page's session: "list", then "subscribe" of the first 64 readable rows of the module's
    table (app.js subscribeShown: MAX_LIVE_ROWS, at LIVE_RATE_HZ = 20; a CANopen node: 16 rows at
    10 updates/s);
  - the Scope's session (app.js startScope): "subscribe" of the picked curves at the chosen rate
    (--curves, --scope-rate; the Scope's highest rate is 100 updates/s, a CANopen node's 20).
The Scope's curves are the first readable rows. Every message is read and parsed as JSON, as the
page does. Prints "ready SESSIONS" once every session has had its subscription's reply and a
first update; on SIGTERM prints "updates PAGE_RATE SCOPE_RATE" (updates per second and session of
each kind, since ready) and exits.

    web_pages.py PORT [--pages 4] [--module 0] [--curves 4] [--scope-rate 100]
"""

import argparse
import json
import os
import signal
import sys
import threading
import time

import websocket  # python3-websocket

MAX_LIVE_ROWS = 64
LIVE_RATE_HZ = 20
CANOPEN_MAX_LIVE_ROWS = 16
CANOPEN_LIVE_RATE_HZ = 10


def rows_of(module):
    """The readable rows of the module's table, in the order app.js rowsOf() lists them, as the
    items of a subscription."""
    rows = []
    for section in module["sections"]:
        if section["kind"] == "objects":
            for entry in section["objects"]:
                if entry["access"] != "wo":
                    rows.append({"module": module["module"], "index": entry["index"], "sub": entry["sub"]})
            continue
        for parameter in section["parameters"]:
            if "R" not in parameter["access"]:
                continue
            if section["kind"] == "axis":
                rows.append({"module": module["module"], "kind": "axis", "number": parameter["number"], "axis": 0})
            else:
                rows.append({"module": module["module"], "kind": "global", "number": parameter["number"],
                             "bank": section["bank"]})
    return rows


class Session:
    def __init__(self, port, kind):
        self.kind = kind
        self.socket = websocket.create_connection(f"ws://127.0.0.1:{port}/ws", subprotocols=["motwin"], timeout=30)
        self.updates = 0
        self.subscribed = threading.Event()
        self.first_update = threading.Event()

    def ask(self, message):
        """A request and its reply, before the session's reading thread starts."""
        self.socket.send(json.dumps(message))
        while True:
            reply = json.loads(self.socket.recv())
            if reply.get("id") == message["id"]:
                return reply

    def subscribe(self, items, rate_hz):
        self.socket.send(json.dumps({"id": 1, "op": "subscribe", "rate_hz": rate_hz, "items": items}))

    def read_forever(self):
        try:
            while True:
                message = json.loads(self.socket.recv())
                if message.get("push") == "update":
                    self.updates += 1
                    self.first_update.set()
                elif message.get("id") == 1:
                    if not message.get("ok"):
                        sys.exit(f"web_pages: subscribe refused: {message}")
                    self.subscribed.set()
        except (websocket.WebSocketException, OSError):
            pass


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("port", type=int)
    parser.add_argument("--pages", type=int, default=4)
    parser.add_argument("--module", type=int, default=0)
    parser.add_argument("--curves", type=int, default=4)
    parser.add_argument("--scope-rate", type=float, default=100)
    options = parser.parse_args()

    sessions = []
    for _ in range(options.pages):
        page = Session(options.port, "page")
        listing = page.ask({"id": 100, "op": "list"})
        module = listing["modules"][options.module]
        rows = rows_of(module)
        canopen = module["protocol"] == "canopen"
        page.subscribe(rows[:CANOPEN_MAX_LIVE_ROWS if canopen else MAX_LIVE_ROWS],
                       CANOPEN_LIVE_RATE_HZ if canopen else LIVE_RATE_HZ)
        scope = Session(options.port, "scope")
        scope.subscribe(rows[:options.curves], options.scope_rate)
        sessions += [page, scope]
    for session in sessions:
        threading.Thread(target=session.read_forever, daemon=True).start()
    for session in sessions:
        if not session.subscribed.wait(30) or not session.first_update.wait(30):
            sys.exit("web_pages: no subscription reply or update within 30 s")

    start = time.monotonic()
    counted = {id(session): session.updates for session in sessions}
    print(f"ready {len(sessions)}", flush=True)

    def finish(*_):
        elapsed = max(time.monotonic() - start, 1e-9)
        rates = {}
        for kind in ("page", "scope"):
            chosen = [s for s in sessions if s.kind == kind]
            total = sum(s.updates - counted[id(s)] for s in chosen)
            rates[kind] = total / elapsed / max(len(chosen), 1)
        print(f"updates {rates['page']:.1f} {rates['scope']:.1f}", flush=True)
        os._exit(0)

    signal.signal(signal.SIGTERM, finish)
    while True:
        signal.pause()


if __name__ == "__main__":
    main()
