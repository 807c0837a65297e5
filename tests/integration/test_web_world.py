#!/usr/bin/python3
"""The web console's simulated world (docs/web-console.md, "world" and "world_set", the World
view) against `motwin serve --web`: a script (python3-websocket) reads a TMCM-142's scenario
signals and sets them, and the module reports them over TMCL/TCP; bad requests are errors and
change nothing; a --node bus is read only. In headless Chromium (Selenium) the World view's
check box closes the left limit switch and a TCP host sees it, a motion over TCP turns the drawn
shaft, at 1280x800 and in a 400 pixel wide window, with no SEVERE entry in the browser's log.
Screenshots: <build>/test-artefacts/web-browser/world-view.png and world-view-narrow.png."""

import os
import sys

sys.dont_write_bytecode = True  # no __pycache__ in the source tree
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

import motwin_harness as mh  # noqa: E402
from motwin_harness import TcpClient, TempDir, check, check_equal, run_tests  # noqa: E402
import browser_harness as bh  # noqa: E402
import web_harness as wh  # noqa: E402

try:  # without Selenium, bh.HeadlessChromium skips the browser test before any of these is used
    from selenium.webdriver.common.keys import Keys
except ImportError:  # pragma: no cover - reported as a skip
    pass

LEFT_ENDSTOP = 11    # TMCM-142 AP 11: 1 while the left limit switch is closed
SWITCH_STATUS = 9    # AP 9: bit 0 right, bit 1 left, bit 2 home
DRIVER_STATUS = 26   # AP 26: bit 1 supply below 15 V
MICROSTEPS_PER_REV = 200 * 1024  # AP 27 = 1 (the default) on the 200-step motor


class WorldServer(wh.WebServer):
    """`motwin serve --module tmcm-142` with TMCL over TCP and the web console."""

    BANNER = mh.Tmcm142Server.BANNER

    def __init__(self, motwin, state_dir):
        super().__init__(motwin, state_dir, module="tmcm-142")


class WorldBusServer(wh.WebBusServer):
    """`motwin serve --node tmcm-142 --node tmcm-3216:node-id=1`: members of a bus take no scenario."""

    FIRST_NODE = "tmcm-142"
    BANNER = r"motwin: node tmcm-142-1 tmcm-142 \(142V1\.06\) eeprom (.+)"


def wait_for(description, condition, tmcl):
    """Polls `condition` while the module's simulated clock runs (no wall-clock assertion)."""
    for _ in range(2000):
        if condition():
            return
        tmcl.wait_sim_ms(5)
    raise mh.TestFailure(f"simulated seconds went by without {description}")


def test_world_ops_over_websocket(motwin):
    wh.require_websocket()
    with TempDir() as state, WorldServer(motwin, state).start() as server, \
            TcpClient(server.tcp_port) as tmcl, server.console() as console:
        world = console.ask("world")
        check_equal((world["ok"], world["settable"], len(world["axes"])), (True, True, 1), "world of a TMCM-142")
        signals = {signal["name"]: signal for signal in world["signals"]}
        supply = signals["VSUPPLY"]
        check_equal((supply["min"], supply["max"], supply["unit"], supply["whole"], supply["value"]),
                    (0, 80, "V", False, 24), "VSUPPLY's row")
        check_equal((signals["REF_L"]["value"], signals["REF_L"]["whole"]), (0, True), "REF_L's row")
        check_equal(signals["REF_R_AT"]["value"], None, "REF_R_AT before it is set")
        check_equal(tmcl.gap(LEFT_ENDSTOP), 0, "AP 11 before")

        reply = console.ask("world_set", signal="REF_L", value=1)
        check_equal((reply["ok"], reply["signal"], reply["value"]), (True, "REF_L", 1), "world_set REF_L 1")
        wait_for("AP 11 to read the closed switch", lambda: tmcl.gap(LEFT_ENDSTOP) == 1, tmcl)
        check_equal(tmcl.gap(SWITCH_STATUS) & 2, 2, "AP 9 bit 1 (left)")
        check_equal(console.ask("world", values_only=True)["values"]["REF_L"], 1, "REF_L read back")
        check_equal(console.ask("world_set", module=0, signal="vsupply", value=12)["ok"], True, "VSUPPLY 12")
        wait_for("AP 26 to say the supply is low", lambda: tmcl.gap(DRIVER_STATUS) & 2 == 2, tmcl)

        # Bad requests: an error each, and the world is as it was.
        before = console.ask("world", values_only=True)["values"]
        for fields, says in ((dict(signal="WARP", value=1), 'unknown signal "WARP"'),
                             (dict(signal="VSUPPLY", value=81), "VSUPPLY takes 0 to 80"),
                             (dict(signal="REF_L", value=0.5), "REF_L takes 0 or 1"),
                             (dict(signal="VSUPPLY", value="30"), '"value": expected a number'),
                             (dict(signal="REF_L", value=False), '"value": expected a number'),
                             (dict(value=1), '"signal": expected'),
                             (dict(module=5, signal="REF_L", value=0), "no module 5")):
            reply = console.ask("world_set", **fields)
            check_equal(reply["ok"], False, f"world_set {fields}")
            check(says in reply.get("error", ""), f"world_set {fields}: error {reply.get('error')!r} names {says!r}")
        check_equal(console.ask("world", values_only="yes")["ok"], False, "values_only must be a boolean")
        after = console.ask("world", values_only=True)["values"]
        check_equal(after, before, "the world after the refused requests")
        check_equal(tmcl.gap(LEFT_ENDSTOP), 1, "AP 11 after the refused requests")

        # The drawn shaft: where the simulated rotor is.
        tmcl.ok(4, 0, 0, MICROSTEPS_PER_REV // 2, "MVP ABS, 0, half a turn")
        wait_for("the shaft to reach half a turn",
                 lambda: abs(console.ask("world", values_only=True)["axes"][0]["position_rev"] - 0.5) < 1e-9, tmcl)
        server.stop()


def test_world_of_a_bus_is_read_only(motwin):
    wh.require_websocket()
    with TempDir() as state, WorldBusServer(motwin, state).start() as server, server.console() as console:
        for module, axes in ((0, 1), (1, 3)):
            world = console.ask("world", module=module)
            check_equal((world["ok"], world["settable"], len(world["axes"])), (True, False, axes), f"module {module}")
        reply = console.ask("world_set", module=1, signal="VSUPPLY", value=12)
        check_equal(reply["ok"], False, "world_set on a node")
        check("not set from here" in reply["error"], f"the error says why: {reply['error']!r}")
        check_equal(console.ask("world", module=1, values_only=True)["values"]["VSUPPLY"], 24, "VSUPPLY unchanged")
        server.stop()


class Browser(bh.ConsolePage):
    # The drawing is made afresh with every poll: read it by script, not by held elements.
    def drawn_angle(self):
        value = self.js('const d = document.querySelector("#world-axis-0 svg"); return d && d.dataset.angleDeg;')
        return float(value) if value is not None else None

    def chips(self):
        return self.js('return [...document.querySelectorAll("#world-axis-0 .world-level-chip")].map(e => e.textContent);')

    def set_number(self, signal, text):
        field = self.find(f'input[type="number"][data-signal="{signal}"]')
        field.click()
        field.send_keys(Keys.CONTROL, "a")
        field.send_keys(text, Keys.ENTER)


def test_world_view(motwin):
    with bh.browser_and_server(Browser, WorldServer, motwin) as (browser, server), \
            TcpClient(server.tcp_port) as tmcl:
        browser.open_console(server.url("/"))
        browser.find('#tabs [data-view="world"]').click()
        browser.wait("the World view's controls", lambda: browser.finds('input[type="checkbox"][data-signal="REF_L"]'))
        browser.wait("the shaft drawn", lambda: browser.drawn_angle() == 0.0)

        # A switch toggled on the page is what the module senses, as a TCP host reads it.
        check_equal(tmcl.gap(LEFT_ENDSTOP), 0, "AP 11 before")
        browser.find('input[type="checkbox"][data-signal="REF_L"]').click()
        wait_for("AP 11 to read the switch closed from the page", lambda: tmcl.gap(LEFT_ENDSTOP) == 1, tmcl)
        browser.wait("the drawing's left switch chip", lambda: "left 1" in browser.chips())
        # A switch position by number: the band drawn at 0.75 rev, and out of range refused.
        browser.set_number("REF_R_AT", "0.75")
        browser.wait("the right switch band", lambda: browser.finds('#world-axis-0 rect[data-switch="R"]'))
        browser.set_number("VSUPPLY", "99")
        browser.wait("the refusal of 99 V", lambda: any(
            "VSUPPLY takes 0 to 80" in note.text for note in browser.finds(".world-reply.error")))
        check_equal(tmcl.gap(DRIVER_STATUS) & 2, 0, "AP 26: the supply was not changed")

        # A motion over TCP turns the drawn shaft.
        tmcl.ok(4, 0, 0, MICROSTEPS_PER_REV // 4, "MVP ABS, 0, a quarter turn")
        browser.wait("the drawn shaft at a quarter turn", lambda: abs((browser.drawn_angle() or 0) - 90.0) < 1e-6)
        browser.screenshot(motwin, "world-view")

        # Narrow: nothing wider than the window.
        browser.driver.set_window_size(400, 800)
        browser.wait("the narrow layout", lambda: browser.driver.execute_script(
            "return document.documentElement.scrollWidth <= window.innerWidth + 1"))
        tmcl.ok(4, 0, 0, MICROSTEPS_PER_REV // 2, "MVP ABS, 0, half a turn")
        browser.wait("the drawn shaft at half a turn", lambda: abs((browser.drawn_angle() or 0) - 180.0) < 1e-6)
        browser.screenshot(motwin, "world-view-narrow")
        browser.driver.set_window_size(*bh.WINDOW)

        # Leaving the view ends its session: its polls stop while the page stays connected.
        browser.find('#tabs [data-view="parameters"]').click()
        browser.wait("the World view's session to close", lambda: not browser.js("return window.MotwinWorld.running"))
        browser.check_log_clean()
        server.stop()


if __name__ == "__main__":
    run_tests([test_world_ops_over_websocket, test_world_of_a_bus_is_read_only, test_world_view])
