"""The web console's side of the integration tests: `motwin serve --web 127.0.0.1:0` and a
WebSocket client of its JSON protocol (docs/web-console.md) on Debian's python3-websocket, as a
script would speak it."""

import json
import time
import urllib.error
import urllib.request

import motwin_harness as mh
from canopen_harness import CanServer

try:
    import websocket  # python3-websocket
except ImportError:  # pragma: no cover - the harness reports it
    websocket = None

REPLY_TIMEOUT = 30.0


def require_websocket():
    """Skips the test when Debian's python3-websocket is missing."""
    if websocket is None:
        raise mh.Skipped("python3-websocket is not installed (scripts/install-deps.sh installs it)")


class WebServer(mh.Server):
    """`motwin serve` of a TMCM-1636 with TMCL over TCP and the web console, both on free ports."""

    PORT_ENDPOINTS = {"tmcl-tcp": "tcp_port", "web": "web_port"}

    def __init__(self, motwin, state_dir, extra_args=(), web="127.0.0.1:0", **kwargs):
        super().__init__(motwin, state_dir, extra_args=["--web", web, *extra_args], **kwargs)

    def url(self, path="/"):
        return f"http://127.0.0.1:{self.web_port}{path}"

    def console(self, query=""):
        return ConsoleClient(self.web_port, query)


class WebTmcm3216TmclServer(WebServer):
    """`motwin serve --module tmcm-3216 --firmware tmcl` with TMCL over TCP and the web console:
    a TMCL module of three motors (docs/tmcm-3216-tmcl.md)."""

    BANNER = r"motwin: tmcm-3216 \(3216V100\) eeprom (.+)"

    def __init__(self, motwin, state_dir, extra_args=()):
        super().__init__(motwin, state_dir, module="tmcm-3216", extra_args=["--firmware", "tmcl", *extra_args])


class WebCanServer(CanServer):
    """`motwin serve` of a TMCM-3216 on socketcand with the web console."""

    PORT_ENDPOINTS = dict(CanServer.PORT_ENDPOINTS, web="web_port")

    def __init__(self, motwin, state_dir, extra_args=(), **kwargs):
        super().__init__(motwin, state_dir, extra_args=["--web", "127.0.0.1:0", *extra_args], **kwargs)

    def url(self, path="/"):
        return f"http://127.0.0.1:{self.web_port}{path}"

    def console(self):
        return ConsoleClient(self.web_port)


class WebBusServer(WebServer):
    """`motwin serve --node FIRST_NODE --node tmcm-3216:node-id=1` on a virtual bus (socketcand on a
    free port) with the web console: two modules in the page's picker. BANNER is the first node's;
    the TMCM-3216's (node tmcm-3216-2) is passed over."""

    FIRST_NODE = "tmcm-1636"
    BANNER = r"motwin: node tmcm-1636-1 tmcm-1636 \(1636V1\d\d\) eeprom (.+)"
    PORT_ENDPOINTS = {"can-socketcand": "can_port", "web": "web_port"}

    def __init__(self, motwin, state_dir):
        super().__init__(motwin, state_dir, tcp=False, extra_args=[
            "--node", self.FIRST_NODE, "--node", "tmcm-3216:node-id=1", "--can", "socketcand:127.0.0.1:0"])
        at = self.args.index("--module")
        del self.args[at:at + 2]  # --node instead

    def _parse_line(self, text):
        if self.banner is not None and text.startswith("motwin: node tmcm-3216-2 tmcm-3216 "):
            return False  # the second node's banner
        return super()._parse_line(text)


def http_get(url):
    """(status, content type, body) of a GET; an HTTP error status is returned, not raised."""
    try:
        with urllib.request.urlopen(url, timeout=REPLY_TIMEOUT) as response:
            return response.status, response.headers.get("Content-Type", ""), response.read()
    except urllib.error.HTTPError as error:
        return error.code, error.headers.get("Content-Type", ""), error.read()


def listening_addresses(port):
    """The local addresses (hex as /proc/net/tcp writes them) of sockets listening on `port`."""
    found = []
    for table in ("/proc/net/tcp", "/proc/net/tcp6"):
        try:
            with open(table) as f:
                next(f)
                for line in f:
                    fields = line.split()
                    address, port_hex = fields[1].rsplit(":", 1)
                    if fields[3] == "0A" and int(port_hex, 16) == port:
                        found.append(address)
        except FileNotFoundError:
            pass
    return found


class ConsoleClient:
    """One WebSocket session: requests with ids, replies matched by id, pushes kept apart."""

    def __init__(self, port, query=""):
        self.ws = websocket.create_connection(f"ws://127.0.0.1:{port}/ws{query}", subprotocols=["motwin"],
                                              timeout=REPLY_TIMEOUT)
        self.next_id = 1
        self.pushes = []
        self.replies = {}

    def close(self):
        self.ws.close()

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()

    def _receive_one(self, timeout):
        self.ws.settimeout(timeout)
        message = json.loads(self.ws.recv())
        if "push" in message:
            self.pushes.append(message)
        else:
            self.replies[json.dumps(message.get("id"))] = message
        return message

    def send_text(self, text, opcode=None):
        if opcode is None:
            self.ws.send(text)
        else:
            self.ws.send(text, opcode=opcode)

    def wait_reply(self, request_id, timeout=REPLY_TIMEOUT):
        key = json.dumps(request_id)
        deadline = time.monotonic() + timeout
        while key not in self.replies:
            remaining = deadline - time.monotonic()
            mh.check(remaining > 0, f"no reply to request {request_id} within {timeout} s")
            self._receive_one(remaining)
        return self.replies.pop(key)

    def ask(self, op, **fields):
        request_id = self.next_id
        self.next_id += 1
        self.ws.send(json.dumps(dict(fields, id=request_id, op=op)))
        return self.wait_reply(request_id)

    def next_update(self, timeout=REPLY_TIMEOUT):
        deadline = time.monotonic() + timeout
        while True:
            for i, push in enumerate(self.pushes):
                if push["push"] == "update":
                    return self.pushes.pop(i)
            remaining = deadline - time.monotonic()
            mh.check(remaining > 0, f"no update push within {timeout} s")
            self._receive_one(remaining)
