#!/usr/bin/python3
"""What CiA-402 masters do with the TMCM-3216 (docs/canopen.md
"CiA-402 expectations of real masters"), as python-canopen's BaseNode402 and ros2_canopen send
it, in raw frames over the socketcand server: 1000/67FF/6502 of every axis, state transitions
with the exact controlwords and statusword masks, quick stop, fault and fault reset with EMCY 0000
naming the axis, 6060 = 0, the homing statusword contract of both masters, and PDO operation
(RPDO controlword and target velocity, event-driven and synchronous TPDOs; axis 1's PDOs
remapped in python-canopen's order).
"""

import os
import struct
import sys
import time

sys.dont_write_bytecode = True  # no __pycache__ in the source tree
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

from canopen_harness import (NMT_RESET_NODE, NMT_START, NMT_STOP, STATE_BOOTUP, CanServer,  # noqa: E402
                             TestFailure, check, check_equal, run_can_tests)
from motwin_harness import FRAME_TIMEOUT, TempDir  # noqa: E402

NODE = 4
SPEED = "10"
# A test that reads a state right after the command that starts a move of about a second of
# simulated time (bit 10 dropping with a write, say) runs in real time: at SPEED the move would
# end within 0.1 s of wall time, which a loaded machine can easily let pass between two requests.
REALTIME = "1"
AXIS = 0x800  # profile object offset per axis

# python-canopen BaseNode402 state masks (mask, value).
STATES = {
    "NOT READY TO SWITCH ON": (0x4F, 0x00),
    "SWITCH ON DISABLED": (0x4F, 0x40),
    "READY TO SWITCH ON": (0x6F, 0x21),
    "SWITCHED ON": (0x6F, 0x23),
    "OPERATION ENABLED": (0x6F, 0x27),
    "QUICK STOP ACTIVE": (0x6F, 0x07),
    "FAULT": (0x4F, 0x08),
    "FAULT REACTION ACTIVE": (0x4F, 0x0F),
}


def serve(motwin, tmp, *extra, speed=SPEED):
    return CanServer(motwin, os.path.join(tmp, "state"), node_id=NODE, speed=speed, extra_args=extra)


def reset(bus):
    bus.nmt(NMT_RESET_NODE, NODE)
    bus.wait_state(NODE, STATE_BOOTUP)


def state_of(status):
    for name, (mask, value) in STATES.items():
        if status & mask == value:
            return name
    return f"unknown {status:#06x}"


def expect_state(bus, name, axis=0, timeout=0.4):
    """As BaseNode402 does: poll 6041 until the state shows, within 0.4 s (of simulated time: the
    drive's own pace, whatever the load on the machine)."""
    status = bus.poll_sim(NODE, lambda: bus.upload_u(NODE, 0x6041 + axis * AXIS, 0),
                          lambda value: state_of(value) == name, timeout, f"axis {axis}: {name}", fail=False)
    if status is None:
        status = bus.upload_u(NODE, 0x6041 + axis * AXIS, 0)
        if state_of(status) != name:
            raise TestFailure(f"axis {axis}: expected {name}, 6041 = {status:#06x} ({state_of(status)})")
    return status


def controlword(bus, value, axis=0):
    bus.download(NODE, 0x6040 + axis * AXIS, 0, value, 2)


def wait_status(bus, mask, value, sim_timeout, axis=0):
    """Polls 6041 until (6041 & mask) == value, within `sim_timeout` seconds of simulated time."""
    return bus.poll_sim(NODE, lambda: bus.upload_u(NODE, 0x6041 + axis * AXIS, 0),
                        lambda status: status & mask == value, sim_timeout,
                        f"axis {axis}: 6041 {value:#06x} under {mask:#06x}")


def test_device_type_and_supported_modes_per_axis(motwin):
    with TempDir() as tmp, serve(motwin, tmp) as server, server.bus() as bus:
        check_equal(bus.upload_u(NODE, 0x1000, 0), 0xFFFF0192, "1000: multi-device module, profile 402")
        for axis in range(3):
            check_equal(bus.upload_u(NODE, 0x67FF + axis * AXIS, 0), 0x00840192, f"67FF axis {axis}")
            check_equal(bus.upload_u(NODE, 0x6502 + axis * AXIS, 0), 0x1A5, f"6502 axis {axis}: pp pv hm csp csv")
            check_equal(state_of(bus.upload_u(NODE, 0x6041 + axis * AXIS, 0)), "SWITCH ON DISABLED", f"axis {axis}")
        check_equal(bus.abort_code(bus.download, NODE, 0x6060, 0, 2, 1), 0x06090030, "6060 = 2 (vl) refused")
        server.stop()


def test_python_canopen_state_transitions(motwin):
    with TempDir() as tmp, serve(motwin, tmp, speed=REALTIME) as server, server.bus() as bus:
        reset(bus)
        axis = 1
        bus.download(NODE, 0x2205, 0, 3, 4)
        bus.download(NODE, 0x6060 + axis * AXIS, 0, 3, 1)
        controlword(bus, 0x80, axis)  # BaseNode402 starts with a fault reset; nothing to reset
        expect_state(bus, "SWITCH ON DISABLED", axis)
        for cw, name in ((0x06, "READY TO SWITCH ON"), (0x07, "SWITCHED ON"), (0x0F, "OPERATION ENABLED")):
            controlword(bus, cw, axis)
            expect_state(bus, name, axis)
        status = bus.upload_u(NODE, 0x6041 + axis * AXIS, 0)
        check_equal(status & 0x0210, 0x0210, "remote and voltage enabled bits")
        # Disable operation (0x07) from standstill, enable again, shutdown (0x06), back up.
        controlword(bus, 0x07, axis)
        expect_state(bus, "SWITCHED ON", axis)
        controlword(bus, 0x0F, axis)
        expect_state(bus, "OPERATION ENABLED", axis)
        controlword(bus, 0x06, axis)
        expect_state(bus, "READY TO SWITCH ON", axis)
        controlword(bus, 0x0F, axis)  # 3 + 4 at once
        expect_state(bus, "OPERATION ENABLED", axis)
        # Quick stop while running (605A = 2 default): quick stop active, then switch on disabled.
        bus.download(NODE, 0x60FF + axis * AXIS, 0, 51200, 4)
        check_equal(bus.upload_u(NODE, 0x6041 + axis * AXIS, 0) & 0x0400, 0, "bit 10 drops with the 60FF write")
        wait_status(bus, 0x0400, 0x0400, 30.0, axis)  # 3 s of wall time at SPEED
        check_equal(bus.upload_u(NODE, 0x606C + axis * AXIS, 0), 51200, "at speed")
        controlword(bus, 0x0B, axis)
        status = bus.upload_u(NODE, 0x6041 + axis * AXIS, 0)
        check_equal(state_of(status), "QUICK STOP ACTIVE", "right after the quick stop command")
        expect_state(bus, "SWITCH ON DISABLED", axis, timeout=1.0)
        check_equal(bus.upload_u(NODE, 0x606C + axis * AXIS, 0), 0, "stopped")
        # 605A = 6: stays in quick stop active, enable operation resumes (transition 16).
        bus.download(NODE, 0x605A + axis * AXIS, 0, 6, 2)
        check_equal(bus.abort_code(bus.download, NODE, 0x605A + axis * AXIS, 0, 3, 2), 0x06090030, "605A = 3")
        for cw in (0x06, 0x0F):
            controlword(bus, cw, axis)
        expect_state(bus, "OPERATION ENABLED", axis)
        controlword(bus, 0x02, axis)
        bus.wait_sim(NODE, 3.0)
        check_equal(state_of(bus.upload_u(NODE, 0x6041 + axis * AXIS, 0)), "QUICK STOP ACTIVE", "605A = 6 stays")
        controlword(bus, 0x0F, axis)
        expect_state(bus, "OPERATION ENABLED", axis)
        # 6060 = 0 is accepted (ros2_canopen after homing); 6061 follows at once.
        bus.download(NODE, 0x6060 + axis * AXIS, 0, 0, 1)
        check_equal(bus.upload_u(NODE, 0x6061 + axis * AXIS, 0), 0, "6061 = 0")
        server.stop()


def test_fault_and_fault_reset_with_emcy(motwin):
    with TempDir() as tmp, serve(motwin, tmp) as server, server.bus() as bus, server.bus() as listener:
        reset(bus)
        bus.nmt(NMT_START, NODE)
        axis = 2
        bus.download(NODE, 0x2405, 0, 3, 4)
        bus.download(NODE, 0x6060 + axis * AXIS, 0, 3, 1)
        for cw in (0x06, 0x07, 0x0F):
            controlword(bus, cw, axis)
        expect_state(bus, "OPERATION ENABLED", axis)
        bus.nmt(NMT_STOP, NODE)  # NMT stopped takes the drive function away: FAULT
        bus.wait_sim_seen_by(listener, 1.0)  # ticks run while stopped (a stopped node answers no marker)
        bus.nmt(NMT_START, NODE)
        expect_state(bus, "FAULT", axis)
        check_equal(bus.upload_u(NODE, 0x1001, 0) & 0x01, 0x01, "1001 generic error while in FAULT")
        bus.drain(0.05)
        controlword(bus, 0x00, axis)
        controlword(bus, 0x80, axis)
        # Sent within the next millisecond, after the SDO response (read it before any other SDO).
        emcy = bus.receive(lambda m: m.arbitration_id == 0x80 + NODE, FRAME_TIMEOUT, "EMCY after the fault reset")
        expect_state(bus, "SWITCH ON DISABLED", axis)
        data = bytes(emcy.data)
        check_equal(len(data), 8, "EMCY length")
        check_equal(struct.unpack_from("<H", data, 0)[0], 0x0000, "EMCY 0000 (fault reset)")
        check_equal(data[4], axis, "additional byte 2: the motor")
        server.stop()


def test_homing_statusword_contract(motwin):
    with TempDir() as tmp, serve(motwin, tmp, "--set", "AXIS0_REF_H_AT=0.5", speed=REALTIME) as server, \
            server.bus() as bus:
        reset(bus)
        bus.download(NODE, 0x6060, 0, 6, 1)
        bus.download(NODE, 0x6098, 0, 19, 1)
        bus.download(NODE, 0x6099, 1, 40000, 4)
        bus.download(NODE, 0x6099, 2, 5000, 4)
        bus.download(NODE, 0x609A, 0, 200000, 4)
        bus.download(NODE, 0x607C, 0, (-1000) & 0xFFFFFFFF, 4)
        for cw in (0x06, 0x07, 0x0F):
            controlword(bus, cw)
        status = bus.upload_u(NODE, 0x6041, 0)
        check_equal(status & 0x3400, 0x0400, "ros2_canopen: bit 10 set while idle in homing mode")
        controlword(bus, 0x1F)
        status = bus.upload_u(NODE, 0x6041, 0)
        # python-canopen fails when it sees bit 10 without bit 12 after writing 0x1F.
        check_equal(status & 0x3400, 0, "bit 10 cleared with the bit 4 edge")
        status = wait_status(bus, 0x3400, 0x1400, 50.0)  # 5 s of wall time at SPEED
        check_equal(bus.upload_u(NODE, 0x6064, 0), (-1000) & 0xFFFFFFFF, "home point = home offset 607C")
        check_equal(bus.upload_u(NODE, 0x2100, 0), (-1000) & 0xFFFFFFFF, "2100 shows the home offset")
        controlword(bus, 0x0F)
        # Method 0: nothing to do, attained at once.
        bus.download(NODE, 0x6098, 0, 0, 1)
        controlword(bus, 0x1F)
        check_equal(bus.upload_u(NODE, 0x6041, 0) & 0x3400, 0x1400, "method 0 attained")
        controlword(bus, 0x0F)
        # ros2_canopen then switches to mode 0.
        bus.download(NODE, 0x6060, 0, 0, 1)
        check_equal(bus.upload_u(NODE, 0x6061, 0), 0, "6061 = 0 after homing")
        server.stop()


def test_pdo_operation_profile_velocity(motwin):
    """The default PDOs of axis 0 (tables 41-47): RPDO 1 = 6040, RPDO 4 = 6040 + 60FF,
    TPDO 1 = 6041 (event driven), TPDO 4 = 6041 + 606C (every SYNC)."""
    with TempDir() as tmp, serve(motwin, tmp) as server, server.bus() as bus:
        reset(bus)
        bus.download(NODE, 0x2005, 0, 3, 4)
        bus.download(NODE, 0x6060, 0, 3, 1)
        bus.nmt(NMT_START, NODE)
        first = bus.receive(lambda m: m.arbitration_id == 0x180 + NODE, FRAME_TIMEOUT, "TPDO 1 on entering operational")
        check_equal(bytes(first.data), bytes([0x40, 0x02]), "TPDO 1: switch on disabled")
        for cw, name in ((0x06, "READY TO SWITCH ON"), (0x07, "SWITCHED ON"), (0x0F, "OPERATION ENABLED")):
            bus.send(0x200 + NODE, struct.pack("<H", cw))
            tpdo = bus.receive(lambda m: m.arbitration_id == 0x180 + NODE, FRAME_TIMEOUT, f"TPDO 1 after {cw:#04x}")
            status = struct.unpack("<H", bytes(tpdo.data))[0]
            check_equal(state_of(status), name, f"TPDO 1 after RPDO 1 = {cw:#04x}")
        bus.send(0x500 + NODE, struct.pack("<Hi", 0x0F, 25600))  # RPDO 4: 6040 + 60FF
        bus.wait_sim(NODE, 3.0)  # at speed
        bus.drain(0.02)
        bus.send(0x080, [])
        tpdo4 = bus.receive(lambda m: m.arbitration_id == 0x480 + NODE, FRAME_TIMEOUT, "TPDO 4 after SYNC")
        status, velocity = struct.unpack("<Hi", bytes(tpdo4.data))
        check_equal(velocity, 25600, "606C in TPDO 4")
        check_equal(status & 0x4400, 0x4400, "target reached, motor activity")
        bus.send(0x500 + NODE, struct.pack("<Hi", 0x0F, 0))
        server.stop()


def test_csp_driven_by_sync_and_rpdo(motwin):
    """ros2_canopen-style cyclic position: the node produces the 1 kHz SYNC (1005 bit 30, 1006 =
    1000 µs), the master answers every SYNC with RPDO 3 (6040 + 607A), TPDO 3 (6041 + 6064) comes
    at every SYNC. The axis follows the set-points: each reported position is one that was sent
    (the demand lands on every set-point one period after the SYNC that took it)."""
    with TempDir() as tmp, CanServer(motwin, os.path.join(tmp, "state"), node_id=NODE, speed="0.2") as server, \
            server.bus() as bus:
        reset(bus)
        bus.download(NODE, 0x2005, 0, 3, 4)
        bus.download(NODE, 0x6060, 0, 8, 1)
        check_equal(bus.upload_u(NODE, 0x60C2, 1), 1, "60C2 sub 1")
        check_equal(bus.upload_u(NODE, 0x60C2, 2), 0xFD, "60C2 sub 2 = -3: 1 ms")
        for cw in (0x06, 0x07, 0x0F):
            controlword(bus, cw)
        bus.nmt(NMT_START, NODE)
        bus.download(NODE, 0x1006, 0, 1000, 4)
        bus.download(NODE, 0x1005, 0, 0x40000080, 4)  # produce the SYNC
        sent = [0]
        positions = []
        deadline = time.monotonic() + 60  # a liveness bound: 200 SYNCs are 1 s of wall time at speed 0.2
        while len(sent) < 200 and time.monotonic() < deadline:
            msg = bus.receive(lambda m: m.arbitration_id in (0x080, 0x380 + NODE), FRAME_TIMEOUT, "SYNC or TPDO 3")
            if msg.arbitration_id == 0x080:
                target = len(sent) * 25  # 25 µsteps per ms: 25000 pps
                bus.send(0x400 + NODE, struct.pack("<Hi", 0x0F, target))
                sent.append(target)
            else:
                status, position = struct.unpack("<Hi", bytes(msg.data))
                check_equal(status & 0x106F, 0x1027, f"TPDO 3 statusword {status:#06x}: enabled, set-point used")
                positions.append(position)
        # The node has the last set-point (a marker behind it is answered), two SYNCs later it has
        # taken it; a loaded machine may run the client faster than the SYNCs come.
        bus.frames_until_marker(NODE)
        for _ in range(2):
            bus.receive(lambda m: m.arbitration_id == 0x080, FRAME_TIMEOUT, "a SYNC after the last set-point")
        bus.download(NODE, 0x1005, 0, 0x80, 4)  # SYNC off: the axis holds the last set-point
        bus.wait_sim(NODE, 0.02)  # 0.1 s of wall time at speed 0.2
        check(len(positions) > 150, f"only {len(positions)} TPDO 3 frames")
        check(all(p in sent for p in positions), f"positions not among the set-points: "
              f"{[p for p in positions if p not in sent][:5]}")
        check(positions == sorted(positions), "positions never go back")
        last = i32(bus.upload_u(NODE, 0x6064, 0))
        check(last == sent[-1] or last == sent[-2], f"6064 {last} at one of the last set-points {sent[-2:]}")
        server.stop()


def pdo_setup_like_python_canopen(bus, comm, mapping, cob_id, trans_type, entries):
    """PdoMap.save() of python-canopen (ros2_canopen writes the same sequence from its DCF):
    COB-ID with bit 31 (not valid), transmission type, mapping count 0, the entries, the count,
    then the COB-ID valid. Bit 30 (no RTR) is set as python-canopen does."""
    bus.download(NODE, comm, 1, cob_id | 0x80000000 | 0x40000000, 4)
    bus.download(NODE, comm, 2, trans_type, 1)
    bus.download(NODE, mapping, 0, 0, 1)
    for sub, entry in enumerate(entries, start=1):
        bus.download(NODE, mapping, sub, entry, 4)
    bus.download(NODE, mapping, 0, len(entries), 1)
    bus.download(NODE, comm, 1, cob_id | 0x40000000, 4)


def test_pdo_setup_of_axis_1_in_master_order(motwin):
    """Remap axis 1's first RPDO (1440/1640) to 6840 + 687A and its first TPDO (1840/1A40) to
    6841 + 6864 (every SYNC) in python-canopen's order, make them valid, and run a pp move of
    axis 1 through them: the set-point handshake and the arrival show in the TPDO."""
    rpdo_cob, tpdo_cob = 0x220 + NODE, 0x1A0 + NODE
    with TempDir() as tmp, serve(motwin, tmp, speed=REALTIME) as server, server.bus() as bus:
        reset(bus)
        check_equal(bus.upload_u(NODE, 0x1440, 1) & 0x80000000, 0x80000000, "axis 1 RPDO 1 starts not valid")
        check_equal(bus.upload_u(NODE, 0x1640, 1), 0x68400010, "axis 1 RPDO 1 maps its own 6840")
        bus.download(NODE, 0x2205, 0, 3, 4)
        bus.download(NODE, 0x6060 + AXIS, 0, 1, 1)
        pdo_setup_like_python_canopen(bus, 0x1440, 0x1640, rpdo_cob, 255, [0x68400010, 0x687A0020])
        pdo_setup_like_python_canopen(bus, 0x1840, 0x1A40, tpdo_cob, 1, [0x68410010, 0x68640020])
        check_equal(bus.upload_u(NODE, 0x1440, 1), rpdo_cob | 0x40000000, "RPDO valid")
        check_equal([bus.upload_u(NODE, 0x1A40, sub) for sub in range(3)], [2, 0x68410010, 0x68640020],
                    "TPDO mapping read back")
        # A valid PDO's mapping cannot change (CiA-301): the master order above is required.
        check_equal(bus.abort_code(bus.download, NODE, 0x1640, 0, 1, 1), 0x08000022, "mapping of a valid RPDO")
        bus.nmt(NMT_START, NODE)
        for cw, name in ((0x06, "READY TO SWITCH ON"), (0x07, "SWITCHED ON"), (0x0F, "OPERATION ENABLED")):
            bus.send(rpdo_cob, struct.pack("<Hi", cw, 0))
            expect_state(bus, name, axis=1)
        bus.send(rpdo_cob, struct.pack("<Hi", 0x1F, 25600))
        bus.drain(0.02)
        bus.send(0x080, [])
        tpdo = bus.receive(lambda m: m.arbitration_id == tpdo_cob, FRAME_TIMEOUT, "axis 1 TPDO after SYNC")
        status, _ = struct.unpack("<Hi", bytes(tpdo.data))
        check_equal(status & 0x146F, 0x1027, f"set-point acknowledged, moving ({status:#06x})")
        bus.send(rpdo_cob, struct.pack("<Hi", 0x0F, 25600))
        # 25600 µsteps at 51200 pps / 51200 pps²: 1.5 s simulated. The TPDOs' stamps (simulated
        # time) bound the wait: 30 s, as 3 s of wall time did at SPEED.
        deadline = tpdo.timestamp + 30.0
        status, position = 0, None
        while tpdo.timestamp < deadline:
            time.sleep(0.02)
            bus.drain(0.005)
            bus.send(0x080, [])
            tpdo = bus.receive(lambda m: m.arbitration_id == tpdo_cob, FRAME_TIMEOUT, "axis 1 TPDO after SYNC")
            status, position = struct.unpack("<Hi", bytes(tpdo.data))
            if status & 0x0400:
                break
        check_equal(status & 0x146F, 0x0427, f"target reached, acknowledge dropped ({status:#06x})")
        check_equal(position, 25600, "6864 of axis 1 in its TPDO")
        check_equal(bus.upload_u(NODE, 0x6064, 0), 0, "axis 0 stayed")
        server.stop()


def i32(value):
    return value - (1 << 32) if value & 0x80000000 else value


def main():
    run_can_tests([
        test_device_type_and_supported_modes_per_axis,
        test_python_canopen_state_transitions,
        test_fault_and_fault_reset_with_emcy,
        test_homing_statusword_contract,
        test_pdo_operation_profile_velocity,
        test_csp_driven_by_sync_and_rpdo,
        test_pdo_setup_of_axis_1_in_master_order,
    ])


if __name__ == "__main__":
    main()
