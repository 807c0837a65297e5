#!/usr/bin/python3
"""The server's start/stop path under valgrind's memcheck: `motwin serve` for a TMCM-1636 (TCP
and pty) and a TMCM-3216 (socketcand), each started, asked one request (GAP 43 = 4000; an SDO
upload of 1000 = FFFF0192), then stopped with SIGTERM. Any invalid access, use of uninitialised
memory or definite/indirect leak makes valgrind exit with status 99 instead of motwin's 0.

Skipped (reported, exit 0) when valgrind is not installed or the binary is built with
AddressSanitizer (the two do not run together; the ASan build checks leaks with LSan instead).
"""

import os
import shutil
import subprocess
import sys

sys.dont_write_bytecode = True  # no __pycache__ in the source tree
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

from canopen_harness import CanServer  # noqa: E402
from motwin_harness import GAP, STATUS_OK, Server, TempDir, check, check_equal, expect_reply, run_tests  # noqa: E402
from test_garbage_clients import (  # noqa: E402
    ANSWER_1000, CAN_NODE, UPLOAD_1000, is_sdo_answer, sdo_answer_data, sdo_element, socketcand_client,
)

VALGRIND_ERROR_STATUS = 99
VALGRIND_ARGS = ["--leak-check=full", "--show-leak-kinds=definite,indirect", "--errors-for-leak-kinds=definite,indirect",
                 f"--error-exitcode={VALGRIND_ERROR_STATUS}", "--track-origins=yes", "--quiet"]
STARTUP_TIMEOUT = 120.0  # valgrind runs the program some 20 to 50 times slower
STOP_TIMEOUT = 60.0


def skip_reason(motwin):
    valgrind = shutil.which("valgrind")
    if valgrind is None:
        return "valgrind is not installed"
    libraries = subprocess.run(["ldd", motwin], capture_output=True, text=True).stdout
    if "libasan" in libraries:
        return "the binary is built with AddressSanitizer"
    return None


def under_valgrind(server):
    server.args = [shutil.which("valgrind")] + VALGRIND_ARGS + server.args
    return server


def stop_and_check(server, what):
    server.stop(timeout=STOP_TIMEOUT)  # checks exit status 0: no valgrind error either
    report = server.stderr_text()
    check("ERROR SUMMARY" not in report or "ERROR SUMMARY: 0 errors" in report, f"{what}: valgrind report {report}")
    print(f"  {what}: exit status 0 under valgrind", flush=True)


def test_tmcm1636_serve_under_valgrind(motwin):
    reason = skip_reason(motwin)
    if reason:
        print(f"  skipped: {reason}", flush=True)
        return
    with TempDir() as tmp:
        server = under_valgrind(Server(motwin, os.path.join(tmp, "state"), pty_link=os.path.join(tmp, "tmcm1636")))
        server.start(timeout=STARTUP_TIMEOUT)
        with server:
            with server.tcp() as c:
                expect_reply(c.request(GAP, 43, timeout=30.0), GAP, STATUS_OK, 4000, "GAP 43 under valgrind")
            stop_and_check(server, "tmcm-1636 (TCP, pty)")


def test_tmcm3216_serve_under_valgrind(motwin):
    reason = skip_reason(motwin)
    if reason:
        print(f"  skipped: {reason}", flush=True)
        return
    with TempDir() as tmp:
        server = under_valgrind(CanServer(motwin, os.path.join(tmp, "state"), node_id=CAN_NODE))
        server.start(timeout=STARTUP_TIMEOUT)
        with server:
            c = socketcand_client(server.can_port)
            try:
                c.send(sdo_element(UPLOAD_1000))
                check_equal(sdo_answer_data(c.read_until(is_sdo_answer, timeout=30.0)), ANSWER_1000,
                            "SDO upload of 1000 under valgrind")
            finally:
                c.close()
            stop_and_check(server, "tmcm-3216 (socketcand)")


if __name__ == "__main__":
    run_tests([test_tmcm1636_serve_under_valgrind, test_tmcm3216_serve_under_valgrind])
