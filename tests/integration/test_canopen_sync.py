#!/usr/bin/python3
"""SYNC of the TMCM-3216 over the socketcand server, raw frames on Debian's python3-can: TPDOs of
synchronous types 1..240 counted in the master's SYNC frames (only in operational, counting from
entering operational), a changed 1005 COB-ID, and the SYNC producer of 1005 bit 30 with the 1006
period (a Motwin extension) driving the node's own synchronous TPDOs.
"""

import os
import sys

sys.dont_write_bytecode = True  # no __pycache__ in the source tree
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

from canopen_harness import NMT_PREOP, NMT_START, NMT_STOP, CanServer, check, check_equal, run_can_tests  # noqa: E402
from motwin_harness import TempDir  # noqa: E402

NODE = 11
DUMMY_U16 = 0x00060010


def serve(motwin, tmp):
    return CanServer(motwin, os.path.join(tmp, "state"), node_id=NODE)


def sync_and_collect(bus, count, cob_id, sync_id=0x080, stopped=False):
    """Sends `count` SYNCs; returns the SYNC numbers (1-based) after which the TPDO came: before
    the node's answer to the marker that follows each SYNC. A stopped node answers no marker:
    then whatever comes within 50 ms counts (no TPDO is expected)."""
    answered = []
    for n in range(1, count + 1):
        bus.send(sync_id, [])
        is_tpdo = lambda m: m.arbitration_id == cob_id  # noqa: E731
        if bus.collect(0.05, is_tpdo) if stopped else bus.frames_until_marker(NODE, is_tpdo):
            answered.append(n)
    return answered


def test_synchronous_tpdos_count_master_syncs(motwin):
    with TempDir() as tmp, serve(motwin, tmp) as server, server.bus() as bus:
        tpdo3 = 0x380 + NODE
        bus.configure_pdo(NODE, 0x1802, tpdo3, 3, [DUMMY_U16])
        check_equal(sync_and_collect(bus, 4, tpdo3), [], "TPDOs at SYNCs in pre-operational")
        bus.nmt(NMT_START, NODE)
        bus.drain(0.05)
        check_equal(sync_and_collect(bus, 9, tpdo3), [3, 6, 9], "type 3: every third SYNC")
        bus.download(NODE, 0x1005, 0, 0x85, 4)
        check_equal(sync_and_collect(bus, 3, tpdo3), [], "SYNCs on the old COB-ID")
        check_equal(sync_and_collect(bus, 3, tpdo3, sync_id=0x85), [3], "SYNCs on the new COB-ID 0x85")
        bus.nmt(NMT_STOP, NODE)
        bus.drain(0.05)
        check_equal(sync_and_collect(bus, 3, tpdo3, sync_id=0x85, stopped=True), [], "TPDOs at SYNCs while stopped")
        server.stop()


def test_sync_producer_drives_own_synchronous_tpdos(motwin):
    with TempDir() as tmp, serve(motwin, tmp) as server, server.bus() as bus:
        tpdo1 = 0x180 + NODE
        bus.configure_pdo(NODE, 0x1800, tpdo1, 2, [DUMMY_U16])
        bus.download(NODE, 0x1006, 0, 20000, 4)        # 20 ms
        bus.download(NODE, 0x1005, 0, 0x40000080, 4)   # bit 30: produce
        check_equal(bus.upload_u(NODE, 0x1005, 0), 0x40000080, "1005 read back")
        frames = bus.collect_sim(NODE, 0.3)
        syncs = [m for m in frames if m.arbitration_id == 0x080]
        check(12 <= len(syncs) <= 17, f"{len(syncs)} SYNCs in 0.3 s (simulated) at 20 ms")
        check(all(len(m.data) == 0 for m in syncs), "SYNC without data (no counter)")
        gaps = [round((b.timestamp - a.timestamp) * 1000) for a, b in zip(syncs, syncs[1:])]
        check(all(gap == 20 for gap in gaps), f"SYNC gaps in ms of simulated time: {gaps}")
        check_equal([m for m in frames if m.arbitration_id == tpdo1], [], "TPDOs in pre-operational")
        bus.nmt(NMT_START, NODE)
        frames = bus.collect_sim(NODE, 0.4)  # from a marker answered after the NMT command
        syncs = [m for m in frames if m.arbitration_id == 0x080]
        tpdos = [m for m in frames if m.arbitration_id == tpdo1]
        check(len(syncs) >= 10, f"{len(syncs)} SYNCs in 0.4 s (simulated)")
        check(abs(len(tpdos) - len(syncs) / 2) <= 1, f"{len(tpdos)} TPDOs for {len(syncs)} SYNCs with type 2")
        for tpdo in tpdos:
            check_equal(bytes(tpdo.data), b"\0\0", "TPDO data")
        bus.download(NODE, 0x1005, 0, 0x80, 4)  # producer off
        bus.drain(0.05)
        check_equal(bus.collect(0.2, lambda m: m.arbitration_id == 0x080), [], "SYNCs after bit 30 cleared")
        bus.nmt(NMT_PREOP, NODE)
        server.stop()


def main():
    run_can_tests([
        test_synchronous_tpdos_count_master_syncs,
        test_sync_producer_drives_own_synchronous_tpdos,
    ])


if __name__ == "__main__":
    main()
