#!/usr/bin/python3
"""kill -9 at every step of every kind of storage write, made certain by the crash hook: a server
started with MOTWIN_CRASH_AT_PERSIST_STEP=STEP (docs/host-runtime.md) SIGKILLs itself just before
STEP of its first EEPROM image write.

Kinds of write: TMCM-1636 STAP (AP 43), STGP (user variable 5) and program download (132, four
CALC, 133); TMCM-142 STAP (AP 20, standby delay) and SCO n, 255 (a coordinate into the EEPROM); TMCM-3216 1010
sub 1 "save" (after 1017 = k) and LSS store configuration (after configure node ID). Steps:
open-temporary, write-temporary, sync-temporary, rename, sync-directory. For each pair, starting
from an image holding the old value:
- the store gets no reply (TCP: the connection closes with no byte; CAN: no SDO response or LSS
  answer) and the server ends by SIGKILL (status -9);
- on disk after the kill: the image file is byte for byte the old image for every step up to
  rename (the hook runs before its step, so at `rename` the rename has not happened) and byte for
  byte the new one at sync-directory; the temporary file is absent (open-temporary,
  sync-directory), empty (write-temporary) or byte for byte the new image (sync-temporary,
  rename); the new image is what the same store writes in a run without the hook;
- a restart without the hook reports nothing damaged, removes the temporary file, leaves the
  image file as it was, and reads back (GAP, GGP, 134, GCO n 255, SDO upload) exactly the old
  value, or the new one at sync-directory.
Also: STEP:N counts the image writes of the process (with rename:2 the first STAP is kept, the
second one is in the temporary file only), and a bad value is a start-up error (status 2, one
`motwin: error:` line naming the variable, no state directory created).
"""

import os
import shutil
import sys

sys.dont_write_bytecode = True  # no __pycache__ in the source tree
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

from canopen_harness import SAVE, CanServer, RawSdoClient, received_frames  # noqa: E402
from motwin_harness import (  # noqa: E402
    BANK_USER, STAP, STATUS_OK, STGP, EepromImage, Server, TempDir, Tmcm142Server, check, check_equal,
    expect_reply, frame, parse_reply, run_tests,
)
from storage_harness import (  # noqa: E402
    CRASH_VARIABLE, DOWNLOAD_END, PROGRAM_LENGTH, check_clean_restart, check_killed_without_reply,
    read_bytes, read_program_values, send_program, tcp_bytes_until_closed,
)

STEPS = ("open-temporary", "write-temporary", "sync-temporary", "rename", "sync-directory")
# The only step the hook reaches after the rename: the image file is then the new one.
STEPS_AFTER_RENAME = ("sync-directory",)
NODE = 5
SCO, GCO = 30, 31
COORDINATE_EEPROM_COPY = 255


def temporary_file_after_crash(step, new_image):
    """What the temporary file holds after a crash just before `step` (None: no such file)."""
    return {"open-temporary": None, "write-temporary": b"", "sync-temporary": new_image, "rename": new_image,
            "sync-directory": None}[step]


def describe(data, old_image, new_image):
    """Which image `data` is, for messages that stay readable."""
    if data is None:
        return "no file"
    if not data:
        return "an empty file"
    if data == old_image:
        return "the old image"
    if data == new_image:
        return "the new image"
    return f"{len(data)} other bytes"


def read_if_present(path):
    return read_bytes(path) if os.path.exists(path) else None


# --- The kinds of storage write -------------------------------------------------------------------

class TmclStore:
    """A store over TMCL on TCP: set_value() changes RAM, STORE_FRAME makes it persistent."""

    server_class = Server
    image_name = "tmcm-1636.eeprom"

    def server(self, motwin, state, env=None):
        return self.server_class(motwin, state, speed="fast", env=env)

    def store(self, server, value):
        with server.tcp() as c:
            self.set_value(c, value)
            reply = parse_reply(c.request_raw(self.store_frame()))
            expect_reply(reply, self.store_frame()[1], STATUS_OK, what=f"{self.name} of {value}")

    def store_until_crash(self, server, value):
        """Sets the value, sends the store; returns what came back before the connection closed."""
        with server.tcp() as c:
            self.set_value(c, value)
            c.send_raw(self.store_frame())
            return tcp_bytes_until_closed(c)

    def loaded(self, server):
        with server.tcp() as c:
            return self.read_value(c)

    def expected(self, value):
        return value


class Tmcm1636Stap(TmclStore):
    test_name = "tmcm1636_stap"
    name = "TMCM-1636 STAP 43"
    old, new = 3100, 2500

    def set_value(self, c, value):
        c.sap(43, value)

    def store_frame(self):
        return frame(STAP, 43)

    def read_value(self, c):
        return c.gap(43)


class Tmcm1636Stgp(TmclStore):
    test_name = "tmcm1636_stgp"
    name = "TMCM-1636 STGP user variable 5"
    old, new = 11, -22

    def set_value(self, c, value):
        c.sgp(5, BANK_USER, value)

    def store_frame(self):
        return frame(STGP, 5, BANK_USER)

    def read_value(self, c):
        return c.ggp(5, BANK_USER)


class Tmcm1636Download(TmclStore):
    test_name = "tmcm1636_program_download"
    name = "TMCM-1636 program download"
    old, new = 7, 8

    def set_value(self, c, value):
        send_program(c, value)

    def store_frame(self):
        return frame(DOWNLOAD_END)

    def read_value(self, c):
        return read_program_values(c)

    def expected(self, value):
        return [value] * PROGRAM_LENGTH


class Tmcm142Stap(TmclStore):
    test_name = "tmcm142_stap"
    name = "TMCM-142 STAP 20"
    server_class = Tmcm142Server
    image_name = "tmcm-142.eeprom"
    old, new = 300, 450

    def set_value(self, c, value):
        c.sap(20, value)

    def store_frame(self):
        return frame(STAP, 20)

    def read_value(self, c):
        return c.gap(20)


class Tmcm142StoredCoordinate(TmclStore):
    """GP 84 = 0 (default): SCO 3, 0, p sets RAM, SCO 3, 255 copies it into the EEPROM image and
    GCO 3, 255 copies it back."""

    test_name = "tmcm142_stored_coordinate"
    name = "TMCM-142 SCO 3, 255"
    server_class = Tmcm142Server
    image_name = "tmcm-142.eeprom"
    old, new = 1000, -3000

    def set_value(self, c, value):
        c.ok(SCO, 3, 0, value, what=f"SCO 3, 0, {value}")

    def store_frame(self):
        return frame(SCO, 3, COORDINATE_EEPROM_COPY)

    def read_value(self, c):
        return expect_reply(c.request(GCO, 3, COORDINATE_EEPROM_COPY), GCO, STATUS_OK, what="GCO 3, 255").value


class CanopenStore:
    """A store over CAN (raw socketcand): set_value() changes RAM, store_request() stores and is
    answered on REPLY_COB_ID."""

    image_name = "tmcm-3216.eeprom"

    def server(self, motwin, state, env=None):
        return CanServer(motwin, state, node_id=NODE, speed="fast", env=env)

    def store(self, server, value):
        sdo = RawSdoClient(server.can_port, NODE)
        try:
            self.set_value(sdo, value)
            sdo.send(*self.store_request())
            check_equal(sdo.receive(self.reply_cob_id), self.success_reply, f"{self.name} of {value}")
        finally:
            sdo.close()

    def store_until_crash(self, server, value):
        """Sets the value, sends the store; returns the replies that came before the connection closed."""
        sdo = RawSdoClient(server.can_port, NODE)
        try:
            self.set_value(sdo, value)
            sdo.send(*self.store_request())
            return received_frames(sdo.raw.elements_until_closed(), self.reply_cob_id)
        finally:
            sdo.close()

    def loaded(self, server):
        sdo = RawSdoClient(server.can_port, NODE)
        try:
            return self.read_value(sdo)
        finally:
            sdo.close()

    def expected(self, value):
        return value


class Tmcm3216Save(CanopenStore):
    test_name = "tmcm3216_1010_save"
    name = "TMCM-3216 1010 sub 1"
    old, new = 250, 400
    reply_cob_id = 0x580 + NODE
    success_reply = bytes([0x60, 0x10, 0x10, 1, 0, 0, 0, 0])

    def set_value(self, sdo, value):
        check_equal(sdo.download(0x1017, 0, value, 2), 0, f"1017 = {value}")

    def store_request(self):
        return 0x600 + NODE, RawSdoClient.download_request(0x1010, 1, SAVE, 4)

    def read_value(self, sdo):
        return sdo.upload(0x1017, 0)


class Tmcm3216LssStore(CanopenStore):
    test_name = "tmcm3216_lss_store_configuration"
    name = "TMCM-3216 LSS store configuration"
    old, new = 7, 9
    reply_cob_id = 0x7E4
    success_reply = bytes([0x17, 0, 0, 0, 0, 0, 0, 0])

    def set_value(self, sdo, value):
        sdo.lss_configure_node_id(value)

    def store_request(self):
        return 0x7E5, [0x17, 0, 0, 0, 0, 0, 0, 0]

    def read_value(self, sdo):
        return sdo.upload(0x2705, 0)  # the stored node ID (--node-id sets the active one)


# --- The crash at every step ----------------------------------------------------------------------

def crash_at_every_step(motwin, kind):
    with TempDir() as tmp:
        template = os.path.join(tmp, "template")
        with kind.server(motwin, template) as server:
            kind.store(server, kind.old)
            server.stop()
        old_image = read_bytes(os.path.join(template, kind.image_name))
        # The new image: what the same store writes when nothing crashes.
        reference = os.path.join(tmp, "reference")
        shutil.copytree(template, reference)
        with kind.server(motwin, reference) as server:
            kind.store(server, kind.new)
            server.stop()
        new_image = read_bytes(os.path.join(reference, kind.image_name))
        check(new_image != old_image, f"{kind.name}: the store of {kind.new} did not change the image")

        for step in STEPS:
            when = f"{kind.name}, crash at {step}"
            state = os.path.join(tmp, step)
            shutil.copytree(template, state)
            image = os.path.join(state, kind.image_name)
            with kind.server(motwin, state, env={CRASH_VARIABLE: step}) as server:
                received = kind.store_until_crash(server, kind.new)
                check_killed_without_reply(server, received, when)
            stored_value, expected_image = ((kind.new, new_image) if step in STEPS_AFTER_RENAME
                                            else (kind.old, old_image))
            check_equal(describe(read_bytes(image), old_image, new_image),
                        describe(expected_image, old_image, new_image), f"{when}: image file after the kill")
            check_equal(describe(read_if_present(image + ".tmp"), old_image, new_image),
                        describe(temporary_file_after_crash(step, new_image), old_image, new_image),
                        f"{when}: temporary file after the kill")
            with kind.server(motwin, state) as server:
                check_clean_restart(server, state, when)
                check_equal(kind.loaded(server), kind.expected(stored_value), f"{when}: value after the restart")
                server.stop()
            check_equal(describe(read_bytes(image), old_image, new_image),
                        describe(expected_image, old_image, new_image), f"{when}: image file after the restart")


KINDS = (Tmcm1636Stap(), Tmcm1636Stgp(), Tmcm1636Download(), Tmcm142Stap(), Tmcm142StoredCoordinate(),
         Tmcm3216Save(), Tmcm3216LssStore())


def crash_test(kind):
    """test_<kind>: the crash at every step for one kind of write (a name for --only and the report)."""
    def test(motwin):
        crash_at_every_step(motwin, kind)
    test.__name__ = f"test_{kind.test_name}"
    return test


# --- The write number and bad values ------------------------------------------------------------

def test_crash_in_the_second_write_of_the_process(motwin):
    with TempDir() as tmp:
        state = os.path.join(tmp, "state")
        with Server(motwin, state) as server:  # the factory image: written by a process of its own
            server.stop()
        with Server(motwin, state, speed="fast", env={CRASH_VARIABLE: "rename:2"}) as server:
            with server.tcp() as c:
                c.sap(43, 1111)
                c.stap(43)  # write 1 of this process
                c.sap(43, 2222)
                c.send_raw(frame(STAP, 43))  # write 2: killed before its rename
                received = tcp_bytes_until_closed(c)
            check_killed_without_reply(server, received, "STAP in write 2")
        image = os.path.join(state, "tmcm-1636.eeprom")
        check_equal(EepromImage(read_bytes(image)).axis_parameter(43), 1111, "AP 43 in the image after the kill")
        temporary = EepromImage(read_bytes(image + ".tmp"))
        check_equal((temporary.problem, temporary.axis_parameter(43)), (None, 2222),
                    "the complete, never renamed temporary file")
        with Server(motwin, state) as server:
            check_clean_restart(server, state, "restart")
            with server.tcp() as c:
                check_equal(c.gap(43), 1111, "AP 43 after the restart")
            server.stop()


def test_a_bad_value_is_a_start_up_error(motwin):
    with TempDir() as tmp:
        state = os.path.join(tmp, "state")
        for value in ("rename:0", "fsync"):
            server = Server(motwin, state, env={CRASH_VARIABLE: value})
            try:
                check_equal(server.start_expect_failure(), 2, f"{value!r}: exit status")
                check_equal(server.stderr_lines(),
                            [f'motwin: error: {CRASH_VARIABLE}="{value}": expected STEP or STEP:N with STEP one of '
                             "open-temporary, write-temporary, sync-temporary, rename, sync-directory and N the "
                             "image write to crash in (1 to 1000000000)"], f"{value!r}: stderr")
            finally:
                server.cleanup()
            check(not os.path.exists(state), f"{value!r}: the state directory was created")


if __name__ == "__main__":
    run_tests([crash_test(kind) for kind in KINDS] +
              [test_crash_in_the_second_write_of_the_process, test_a_bad_value_is_a_start_up_error])
