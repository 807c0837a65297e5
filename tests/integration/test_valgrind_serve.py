#!/usr/bin/python3
"""The server's start/stop path under valgrind's memcheck: `motwin serve` for a TMCM-1636 (TCP
and pty), a TMCM-142 (TCP and pty, binary and ASCII) and a TMCM-3216 (socketcand, SLCAN over TCP
and SLCAN on a pty), each started, asked a request on each kind of endpoint (GAP 43 = 4000;
GAP 4 = 13743895 and `AGAP 4, 0`; an SDO upload of 1000 = FFFF0192), then stopped with SIGTERM.
Any invalid access, use of uninitialised memory or definite/indirect leak makes valgrind exit
with status 99 instead of motwin's 0.

Skipped, visibly (`skip ...` lines, exit status 77: CTest lists the script as "Skipped"), when
valgrind is not installed (scripts/install-deps.sh installs it) or the binary is built with
AddressSanitizer (the two do not run together; the ASan build checks leaks with LSan instead).
"""

import os
import shutil
import subprocess
import sys

sys.dont_write_bytecode = True  # no __pycache__ in the source tree
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

from can_bus_harness import BusServer  # noqa: E402
from client_harness import (  # noqa: E402
    ANSWER_1000, SLCAN_UNIT_ENDS, UPLOAD_1000, UnitPty, sdo_answer_data, sdo_answer_of, sdo_element, slcan_answer,
    slcan_client, slcan_line, slcan_open, socketcand_client,
)
from motwin_harness import (  # noqa: E402
    GAP, STATUS_OK, Server, Skipped, TcpClient, TempDir, check, check_equal, expect_reply, run_tests,
)

VALGRIND_ERROR_STATUS = 99
VALGRIND_ARGS = ["--leak-check=full", "--show-leak-kinds=definite,indirect", "--errors-for-leak-kinds=definite,indirect",
                 f"--error-exitcode={VALGRIND_ERROR_STATUS}", "--track-origins=yes", "--quiet"]
STARTUP_TIMEOUT = 120.0  # valgrind runs the program some 20 to 50 times slower
STOP_TIMEOUT = 60.0
REQUEST_TIMEOUT = 30.0
NODE = 5
TMCM142_AP4_DEFAULT = 13743895
ENTER_ASCII = 139


def skip_unless_valgrind_applies(motwin):
    if shutil.which("valgrind") is None:
        raise Skipped("valgrind is not installed (scripts/install-deps.sh installs it)")
    libraries = subprocess.run(["ldd", motwin], capture_output=True, text=True).stdout
    if "libasan" in libraries:
        raise Skipped("the binary is built with AddressSanitizer (its leak check is LSan's)")


def start_under_valgrind(server):
    server.args = [shutil.which("valgrind")] + VALGRIND_ARGS + server.args
    return server.start(timeout=STARTUP_TIMEOUT)


def stop_and_check(server, what):
    server.stop(timeout=STOP_TIMEOUT)  # checks exit status 0: no valgrind error either
    report = server.stderr_text()
    check("ERROR SUMMARY" not in report or "ERROR SUMMARY: 0 errors" in report, f"{what}: valgrind report {report}")
    print(f"  {what}: exit status 0 under valgrind", flush=True)


def test_tmcm1636_serve_under_valgrind(motwin):
    skip_unless_valgrind_applies(motwin)
    with TempDir() as tmp:
        server = Server(motwin, os.path.join(tmp, "state"), pty_link=os.path.join(tmp, "tmcm1636"))
        with start_under_valgrind(server):
            with server.tcp() as c:
                expect_reply(c.request(GAP, 43, timeout=REQUEST_TIMEOUT), GAP, STATUS_OK, 4000, "GAP 43 under valgrind")
            stop_and_check(server, "tmcm-1636 (TCP, pty)")


def test_tmcm142_serve_under_valgrind(motwin):
    skip_unless_valgrind_applies(motwin)
    with TempDir() as tmp:
        server = BusServer(motwin, os.path.join(tmp, "state"),
                           ["--module", "tmcm-142", "--tmcl-tcp", "127.0.0.1:0",
                            "--tmcl-pty", os.path.join(tmp, "tmcm142")])
        with start_under_valgrind(server):
            with TcpClient(server.tcp_port_of()) as c:
                expect_reply(c.request(GAP, 4, timeout=REQUEST_TIMEOUT), GAP, STATUS_OK, TMCM142_AP4_DEFAULT,
                             "GAP 4 under valgrind")
                expect_reply(c.request(ENTER_ASCII, timeout=REQUEST_TIMEOUT), ENTER_ASCII, STATUS_OK, 0, "139")
                c.send_raw(b"AGAP 4, 0\r")
                expected = f"AGAP 4, 0\rBA 100 {TMCM142_AP4_DEFAULT}\r".encode()  # echo, then the reply
                check_equal(c.read_exact(len(expected), REQUEST_TIMEOUT), expected, "ASCII GAP 4 under valgrind")
            stop_and_check(server, "tmcm-142 (TCP binary and ASCII, pty)")


def test_tmcm3216_serve_under_valgrind(motwin):
    skip_unless_valgrind_applies(motwin)
    with TempDir() as tmp:
        link = os.path.join(tmp, "slcan0")
        server = BusServer(motwin, os.path.join(tmp, "state"),
                           ["--module", "tmcm-3216", "--node-id", str(NODE), "--can", "socketcand:127.0.0.1:0",
                            "--can", "slcan-tcp:127.0.0.1:0", "--can", f"slcan:{link}"])
        with start_under_valgrind(server):
            c = socketcand_client(server.port("can-socketcand"))
            try:
                c.send(sdo_element(NODE, UPLOAD_1000))
                check_equal(sdo_answer_data(c.read_until(sdo_answer_of(NODE), timeout=REQUEST_TIMEOUT)), ANSWER_1000,
                            "SDO upload of 1000 over socketcand under valgrind")
            finally:
                c.close()
            answer = slcan_line(0x580 + NODE, ANSWER_1000) + "\r"
            for name, client in (("SLCAN over TCP", lambda: slcan_client(server.port("can-slcan-tcp"))),
                                 ("SLCAN on a pty", lambda: slcan_open(UnitPty(link, SLCAN_UNIT_ENDS)))):
                s = client()
                try:
                    s.send(slcan_line(0x600 + NODE, UPLOAD_1000) + "\r")
                    check_equal(slcan_answer(s), "z\r", f"{name}: upload acknowledged")
                    s.read_until(lambda u: u == answer, timeout=REQUEST_TIMEOUT, what=f"{name}: the SDO answer")
                finally:
                    s.close()
            stop_and_check(server, "tmcm-3216 (socketcand, SLCAN over TCP and on a pty)")


if __name__ == "__main__":
    run_tests([test_tmcm1636_serve_under_valgrind, test_tmcm142_serve_under_valgrind,
               test_tmcm3216_serve_under_valgrind])
