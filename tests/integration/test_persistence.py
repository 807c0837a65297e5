#!/usr/bin/python3
"""The EEPROM image of `motwin serve` (`<state-dir>/tmcm-1636.eeprom`).

- Stored values (STAP, STGP, auto-stored SGP) survive a restart after SIGTERM or SIGINT;
  unstored ones do not. GP 85 = 1 makes the stored user variables start at 0 after a restart.
- A damaged image (bytes flipped, truncated, extended, empty, another module's image, random
  bytes) is reported by exactly one stderr line containing "damaged"; the module starts from
  factory defaults, works, and its next store writes a valid image again.
- A second server on the same state directory is refused; the first one keeps working.
- SIGTERM while clients storm stores and motion commands: exit 0, valid image, pty link gone.
- kill -9 loop: 100 times start (--speed fast, TCP + a pty whose link the previous, killed server
  left stale), storm SAP/STAP 43, SAP/STAP 44, SGP/STGP user variable 0 with a counter n, and
  SIGKILL 0..150 ms (seeded random) after the storm began, then check that the file on disk is a valid
  image whose stored tuple is a prefix of the storm's sequence (43 >= 44 >= uv0 >= 43 - 1), that
  every acknowledged store is in it, and that the restarted server loads it (no "damaged" line)
  with exactly those values.
"""

import os
import random
import signal
import socket
import struct
import sys
import threading
import time

sys.dont_write_bytecode = True  # no __pycache__ in the source tree
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

from motwin_harness import (  # noqa: E402
    BANK_GLOBAL, BANK_USER, DEFAULT_ACCELERATION, DEFAULT_AUTO_START, DEFAULT_MAX_VELOCITY,
    DEFAULT_REACHED_DISTANCE, DEFAULT_REACHED_VELOCITY, GAP, GGP, SAP, SGP, STAP, STATUS_OK, STGP, Server, TempDir,
    check, check_equal, damaged_lines, encode_eeprom_image, frame, parse_reply, read_eeprom_image, run_tests, TcpClient, EepromImage,
)

IMAGE_NAME = "tmcm-1636.eeprom"
KILL_LOOP_ITERATIONS = 100
MAX_CYCLES_PER_ITERATION = 900  # keeps n below AP 44's maximum (100000) over 100 iterations


def image_path(state_dir):
    return os.path.join(state_dir, IMAGE_NAME)


def check_no_damaged(server, when):
    lines = damaged_lines(server.stderr_lines())
    check(not lines, f"{when}: unexpected 'damaged' report on stderr: {lines!r}")


# --- Restart --------------------------------------------------------------------------------

def store_some_values(c):
    c.sap(43, 3100)
    c.stap(43)
    c.sap(44, 1500)
    c.stap(44)
    c.sap(53, 9)
    c.stap(53)
    c.sap(93, -300)
    c.stap(93)
    c.sgp(0, BANK_USER, -1)
    c.stgp(0, BANK_USER)
    c.sgp(55, BANK_USER, 123456)
    c.stgp(55, BANK_USER)
    c.sgp(77, BANK_GLOBAL, 0)  # auto start mode: automatically stored (A)
    # Not stored:
    c.sap(54, 1000)
    c.sgp(1, BANK_USER, 7)
    c.sgp(100, BANK_USER, 8)
    c.sap(52, 4444)


def check_stored_values(c, when):
    check_equal(c.gap(43), 3100, f"{when}: AP 43")
    check_equal(c.gap(44), 1500, f"{when}: AP 44")
    check_equal(c.gap(53), 9, f"{when}: AP 53")
    check_equal(c.gap(93), -300, f"{when}: AP 93")
    check_equal(c.ggp(0, BANK_USER), -1, f"{when}: user variable 0")
    check_equal(c.ggp(55, BANK_USER), 123456, f"{when}: user variable 55")
    check_equal(c.ggp(77, BANK_GLOBAL), 0, f"{when}: GP 77")
    check_equal(c.gap(54), DEFAULT_REACHED_VELOCITY, f"{when}: unstored AP 54")
    check_equal(c.ggp(1, BANK_USER), 0, f"{when}: unstored user variable 1")
    check_equal(c.ggp(100, BANK_USER), 0, f"{when}: user variable 100")
    check_equal(c.gap(52), 0, f"{when}: AP 52")


def test_restart_keeps_stored_values(motwin):
    with TempDir() as tmp:
        state = os.path.join(tmp, "state")  # does not exist yet: serve creates it
        with Server(motwin, state) as server:
            check_equal(os.path.realpath(server.eeprom_path), os.path.realpath(image_path(state)), "eeprom path in banner")
            check_no_damaged(server, "first start")
            check(os.path.isfile(image_path(state)), "no image file after the first start")
            with server.tcp() as c:
                check_equal(c.gap(43), DEFAULT_MAX_VELOCITY, "first start: AP 43")
                store_some_values(c)
            server.stop(signal.SIGTERM)
        image = read_eeprom_image(image_path(state))
        check(image.problem is None, f"image after SIGTERM is invalid: {image.problem}")
        check_equal(image.module_name, "tmcm-1636", "module name in the image header")
        check_equal((image.axis_parameter(43), image.axis_parameter(44), image.user_variable(55),
                     image.global_parameter(77)), (3100, 1500, 123456, 0), "stored slots in the file")
        check_equal(image.axis_parameter(54), DEFAULT_REACHED_VELOCITY, "unstored AP 54 slot in the file")

        with Server(motwin, state) as server:
            check_no_damaged(server, "restart after SIGTERM")
            with server.tcp() as c:
                check_stored_values(c, "after SIGTERM restart")
                c.sap(54, 1000)  # unstored again
            server.stop(signal.SIGINT)
        with Server(motwin, state) as server:
            check_no_damaged(server, "restart after SIGINT")
            with server.tcp() as c:
                check_stored_values(c, "after SIGINT restart")
                c.sgp(77, BANK_GLOBAL, DEFAULT_AUTO_START)
            server.stop()
        check_equal(read_eeprom_image(image_path(state)).global_parameter(77), DEFAULT_AUTO_START, "GP 77 slot")



def test_another_firmware_takes_the_image_over(motwin):
    """`--firmware 1.13` on a 1.09 image (docs/tmcm-1636.md "EEPROM image and firmware changes"):
    one stderr line names both firmwares, nothing is called damaged, the stored settings stay,
    1.13's new rows have their defaults and the header records 1636V113 from then on."""
    with TempDir() as tmp:
        state = os.path.join(tmp, "state")
        with Server(motwin, state) as server:
            with server.tcp() as c:
                store_some_values(c)
            server.stop()
        check_equal(read_eeprom_image(image_path(state)).firmware, "1636V109", "firmware recorded by 1.09")
        with Server(motwin, state, extra_args=["--firmware", "1.13"]) as server:
            with server.tcp() as c:
                check_stored_values(c, "1.13 on the 1.09 image")
                check_equal(c.gap(56), 65536, "AP 56 (new in 1.13) at its default")
            server.stop()
            lines = server.stderr_lines()
            check_no_damaged(server, "firmware change")
            update = [line for line in lines if "was written by firmware 1636V109; 1636V113 takes it over" in line]
            check_equal(len(update), 1, f"one line about the firmware change in {lines!r}")
        image = read_eeprom_image(image_path(state))
        check(image.problem is None, f"image after the firmware change is invalid: {image.problem}")
        check_equal(image.firmware, "1636V113", "firmware recorded after the change")
        check_equal(image.axis_parameter(43), 3100, "AP 43 slot kept")


def test_gp_85_decides_whether_user_variables_come_back(motwin):
    """GP 85 = 1 (stored at once, like every SGP from 64 on): after a restart the stored user
    variables start at 0, and RSGP still fetches the stored copy; GP 85 = 0: they come back."""
    with TempDir() as tmp:
        state = os.path.join(tmp, "state")
        with Server(motwin, state) as server:
            with server.tcp() as c:
                c.sgp(3, BANK_USER, 1234)
                c.stgp(3, BANK_USER)
                c.sgp(85, BANK_GLOBAL, 1)
            server.stop()
        check_equal((read_eeprom_image(image_path(state)).global_parameter(85),
                     read_eeprom_image(image_path(state)).user_variable(3)), (1, 1234), "GP 85 and variable 3 in the file")
        with Server(motwin, state) as server:
            with server.tcp() as c:
                check_equal(c.ggp(85, BANK_GLOBAL), 1, "GP 85 after the restart")
                check_equal(c.ggp(3, BANK_USER), 0, "GP 85 = 1: user variable 3 starts at 0")
                c.rsgp(3, BANK_USER)
                check_equal(c.ggp(3, BANK_USER), 1234, "RSGP fetches the stored copy")
                c.sgp(85, BANK_GLOBAL, 0)
                c.sgp(3, BANK_USER, 5)  # RAM only
            server.stop()
        with Server(motwin, state) as server:
            with server.tcp() as c:
                check_equal(c.ggp(3, BANK_USER), 1234, "GP 85 = 0: user variable 3 restored")
            server.stop()


# --- Damaged images -------------------------------------------------------------------------

def flip(data, offset):
    data = bytearray(data)
    data[offset] ^= 0xFF
    return bytes(data)


def corruptions(good):
    image = read_eeprom_image_bytes(good)
    payload = image.payload
    rng = random.Random(1636)
    return [
        ("payload byte flipped", flip(good, 64 + 43 * 4)),
        ("last byte flipped", flip(good, len(good) - 1)),
        ("magic flipped", flip(good, 0)),
        ("header CRC flipped", flip(good, 61)),
        ("truncated to half", good[:len(good) // 2]),
        ("truncated by one byte", good[:-1]),
        ("truncated inside the header", good[:20]),
        ("one byte appended", good + b"\0"),
        ("empty file", b""),
        ("image of another module", encode_eeprom_image("tmcm-142", image.layout_version, payload)),
        ("other layout version", encode_eeprom_image("tmcm-1636", image.layout_version + 1, payload)),
        ("other payload size", encode_eeprom_image("tmcm-1636", image.layout_version, payload[:-8])),
        ("random bytes", bytes(rng.randrange(256) for _ in range(len(good)))),
    ]


def read_eeprom_image_bytes(data):
    return EepromImage(data)


def make_good_image(motwin, tmp):
    state = os.path.join(tmp, "template")
    with Server(motwin, state) as server:
        with server.tcp() as c:
            c.sap(43, 3100)
            c.stap(43)
            c.sgp(0, BANK_USER, 99)
            c.stgp(0, BANK_USER)
        server.stop()
    with open(image_path(state), "rb") as f:
        good = f.read()
    image = read_eeprom_image_bytes(good)
    check(image.problem is None, f"template image invalid: {image.problem}")
    check_equal(image.axis_parameter(43), 3100, "template AP 43 slot")
    return good


def test_damaged_images(motwin):
    with TempDir() as tmp:
        good = make_good_image(motwin, tmp)
        for index, (name, data) in enumerate(corruptions(good)):
            state = os.path.join(tmp, f"case{index}")
            os.makedirs(state)
            with open(image_path(state), "wb") as f:
                f.write(data)
            with Server(motwin, state) as server:
                lines = damaged_lines(server.stderr_lines())
                check_equal(len(lines), 1, f"{name}: number of 'damaged' lines on stderr ({server.stderr_lines()!r})")
                with server.tcp() as c:
                    check_equal(c.gap(43), DEFAULT_MAX_VELOCITY, f"{name}: AP 43 factory default")
                    check_equal(c.gap(44), DEFAULT_ACCELERATION, f"{name}: AP 44 factory default")
                    check_equal(c.gap(53), DEFAULT_REACHED_DISTANCE, f"{name}: AP 53 factory default")
                    check_equal(c.ggp(0, BANK_USER), 0, f"{name}: user variable 0")
                    check_equal(c.ggp(77, BANK_GLOBAL), DEFAULT_AUTO_START, f"{name}: GP 77")
                    # Still a working module, and it can store again.
                    c.sap(43, 2222)
                    check_equal(c.gap(43), 2222, f"{name}: AP 43 after SAP")
                    c.stap(43)
                server.stop()
                check_equal(len(damaged_lines(server.stderr_lines())), 1, f"{name}: 'damaged' lines at exit")
            # The damaged file is kept for inspection (src/host/eeprom_file.h).
            kept = image_path(state) + ".damaged"
            check(os.path.isfile(kept), f"{name}: {kept} missing")
            with open(kept, "rb") as f:
                check(f.read() == data, f"{name}: {kept} does not hold the damaged bytes")
            image = read_eeprom_image(image_path(state))
            check(image.problem is None, f"{name}: image after the new STAP invalid: {image.problem}")
            with Server(motwin, state) as server:
                check_no_damaged(server, f"{name}: restart")
                with server.tcp() as c:
                    check_equal(c.gap(43), 2222, f"{name}: AP 43 after restart")
                server.stop()


def test_state_dir_in_use(motwin):
    with TempDir() as tmp:
        state = os.path.join(tmp, "state")
        with Server(motwin, state) as first:
            with first.tcp() as c:
                c.sap(43, 1234)
                c.stap(43)
                second = Server(motwin, state)
                try:
                    status = second.start_expect_failure()
                    check(status != 0, "a second server on the same state directory must fail")
                    check(second.stderr_text().strip() != "", "the refused server printed no error on stderr")
                finally:
                    second.cleanup()
                check_equal(c.gap(43), 1234, "first server after the refused second one")
                c.sap(43, 1500)
                c.stap(43)
            first.stop()
        check_equal(read_eeprom_image(image_path(state)).axis_parameter(43), 1500, "AP 43 slot")


# --- kill -9 loop -----------------------------------------------------------------------------

# The storm's sequence for counter n; `key` names the stored slot each store writes.
STEPS = (
    ("ap43", lambda n: frame(SAP, 43, 0, n), lambda: frame(STAP, 43), SAP, STAP),
    ("ap44", lambda n: frame(SAP, 44, 0, n), lambda: frame(STAP, 44), SAP, STAP),
    ("uv0", lambda n: frame(SGP, 0, BANK_USER, n), lambda: frame(STGP, 0, BANK_USER), SGP, STGP),
)
KEYS = [step[0] for step in STEPS]


class StormBook:
    """What the storm sent and what the module acknowledged, per stored slot."""

    def __init__(self, baseline):
        self.acked = {key: baseline for key in KEYS}  # last n whose store got status 100
        self.sent = {key: baseline for key in KEYS}   # last n whose store was sent
        self.cycles = 0
        self.failure = None
        self.ended_by = None


def recv_reply(sock):
    data = b""
    while len(data) < 9:
        chunk = sock.recv(9 - len(data))
        if not chunk:
            raise ConnectionError("closed")
        data += chunk
    return parse_reply(data)


def storm(sock, first_n, book, started):
    started.set()
    n = first_n
    try:
        while book.cycles < MAX_CYCLES_PER_ITERATION:
            for key, set_frame, store_frame, set_command, store_command in STEPS:
                sock.sendall(set_frame(n))
                r = recv_reply(sock)
                if (r.status, r.command, r.value) != (STATUS_OK, set_command, n):
                    book.failure = f"set {key} = {n}: reply {r.raw.hex(' ')}"
                    return
                book.sent[key] = n
                sock.sendall(store_frame())
                r = recv_reply(sock)
                if (r.status, r.command) != (STATUS_OK, store_command):
                    book.failure = f"store {key} = {n}: reply {r.raw.hex(' ')}"
                    return
                book.acked[key] = n
            book.cycles += 1
            n += 1
        book.ended_by = "cycle limit"
    except (OSError, ConnectionError) as error:  # the SIGKILL
        book.ended_by = f"connection: {error!r}"


def check_stored_tuple(values, book, when):
    a, b, u = values["ap43"], values["ap44"], values["uv0"]
    # A prefix of SAP/STAP 43 n, SAP/STAP 44 n, SGP/STGP uv0 n: never a mix of two images.
    check(a >= b >= u >= a - 1, f"{when}: stored (AP 43, AP 44, uv 0) = {(a, b, u)} is not a consistent image")
    for key in KEYS:
        check(book.acked[key] <= values[key] <= book.sent[key],
              f"{when}: stored {key} = {values[key]}, but acknowledged {book.acked[key]} and sent {book.sent[key]} "
              f"(an acknowledged store was lost, or a value never stored appeared)")


def read_stored_tuple(c):
    return {"ap43": c.gap(43), "ap44": c.gap(44), "uv0": c.ggp(0, BANK_USER)}


def test_kill9_loop(motwin):
    rng = random.Random(int(os.environ.get("MOTWIN_KILL_SEED", "20240611")))
    with TempDir() as tmp:
        state = os.path.join(tmp, "state")
        # Seed: a complete tuple (1, 1, 1).
        with Server(motwin, state, speed="fast") as server:
            with server.tcp() as c:
                c.sap(43, 1)
                c.stap(43)
                c.sap(44, 1)
                c.stap(44)
                c.sgp(0, BANK_USER, 1)
                c.stgp(0, BANK_USER)
            server.stop()
        book = StormBook(1)
        link = os.path.join(tmp, "pty")
        partial_tuples = 0
        total_cycles = 0
        kills_during_storm = 0
        for iteration in range(KILL_LOOP_ITERATIONS):
            when = f"iteration {iteration}"
            # The file as the kill left it: valid, and a consistent tuple.
            image = read_eeprom_image(image_path(state))
            check(image.problem is None, f"{when}: image on disk is invalid after SIGKILL: {image.problem}")
            on_disk = {"ap43": image.axis_parameter(43), "ap44": image.axis_parameter(44), "uv0": image.user_variable(0)}
            check_stored_tuple(on_disk, book, f"{when} (file)")

            if on_disk["ap44"] != on_disk["ap43"] or on_disk["uv0"] != on_disk["ap43"]:
                partial_tuples += 1
            # The pty link left by the killed server is stale: the new server replaces it.
            server = Server(motwin, state, pty_link=link, speed="fast")
            try:
                server.start()
                check_no_damaged(server, when)
                check_equal(os.path.realpath(link), server.pty_device, f"{when}: pty link target")
                sock = socket.create_connection(("127.0.0.1", server.tcp_port), timeout=5.0)
                sock.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
                try:
                    c = TcpClient.from_socket(sock)
                    loaded = read_stored_tuple(c)
                    check_equal(loaded, on_disk, f"{when}: values loaded by the server vs. the file")
                    # Complete an interrupted cycle, so that the tuple is (m, m, m).
                    m = loaded["ap43"]
                    if loaded["ap44"] != m:
                        c.sap(44, m)
                        c.stap(44)
                    if loaded["uv0"] != m:
                        c.sgp(0, BANK_USER, m)
                        c.stgp(0, BANK_USER)
                    book = StormBook(m)
                    started = threading.Event()
                    sock.settimeout(10.0)
                    thread = threading.Thread(target=storm, args=(sock, m + 1, book, started), daemon=True)
                    thread.start()
                    started.wait(5.0)
                    time.sleep(rng.uniform(0.0, 0.150))
                    alive = server.alive()
                    server.kill()
                    thread.join(15.0)
                    check(not thread.is_alive(), f"{when}: storm client still blocked after the kill")
                finally:
                    sock.close()
                check(alive, f"{when}: server died on its own before the kill: {server.stderr_text()!r}")
                check(book.failure is None, f"{when}: {book.failure}")
                if book.ended_by and book.ended_by.startswith("connection"):
                    kills_during_storm += 1
                total_cycles += book.cycles
            finally:
                server.cleanup()
        # One last clean start: the last tuple loads.
        image = read_eeprom_image(image_path(state))
        check(image.problem is None, f"final image invalid: {image.problem}")
        with Server(motwin, state, speed="fast") as server:
            check_no_damaged(server, "final start")
            with server.tcp() as c:
                final = read_stored_tuple(c)
                check_stored_tuple(final, book, "final start")
            server.stop()
        check(final["ap43"] > 1, f"the storms never stored anything (final {final})")
        print(f"  kill -9 loop: {KILL_LOOP_ITERATIONS} kills, {kills_during_storm} during a storm, "
              f"{total_cycles} complete cycles, {partial_tuples} images with a half-done cycle, final tuple {final}",
              flush=True)


def test_sigterm_under_load(motwin):
    """SIGTERM while clients storm stores and motion commands: exit 0, a valid image holding a
    value the storm stored, the pty link removed."""
    rng = random.Random(75)
    for iteration in range(6):
        when = f"iteration {iteration}"
        with TempDir() as tmp:
            state = os.path.join(tmp, "state")
            link = os.path.join(tmp, "pty")
            with Server(motwin, state, pty_link=link, speed="fast" if iteration % 2 == 0 else None) as server:
                stop = threading.Event()
                errors = []

                def client(index):
                    try:
                        with server.tcp() as c:
                            n = 0
                            while not stop.is_set():
                                c.sap(43, 100 + n % 1000)
                                c.stap(43)
                                c.ok(1, 0, 0, (n * 7) % 3000)  # ROR
                                n += 1
                    except Exception as error:  # noqa: BLE001 - the end of the server ends the loop
                        if not stop.is_set():
                            errors.append(f"client {index} before SIGTERM: {error!r}")

                threads = [threading.Thread(target=client, args=(i,), daemon=True) for i in range(3)]
                for t in threads:
                    t.start()
                with server.serial() as pty_client:
                    pty_client.send_raw(frame(GAP, 43) * 50 + frame(SAP, 43, 0, 1)[:5])  # unread replies, a half frame
                    time.sleep(rng.uniform(0.02, 0.2))
                    check(not errors, f"{when}: {errors}")
                    stop.set()
                    server.stop(signal.SIGTERM)
                for t in threads:
                    t.join(10.0)
                    check(not t.is_alive(), f"{when}: a client hangs after the server exited")
            check(not os.path.lexists(link), f"{when}: pty link left behind after a clean exit")
            image = read_eeprom_image(image_path(state))
            check(image.problem is None, f"{when}: image after SIGTERM under load invalid: {image.problem}")
            check(100 <= image.axis_parameter(43) < 1100 or image.axis_parameter(43) == DEFAULT_MAX_VELOCITY,
                  f"{when}: stored AP 43 = {image.axis_parameter(43)} was never stored")


if __name__ == "__main__":
    run_tests([test_restart_keeps_stored_values, test_another_firmware_takes_the_image_over, test_gp_85_decides_whether_user_variables_come_back,
               test_damaged_images, test_state_dir_in_use, test_sigterm_under_load, test_kill9_loop])
