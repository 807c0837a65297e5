#!/usr/bin/python3
"""Bit-rate mismatch on the virtual bus, with Debian's python3-can over socketcand: a node whose
active bit rate differs from `--can-bitrate` neither receives the bus's frames nor gets its own
onto the bus, `--can-stats` counts it per node, and on a bus of its rate it answers again.

- TMCM-3216, LSS: configure bit timing 500 kbit/s + activate: silent on the 1 Mbit/s bus (SDO, NMT
  reset, LSS); the activated rate is forgotten at power-up, so a restart brings it back.
- TMCM-3216, 2704 + store + NMT reset: silent at 1 Mbit/s, its heartbeats counted as not sent until
  the controller is error-passive; back on a 500 kbit/s bus; 2704 = 1000 + store + reset: silent
  there, back on 1 Mbit/s.
- A TMCL module (GP 69 + reset) cut off beside a TMCM-3216 that keeps answering (`--node`).
"""

import os
import re
import sys
import time

sys.dont_write_bytecode = True  # no __pycache__ in the source tree
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

from can_bus_harness import BusServer, TmclCan  # noqa: E402
from canopen_harness import (  # noqa: E402
    NMT_RESET_NODE, SAVE, STATE_PREOP, CanopenClient, CanServer, TestFailure, check, check_equal,
    run_can_tests,
)
from motwin_harness import TempDir  # noqa: E402

NODE = 4
NODE_STATS = re.compile(r" node (\S+) bitrate (\d+) (on|off)-speed (\S+) rec (\d+) tec (\d+) missed (\d+) "
                        r"not-sent (\d+) bus-off (\d+)")


def serve(motwin, tmp, bitrate, *extra):
    return CanServer(motwin, os.path.join(tmp, "state"), node_id=NODE,
                     extra_args=["--can-bitrate", bitrate, "--can-stats", "0.1"] + list(extra))


def node_stats(line):
    """{name: (bitrate, off_speed, state, rec, tec, missed, not_sent, bus_off)} of a can-stats line."""
    return {m.group(1): (int(m.group(2)), m.group(3) == "off", m.group(4), int(m.group(5)), int(m.group(6)),
                         int(m.group(7)), int(m.group(8)), int(m.group(9)))
            for m in NODE_STATS.finditer(line)}


def wait_for_stats(server, name, predicate, what, timeout=60.0):
    """The first node part of a can-stats line (printed from now on) for which predicate holds."""
    seen = len(server.stdout_lines)
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        lines = server.stdout_lines[seen:]
        for line in lines:
            stats = node_stats(line).get(name) if line.startswith("can-stats") else None
            if stats is not None and predicate(stats):
                return stats
        time.sleep(0.05)
    raise TestFailure(f"no can-stats line with {what} for {name}: {server.stdout_lines[-5:]!r}")


def silent(bus, what, wait=0.4):
    """Sends an NMT reset node and an SDO upload of 1000; nothing may come back."""
    bus.drain()
    bus.nmt(NMT_RESET_NODE, NODE)  # a node on the bus would boot at once and answer the SDO
    bus.send(0x600 + NODE, [0x40, 0x00, 0x10, 0x00, 0, 0, 0, 0])
    check_equal(bus.collect(wait, lambda m: m.arbitration_id in (0x580 + NODE, 0x700 + NODE)), [], what)


def test_lss_activated_bit_rate_cuts_the_node_off_until_power_up(motwin):
    with TempDir() as tmp:
        with serve(motwin, tmp, "1M") as server, server.bus() as bus, server.bus() as listener:
            check_equal(bus.upload_u(NODE, 0x2707, 0), 1000, "2707 at start")
            bus.lss([0x04, 0x01], answer=False)  # switch state global: configuration
            check_equal(bus.lss([0x13, 0, 2])[:2], bytes([0x13, 0]), "configure bit timing 500 kbit/s")
            bus.lss([0x15, 20, 0], answer=False)  # activate bit timing, switch delay 20 ms: after 40 ms
            bus.wait_sim_seen_by(listener, 0.2)
            silent(bus, "answers of a node switched to 500 kbit/s on a 1 Mbit/s bus")
            check_equal(bus.lss_silent([0x5E]), [], "LSS inquire node ID at 500 kbit/s")
            stats = wait_for_stats(server, "tmcm-3216", lambda s: s[1] and s[5] >= 3, "off-speed, 3 frames missed")
            check_equal(stats[0], 500000, "the node's bit rate in can-stats")
            server.stop()
        # Power-up forgets an activated rate (it was not stored): 2704 = 1000 applies again.
        with serve(motwin, tmp, "1M") as server, server.bus() as bus:
            check_equal(bus.upload_u(NODE, 0x2707, 0), 1000, "2707 after a restart")
            check_equal(bus.upload_u(NODE, 0x2704, 0), 1000, "2704 unchanged")
            server.stop()


def test_stored_bit_rate_applies_at_reset_and_the_node_returns_on_a_bus_of_its_rate(motwin):
    with TempDir() as tmp:
        with serve(motwin, tmp, "1M") as server, server.bus() as bus:
            bus.download(NODE, 0x1017, 0, 100, 2)   # heartbeat every 100 ms
            bus.download(NODE, 0x2704, 0, 500, 2)
            bus.download(NODE, 0x1010, 1, SAVE, 4)  # everything, 2704 and 1017 included
            check_equal(bus.upload_u(NODE, 0x2707, 0), 1000, "2704 applies at the next reset only")
            bus.drain()
            bus.nmt(NMT_RESET_NODE, NODE)
            check_equal(bus.collect(0.5, lambda m: m.arbitration_id == 0x700 + NODE), [],
                        "boot-up and heartbeats at 500 kbit/s on a 1 Mbit/s bus")
            silent(bus, "answers after the reset")
            # Every heartbeat fails: TEC +8 each, error-passive from the 16th (1.6 s).
            stats = wait_for_stats(server, "tmcm-3216", lambda s: s[2] == "error-passive", "error-passive")
            check(stats[1] and stats[4] >= 128 and stats[6] >= 16, f"counters of the cut-off node: {stats}")
            server.stop()
        with serve(motwin, tmp, "500k") as server, server.bus() as bus:
            bus.wait_state(NODE, STATE_PREOP)  # its heartbeat reaches the bus
            check_equal(bus.upload_u(NODE, 0x2707, 0), 500, "2707 on a 500 kbit/s bus")
            bus.download(NODE, 0x2704, 0, 1000, 2)
            bus.download(NODE, 0x2706, 1, SAVE, 4)
            silent(bus, "answers after going back to 1 Mbit/s on a 500 kbit/s bus")
            server.stop()
        with serve(motwin, tmp, "1M") as server, server.bus() as bus:
            check_equal(bus.upload_u(NODE, 0x2707, 0), 1000, "2707 back on 1 Mbit/s")
            bus.nmt(NMT_RESET_NODE, NODE)
            bus.wait_state(NODE, 0x00)
            bus.wait_sim(NODE, 0.3)  # can-stats lines, every 0.1 s
            server.stop()
        lines = [line for line in server.stdout_lines if line.startswith("can-stats")]
        check(lines and not any(" node tmcm-3216 " in line for line in lines),
              f"a node that is on speed is not listed: {lines[-3:]!r}")


def test_tmcl_module_off_speed_beside_a_canopen_node(motwin):
    with TempDir() as tmp:
        args = ["--node", "tmcm-3216:node-id=4", "--node", "tmcm-1636", "--can", "socketcand:127.0.0.1:0",
                "--can-stats", "0.1"]
        with BusServer(motwin, os.path.join(tmp, "state"), args) as server:
            bus = CanopenClient(server.port())
            try:
                tmcl = TmclCan(bus.bus)
                tmcl.ok(9, 69, 0, 7)  # SGP 69 = 500 kbit/s: applies at the next power-up
                tmcl.ok(255, 0, 0, 1234)  # reset: the reply, then the controller starts at 500 kbit/s
                tmcl.send_raw([136, 1, 0, 0, 0, 0, 0])
                check_equal(bus.collect(0.3, lambda m: m.arbitration_id == 2), [], "TMCL replies at 500 kbit/s")
                check_equal(bus.upload_u(NODE, 0x1000, 0), 0xFFFF0192, "the TMCM-3216 keeps answering")
                stats = wait_for_stats(server, "tmcm-1636-2", lambda s: s[1] and s[5] >= 1, "off-speed")
                check_equal(stats[0], 500000, "the TMCL node's bit rate")
                lines = [line for line in server.stdout_lines if line.startswith("can-stats")]
                check(not any(" node tmcm-3216-1 " in line for line in lines), f"the CANopen node is fine: {lines[-1]!r}")
            finally:
                bus.close()
            server.stop()


def main():
    run_can_tests([
        test_lss_activated_bit_rate_cuts_the_node_off_until_power_up,
        test_stored_bit_rate_applies_at_reset_and_the_node_returns_on_a_bus_of_its_rate,
        test_tmcl_module_off_speed_beside_a_canopen_node,
    ])


if __name__ == "__main__":
    main()
