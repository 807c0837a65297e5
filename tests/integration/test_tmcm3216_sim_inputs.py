#!/usr/bin/python3
"""Inputs of the simulated TMCM-3216 board over the socketcand server: the shutdown switch
(ENABLE) opened by a scenario sends one EMCY 5441 (motor byte 255) and puts every axis into FAULT;
a fault reset is refused while it stays open and accepted once it closes. A motor per axis
(--motor nema17,ideal,nema23) and the CLI errors of a wrong motor list.
"""

import os
import struct
import subprocess
import sys

sys.dont_write_bytecode = True  # no __pycache__ in the source tree
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

from canopen_harness import NMT_START, CanServer, check, check_equal, run_can_tests  # noqa: E402
from motwin_harness import FRAME_TIMEOUT, TempDir  # noqa: E402

NODE = 5
# Simulated seconds after start: the set-up (python-can's start, the SDO writes) must end before
# the switch opens, and the checks of the open switch before it closes, also on a loaded machine.
OPEN_AT_S = 5.0
CLOSE_AT_S = 8.0


def emcy_fields(msg):
    data = bytes(msg.data)
    return struct.unpack_from("<H", data, 0)[0], data[2], data[3], data[4]


def test_shutdown_switch_from_a_scenario(motwin):
    with TempDir() as tmp:
        scenario = os.path.join(tmp, "scenario.txt")
        with open(scenario, "w") as f:
            f.write(f"{OPEN_AT_S} ENABLE 0\n{CLOSE_AT_S} ENABLE 1\n")
        server = CanServer(motwin, os.path.join(tmp, "state"), node_id=NODE,
                           extra_args=["--motor", "nema17,ideal,nema23", "--scenario", scenario])
        with server, server.bus() as bus:
            bus.nmt(NMT_START, NODE)
            bus.download(NODE, 0x2005, 0, 3, 4)  # no limit switches on motor 0
            bus.download(NODE, 0x6060, 0, 3, 1)  # pv
            for cw in (6, 7, 15):
                bus.download(NODE, 0x6040, 0, cw, 2)
            bus.download(NODE, 0x60FF, 0, 20000, 4)
            check(bus.sim_now(NODE) < OPEN_AT_S - 0.3, "set-up took too long for the scenario")
            check_equal(bus.upload_u(NODE, 0x6041, 0) & 0x6F, 0x27, "motor 0 operation enabled")
            emcy = bus.receive_sim(NODE, lambda m: m.arbitration_id == 0x80 + NODE, OPEN_AT_S, "EMCY 5441")
            check_equal(emcy_fields(emcy), (0x5441, 0x21, 0, 255), "EMCY: shutdown switch, 1001, byte 1, byte 2")
            bus.wait_sim(NODE, 0.8)  # motor 0 stops on the quick-stop ramp (6085) before FAULT
            for axis in range(3):
                status = bus.upload_u(NODE, 0x6041 + axis * 0x800, 0)
                check_equal(status & 0x4F, 0x08, f"motor {axis} in FAULT (6041 = {status:#06x})")
            check_equal(bus.upload_u(NODE, 0x1001, 0), 0x21, "1001: generic, device profile")
            # Still open: the reset is refused and the reason sent again.
            bus.drain()
            bus.download(NODE, 0x6040, 0, 0x80, 2)
            again = bus.receive(lambda m: m.arbitration_id == 0x80 + NODE, FRAME_TIMEOUT, "EMCY 5441 again")
            check_equal(emcy_fields(again), (0x5441, 0x21, 0, 255), "EMCY after a refused fault reset")
            check_equal(bus.upload_u(NODE, 0x6041, 0) & 0x4F, 0x08, "motor 0 stays in FAULT")
            bus.download(NODE, 0x6040, 0, 0, 2)
            check(bus.sim_now(NODE) < CLOSE_AT_S, "the checks of the open switch took too long for the scenario")
            # Closed by the scenario: the next reset is accepted.
            bus.wait_sim_until(NODE, CLOSE_AT_S + 0.3)
            bus.drain()
            bus.download(NODE, 0x6040, 0, 0x80, 2)
            reset = bus.receive(lambda m: m.arbitration_id == 0x80 + NODE, FRAME_TIMEOUT, "EMCY 0000")
            check_equal(emcy_fields(reset), (0x0000, 0x21, 0, 0), "fault reset of motor 0 (motors 1, 2 still FAULT)")
            check_equal(bus.upload_u(NODE, 0x6041, 0) & 0x4F, 0x40, "motor 0 switch on disabled")
            server.stop()


def test_motor_list_errors(motwin):
    with TempDir() as tmp:
        for motors, expected in (("nema17,ideal", "names 2 motors for 3 axes"),
                                 ("nema17,nema99,ideal", "motor of axis 1: unknown stepper motor \"nema99\"")):
            state = os.path.join(tmp, "state")
            result = subprocess.run([motwin, "serve", "--module", "tmcm-3216", "--node-id", "1", "--state-dir", state,
                                     "--can", "socketcand:127.0.0.1:0", "--motor", motors],
                                    stdout=subprocess.PIPE, stderr=subprocess.PIPE, timeout=20)
            check(result.returncode != 0, f"--motor {motors}: exit status {result.returncode}")
            err = result.stderr.decode()
            check(expected in err, f"--motor {motors}: error {err!r}")
            check(not os.path.exists(state) or not os.listdir(state), f"--motor {motors}: nothing written")


def main():
    run_can_tests([
        test_shutdown_switch_from_a_scenario,
        test_motor_list_errors,
    ])


if __name__ == "__main__":
    main()
