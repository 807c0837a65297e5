#!/usr/bin/python3
"""The TMCM-3216's I/O and stepper hardware objects over the socketcand server: inputs set with
--set reach 2702, 270E and each axis's 60FD; 2711 and 2703 drive DIO pins (logged as output
lines); 2005 is refused outside SWITCH ON DISABLED; a new microstep resolution (2000) shows in 2107
once the power stage is off; driver temperature reaches 2102.
"""

import os
import sys

sys.dont_write_bytecode = True  # no __pycache__ in the source tree
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

from canopen_harness import NMT_START, CanServer, check, check_equal, run_can_tests  # noqa: E402
from motwin_harness import TempDir  # noqa: E402

NODE = 9
ABORT_INVALID_VALUE = 0x06090030
ABORT_DEVICE_STATE = 0x08000022


def test_inputs_outputs_and_switches(motwin):
    with TempDir() as tmp:
        server = CanServer(motwin, os.path.join(tmp, "state"), node_id=NODE,
                           extra_args=["--set", "DIO2=1", "--set", "AIN1=1234", "--set", "AXIS0_REF_L=1",
                                       "--set", "AXIS1_REF_H=1"])
        with server, server.bus() as bus:
            check_equal(bus.upload_u(NODE, 0x2702, 0), 1 << 18, "2702: DIO2 high")
            check_equal(bus.upload_u(NODE, 0x270E, 1), 0, "270E sub 1: AIN0")
            check_equal(bus.upload_u(NODE, 0x270E, 2), 1234, "270E sub 2: AIN1")
            check_equal(bus.upload_u(NODE, 0x60FD, 0), (1 << 18) | 1, "60FD of motor 0: left limit, DIO2")
            check_equal(bus.upload_u(NODE, 0x68FD, 0), (1 << 18) | 4, "60FD of motor 1: home switch, DIO2")
            # 2005 bit 0 disables the left limit switch of motor 0, bit 2 inverts it.
            bus.download(NODE, 0x2005, 0, 1, 4)
            bus.wait_sim(NODE, 0.05)
            check_equal(bus.upload_u(NODE, 0x60FD, 0), 1 << 18, "60FD with the left switch disabled")
            bus.download(NODE, 0x2005, 0, 4, 4)
            bus.wait_sim(NODE, 0.05)
            check_equal(bus.upload_u(NODE, 0x60FD, 0), 1 << 18, "60FD with the left switch inverted")
            # DIO0 as a push-pull output, switched through the mask.
            check_equal(bus.abort_code(bus.download, NODE, 0x2711, 0, 0x10, 2), ABORT_INVALID_VALUE, "2711 bit 4")
            bus.download(NODE, 0x2711, 0, 0x0101, 2)
            bus.download(NODE, 0x2703, 1, 1 << 16, 4)
            check_equal(bus.upload_u(NODE, 0x2703, 1), 1 << 16, "2703 sub 1 reads back as written")
            bus.wait_sim(NODE, 0.05)
            check_equal(bus.upload_u(NODE, 0x2702, 0), 1 << 18, "2702: DIO0 not switched without the mask")
            check_equal(bus.abort_code(bus.download, NODE, 0x2703, 1, 0x65766173, 4), ABORT_INVALID_VALUE,
                        "2703 sub 1: bits that name no output")
            bus.download(NODE, 0x2703, 2, 0xF << 16, 4)
            bus.download(NODE, 0x2703, 1, 1 << 16, 4)
            check_equal(bus.upload_u(NODE, 0x2703, 1), 1 << 16, "2703 sub 1 through the mask")
            bus.wait_sim(NODE, 0.05)
            check_equal(bus.upload_u(NODE, 0x2702, 0), (1 << 18) | (1 << 16), "2702 reads the output back")
            server.stop()
        outputs = [line for line in server.stdout_lines if line.startswith("output ")]
        check(any(line.startswith("output DIO0 1 at ") for line in outputs), f"DIO0 output logged: {outputs!r}")


def test_stepper_objects_and_states(motwin):
    with TempDir() as tmp:
        server = CanServer(motwin, os.path.join(tmp, "state"), node_id=NODE,
                           extra_args=["--set", "AXIS2_DRIVER_TEMP=130"])
        with server, server.bus() as bus:
            bus.nmt(NMT_START, NODE)
            check_equal(bus.upload_u(NODE, 0x2400, 0), 8, "2000 of motor 2")
            check_equal(bus.upload_u(NODE, 0x2489, 0), 200, "2089 of motor 2: 2 s")
            check_equal(bus.upload_u(NODE, 0x2502, 0), 0x40, "2102 of motor 2: temperature pre-warning")
            check_equal(bus.upload_u(NODE, 0x2102, 0), 0, "2102 of motor 0")
            bus.download(NODE, 0x2405, 0, 3, 4)  # no limit switches on motor 2
            for cw in (6, 7, 15):
                bus.download(NODE, 0x7040, 0, cw, 2)
            bus.wait_sim(NODE, 0.05)
            check_equal(bus.upload_u(NODE, 0x7041, 0) & 0x6F, 0x27, "motor 2 operation enabled")
            check_equal(bus.abort_code(bus.download, NODE, 0x2405, 0, 0, 4), ABORT_DEVICE_STATE,
                        "2005 outside SWITCH ON DISABLED")
            check_equal(bus.abort_code(bus.download, NODE, 0x240B, 2, 1, 1), ABORT_DEVICE_STATE,
                        "200B outside SWITCH ON DISABLED")
            bus.download(NODE, 0x2403, 0, 200, 1)  # currents may change any time
            bus.download(NODE, 0x2400, 0, 4, 1)
            bus.wait_sim(NODE, 0.05)
            check_equal(bus.upload_u(NODE, 0x2507, 0), 8, "2107 while the power stage is on")
            bus.download(NODE, 0x7040, 0, 0, 2)  # disable voltage: SWITCH ON DISABLED
            bus.wait_sim(NODE, 0.05)
            check_equal(bus.upload_u(NODE, 0x2507, 0), 4, "2107 after the power stage went off")
            bus.download(NODE, 0x2405, 0, 0, 4)
            check_equal(bus.upload_u(NODE, 0x2405, 0), 0, "2005 written in SWITCH ON DISABLED")
            server.stop()


def main():
    run_can_tests([
        test_inputs_outputs_and_switches,
        test_stepper_objects_and_states,
    ])


if __name__ == "__main__":
    main()
