#!/usr/bin/python3
"""PDOs of the TMCM-3216 over the socketcand server, raw frames on Debian's python3-can:
reconfiguration in python-canopen's exact order (PdoMap.save) with the refusals of a valid PDO,
a not mappable object and a mapping over 64 bits; first transmission on entering operational and
the event timer (gaps checked in the simulated-time stamps); no PDOs outside operational; RPDO
length errors answered by EMCY 8210 / 8220 and 0000; the PDO configuration stored with 1010 and
back after a restart of the server.
"""

import os
import sys

sys.dont_write_bytecode = True  # no __pycache__ in the source tree
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

from canopen_harness import (  # noqa: E402
    NMT_PREOP, NMT_START, SAVE, CanServer, check, check_equal, run_can_tests,
)
from motwin_harness import FRAME_TIMEOUT, TempDir  # noqa: E402

NODE = 9
DUMMY_U8, DUMMY_U16, DUMMY_U32 = 0x00050008, 0x00060010, 0x00070020


def serve(motwin, tmp):
    return CanServer(motwin, os.path.join(tmp, "state"), node_id=NODE)


def pdo_frames(frames, cob_id):
    return [m for m in frames if m.arbitration_id == cob_id]


def test_default_pdos_of_axis_0(motwin):
    # Tables 45/47: TPDO 1 (6041) and TPDO 2 (6041, 6061) are event driven and go out once on
    # entering operational; TPDO 3/4 are synchronous; the PDOs of axes 1 and 2 start disabled.
    with TempDir() as tmp, serve(motwin, tmp) as server, server.bus() as bus:
        bus.nmt(NMT_START, NODE)
        is_pdo = lambda m: 0x180 <= m.arbitration_id < 0x580  # noqa: E731
        first = bus.receive(is_pdo, FRAME_TIMEOUT, "a TPDO on entering operational")
        frames = [first] + bus.collect_sim(NODE, 0.3, is_pdo, since=first.timestamp)
        check_equal([(m.arbitration_id, bytes(m.data)) for m in frames],
                    [(0x180 + NODE, bytes([0x40, 0x02])), (0x280 + NODE, bytes([0x40, 0x02, 0x00]))],
                    "TPDO 1 and 2 of axis 0 (switch on disabled, mode 0)")
        server.stop()


def test_reconfiguration_in_python_canopen_order_and_event_timer(motwin):
    with TempDir() as tmp, serve(motwin, tmp) as server, server.bus() as bus:
        cob_id = 0x180 + NODE
        bus.configure_pdo(NODE, 0x1800, cob_id, 0xFF, [DUMMY_U32, DUMMY_U16], event_ms=100)
        check_equal(bus.upload_u(NODE, 0x1A00, 0), 2, "1A00 sub 0")
        check_equal(bus.upload_u(NODE, 0x1A00, 1), DUMMY_U32, "1A00 sub 1")
        check_equal(bus.upload_u(NODE, 0x1800, 5), 100, "1800 sub 5 event timer")
        check_equal(bus.collect(0.2, lambda m: m.arbitration_id == cob_id), [], "TPDO in pre-operational")
        bus.nmt(NMT_START, NODE)
        # 0.75 s of simulated time from the first TPDO on, which goes out with the NMT command.
        first = bus.receive(lambda m: m.arbitration_id == cob_id, FRAME_TIMEOUT, "the first TPDO")
        frames = [first] + pdo_frames(bus.collect_sim(NODE, 0.75, since=first.timestamp), cob_id)
        check(6 <= len(frames) <= 9, f"{len(frames)} TPDOs in 0.75 s (simulated) with a 100 ms event timer")
        check_equal(bytes(frames[0].data), bytes(6), "TPDO data (6 dummy bytes)")
        gaps = [round((b.timestamp - a.timestamp) * 1000) for a, b in zip(frames, frames[1:])]
        # The first one goes out when the NMT frame arrives, between two 1 ms service ticks.
        check(99 <= gaps[0] <= 100 and all(gap == 100 for gap in gaps[1:]),
              f"TPDO gaps in ms of simulated time: {gaps}")
        bus.nmt(NMT_PREOP, NODE)
        bus.frames_until_marker(NODE)  # what was sent before the NMT command took effect
        check_equal(bus.collect(0.3, lambda m: m.arbitration_id == cob_id), [], "TPDOs in pre-operational")
        server.stop()


def test_mapping_refusals(motwin):
    with TempDir() as tmp, serve(motwin, tmp) as server, server.bus() as bus:
        check_equal(bus.abort_code(bus.download, NODE, 0x1A01, 0, 0, 1), 0x08000022, "mapping of a valid PDO")
        bus.download(NODE, 0x1801, 1, 0x80000280 + NODE, 4)
        bus.download(NODE, 0x1A01, 0, 0, 1)
        check_equal(bus.abort_code(bus.download, NODE, 0x1A01, 1, 0x10000020, 4), 0x06040041, "1000 not mappable")
        check_equal(bus.abort_code(bus.download, NODE, 0x1A01, 1, 0x60430010, 4), 0x06040041, "6043 absent")
        for sub, entry in ((1, DUMMY_U32), (2, DUMMY_U32), (3, DUMMY_U8)):
            bus.download(NODE, 0x1A01, sub, entry, 4)
        check_equal(bus.abort_code(bus.download, NODE, 0x1A01, 0, 3, 1), 0x06040042, "72 bits")
        check_equal(bus.abort_code(bus.download, NODE, 0x1801, 2, 252, 1), 0x06090030, "RTR-only type 252")
        bus.download(NODE, 0x1A01, 0, 2, 1)
        check_equal(bus.abort_code(bus.download, NODE, 0x1A01, 1, DUMMY_U8, 4), 0x08000022, "entry while sub 0 = 2")
        server.stop()


def test_rpdo_length_errors_send_emcy(motwin):
    with TempDir() as tmp, serve(motwin, tmp) as server, server.bus() as bus:
        bus.configure_pdo(NODE, 0x1400, 0x200 + NODE, 0xFF, [DUMMY_U16, DUMMY_U8])
        bus.nmt(NMT_START, NODE)
        bus.drain(0.05)
        emcy = 0x80 + NODE
        bus.send(0x200 + NODE, [1, 2])
        msg = bus.receive(lambda m: m.arbitration_id == emcy, FRAME_TIMEOUT, "EMCY 8210")
        check_equal(bytes(msg.data), bytes([0x10, 0x82, 0x11, 0x00, 0xFF, 0, 0, 0]), "EMCY 8210 (PDO too short)")
        check_equal(bus.upload_u(NODE, 0x1001, 0), 0x11, "1001 during the error")
        bus.send(0x200 + NODE, [1, 2, 3])
        msg = bus.receive(lambda m: m.arbitration_id == emcy, FRAME_TIMEOUT, "EMCY 0000")
        check_equal(bytes(msg.data), bytes([0, 0, 0, 0, 0xFF, 0, 0, 0]), "EMCY 0000 (error reset)")
        bus.send(0x200 + NODE, [1, 2, 3, 4, 5])
        msg = bus.receive(lambda m: m.arbitration_id == emcy, FRAME_TIMEOUT, "EMCY 8220")
        check_equal(bytes(msg.data[:3]), bytes([0x20, 0x82, 0x11]), "EMCY 8220 (PDO too long)")
        server.stop()


def test_pdo_configuration_survives_store_and_restart(motwin):
    with TempDir() as tmp:
        with serve(motwin, tmp) as server, server.bus() as bus:
            bus.configure_pdo(NODE, 0x1801, 0x280 + NODE, 0xFE, [DUMMY_U8], event_ms=50)
            bus.download(NODE, 0x1010, 1, SAVE, 4)
            server.stop()
        with serve(motwin, tmp) as server, server.bus() as bus:
            check_equal(bus.upload_u(NODE, 0x1801, 2), 0xFE, "1801 sub 2 after restart")
            check_equal(bus.upload_u(NODE, 0x1A01, 0), 1, "1A01 sub 0 after restart")
            check_equal(bus.upload_u(NODE, 0x1A01, 1), DUMMY_U8, "1A01 sub 1 after restart")
            bus.nmt(NMT_START, NODE)
            first = bus.receive(lambda m: m.arbitration_id == 0x280 + NODE, FRAME_TIMEOUT, "the first TPDO 2")
            frames = [first] + pdo_frames(bus.collect_sim(NODE, 0.4, since=first.timestamp), 0x280 + NODE)
            check(len(frames) >= 5, f"{len(frames)} TPDOs in 0.4 s (simulated) at 50 ms after the restart")
            check_equal(bytes(frames[0].data), b"\0", "TPDO 2 data")
            server.stop()


def main():
    run_can_tests([
        test_default_pdos_of_axis_0,
        test_reconfiguration_in_python_canopen_order_and_event_timer,
        test_mapping_refusals,
        test_rpdo_length_errors_send_emcy,
        test_pdo_configuration_survives_store_and_restart,
    ])


if __name__ == "__main__":
    main()
