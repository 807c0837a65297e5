#!/usr/bin/python3
"""`motwin lss` (a CiA-305 master, src/tools/lss_client.*) against the TMCM-3216's LSS slave on
one virtual bus: switch state global and selective, inquire identity and node ID, configure and
store a node ID (it survives a restart), and fastscan finding two unconfigured modules one
after the other by their serial numbers; activate bit timing switching the node's rate (2707).
The master's frames are checked in a candump capture.
"""

import os
import re
import subprocess
import sys

sys.dont_write_bytecode = True  # no __pycache__ in the source tree
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

from can_bus_harness import BusServer, check, check_equal  # noqa: E402
from canopen_harness import CanopenClient, TestFailure  # noqa: E402
from motwin_harness import TempDir, run_tests  # noqa: E402

VENDOR, PRODUCT, REVISION = 0x286, 3216, 0x00010004
# `motwin lss` waits this long for an answer that must come (a liveness bound: the wait ends with
# the answer), and a fastscan step this long for an answer that may not come (silence says "no",
# so a late answer on a loaded machine would mislead the scan; the default is 0.05 s).
ANSWER_TIMEOUT = "10"
FASTSCAN_STEP_TIMEOUT = "0.5"
# How long one `motwin lss` may run at all: a liveness bound, not a speed check. A fastscan is 128
# probes, each a round trip plus a settle time and, for every 1 bit of the identity, a silent step
# timeout; under ASan on a loaded machine that took more than the 30 s this once was.
COMMAND_TIMEOUT = 300


def lss(motwin, server, *args):
    result = subprocess.run([motwin, "lss", "--can", f"socketcand:127.0.0.1:{server.port()}", *args],
                            capture_output=True, timeout=COMMAND_TIMEOUT)
    return result.returncode, result.stdout.decode().strip(), result.stderr.decode().strip()


def lss_ok(motwin, server, *args):
    status, out, err = lss(motwin, server, "--timeout", ANSWER_TIMEOUT, *args)
    check_equal(status, 0, f"motwin lss {' '.join(args)} (stderr {err!r})")
    return out


def candump_frames(path):
    frames = []
    for line in open(path):
        m = re.fullmatch(r"\(\d+\.\d{6}\) can0 ([0-9A-F]+)#([0-9A-F]*)", line.strip())
        check(m is not None, f"capture line {line!r}")
        frames.append((int(m.group(1), 16), bytes.fromhex(m.group(2))))
    return frames


def test_configure_store_and_inquire(motwin):
    with TempDir() as tmp:
        state = os.path.join(tmp, "state")
        capture = os.path.join(tmp, "bus.log")
        args = ["--module", "tmcm-3216", "--node-id", "5", "--can", "socketcand:127.0.0.1:0"]
        with BusServer(motwin, state, args + ["--can-capture", capture]) as server:
            # Nobody in configuration state: inquiries get no answer (exit status 2).
            status, _, err = lss(motwin, server, "--timeout", "0.3", "inquire", "node-id")
            check_equal(status, 2, f"inquire in waiting state ({err})")
            lss_ok(motwin, server, "switch-selective", hex(VENDOR), str(PRODUCT), hex(REVISION), "1")
            check_equal(lss_ok(motwin, server, "inquire", "all"),
                        f"vendor 0x{VENDOR:08X} product 0x{PRODUCT:08X} revision 0x{REVISION:08X} serial 0x00000001 "
                        "node-id 5", "inquire all")
            check_equal(lss_ok(motwin, server, "inquire", "serial"), "0x00000001", "inquire serial")
            lss_ok(motwin, server, "set-node-id", "9")
            lss_ok(motwin, server, "set-bitrate", "1000")
            lss_ok(motwin, server, "store")
            lss_ok(motwin, server, "switch-global", "waiting")
            status, _, err = lss(motwin, server, "set-bitrate", "33")
            check_equal(status, 2, "a bit rate outside CiA-305 table 0")
            check("table 0" in err, err)
            client = CanopenClient(server.port())
            try:
                client.nmt(0x81, 5)  # the new node ID applies at the reset
                client.wait_state(9, 0x00)
                check_equal(client.upload_u(9, 0x1018, 4), 1, "1018 sub 4 as node 9")
            finally:
                client.close()
            server.stop()
        frames = [f for f in candump_frames(capture) if f[0] in (0x7E4, 0x7E5)]
        master = [data for cob, data in frames if cob == 0x7E5]
        check_equal(master[0], bytes([0x5E, 0, 0, 0, 0, 0, 0, 0]), "the first inquiry")
        check_equal(master[1:5], [bytes([0x40, 0x86, 0x02, 0, 0, 0, 0, 0]), bytes([0x41, 0x90, 0x0C, 0, 0, 0, 0, 0]),
                                  bytes([0x42, 0x04, 0x00, 0x01, 0x00, 0, 0, 0]), bytes([0x43, 1, 0, 0, 0, 0, 0, 0])],
                    "switch state selective frames")
        check(bytes([0x11, 9, 0, 0, 0, 0, 0, 0]) in master, "configure node ID 9 frame")
        check(bytes([0x13, 0, 0, 0, 0, 0, 0, 0]) in master, "configure bit timing table 0 index 0 frame")
        check(bytes([0x17, 0, 0, 0, 0, 0, 0, 0]) in master, "store frame")
        check_equal(master[-1], bytes([0x04, 0, 0, 0, 0, 0, 0, 0]), "switch state global waiting")
        check(bytes([0x44, 0, 0, 0, 0, 0, 0, 0]) in [d for c, d in frames if c == 0x7E4], "slave answered 0x44")
        # The stored node ID survives a restart (without --node-id: the stored one applies).
        with BusServer(motwin, state, ["--module", "tmcm-3216", "--can", "socketcand:127.0.0.1:0"]) as server:
            client = CanopenClient(server.port())
            try:
                check_equal(client.upload_u(9, 0x1000, 0), 0xFFFF0192, "node 9 after a restart")
            finally:
                client.close()
            server.stop()


def test_fastscan_finds_unconfigured_modules(motwin):
    with TempDir() as tmp:
        args = ["--node", "tmcm-3216:node-id=1,serial=7", "--node", "tmcm-3216:node-id=2,serial=3",
                "--can", "socketcand:127.0.0.1:0"]
        with BusServer(motwin, os.path.join(tmp, "state"), args) as server:
            status, _, err = lss(motwin, server, "fastscan")
            check_equal(status, 1, f"fastscan with every node configured ({err})")
            check("no unconfigured" in err, err)
            # Both to "unconfigured" (255), stored, and reset.
            lss_ok(motwin, server, "switch-global", "configuration")
            lss_ok(motwin, server, "set-node-id", "255")
            lss_ok(motwin, server, "store")
            lss_ok(motwin, server, "switch-global", "waiting")
            client = CanopenClient(server.port())
            try:
                client.nmt(0x81, 0)
                # Reset: an unconfigured slave answers a fastscan reset (the master's first question)
                # once its restart time has passed (docs/canopen.md "Start-up timing"); it sends no
                # boot-up, so the master asks again until one answers (bounded).
                for attempt in range(100):
                    try:
                        client.lss([0x51, 0, 0, 0, 0, 0x80, 0, 0], timeout=0.1)
                        break
                    except TestFailure:
                        check(attempt < 99, "no unconfigured slave answered the fastscan reset")
                check_equal(lss_ok(motwin, server, "fastscan", "--step-timeout", FASTSCAN_STEP_TIMEOUT,
                                   "--node-id", "20", "--store"),
                            f"vendor 0x{VENDOR:08X} product 0x{PRODUCT:08X} revision 0x{REVISION:08X} serial 0x00000003",
                            "the lower identity first")
                check_equal(lss_ok(motwin, server, "fastscan", "--step-timeout", FASTSCAN_STEP_TIMEOUT,
                                   "--node-id", "21"),
                            f"vendor 0x{VENDOR:08X} product 0x{PRODUCT:08X} revision 0x{REVISION:08X} serial 0x00000007",
                            "then the other")
                check_equal(lss(motwin, server, "fastscan")[0], 1, "nobody left unconfigured")
                check_equal(client.upload_u(20, 0x1018, 4), 3, "node 20 is serial 3")
                check_equal(client.upload_u(21, 0x1018, 4), 7, "node 21 is serial 7")
            finally:
                client.close()
            server.stop()


def test_activate_bitrate(motwin):
    # A bus without bit timing (--can-bitrate 0), so that the node stays reachable at its new rate.
    with TempDir() as tmp:
        capture = os.path.join(tmp, "bus.log")
        args = ["--module", "tmcm-3216", "--node-id", "5", "--can", "socketcand:127.0.0.1:0", "--can-bitrate", "0",
                "--can-capture", capture]
        with BusServer(motwin, os.path.join(tmp, "state"), args) as server:
            client = CanopenClient(server.port())
            try:
                check_equal(client.upload_u(5, 0x2707, 0), 1000, "2707 before")
                lss_ok(motwin, server, "switch-global", "configuration")
                lss_ok(motwin, server, "set-bitrate", "250")
                status, _, err = lss(motwin, server, "activate-bitrate", "70000")
                check_equal(status, 2, f"a switch delay above 65535 ms ({err})")
                check_equal(lss_ok(motwin, server, "activate-bitrate", "100"), "", "activate-bitrate output")
                lss_ok(motwin, server, "switch-global", "waiting")
                # Active after twice the delay (200 ms of simulated time).
                client.poll_sim(5, lambda: client.upload_u(5, 0x2707, 0), lambda rate: rate == 250, 3.0,
                                "2707 = 250 after the activation", interval=0.05)
                check_equal(client.upload_u(5, 0x2707, 0), 250, "2707 after the activation")
                check_equal(client.upload_u(5, 0x2704, 0), 1000, "2704: an activated rate is not stored")
            finally:
                client.close()
            server.stop()
        master = [data for cob, data in candump_frames(capture) if cob == 0x7E5]
        check_equal(master, [bytes([0x04, 0x01, 0, 0, 0, 0, 0, 0]), bytes([0x13, 0, 3, 0, 0, 0, 0, 0]),
                             bytes([0x15, 100, 0, 0, 0, 0, 0, 0]), bytes([0x04, 0, 0, 0, 0, 0, 0, 0])],
                    "the master's frames: configuration, bit timing 250 (index 3), activate 100 ms, waiting")


if __name__ == "__main__":
    run_tests([test_configure_store_and_inquire, test_fastscan_finds_unconfigured_modules, test_activate_bitrate])
