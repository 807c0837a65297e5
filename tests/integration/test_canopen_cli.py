#!/usr/bin/python3
"""`motwin sdo read|write` and `motwin nmt` against a running TMCM-3216 on socketcand: values in
every type, segmented upload of 1008, exit status 1 with the abort code for a refused transfer,
2 with no answer; an NMT start seen by a python-can observer on the same bus; every NMT command
(start, stop, preop, reset, reset-comm, addressed and broadcast) seen in the heartbeat and the
boot-up, and refused commands that send nothing.
"""

import os
import subprocess
import sys

sys.dont_write_bytecode = True  # no __pycache__ in the source tree
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

from canopen_harness import (  # noqa: E402
    NMT_PREOP, NMT_START, NMT_STOP, STATE_BOOTUP, STATE_OPERATIONAL, STATE_PREOP, STATE_STOPPED, CanServer, check,
    check_equal,
)
from motwin_harness import TempDir, run_tests  # noqa: E402

NODE = 12
NMT_COMMANDS = {"start": NMT_START, "stop": NMT_STOP, "preop": NMT_PREOP}


def motwin_run(motwin, *args):
    result = subprocess.run([motwin, *args], capture_output=True, timeout=30)
    return result.returncode, result.stdout.decode(), result.stderr.decode()


def test_sdo_and_nmt_commands(motwin):
    with TempDir() as tmp, CanServer(motwin, os.path.join(tmp, "state"), node_id=NODE) as server:
        can = f"--can=socketcand:127.0.0.1:{server.can_port}"

        def ok(*args):
            status, out, err = motwin_run(motwin, *args)
            check_equal(status, 0, f"{args}: exit status (stderr {err!r})")
            return out.strip()

        check_equal(ok("sdo", "read", can, str(NODE), "1000", "0"), "0xFFFF0192", "1000")
        check_equal(ok("sdo", "read", can, str(NODE), "0x1018", "2", "u32"), "3216", "1018 sub 2")
        check_equal(ok("sdo", "read", can, str(NODE), "1008", "0", "str"), "TMCM-3216", "1008 (segmented)")
        ok("sdo", "write", can, str(NODE), "1017", "0", "u16", "300")
        check_equal(ok("sdo", "read", can, str(NODE), "1017", "0", "u16"), "300", "1017 read back")
        ok("sdo", "write", can, str(NODE), "1016", "1", "hex", "E8030500")
        check_equal(ok("sdo", "read", can, str(NODE), "1016", "1"), "0x000503E8", "1016 sub 1")

        status, _, err = motwin_run(motwin, "sdo", "read", can, str(NODE), "1234", "0")
        check_equal(status, 1, "exit status of an abort")
        check("0x06020000" in err and "does not exist" in err, f"stderr {err!r}")
        status, _, err = motwin_run(motwin, "sdo", "write", can, str(NODE), "1017", "0", "u32", "5")
        check_equal(status, 1, "exit status of a wrong size")
        check("0x06070012" in err, f"stderr {err!r}")
        status, _, err = motwin_run(motwin, "sdo", "read", can, str(NODE + 1), "1000", "0")
        check_equal(status, 2, "exit status without an answer")
        status, _, err = motwin_run(motwin, "sdo", "write", can, str(NODE), "1017", "0", "u16", "-5")
        check_equal(status, 2, "a negative unsigned value")

        with server.bus() as bus:
            bus.drain(0.1)
            ok("nmt", can, "start", str(NODE))
            bus.wait_state(NODE, STATE_OPERATIONAL)
        server.stop()


def test_nmt_commands_change_the_state(motwin):
    """Every `motwin nmt` command, checked by the heartbeat (sent at once on a state change) and
    by the boot-up; stopped: SDO is not answered (exit status 2)."""
    with TempDir() as tmp, CanServer(motwin, os.path.join(tmp, "state"), node_id=NODE) as server:
        can = f"--can=socketcand:127.0.0.1:{server.can_port}"

        def ok(*args):
            status, out, err = motwin_run(motwin, *args)
            check_equal(status, 0, f"{args}: exit status (stderr {err!r})")
            return out.strip()

        with server.bus() as bus:
            bus.download(NODE, 0x1017, 0, 1000, 2)  # 1 s: the state changes show as extra heartbeats
            bus.drain(0.1)
            for command, state in (("start", STATE_OPERATIONAL), ("stop", STATE_STOPPED), ("preop", STATE_PREOP),
                                   ("start", STATE_OPERATIONAL)):
                check_equal(ok("nmt", can, command, str(NODE)), "", f"nmt {command}: output")
                # Within 0.8 s of simulated time of the NMT frame (the period is 1 s).
                msg = bus.state_after_nmt(NODE, NMT_COMMANDS[command], state, within=0.8)
                check_equal(bytes(msg.data), bytes([state]), f"heartbeat after nmt {command}")
                if command == "stop":
                    status, _, _ = motwin_run(motwin, "sdo", "read", can, str(NODE), "1000", "0")
                    check_equal(status, 2, "SDO while stopped: no answer")
            ok("nmt", can, "reset", str(NODE))
            bus.wait_state(NODE, STATE_BOOTUP)
            check_equal(ok("sdo", "read", can, str(NODE), "1017", "0", "u16"), "0", "1017 back to its default")
            ok("nmt", can, "start", "0")  # broadcast
            since = bus.wait_nmt(NMT_START, 0).timestamp  # 0.3 s of simulated time from the NMT frame on
            frames = bus.collect_sim(NODE, 0.3, lambda m: m.arbitration_id in (0x180 + NODE, 0x700 + NODE), since=since)
            check_equal([(m.arbitration_id, bytes(m.data)) for m in frames], [(0x180 + NODE, bytes([0x40, 0x02]))],
                        "TPDO 1 on entering operational (statusword), no heartbeat (1017 = 0)")
            ok("sdo", "write", can, str(NODE), "1017", "0", "u16", "1000")
            bus.wait_state(NODE, STATE_OPERATIONAL)
            ok("nmt", can, "reset-comm", "0")
            bus.wait_state(NODE, STATE_BOOTUP)
            check_equal(ok("sdo", "read", can, str(NODE), "1017", "0", "u16"), "0", "1017 after reset communication")
            bus.drain(0.1)
            for bad in (["bogus", str(NODE)], ["start", "128"]):
                status, _, err = motwin_run(motwin, "nmt", can, *bad)
                check_equal(status, 2, f"nmt {' '.join(bad)} (stderr {err!r})")
            check_equal(bus.collect(0.2, lambda m: m.arbitration_id == 0x000), [], "NMT frames of refused commands")
        server.stop()


if __name__ == "__main__":
    run_tests([test_sdo_and_nmt_commands, test_nmt_commands_change_the_state])
