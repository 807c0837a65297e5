"""CAN helpers for the integration tests: `motwin serve --module tmcm-3216 --can socketcand:...`
and a raw-frame CANopen client on Debian's python3-can (socketcand interface).

Builds on motwin_harness (process handling, the serve contract, watchdog, run_tests): CanServer
only declares its banner and endpoint lines. The python-can bus itself (opening, receiving,
collecting) is can_bus_harness's. Raw frames on purpose: what is checked is the wire, not a library's view.
"""

import itertools
import socket
import struct
import time

import can_bus_harness
import motwin_harness as mh
from motwin_harness import FRAME_TIMEOUT, ServerError, TestFailure, check, check_equal  # noqa: F401 - re-exported

NMT_START, NMT_STOP, NMT_PREOP, NMT_RESET_NODE, NMT_RESET_COMM = 0x01, 0x02, 0x80, 0x81, 0x82
STATE_BOOTUP, STATE_STOPPED, STATE_OPERATIONAL, STATE_PREOP = 0x00, 0x04, 0x05, 0x7F
SAVE = 0x65766173
LOAD = 0x64616F6C
# A liveness bound (an answer must come at all), generous for the ASan build on a loaded machine.
SDO_TIMEOUT = 10.0
# The simulation falls behind the wall clock when the machine is loaded (src/host/pacing.h):
# waits for simulated progress fail only when simulated time stands still this long.
SIM_STALL_LIMIT = 60.0
# A frame a test sends to order events on the bus: no CANopen service uses this identifier.
SEQUENCE_POINT_ID = 0x7FF
_sequence_point_numbers = itertools.count()
# Markers: SDO uploads of 1000 (device type, a variable) with a sub-index 1..255 that tells them
# apart; each is answered at once with the abort 06090011 (no such sub-index), which echoes the
# sub-index and is stamped with the bus time.
_marker_numbers = itertools.count()


def crc16_ccitt(data, crc=0):
    """CRC of SDO block transfer: polynomial 0x1021, initial value 0, no reflection."""
    for byte in data:
        crc ^= byte << 8
        for _ in range(8):
            crc = ((crc << 1) ^ 0x1021) & 0xFFFF if crc & 0x8000 else (crc << 1) & 0xFFFF
    return crc


class CanServer(mh.Server):
    """`motwin serve` running a TMCM-3216 on a socketcand endpoint on a free port."""

    BANNER = r"motwin: tmcm-3216 \(CANopen V1\.04\) eeprom (.+)"
    PORT_ENDPOINTS = {"can-socketcand": "can_port", "can-slcan-tcp": "slcan_port"}

    def __init__(self, motwin, state_dir, node_id=None, speed=None, extra_args=(),
                 can=("socketcand:127.0.0.1:0",), env=None):
        args = [arg for spec in can for arg in ("--can", spec)]
        if node_id is not None:
            args += ["--node-id", str(node_id)]
        super().__init__(motwin, state_dir, tcp=False, speed=speed, extra_args=args + list(extra_args),
                         module="tmcm-3216", env=env)

    def bus(self):
        return CanopenClient(self.can_port)

    def slcan_bus(self):
        return CanopenClient(self.slcan_port, interface="slcan")


def check_store_and_restore_across_restart(serve, connect, node, store_more=lambda bus: None,
                                           check_more_stored=lambda bus: None, check_more_restored=lambda bus: None):
    """The storage contract of docs/canopen.md ("Device contract masters rely on"): what 1010 sub 1
    ("save") stored comes back after a restart of the server, an unsaved 1015 does not, and the
    defaults 1011 sub 1 ("load") restores apply at the next reset node, not before.

    serve(): a new CanServer on the same state directory each time; connect(server): the client
    the test speaks through (server.bus, server.slcan_bus). store_more(bus) sets what else the test
    stores (before the save); check_more_stored(bus) checks it after the restart and
    check_more_restored(bus) after the restore and reset."""
    with serve() as server, connect(server) as bus:
        bus.download(node, 0x1017, 0, 250, 2)
        store_more(bus)
        bus.download(node, 0x1010, 1, SAVE, 4)
        bus.download(node, 0x1015, 0, 7, 2)  # not saved
        server.stop()
    with serve() as server, connect(server) as bus:
        check_equal(bus.upload_u(node, 0x1017, 0), 250, "1017 after restart")
        check_more_stored(bus)
        check_equal(bus.upload_u(node, 0x1015, 0), 0, "unsaved 1015 after restart")
        bus.download(node, 0x1011, 1, LOAD, 4)
        check_equal(bus.upload_u(node, 0x1017, 0), 250, "restored defaults wait for a reset")
        bus.nmt(NMT_RESET_NODE, node)
        bus.wait_state(node, STATE_BOOTUP)
        check_equal(bus.upload_u(node, 0x1017, 0), 0, "1017 after restore and reset")
        check_more_restored(bus)
        server.stop()


class SdoAborted(TestFailure):
    def __init__(self, code, index, sub):
        super().__init__(f"SDO abort {code:08X} on {index:04X} sub {sub}")
        self.code = code


class CanopenClient:
    """python-can's socketcand Bus with CANopen master helpers speaking raw frames.

    Simulated time: socketcand frames carry the bus time (simulated seconds) as their stamp, and
    the simulation runs slower than the wall clock on a loaded machine. What a test expects of
    simulated time (a period, a ramp, a timeout of the node) it waits for in simulated time:
    sim_now(), wait_sim(), poll_sim(), collect_sim(). python-can stamps SLCAN frames with wall
    time: an SLCAN client measures simulated time with a socketcand client on the same bus."""

    def __init__(self, port, interface="socketcand"):
        import can  # Debian's python3-can
        self.can = can
        self.stamps_simulated_time = interface == "socketcand"
        self.bus = can_bus_harness.open_bus(port, interface)

    def close(self):
        self.bus.shutdown()

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()

    def send(self, cob_id, data):
        self.bus.send(self.can.Message(arbitration_id=cob_id, data=bytes(data), is_extended_id=False))

    def receive(self, predicate, timeout, what="frame"):
        """The first frame for which predicate(msg) is true; other frames are skipped."""
        return can_bus_harness.receive(self.bus, predicate, timeout, what)

    def collect(self, duration, predicate=lambda msg: True):
        """Every frame matching predicate within `duration` seconds (wall time)."""
        return can_bus_harness.collect(self.bus, duration, predicate)

    def drain(self, duration=0.05):
        self.collect(duration)

    # Simulated time ---------------------------------------------------------------------------------
    def frames_until_marker(self, node, predicate=lambda msg: True):
        """Sends a marker to `node` and returns the frames matching predicate that arrive before
        its answer: the node handles frames in the order the bus carries them and answers an SDO
        request at once, so what it did for every frame sent before the marker (a TPDO at a
        SYNC, say) is among them. The node must answer SDO (not stopped)."""
        frames = []
        self._marker(node, predicate, frames)
        return frames

    def frames_seen_by(self, listener, node, predicate=lambda msg: True):
        """frames_until_marker() as `listener`, a socketcand client on the same bus, sees them:
        this client's own frames among them, with the bus times they were taken in. This client
        sends the marker and reads up to its answer too, so that the answer is not taken for the
        reply to a later SDO request of either client."""
        check(listener.stamps_simulated_time, "bus times need a socketcand listener")
        frames = []
        answer = self._marker(node)
        listener._follow_marker(node, answer, predicate, frames)
        return frames

    def _marker(self, node, predicate=None, frames=None):
        """Sends a new marker to `node` and reads up to its answer (see _up_to_marker_answer)."""
        sub = 1 + next(_marker_numbers) % 255
        self.send(0x600 + node, [0x40, 0x00, 0x10, sub, 0, 0, 0, 0])
        return self._up_to_marker_answer(node, sub, predicate, frames)

    def _up_to_marker_answer(self, node, sub, predicate=None, frames=None):
        """Reads up to the answer of `node` to marker `sub`; frames before it that match
        `predicate` are appended to `frames` (bus order), other markers and their answers
        excepted. Returns the answer."""
        while True:
            msg = self.receive(lambda m: True, SDO_TIMEOUT, f"SDO answer of node {node} to marker {sub}")
            data = bytes(msg.data)
            is_marker = len(data) == 8 and data[1:3] == b"\x00\x10" and data[3] != 0 and (
                (msg.arbitration_id == 0x600 + node and data[0] == 0x40) or msg.arbitration_id == 0x580 + node)
            if is_marker and msg.arbitration_id == 0x580 + node and data[3] == sub:
                return msg
            if not is_marker and predicate is not None and predicate(msg):
                frames.append(msg)

    def _follow_marker(self, node, answer, predicate=None, frames=None):
        """Reads up to the answer to another client's marker (collect_sim with a clock)."""
        return self._up_to_marker_answer(node, answer.data[3], predicate, frames)

    def sim_now(self, node, others=()):
        """The bus time (simulated seconds) now: the stamp of `node`'s answer to a marker. This
        client and `others` (clients on the same bus, SLCAN ones too) drop what arrived before
        it, so that they all go on from the same point of the bus."""
        check(self.stamps_simulated_time, "simulated time needs a socketcand client")
        answer = self._marker(node)
        for other in others:
            other._follow_marker(node, answer)
        return answer.timestamp

    def wait_sim(self, node, seconds):
        """Waits until `seconds` of simulated time have passed (what time.sleep(seconds / speed)
        means when the host keeps up). Frames that arrive meanwhile are dropped."""
        if seconds > 0:
            self.poll_sim(node, lambda: None, lambda _: False, seconds, "simulated time", fail=False)

    def wait_sim_until(self, node, sim_time):
        """Waits until the bus time is `sim_time` (simulated seconds since the server started, the
        clock of --scenario files)."""
        self.wait_sim(node, sim_time - self.sim_now(node))

    def receive_sim(self, node, predicate, sim_timeout, what="frame"):
        """receive() with a timeout in simulated time: the first frame matching predicate, which
        must come within `sim_timeout` seconds of simulated time (marker stamps of `node`)."""
        frames = []
        start = last = self._marker(node, predicate, frames).timestamp
        last_progress = time.monotonic()
        while not frames:
            time.sleep(0.005)
            now = self._marker(node, predicate, frames).timestamp
            if frames:
                break
            if now >= start + sim_timeout:
                raise TestFailure(f"no {what} within {sim_timeout} s of simulated time")
            if now > last:
                last, last_progress = now, time.monotonic()
            elif time.monotonic() - last_progress > SIM_STALL_LIMIT:
                raise TestFailure(f"{what}: simulated time stood still at {now} s for {SIM_STALL_LIMIT} s")
        return frames[0]

    def wait_sim_seen_by(self, listener, seconds):
        """wait_sim() for any NMT state (a stopped node answers no marker): this client sends
        sequence points (SEQUENCE_POINT_ID) until `listener`, a socketcand client on the same bus,
        sees one stamped `seconds` later than the first. The bus stamps a client's frame with the
        simulated time it takes it in, after every frame this client sent before."""
        check(listener.stamps_simulated_time, "simulated time needs a socketcand client")

        def stamp_of_a_sequence_point():
            number = next(_sequence_point_numbers) & 0xFFFF
            point = bytes([2, number & 0xFF, number >> 8])
            self.send(SEQUENCE_POINT_ID, point)
            return listener.receive(lambda m: m.arbitration_id == SEQUENCE_POINT_ID and bytes(m.data) == point,
                                    FRAME_TIMEOUT, "a sequence point").timestamp

        start = last = stamp_of_a_sequence_point()
        last_progress = time.monotonic()
        while last < start + seconds:
            time.sleep(0.005)
            now = stamp_of_a_sequence_point()
            if now > last:
                last, last_progress = now, time.monotonic()
            elif time.monotonic() - last_progress > SIM_STALL_LIMIT:
                raise TestFailure(f"simulated time stood still at {now} s for {SIM_STALL_LIMIT} s")

    def poll_sim(self, node, probe, done, sim_timeout, what, interval=0.005, fail=True):
        """Calls probe() (SDO requests) until done(its value); returns that value. Fails when
        `sim_timeout` seconds of simulated time (marker stamps of `node`) passed without it, or
        the simulated time stood still for SIM_STALL_LIMIT seconds of wall time; with fail=False
        returns None once the simulated time is up."""
        start = last = self.sim_now(node)
        last_progress = time.monotonic()
        while True:
            value = probe()
            if done(value):
                return value
            now = self.sim_now(node)
            if now >= start + sim_timeout:
                if not fail:
                    return None
                raise TestFailure(f"{what}: not within {sim_timeout} s of simulated time (last {value!r})")
            if now > last:
                last, last_progress = now, time.monotonic()
            elif time.monotonic() - last_progress > SIM_STALL_LIMIT:
                raise TestFailure(f"{what}: simulated time stood still at {now} s for {SIM_STALL_LIMIT} s")
            time.sleep(interval)

    def collect_sim(self, node, duration, predicate=lambda msg: True, since=None, clock=None):
        """collect() in simulated time: every frame matching predicate that the bus carries from
        `since` (a sim_now(); default: now, the answer to a first marker) until `duration`
        seconds later, as this client receives them. Markers to `node` (which must answer SDO:
        pre-operational or operational) find the end of the window in bus order. `clock`: a
        socketcand client on the same bus when this client's stamps are wall time (SLCAN): it
        sees the same frames with their bus times, and this client's must be the same ones
        (pass since=clock.sim_now(node, others=[this client]) to start elsewhere than now)."""
        clock = clock or self
        check(clock.stamps_simulated_time, "simulated time needs a socketcand client")
        others = [self] if clock is not self else []
        if since is None:
            since = clock.sim_now(node, others)
        mine, theirs = [], []
        last, last_progress = since, time.monotonic()
        while True:
            answer = clock._marker(node, predicate, theirs)
            now = answer.timestamp
            for other in others:
                other._follow_marker(node, answer, predicate, mine)
            if now >= since + duration:
                break
            if now > last:
                last, last_progress = now, time.monotonic()
            elif time.monotonic() - last_progress > SIM_STALL_LIMIT:
                raise TestFailure(f"collect_sim: simulated time stood still at {now} s for {SIM_STALL_LIMIT} s")
            time.sleep(0.01)
        inside = [m for m in theirs if m.timestamp <= since + duration]
        if not others:
            return inside
        check_equal([(m.arbitration_id, bytes(m.data)) for m in mine],
                    [(m.arbitration_id, bytes(m.data)) for m in theirs], "frames seen by both clients")
        return mine[:len(inside)]

    # NMT ------------------------------------------------------------------------------------------
    def nmt(self, command, node):
        self.send(0x000, [command, node])

    def wait_state(self, node, state, timeout=FRAME_TIMEOUT):
        return self.receive(lambda m: m.arbitration_id == 0x700 + node and len(m.data) == 1 and m.data[0] == state,
                            timeout, f"state {state:#04x} from node {node}")

    def wait_nmt(self, command, node):
        """The next NMT `command` frame for `node` or for all (0) that another client sends."""
        return self.receive(lambda m: m.arbitration_id == 0 and len(m.data) == 2 and m.data[0] == command and
                            m.data[1] in (node, 0), FRAME_TIMEOUT, f"NMT {command:#04x}")

    def state_after_nmt(self, node, command, state, within):
        """The heartbeat of `node` with `state` that follows the NMT `command` another client sent
        (to `node` or to all, 0), both as this socketcand client sees them; checks that it came
        within `within` seconds of simulated time of the NMT frame: a state change sends its
        heartbeat at once, not at the next period."""
        check(self.stamps_simulated_time, "simulated time needs a socketcand client")
        nmt = self.wait_nmt(command, node)
        beat = self.wait_state(node, state)
        delay = beat.timestamp - nmt.timestamp
        check(delay <= within, f"heartbeat {state:#04x} {delay:.3f} s (simulated) after NMT {command:#04x}")
        return beat

    # SDO ------------------------------------------------------------------------------------------
    def _request(self, node, data, timeout=SDO_TIMEOUT):
        self.send(0x600 + node, data)
        return self.receive(lambda m: m.arbitration_id == 0x580 + node, timeout, f"SDO response of node {node}")

    @staticmethod
    def _check_abort(response, index, sub):
        data = bytes(response.data)
        check_equal(len(data), 8, "SDO response length")
        if data[0] == 0x80:
            code = struct.unpack_from("<I", data, 4)[0]
            check_equal(struct.unpack_from("<HB", data, 1), (index, sub), "abort multiplexer")
            raise SdoAborted(code, index, sub)
        return data

    def upload(self, node, index, sub):
        data = self._check_abort(self._request(node, [0x40, index & 0xFF, index >> 8, sub, 0, 0, 0, 0]), index, sub)
        check_equal(struct.unpack_from("<HB", data, 1), (index, sub), "upload response multiplexer")
        if data[0] & 0x02:  # expedited
            n = 4 - ((data[0] >> 2) & 3) if data[0] & 0x01 else 4
            return data[4:4 + n]
        check_equal(data[0], 0x41, "initiate upload response")
        size = struct.unpack_from("<I", data, 4)[0]
        value = b""
        toggle = 0
        while True:
            seg = self._check_abort(self._request(node, [0x60 | toggle, 0, 0, 0, 0, 0, 0, 0]), index, sub)
            check_equal(seg[0] & 0x10, toggle, "upload segment toggle")
            value += seg[1:8 - ((seg[0] >> 1) & 7)]
            if seg[0] & 0x01:
                break
            toggle ^= 0x10
        check_equal(len(value), size, "segmented upload size")
        return value

    def upload_u(self, node, index, sub):
        return int.from_bytes(self.upload(node, index, sub), "little")

    def download(self, node, index, sub, value, size):
        payload = value.to_bytes(size, "little") if isinstance(value, int) else bytes(value)
        check(len(payload) <= 4, "expedited download only")
        header = 0x23 | ((4 - len(payload)) << 2)
        data = self._check_abort(
            self._request(node, [header, index & 0xFF, index >> 8, sub] + list(payload.ljust(4, b"\0"))), index, sub)
        check_equal(data[0], 0x60, "initiate download response")

    # SDO block transfer (CiA-301 7.2.4.3.9+) -----------------------------------------------------
    def block_upload(self, node, index, sub, blksize=127, crc=True, pst=0):
        """Block upload with raw frames; returns the bytes. Checks sequence numbers and the CRC."""
        mux = [index & 0xFF, index >> 8, sub]
        data = self._check_abort(self._request(node, [0xA0 | (4 if crc else 0)] + mux + [blksize, pst, 0, 0]),
                                 index, sub)
        check_equal(data[0] & 0xE3, 0xC2, "block upload initiate response (size indicated)")
        server_crc = bool(data[0] & 0x04)
        size = struct.unpack_from("<I", data, 4)[0]
        self.send(0x600 + node, [0xA3, 0, 0, 0, 0, 0, 0, 0])
        value = b""
        while True:
            last = False
            seqno = 0
            while not last and seqno < blksize:
                seg = self.receive(lambda m: m.arbitration_id == 0x580 + node, SDO_TIMEOUT, "upload segment")
                seg = bytes(seg.data)
                check_equal(seg[0] & 0x7F, seqno + 1, "upload segment sequence number")
                seqno += 1
                value += seg[1:8]
                last = bool(seg[0] & 0x80)
            self.send(0x600 + node, [0xA2, seqno, blksize, 0, 0, 0, 0, 0])
            if last:
                break
        end = self._check_abort(
            self.receive(lambda m: m.arbitration_id == 0x580 + node, SDO_TIMEOUT, "block upload end"), index, sub)
        check_equal(end[0] & 0xE3, 0xC1, "block upload end request")
        value = value[:len(value) - ((end[0] >> 2) & 7)]
        check_equal(len(value), size, "block upload size")
        if crc and server_crc:
            check_equal(struct.unpack_from("<H", end, 1)[0], crc16_ccitt(value), "block upload CRC")
        self.send(0x600 + node, [0xA1, 0, 0, 0, 0, 0, 0, 0])
        return value

    def block_download(self, node, index, sub, value, crc=True, crc_value=None):
        """Block download with raw frames, in the sub-blocks the server asks for."""
        mux = [index & 0xFF, index >> 8, sub]
        data = self._check_abort(
            self._request(node, [0xC2 | (4 if crc else 0)] + mux + list(struct.pack("<I", len(value)))), index, sub)
        check_equal(data[0] & 0xE3, 0xA0, "block download initiate response")
        blksize = data[4]
        check(1 <= blksize <= 127, f"server block size {blksize}")
        segments = [value[i:i + 7] for i in range(0, len(value), 7)] or [b""]
        position = 0
        while position < len(segments):
            block = segments[position:position + blksize]
            for n, segment in enumerate(block, start=1):
                last = position + n == len(segments)
                self.send(0x600 + node, [(0x80 if last else 0) | n] + list(segment.ljust(7, b"\0")))
            ack = self._check_abort(
                self.receive(lambda m: m.arbitration_id == 0x580 + node, SDO_TIMEOUT, "sub-block ack"), index, sub)
            check_equal(ack[0], 0xA2, "block download sub-block response")
            position += ack[1]
            blksize = ack[2]
        unused = 7 - len(segments[-1]) if value else 7
        crc_field = crc16_ccitt(value) if crc_value is None else crc_value
        end = self._check_abort(self._request(node, [0xC1 | (unused << 2)] + list(struct.pack("<H", crc_field)) +
                                              [0, 0, 0, 0, 0]), index, sub)
        check_equal(end[0], 0xA1, "block download end response")

    # PDO / SYNC / LSS -------------------------------------------------------------------------------
    def configure_pdo(self, node, comm_index, cob_id, transmission_type, entries, inhibit_100us=0, event_ms=0):
        """python-canopen's PdoMap.save() order: COB-ID with bit 31, type, (TPDO) inhibit, event timer,
        SYNC start value (may abort), mapping count 0, entries, count, COB-ID without bit 31."""
        transmit = comm_index >= 0x1800
        self.download(node, comm_index, 1, cob_id | 0x80000000, 4)
        self.download(node, comm_index, 2, transmission_type, 1)
        if transmit:
            self.download(node, comm_index, 3, inhibit_100us, 2)
            self.download(node, comm_index, 5, event_ms, 2)
            try:
                self.download(node, comm_index, 6, 0, 1)
            except SdoAborted:
                pass  # python-canopen ignores a missing SYNC start value
        map_index = comm_index + 0x200
        self.download(node, map_index, 0, 0, 1)
        for sub, entry in enumerate(entries, start=1):
            self.download(node, map_index, sub, entry, 4)
        self.download(node, map_index, 0, len(entries), 1)
        self.download(node, comm_index, 1, cob_id, 4)

    def lss(self, data, answer=True, timeout=SDO_TIMEOUT):
        """One LSS master frame (0x7E5, padded to 8 bytes); the slave's answer (0x7E4) or None."""
        self.send(0x7E5, list(data) + [0] * (8 - len(data)))
        if not answer:
            return None
        return bytes(self.receive(lambda m: m.arbitration_id == 0x7E4, timeout, f"LSS answer to {data[0]:#04x}").data)

    def lss_answered(self, data, listener):
        """Sends one LSS master frame and tells whether a slave answered it, with no time window
        (fastscan asks questions that only the right slave answers). `listener`, a socketcand
        client on the same bus, sees the frame between two sequence points (SEQUENCE_POINT_ID)
        that this client sends just before and after it, and the answer if any between them: a
        slave answers an LSS frame while it handles it, before the bus carries the next frame.
        This client must get the answer too."""
        number = next(_sequence_point_numbers) & 0xFFFF
        self.send(SEQUENCE_POINT_ID, [0, number & 0xFF, number >> 8])
        self.send(0x7E5, list(data) + [0] * (8 - len(data)))
        self.send(SEQUENCE_POINT_ID, [1, number & 0xFF, number >> 8])

        def sequence_point(end):
            return lambda m: m.arbitration_id == SEQUENCE_POINT_ID and bytes(m.data) == bytes(
                [end, number & 0xFF, number >> 8])

        listener.receive(sequence_point(0), SDO_TIMEOUT, f"the frame before LSS {data[0]:#04x}")
        after = sequence_point(1)
        answers = []
        while True:
            msg = listener.receive(lambda m: m.arbitration_id == 0x7E4 or after(m), SDO_TIMEOUT,
                                   f"the frame after LSS {data[0]:#04x}")
            if after(msg):
                break
            answers.append(bytes(msg.data))
        for answer in answers:
            mine = bytes(self.receive(lambda m: m.arbitration_id == 0x7E4, SDO_TIMEOUT, "the LSS answer").data)
            check_equal(mine, answer, f"LSS answer to {data[0]:#04x} as the listener saw it")
        return bool(answers)

    def lss_fastscan(self, listener):
        """python-canopen's LssMaster.fast_scan() in raw frames; the identity found, or None.
        python-canopen takes silence within a time window for "no"; here `listener` tells for sure
        (lss_answered), so that a loaded machine cannot turn a late "yes" into a "no"."""
        def ask(id_number, bit_checked, lss_sub, lss_next):
            frame = [0x51] + list(struct.pack("<I", id_number)) + [bit_checked, lss_sub, lss_next]
            return self.lss_answered(frame, listener)

        if not ask(0, 0x80, 0, 0):
            return None
        found = [0, 0, 0, 0]
        for lss_sub in range(4):
            for bit_checked in range(31, -1, -1):
                if not ask(found[lss_sub], bit_checked, lss_sub, lss_sub):
                    found[lss_sub] |= 1 << bit_checked
            if not ask(found[lss_sub], 0, lss_sub, (lss_sub + 1) & 3):
                return None
        return found

    def lss_silent(self, data, wait=0.2):
        """Sends an LSS frame that must not be answered; returns the answers seen (should be [])."""
        self.send(0x7E5, list(data) + [0] * (8 - len(data)))
        return self.collect(wait, lambda m: m.arbitration_id == 0x7E4)

    def abort_code(self, operation, *args):
        try:
            operation(*args)
        except SdoAborted as aborted:
            return aborted.code
        raise TestFailure(f"{operation.__name__}{args} was not aborted")


class RawSocketcand:
    """A plain TCP socket speaking the socketcand protocol by hand (for garbage tests)."""

    def __init__(self, port):
        self.sock = socket.create_connection(("127.0.0.1", port), timeout=5)
        self.sock.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
        self.buffer = b""

    def send(self, text):
        self.sock.sendall(text.encode("ascii") if isinstance(text, str) else text)

    def _pop_element(self):
        """The first complete `< ... >` element in the buffer, taken out of it; None if there is none."""
        start = self.buffer.find(b"<")
        end = self.buffer.find(b">", start + 1) if start >= 0 else -1
        if start < 0 or end < 0:
            return None
        element = self.buffer[start:end + 1].decode("ascii")
        self.buffer = self.buffer[end + 1:]
        return element

    def _receive_more(self, deadline, waiting_for):
        """Appends what arrives before `deadline` to the buffer; False when the server closed."""
        remaining = deadline - time.monotonic()
        if remaining <= 0:
            raise TestFailure(f"timed out waiting for {waiting_for} (have {self.buffer!r})")
        self.sock.settimeout(remaining)
        try:
            chunk = self.sock.recv(4096)
        except socket.timeout:
            return True
        self.buffer += chunk
        return bool(chunk)

    def read_element(self, timeout=FRAME_TIMEOUT):
        deadline = time.monotonic() + timeout
        while True:
            element = self._pop_element()
            if element is not None:
                return element
            if not self._receive_more(deadline, f"a socketcand element ({timeout} s)"):
                raise TestFailure("socketcand server closed the connection")

    def elements_until_closed(self, timeout=30.0):
        """Every element that arrives until the server closes the connection (a crash)."""
        elements = []
        deadline = time.monotonic() + timeout
        while True:
            element = self._pop_element()
            if element is not None:
                elements.append(element)
                continue
            try:
                if not self._receive_more(deadline, f"the server to close the connection (received {elements!r})"):
                    return elements
            except ConnectionResetError:
                return elements

    def close(self):
        self.sock.close()


def frame_element(cob_id, data):
    """`< send ... >` for one frame in rawmode."""
    return "< send %03X %d %s >" % (cob_id, len(data), " ".join(f"{b:02X}" for b in data))


def received_frames(elements, cob_id):
    """The data of the `< frame ... >` elements with that COB-ID."""
    frames = []
    for element in elements:
        parts = element.split()
        if len(parts) >= 5 and parts[1] == "frame" and int(parts[2], 16) == cob_id:
            frames.append(bytes.fromhex(parts[4]))
    return frames


class RawSdoClient:
    """A plain socketcand connection in rawmode with expedited SDO to one node and LSS: no
    python-can, so that a server killed in the middle of a request is just a closed socket."""

    def __init__(self, port, node):
        self.node = node
        self.raw = RawSocketcand(port)
        check_equal(self.raw.read_element(), "< hi >", "greeting")
        self.raw.send("< open can0 >")
        check_equal(self.raw.read_element(), "< ok >", "open")
        self.raw.send("< rawmode >")
        check_equal(self.raw.read_element(), "< ok >", "rawmode")

    def send(self, cob_id, data):
        self.raw.send(frame_element(cob_id, data))

    def receive(self, cob_id):
        while True:
            frames = received_frames([self.raw.read_element()], cob_id)
            if frames:
                return frames[0]

    def request(self, data):
        self.send(0x600 + self.node, data)
        return self.receive(0x580 + self.node)

    @staticmethod
    def download_request(index, sub, value, size):
        header = 0x23 | ((4 - size) << 2)
        return [header, index & 0xFF, index >> 8, sub] + list(value.to_bytes(4, "little"))

    def download(self, index, sub, value, size):
        """0 on success, else the abort code."""
        response = self.request(self.download_request(index, sub, value, size))
        if response[0] == 0x80:
            return struct.unpack_from("<I", response, 4)[0]
        check_equal(response[0], 0x60, f"download response for {index:04X}")
        return 0

    def upload(self, index, sub):
        response = self.request([0x40, index & 0xFF, index >> 8, sub, 0, 0, 0, 0])
        check(response[0] & 0xE3 == 0x43, f"expedited upload response {response.hex()}")
        return struct.unpack_from("<I", response, 4)[0]

    def lss(self, data):
        """One LSS master frame; the slave's answer."""
        self.send(0x7E5, list(data) + [0] * (8 - len(data)))
        return self.receive(0x7E4)

    def lss_configure_node_id(self, node_id):
        """Switch state global "configuration" (no answer), then configure node ID."""
        self.send(0x7E5, [0x04, 0x01, 0, 0, 0, 0, 0, 0])
        check_equal(self.lss([0x11, node_id])[:2], bytes([0x11, 0]), f"LSS configure node ID {node_id}")

    def close(self):
        self.raw.close()

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()


def run_can_tests(tests):
    """motwin_harness.run_tests for scripts that need Debian's python3-can: fails at once, naming
    the install script, when it is missing."""
    mh.parse_arguments()  # usage errors (--help, no --motwin) first, as before the python3-can check
    try:
        import can  # noqa: F401
    except ImportError:
        raise TestFailure("python3-can is missing: run scripts/install-deps.sh")
    mh.run_tests(tests)
