#!/usr/bin/python3
"""The Scope view's datalogger mode (docs/web-console.md, docs/datalogger.md): the console's
"datalogger" op spoken by a script over the WebSocket (python3-websocket), its samples checked
against GET_SAMPLE (142 type 9) over TMCL/TCP on the same serve; then in headless Chromium
(Selenium, browser_harness.py) a TMCM-1636 velocity step captured at 2 kHz with a trigger and
pretrigger, plotted at 0.5 ms spacing, exported, repeated; a TMCM-142 offers no datalogger mode.
Screenshots under <build>/test-artefacts/web-datalogger/. The browser test skips (status 77)
only when the browser cannot start."""

import csv
import io
import os
import sys

sys.dont_write_bytecode = True  # no __pycache__ in the source tree
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

import motwin_harness as mh  # noqa: E402
from motwin_harness import ROR, MST, TcpClient, TempDir, check, check_equal, run_tests  # noqa: E402
import browser_harness as bh  # noqa: E402
import web_harness as wh  # noqa: E402

try:  # without Selenium, bh.HeadlessChromium skips the tests before any of these is used
    from selenium.webdriver.common.by import By
    from selenium.webdriver.support.ui import Select
except ImportError:  # pragma: no cover - reported as a skip
    pass

RAMDEBUG, GET_STATE, GET_SAMPLE = 142, 8, 9
STATUS_OK = 100
ACTUAL_VELOCITY, ACTUAL_POSITION, TORQUE_CURRENT = 42, 52, 31  # TMCM-1636 axis parameters
STEP_RPM = 2000
TRIGGER_RPM = 50


def wait_for_state(console, state):
    """Polls the capture's state over the console until it is `state` (the simulation runs on)."""
    for _ in range(100000):
        reply = console.ask("datalogger", action="state")
        check(reply["ok"], f"state: {reply}")
        if reply["state"] == state:
            return reply
    raise mh.TestFailure(f"the datalogger never reached {state}")


class Tmcm142WebServer(wh.WebServer):
    BANNER = r"motwin: tmcm-142 \(142V1\.06\) eeprom (.+)"

    def __init__(self, motwin, state_dir):
        super().__init__(motwin, state_dir, module="tmcm-142")


def test_datalogger_over_websocket(motwin):
    """A capture through the op equals what GET_SAMPLE answers over TMCL/TCP; the trigger and
    pretrigger land where the module puts them; a TMCM-142 refuses with its own status."""
    wh.require_websocket()
    with TempDir() as state, wh.WebServer(motwin, state).start() as server, TcpClient(server.tcp_port) as tmcl, \
            server.console() as console:
        info = console.ask("datalogger", action="info")
        check_equal((info["ok"], info["channels"], info["buffer_words"], info["base_rate_hz"]), (True, 4, 8192, 2000),
                    "info: the TMCM-1636's figures")
        started = console.ask("datalogger", action="start", samples=600, prescaler=0,
                              channels=[{"kind": "axis", "number": ACTUAL_VELOCITY},
                                        {"kind": "axis", "number": ACTUAL_POSITION}],
                              trigger={"channel": 0, "level": TRIGGER_RPM, "edge": "rising", "pretrigger": 100})
        check(started["ok"], f"start: {started}")
        wait_for_state(console, "trigger")
        tmcl.ok(ROR, 0, 0, STEP_RPM, f"ROR 0, {STEP_RPM}")
        complete = wait_for_state(console, "complete")
        check_equal(complete["captured_words"], 1200, "captured words")
        tmcl.ok(MST, 0, 0, 0, "MST")
        read = console.ask("datalogger", action="read")
        check(read["ok"], f"read: {read}")
        check_equal((read["samples"], read["pretrigger_samples"], read["base_rate_hz"]), (600, 100, 2000),
                    "samples, pretrigger, base rate")
        check_equal([c["number"] for c in read["channels"]], [ACTUAL_VELOCITY, ACTUAL_POSITION], "channels")
        velocity, position = read["values"]
        check(velocity[99] <= TRIGGER_RPM < velocity[100], f"the trigger at sample 100: {velocity[95:105]}")
        # The velocity ramp (AP 44, 2000 rpm/s by default) adds about 500 rpm in the 0.25 s after the trigger.
        check(velocity[-1] > velocity[100] + 300, f"the velocity rises: {velocity[100]} .. {velocity[-1]}")
        check(position[-1] > position[100], "the position advances")
        # The same words over TMCL/TCP, row by row (velocity, position).
        for k in range(1200):
            reply = tmcl.request(RAMDEBUG, GET_SAMPLE, 0, k)
            check_equal(reply.status, STATUS_OK, f"GET_SAMPLE {k}")
            check_equal(reply.value, read["values"][k % 2][k // 2], f"GET_SAMPLE {k} against the op's value")
        stopped = console.ask("datalogger", action="stop")
        check(stopped["ok"], "stop")
        check_equal(console.ask("datalogger", action="state")["state"], "idle", "state after stop")
        server.stop()
    with TempDir() as state, Tmcm142WebServer(motwin, state).start() as server, server.console() as console:
        refused = console.ask("datalogger", action="info")
        check_equal((refused["ok"], refused.get("status")), (False, 2), "a TMCM-142's answer to 142 GET_INFO")
        server.stop()


class Browser(bh.ConsolePage):
    ARTEFACTS = "web-datalogger"

    def datalogger(self, expression):
        return self.js("const d = window.motwinDatalogger; return " + expression + ";")


def set_number(browser, css, value):
    browser.js("const e = document.querySelector(arguments[0]); e.value = arguments[1];"
               "e.dispatchEvent(new Event('input'));", css, str(value))


def test_datalogger_in_browser(motwin):
    """A TMCM-1636 velocity step captured at 2 kHz from the Scope view: the plotted sample count
    and 0.5 ms spacing, the trigger at 0 s, the curve moving, CSV and PNG export; repeat captures
    again; a TMCM-142 offers no datalogger mode; no SEVERE browser log entry."""
    with bh.browser_and_server(Browser, wh.WebServer, motwin) as (browser, server), \
            TcpClient(server.tcp_port) as tmcl:
        browser.open_console(server.url("/"))
        browser.show("scope")
        browser.wait("the datalogger mode to be offered", lambda: browser.find("#scope-mode").is_displayed())
        check("2000 Hz" in browser.find("#datalogger-mode-label").text, "the mode names the base rate")
        check(browser.find("#view-scope .scope-setup").is_displayed(), "live mode first")
        browser.find('input[name=scope-mode][value="datalogger"]').click()
        browser.wait("the datalogger controls", lambda: browser.find("#datalogger").is_displayed())
        check(not browser.find("#view-scope .scope-setup").is_displayed(), "the live controls are hidden")
        channels = browser.driver.find_elements(By.CSS_SELECTOR, "#datalogger-channels select")
        check_equal(len(channels), 4, "one picker per datalogger channel")
        Select(channels[0]).select_by_value(f"a{ACTUAL_VELOCITY}")
        Select(channels[1]).select_by_value(f"a{ACTUAL_POSITION}")
        Select(channels[2]).select_by_value(f"a{TORQUE_CURRENT}")
        rate = Select(browser.find("#datalogger-rate"))
        check_equal(len(rate.options), 8, "rates: the base rate and its prescalers")
        rate.select_by_value("0")  # 2000 Hz
        check("2000 Hz" in rate.first_selected_option.text, f"rate {rate.first_selected_option.text}")
        set_number(browser, "#datalogger-samples", 1000)
        check_equal(browser.find("#datalogger-samples").get_attribute("max"), str(8192 // 3), "samples at most")
        Select(browser.find("#datalogger-trigger")).select_by_index(1)  # the first channel: velocity
        Select(browser.find("#datalogger-edge")).select_by_value("rising")
        set_number(browser, "#datalogger-level", TRIGGER_RPM)
        set_number(browser, "#datalogger-pretrigger", 200)
        browser.find("#datalogger-start").click()
        browser.wait("the capture to be armed", lambda: "armed (trigger)" in browser.find("#datalogger-note").text)
        browser.screenshot(motwin, "datalogger-armed")
        check_equal(browser.datalogger("d.captures"), 0, "nothing captured before the trigger")

        tmcl.ok(ROR, 0, 0, STEP_RPM, f"ROR 0, {STEP_RPM}")
        browser.wait("the capture to be plotted", lambda: browser.datalogger("d.captures") == 1)
        check(not browser.datalogger("d.running"), "single shot: done after one capture")
        data = browser.datalogger("d.scope.uplot.data")
        times, velocity, position, torque = data
        check_equal(len(times), 1000, "plotted samples")
        check_equal([len(velocity), len(position), len(torque)], [1000] * 3, "samples per curve")
        spacings = {round(b - a, 9) for a, b in zip(times, times[1:])}
        check_equal(spacings, {0.0005}, "sample spacing at 2 kHz (s)")
        check_equal((times[0], times[200]), (-0.1, 0.0), "200 samples before the trigger at 0 s")
        check(velocity[199] <= TRIGGER_RPM < velocity[200], f"the trigger's crossing at 0 s: {velocity[195:205]}")
        check(velocity[-1] > velocity[200] + 300, f"the velocity curve rises: {velocity[200]} .. {velocity[-1]}")
        check(position[-1] > position[200] + 100, f"the position curve moves: {position[200]} .. {position[-1]}")
        check_equal(browser.datalogger("d.scope.series.map(s => s.name)"), ["AP42", "AP52", "AP31"], "the curves")
        check("captured 1000 samples" in browser.find("#datalogger-note").text, browser.find("#datalogger-note").text)
        browser.screenshot(motwin, "datalogger-step")

        # Exports, through the scope component: the CSV's rows are the samples.
        rows = list(csv.reader(io.StringIO(browser.datalogger("d.scope.exportCsv()"))))
        check_equal(rows[0], ["time_s", "AP42", "AP52", "AP31"], "CSV header")
        check_equal(len(rows), 1001, "CSV rows")
        check_equal((float(rows[201][0]), int(rows[201][1])), (0.0, velocity[200]), "CSV row at the trigger")
        png = browser.datalogger("d.scope.exportPng()")
        check(png.startswith("data:image/png;base64,"), "PNG export")
        # Zoom and cursor: the component's own.
        browser.datalogger("d.scope.zoom(-0.01, 0.01)")
        check_equal([round(v, 6) for v in browser.datalogger("[d.scope.uplot.scales.x.min, d.scope.uplot.scales.x.max]")],
                    [-0.01, 0.01], "zoom to 20 ms around the trigger")
        browser.datalogger("d.scope.resetZoom()")

        # A narrow window: controls wrap, the plot follows the width.
        browser.driver.set_window_size(400, 800)
        browser.wait("the plot to fit 400 px", lambda: browser.datalogger("d.scope.uplot.width") <= 400)
        browser.screenshot(motwin, "datalogger-narrow")
        browser.driver.set_window_size(*bh.WINDOW)

        # Repeat: another capture comes without another click; Stop ends it.
        tmcl.ok(MST, 0, 0, 0, "MST")
        Select(browser.find("#datalogger-trigger")).select_by_index(0)  # none: at once
        Select(browser.find("#datalogger-repeat")).select_by_value("repeat")
        set_number(browser, "#datalogger-samples", 200)
        browser.find("#datalogger-start").click()
        browser.wait("repeated captures", lambda: browser.datalogger("d.captures") >= 3)
        check(browser.datalogger("d.running"), "repeat keeps capturing")
        check_equal(len(browser.datalogger("d.scope.uplot.data[0]")), 200, "samples of a repeated capture")
        browser.find("#datalogger-stop").click()
        browser.wait("the capture to stop", lambda: not browser.datalogger("d.running"))
        # Stop is INIT, the page's last request: once its session is closed, the module's
        # datalogger is idle (GET_STATE over TMCL/TCP).
        browser.wait("the mode's session to close after Stop", lambda: not browser.datalogger("d.sessionOpen"))
        check_equal(tmcl.request(RAMDEBUG, GET_STATE).value, 0, "the module's datalogger state after Stop")

        # Live mode again: its controls back, the datalogger's hidden.
        browser.find('input[name=scope-mode][value="live"]').click()
        check(browser.find("#view-scope .scope-setup").is_displayed(), "live controls")
        check(not browser.find("#datalogger").is_displayed(), "datalogger controls hidden in live mode")
        browser.check_log_clean()
        server.stop()

    with bh.browser_and_server(Browser, Tmcm142WebServer, motwin) as (browser, server):
        browser.open_console(server.url("/"))
        browser.show("scope")
        browser.wait("the live scope's curves", lambda: browser.js("return document.querySelectorAll('#scope-choices li').length") > 0)
        # The page asked GET_INFO and the TMCM-142 answered status 2: wait for that answer.
        browser.wait("the module's answer to GET_INFO", lambda: browser.js("return window.motwinDatalogger.infoAnswered"))
        check(not browser.js("return window.motwinDatalogger.available"), "no datalogger on a TMCM-142")
        check(not browser.find("#scope-mode").is_displayed(), "no datalogger mode on a TMCM-142")
        check(browser.find("#view-scope .scope-setup").is_displayed(), "live controls on a TMCM-142")
        browser.screenshot(motwin, "datalogger-tmcm142")
        browser.check_log_clean()
        server.stop()


if __name__ == "__main__":
    run_tests([test_datalogger_over_websocket, test_datalogger_in_browser])
