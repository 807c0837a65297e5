#!/usr/bin/python3
"""The web console's program ops and Program view (docs/web-console.md): over a real WebSocket
(python3-websocket) on a TMCM-1636 and a TMCM-142, and in headless Chromium (Selenium): a program
assembled and downloaded from the page, read back and disassembled, stepped with the program
counter and accumulator the page shows checked against command 135 over TMCL/TCP, run (a user
variable counts, read over TCP), stopped, reset; assembler errors with line numbers; the view in
a 400 pixel wide window; no SEVERE entry in the browser's log. Screenshots in
<build>/test-artefacts/web-program/. The browser test skips (status 77) only when Chromium cannot
start."""

import os
import struct
import sys
import time

sys.dont_write_bytecode = True  # no __pycache__ in the source tree
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

import motwin_harness as mh  # noqa: E402
from motwin_harness import TcpClient, TempDir, check, check_equal, run_tests  # noqa: E402
import browser_harness as bh  # noqa: E402
import can_bus_harness as cbh  # noqa: E402
import web_harness as wh  # noqa: E402

try:  # without Selenium, bh.HeadlessChromium skips the test before any of these is used
    from selenium.webdriver.common.by import By
except ImportError:  # pragma: no cover - reported as a skip
    pass

APPLICATION_STATUS = 135
GLOBAL_BANK_USER = 2
# Counts in the accumulator and copies it to user variable 0 (GGP 0, 2).
COUNTER = """// counter: user variable 0 counts up
Loop:  CALC ADD, 1
       AGP 0, 2
       JA Loop
"""
# Stepping from a reset: (program counter, accumulator) after each 130.
STEPS = [(1, 1), (2, 1), (0, 1), (1, 2)]


class Web142Server(wh.WebServer):
    BANNER = mh.Tmcm142Server.BANNER

    def __init__(self, motwin, state_dir, **options):
        super().__init__(motwin, state_dir, module="tmcm-142", **options)


def tcp_status(tmcl):
    """(mode, program counter, accumulator) by command 135 over TMCL/TCP."""
    status = mh.expect_reply(tmcl.request(APPLICATION_STATUS, 1), APPLICATION_STATUS, what="135 type 1").value
    accumulator = mh.expect_reply(tmcl.request(APPLICATION_STATUS, 2), APPLICATION_STATUS, what="135 type 2").value
    return (status >> 24) & 0xFF, status & 0xFFFF, accumulator


def wait_for(description, condition):
    return mh.poll_until(description, condition, bh.WAIT_S, interval=0.01)


def check_program_ops(server):
    with TcpClient(server.tcp_port) as tmcl, server.console() as console:
        reply = console.ask("program_download", module=0, source=COUNTER, file_name="counter.tmc")
        check_equal((reply["ok"], reply["count"], reply["verified"]), (True, 4, True), f"download: {reply}")
        check_equal(reply["labels"], [{"name": "Loop", "address": 0}], "labels of the download")
        # What a TMCL host reads back with 134 is what was downloaded.
        for address, (command, value) in enumerate([(19, 1), (35, 0), (22, 0), (28, 0)]):
            stored = tmcl.request(134, 0, 0, address)
            check_equal((stored.status, stored.command, stored.value), (100, command, value), f"134 at {address}")

        read = console.ask("program_read", module=0)
        check_equal(read["end"], "nop", "program_read ends at the download's NOP")
        check_equal([(line["address"], line.get("label"), line["text"]) for line in read["instructions"]],
                    [(0, "L0", "CALC ADD, 1"), (1, None, "AGP 0, 2"), (2, None, "JA L0"), (3, None, "STOP")],
                    "the program read back, one line per address")

        check_equal(console.ask("program_control", module=0, action="reset")["status"], 100, "reset (131)")
        for step, expected in enumerate(STEPS):
            check_equal(console.ask("program_control", module=0, action="step")["ok"], True, f"step {step}")
            # The instruction runs at the next control tick: wait for it, then compare with TCP.
            wait_for(f"step {step}", lambda: tcp_status(tmcl)[1:] == expected)
            status = console.ask("app_status", module=0)
            check_equal((status["mode_name"], status["program_counter"], status["accumulator"]),
                        ("step",) + expected, f"app_status after step {step}")
            check_equal((status["mode"], status["program_counter"], status["accumulator"]), tcp_status(tmcl),
                        f"app_status = 135 over TCP after step {step}")

        check_equal(console.ask("program_control", module=0, action="continue")["status"], 100, "continue")
        before = tmcl.ggp(0, GLOBAL_BANK_USER)
        wait_for("user variable 0 to count", lambda: tmcl.ggp(0, GLOBAL_BANK_USER) > before + 100)
        check_equal(console.ask("program_control", module=0, action="stop")["status"], 100, "stop (128)")
        status = console.ask("app_status", module=0)
        check_equal((status["mode_name"], status["stop_reason"]), ("stop", 2), "status after stop")
        check_equal(tcp_status(tmcl)[0], 0, "mode over TCP after the console's stop")

        failed = console.ask("program_download", module=0, source="  MVP ABS, 0, 1000\n  FLY 1\n", file_name="bad.tmc")
        check_equal((failed["ok"], failed["errors"][0]["line"]), (False, 2), f"assembly error: {failed}")
        check_equal(tmcl.request(134, 0, 0, 0).command, 19, "program memory after a source that does not assemble")


def test_program_ops_over_websocket(motwin):
    wh.require_websocket()
    for server_class in (wh.WebServer, Web142Server):
        with TempDir() as state, server_class(motwin, state).start() as server:
            check_program_ops(server)
            server.stop()


def test_tmcl_over_can_node(motwin):
    """A TMCM-1636 that is only a node of the bus (`--node tmcm-1636` beside a TMCM-3216) is reached
    by TMCL over CAN: parameters, a direct-mode instruction, the program ops, an ID change; checked
    by a TMCL-over-CAN host on socketcand (python3-can)."""
    wh.require_websocket()
    try:
        import can  # noqa: F401 - Debian's python3-can
    except ImportError:
        raise mh.Skipped("python3-can is not installed (scripts/install-deps.sh installs it)")
    args = ["--node", "tmcm-1636", "--node", "tmcm-3216:node-id=1", "--can", "socketcand:127.0.0.1:0",
            "--web", "127.0.0.1:0"]
    with TempDir() as state, cbh.BusServer(motwin, state, args).start() as server:
        bus = cbh.open_bus(server.port())
        host = cbh.TmclCan(bus)
        try:
            with wh.ConsoleClient(server.port("web")) as console:
                modules = console.ask("list")["modules"]
                check_equal([(m["name"], m["protocol"]) for m in modules],
                            [("tmcm-1636-1", "tmcl"), ("tmcm-3216-2", "canopen")], "the listed modules")
                check_equal(modules[0]["tmcl_can"], {"receive_id": 1, "send_id": 2}, "TMCL over CAN IDs")
                check(any(p["number"] == 11 for p in modules[0]["sections"][0]["parameters"]), "AP 11 listed")

                # A parameter set by the console, read by the CAN host, and the other way round.
                check_equal(console.ask("set", module=0, kind="global", number=0, bank=2, value=4321)["status"], 100,
                            "SGP 0, 2 over CAN")
                sync_can_host(console, bus)
                check_equal(host.ok(10, 0, 2), 4321, "GGP 0, 2 by the CAN host")
                host.ok(5, 11, 0, 1111)  # SAP 11 (max current), 0, 1111
                check_equal(console.ask("get", module=0, number=11)["value"], 1111, "GAP 11 by the console")
                refused = console.ask("set", module=0, number=11, value=60001)
                check_equal((refused["ok"], refused["status"]), (False, 4), "the module's own range check over CAN")
                reply = console.ask("tmcl", module=0, text="136 0")
                check(reply["ok"] and reply["version"].startswith("1636V1"), f"136 0 over CAN: {reply}")
                update = console.ask("subscribe", items=[{"module": 0, "kind": "global", "number": 0, "bank": 2}],
                                     rate_hz=20)
                check_equal(update["ok"], True, "subscribe over CAN")
                check_equal(console.next_update()["values"][0]["value"], 4321, "a live value over CAN")
                console.ask("unsubscribe")

                # The program ops over CAN, checked with 134 and 135 by the CAN host.
                reply = console.ask("program_download", module=0, source=COUNTER)
                check_equal((reply["ok"], reply["verified"]), (True, True), f"download over CAN: {reply}")
                sync_can_host(console, bus)
                check_equal(host.request(134, 0, 0, 2)[2], 22, "134 at 2 by the CAN host: JA")
                read = console.ask("program_read", module=0)
                check_equal([line["text"] for line in read["instructions"]], ["CALC ADD, 1", "AGP 0, 2", "JA L0", "STOP"],
                            "program_read over CAN")
                console.ask("program_control", module=0, action="reset")
                for step, expected in enumerate(STEPS):
                    check_equal(console.ask("program_control", module=0, action="step")["ok"], True, f"step {step}")
                    wait_for(f"step {step}", lambda: (console.ask("app_status", module=0)["program_counter"],
                                                      console.ask("app_status", module=0)["accumulator"]) == expected)
                    sync_can_host(console, bus)
                    pc = host.ok(135, 1) & 0xFFFF
                    check_equal((pc, host.ok(135, 2)), expected, f"135 by the CAN host after step {step}")

                # New IDs (SGP 71, 70) take effect with the next frame: the console follows them.
                check_equal(console.ask("set", module=0, kind="global", number=71, bank=0, value=5)["status"], 100,
                            "SGP 71 = 5")
                check_equal(console.ask("set", module=0, kind="global", number=70, bank=0, value=6)["status"], 100,
                            "SGP 70 = 6")
                check_equal(console.ask("get", module=0, kind="global", number=0, bank=2)["value"], 1,
                            "GGP over the new IDs")
                check_equal(console.ask("list")["modules"][0]["tmcl_can"], {"receive_id": 5, "send_id": 6},
                            "the IDs listed")
                sync_can_host(console, bus, send_id=6)
                check_equal(cbh.TmclCan(bus, receive_id=5, send_id=6).ok(10, 0, 2), 1, "the CAN host on the new IDs")

                # The bus monitor shows the console's TMCL frames and the module's replies.
                check_equal(console.ask("monitor", enable=True)["ok"], True, "monitor")
                console.ask("get", module=0, kind="global", number=0, bank=2)
                seen_ids = set()

                def console_frames_seen():
                    console.ask("list")  # reads the pushes that came meanwhile
                    for push in console.pushes:
                        if push["push"] == "frames":
                            seen_ids.update(frame["id"] for frame in push["frames"])
                    console.pushes.clear()
                    return {5, 6} <= seen_ids
                wait_for("the console's TMCL frames in the monitor", console_frames_seen)
        finally:
            bus.shutdown()
        server.stop()


SYNC_MARKS = iter(range(1000, 1000000))


def sync_can_host(console, bus, send_id=2):
    """The CAN host hears every reply the module sends the console too (TMCL over CAN has no
    request tag): it drops them, up to the reply to an SGP of user variable 50 with a value of
    its own that the console sends last."""
    mark = next(SYNC_MARKS)
    check_equal(console.ask("tmcl", module=0, text=f"SGP 50, 2, {mark}")["status"], 100, "SGP 50, 2 over CAN")
    cbh.receive(bus, lambda m: m.arbitration_id == send_id and len(m.data) >= 7 and m.data[2] == 9 and
                struct.unpack_from(">i", bytes(m.data), 3)[0] == mark, mh.FRAME_TIMEOUT, f"the reply to SGP 50, 2, {mark}")


class Browser(bh.ConsolePage):
    ARTEFACTS = "web-program"

    def text(self, element_id):
        return self.driver.find_element(By.ID, element_id).text

    def status_shown(self):
        """(mode, program counter, accumulator) as the view shows them, or None before a status."""
        shown = [self.text("program-mode"), self.text("program-pc"), self.text("program-accumulator")]
        if "–" in shown:
            return None
        return shown[0], int(shown[1]), int(shown[2])

    def replies_seen(self):
        return self.js("return window.motwinProgram.statusReplies")


MODE_NAMES = {0: "stop", 1: "run", 2: "step", 3: "reset"}


def test_program_view(motwin):
    with bh.browser_and_server(Browser, wh.WebServer, motwin) as (browser, server), \
            TcpClient(server.tcp_port) as tmcl:
        browser.open_console(server.url("/"))
        browser.show("program")
        # Factory memory: STOP everywhere, read to its end.
        browser.wait("the stored program", lambda: len(browser.finds("#program-lines tbody tr")) == 2048)
        browser.wait("a live status", lambda: browser.status_shown() is not None)

        # A source with errors: nothing downloaded, the errors with their line numbers.
        source = browser.find("#program-source")
        source.send_keys("  MVP ABS, 0, 1000\n  FLY 1\n  JA Nowhere\n")
        browser.find("#program-download").click()
        browser.wait("the assembler's errors", lambda: len(browser.finds("#program-errors li")) == 2)
        errors = [item.text for item in browser.finds("#program-errors li")]
        check(errors[0].startswith("program.tmc line 2") and "FLY" in errors[0], f"first error: {errors}")
        check(errors[1].startswith("program.tmc line 3"), f"second error: {errors}")
        browser.screenshot(motwin, "program-errors")
        check_equal(tmcl.request(134, 0, 0, 0).command, 28, "program memory after a source with errors (STOP)")
        browser.finds("#program-errors li")[0].click()  # selects line 2 in the source
        check_equal(browser.js("const a = document.getElementById('program-source');"
                               "return a.value.substring(a.selectionStart, a.selectionEnd)"), "  FLY 1",
                    "the error's line selected in the source")

        # The counter, downloaded from the page and verified, read back one line per address.
        browser.js("document.getElementById('program-source').value = arguments[0]", COUNTER)
        browser.find("#program-download").click()
        browser.wait("the download", lambda: "verified" in browser.text("program-note"))
        check_equal(browser.finds("#program-errors li"), [], "no errors after a good download")
        browser.wait("the program read back", lambda: len(browser.finds("#program-lines tbody tr")) == 4)
        lines = [[cell.text for cell in row.find_elements(By.TAG_NAME, "td")]
                 for row in browser.finds("#program-lines tbody tr")]
        check_equal([line[1:] for line in lines], [["L0", "CALC ADD, 1"], ["", "AGP 0, 2"], ["", "JA L0"], ["", "STOP"]],
                    "the listing")
        check_equal(tmcl.request(134, 0, 0, 2).command, 22, "JA stored at address 2, read over TCP")

        # Reset, then step: the view's PC and accumulator equal 135 over TCP; the PC line is marked.
        browser.find("#program-reset").click()
        browser.wait("reset", lambda: browser.status_shown() == ("reset", 0, 0))
        for step, expected in enumerate(STEPS):
            browser.find("#program-step").click()
            browser.wait(f"step {step} shown", lambda: browser.status_shown() == ("step",) + expected)
            mode, pc, accumulator = tcp_status(tmcl)
            check_equal((MODE_NAMES[mode], pc, accumulator), browser.status_shown(), f"135 over TCP after step {step}")
            marked = browser.finds("#program-lines tr.pc")
            check_equal([row.get_attribute("data-address") for row in marked], [str(expected[0])],
                        f"the line at the program counter after step {step}")
        browser.screenshot(motwin, "program-step")

        # Run: user variable 0 counts (read over TCP) and the view's accumulator follows.
        before = tmcl.ggp(0, GLOBAL_BANK_USER)
        browser.find("#program-continue").click()
        wait_for("user variable 0 to count", lambda: tmcl.ggp(0, GLOBAL_BANK_USER) > before + 1000)
        browser.wait("the view's accumulator to follow",
                     lambda: browser.status_shown()[0] == "run" and browser.status_shown()[2] > before + 1000)
        # Live: several status replies a second (wall time) while the view is open.
        seen = browser.replies_seen()
        start = time.monotonic()
        browser.wait("more status replies", lambda: browser.replies_seen() >= seen + 10)
        rate = 10 / (time.monotonic() - start)
        print(f"program view: {rate:.1f} status updates a second", flush=True)
        browser.screenshot(motwin, "program-run")
        browser.find("#program-stop").click()
        browser.wait("stop shown", lambda: browser.status_shown()[0] == "stop")
        check_equal(tcp_status(tmcl)[0], 0, "mode over TCP after the page's Stop")
        check("stopped by the host" in browser.text("program-stop-reason"), "the stop reason shown")
        stopped_at = tmcl.ggp(0, GLOBAL_BANK_USER)
        tmcl.wait_sim_ms(50)
        check_equal(tmcl.ggp(0, GLOBAL_BANK_USER), stopped_at, "user variable 0 50 ms after Stop")
        browser.find("#program-reset").click()
        browser.wait("reset shown", lambda: browser.status_shown() == ("reset", 0, 0))
        check_equal(tcp_status(tmcl), (3, 0, 0), "135 over TCP after the page's Reset")

        # Run from a line picked in the listing: address 3 is the STOP, which stops the program there.
        browser.finds("#program-lines tbody tr")[3].click()
        check_equal(browser.find("#program-address").get_attribute("value"), "3", "the picked address")
        browser.find("#program-run").click()
        browser.wait("the STOP at 3", lambda: browser.text("program-stop-reason") == "STOP instruction at 3")
        check_equal(mh.expect_reply(tmcl.request(APPLICATION_STATUS, 4), APPLICATION_STATUS).value, (1 << 16) | 3,
                    "135 type 4 over TCP: STOP instruction at address 3")
        check_equal(tmcl.ggp(0, GLOBAL_BANK_USER), stopped_at, "user variable 0 after running only the STOP")
        browser.screenshot(motwin, "program")

        # A narrow window: nothing wider than the window.
        browser.driver.set_window_size(400, 800)
        browser.wait("the narrow layout", lambda: browser.js(
            "return document.documentElement.scrollWidth <= window.innerWidth + 1"))
        browser.screenshot(motwin, "program-narrow")
        # Leaving the view closes its session: no more status replies.
        browser.find('#tabs [data-view="parameters"]').click()
        seen = browser.replies_seen()
        tmcl.wait_sim_ms(300)
        check(browser.replies_seen() <= seen + 1, "status replies after leaving the view")
        browser.check_log_clean()
        server.stop()


def test_program_view_over_can(motwin):
    """The Program view of a TMCM-1636 that is only a node of the bus (TMCL over CAN): download and
    step from the page, the status shown equal to app_status asked by a script's session (over the
    same console port: a second TMCL-over-CAN host would confuse the module's replies)."""
    args = ["--node", "tmcm-1636", "--node", "tmcm-3216:node-id=1", "--can", "socketcand:127.0.0.1:0",
            "--web", "127.0.0.1:0"]
    with bh.browser_and_server(Browser, cbh.BusServer, motwin, args) as (browser, server), \
            wh.ConsoleClient(server.port("web")) as console:
        browser.open_console(f"http://127.0.0.1:{server.port('web')}/")
        browser.wait("two modules", lambda: len(browser.finds("#module-picker option")) == 2)
        browser.find('#tabs [data-view="program"]').click()
        browser.wait("the program view", lambda: browser.find("#program-body").is_displayed())
        browser.wait("a live status", lambda: browser.status_shown() is not None)
        browser.js("document.getElementById('program-source').value = arguments[0]", COUNTER)
        browser.find("#program-download").click()
        browser.wait("the download", lambda: "verified" in browser.text("program-note"))
        browser.wait("the program read back", lambda: len(browser.finds("#program-lines tbody tr")) == 4)
        browser.find("#program-reset").click()
        browser.wait("reset", lambda: browser.status_shown() == ("reset", 0, 0))
        for step, expected in enumerate(STEPS[:2]):
            browser.find("#program-step").click()
            browser.wait(f"step {step} shown", lambda: browser.status_shown() == ("step",) + expected)
            status = console.ask("app_status", module=0)
            check_equal(("step", status["program_counter"], status["accumulator"]), browser.status_shown(),
                        f"app_status of a script after step {step}")
        browser.screenshot(motwin, "program-can-node")
        # The CANopen node beside it has no program: the view says so.
        browser.js("const p = document.getElementById('module-picker'); p.value = '1';"
                   "p.dispatchEvent(new Event('change'));")
        browser.wait("the line for a module without TMCL", lambda: browser.find("#program-none").is_displayed())
        check(not browser.find("#program-body").is_displayed(), "no program body for a CANopen node")
        browser.check_log_clean()
        server.stop()


if __name__ == "__main__":
    run_tests([test_program_ops_over_websocket, test_tmcl_over_can_node, test_program_view, test_program_view_over_can])
