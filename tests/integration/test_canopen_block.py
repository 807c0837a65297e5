#!/usr/bin/python3
"""SDO block transfer (CiA-301) of the TMCM-3216 over the socketcand server, raw frames on Debian's
python3-can: block upload of 1008 and 1018 with CRC, in sub-blocks of 127 and of 1 segment;
block download of 1017 and 1016 with CRC and read-back; a wrong CRC aborts 05040004 and leaves
the object unchanged; the protocol switch threshold answers small objects with a normal upload;
block size 0 aborts 05040002; a client that disappears mid-transfer is timed out (05040000) and
the server goes on serving.
"""

import os
import struct
import sys

sys.dont_write_bytecode = True  # no __pycache__ in the source tree
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

from can_bus_harness import collect_through  # noqa: E402
from canopen_harness import CanServer, check_equal, crc16_ccitt, run_can_tests  # noqa: E402
from motwin_harness import FRAME_TIMEOUT, TempDir  # noqa: E402

NODE = 7


def serve(motwin, tmp):
    return CanServer(motwin, os.path.join(tmp, "state"), node_id=NODE)


def test_block_upload_with_crc(motwin):
    with TempDir() as tmp, serve(motwin, tmp) as server, server.bus() as bus:
        check_equal(bus.block_upload(NODE, 0x1008, 0), b"TMCM-3216", "1008 by block upload")
        check_equal(bus.block_upload(NODE, 0x1008, 0, blksize=1), b"TMCM-3216", "1008 in sub-blocks of 1")
        check_equal(bus.block_upload(NODE, 0x1008, 0, crc=False), b"TMCM-3216", "1008 without CRC")
        check_equal(bus.block_upload(NODE, 0x1018, 2), struct.pack("<I", 3216), "1018 sub 2 by block upload")
        server.stop()


def test_block_download_with_crc(motwin):
    with TempDir() as tmp, serve(motwin, tmp) as server, server.bus() as bus:
        bus.block_download(NODE, 0x1017, 0, struct.pack("<H", 1234))
        check_equal(bus.upload_u(NODE, 0x1017, 0), 1234, "1017 after block download")
        bus.block_download(NODE, 0x1016, 1, struct.pack("<I", 0x00030064), crc=False)
        check_equal(bus.upload_u(NODE, 0x1016, 1), 0x00030064, "1016 sub 1 after block download")
        bus.download(NODE, 0x1017, 0, 0, 2)
        server.stop()


def test_wrong_crc_and_bad_block_size_abort(motwin):
    with TempDir() as tmp, serve(motwin, tmp) as server, server.bus() as bus:
        value = struct.pack("<H", 777)
        code = bus.abort_code(bus.block_download, NODE, 0x1017, 0, value, True, crc16_ccitt(value) ^ 0x0001)
        check_equal(code, 0x05040004, "wrong CRC")
        check_equal(bus.upload_u(NODE, 0x1017, 0), 0, "1017 unchanged after the CRC error")
        check_equal(bus.abort_code(bus.block_upload, NODE, 0x1008, 0, 0), 0x05040002, "block size 0")
        check_equal(bus.abort_code(bus.block_upload, NODE, 0x1008, 0, 128), 0x05040002, "block size 128")
        check_equal(bus.abort_code(bus.block_upload, NODE, 0x1234, 0), 0x06020000, "absent object")
        check_equal(bus.abort_code(bus.block_download, NODE, 0x1000, 0, b"\0\0\0\0"), 0x06010002, "read-only")
        server.stop()


def test_protocol_switch_threshold(motwin):
    with TempDir() as tmp, serve(motwin, tmp) as server, server.bus() as bus:
        # pst 21: 1008 (9 bytes) comes as a normal segmented upload.
        bus.send(0x600 + NODE, [0xA4, 0x08, 0x10, 0x00, 127, 21, 0, 0])
        msg = bus.receive(lambda m: m.arbitration_id == 0x580 + NODE, FRAME_TIMEOUT,
                          "answer to a block upload with pst")
        check_equal(bytes(msg.data), bytes([0x41, 0x08, 0x10, 0x00, 9, 0, 0, 0]), "segmented initiate response")
        bus.send(0x600 + NODE, [0x80, 0x08, 0x10, 0x00, 0, 0, 0, 0])  # client abort
        check_equal(bus.upload(NODE, 0x1008, 0), b"TMCM-3216", "segmented upload after the client's abort")
        server.stop()


def test_client_gone_mid_block_transfer(motwin):
    with TempDir() as tmp, serve(motwin, tmp) as server:
        with server.bus() as bus:
            bus.send(0x600 + NODE, [0xC6, 0x17, 0x10, 0x00, 2, 0, 0, 0])
            bus.receive(lambda m: m.arbitration_id == 0x580 + NODE, FRAME_TIMEOUT, "block download initiate response")
        with server.bus() as bus:
            # Inside a sub-block every frame is a segment, so the stale transfer ends by the server's
            # 1 s timeout (abort 05040000), not by a new initiate.
            aborts = collect_through(bus.bus, lambda m: m.arbitration_id == 0x580 + NODE, lambda m: True, linger=0.5)
            check_equal([bytes(m.data) for m in aborts], [bytes([0x80, 0x17, 0x10, 0x00, 0x00, 0x00, 0x04, 0x05])],
                        "timeout abort of the abandoned block download")
            check_equal(bus.block_upload(NODE, 0x1008, 0), b"TMCM-3216", "block upload by a new client")
        server.stop()


def main():
    run_can_tests([
        test_block_upload_with_crc,
        test_block_download_with_crc,
        test_wrong_crc_and_bad_block_size_abort,
        test_protocol_switch_threshold,
        test_client_gone_mid_block_transfer,
    ])


if __name__ == "__main__":
    main()
