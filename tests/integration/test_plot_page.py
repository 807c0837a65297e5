#!/usr/bin/python3
"""Trace pages and the scope component in a real browser: headless Chromium driven by Selenium
(Debian's chromium, chromium-driver, python3-selenium).

1. The page `motwin run --plot` writes for a TMCM-1636 position step (tests/programs/
   tmcm1636_position_step.tmc on the default-24v motor): its curves hold the run's CSV trace,
   drag zoom and double-click reset, the cursor readout, a level trigger from the toolbar, CSV and
   PNG export, at 1280x800 and in a narrow window; no SEVERE entry in the browser log.
2. web/site/scope.js live: a page pushes 4 curves at 25 samples a second; after the last push the
   plot shows the last point, with at most one redraw per push; pause holds the view, a live
   trigger freezes its window around the crossing.

Artefacts (kept after the run): build/test-artefacts/plot-page/ holds the trace page, its CSV,
screenshots of both pages and the exported PNG. scripts/update-doc-images.sh copies the trace
page's screenshot to docs/images/trace-step-response.png. Every wait is for a condition
(WebDriverWait); the script skips (exit status 77) only when no browser can start.
"""

import base64
import csv
import io
import os
import struct
import subprocess
import sys
import zlib

sys.dont_write_bytecode = True  # no __pycache__ in the source tree
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

import browser_harness as bh  # noqa: E402
from motwin_harness import check, check_equal, run_tests  # noqa: E402

SOURCE_ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
STEP_PROGRAM = os.path.join(SOURCE_ROOT, "tests", "programs", "tmcm1636_position_step.tmc")
UPLOT_JS = os.path.join(SOURCE_ROOT, "web", "node_modules", "uplot", "dist", "uPlot.iife.min.js")
UPLOT_CSS = os.path.join(SOURCE_ROOT, "web", "node_modules", "uplot", "dist", "uPlot.min.css")
SCOPE_JS = os.path.join(SOURCE_ROOT, "web", "site", "scope.js")
SCOPE_CSS = os.path.join(SOURCE_ROOT, "web", "site", "scope.css")
COLUMNS = ["AP50", "AP52", "AP42", "AP31"]  # target and actual position, velocity, torque current
UNITS = ["counts", "counts", "rpm", "mA"]
WAIT_S = 60.0  # bounds a failing wait on a loaded machine; nothing asserts how long a wait took
LIVE_PUSHES = 75  # 3 s at 25 a second
LIVE_PERIOD_S = 0.04
LIVE_WINDOW_S = 2.0


def artefact_dir(motwin):
    return bh.artefact_dir(motwin, "plot-page")


# --- The browser ---------------------------------------------------------------------------------

class Browser(bh.HeadlessChromium):
    """Headless Chromium for trace pages and the scope component; waits bounded by WAIT_S."""

    def __init__(self):
        super().__init__()
        self.driver.set_script_timeout(WAIT_S)

    def wait_for(self, condition, what):
        """Polls `condition(driver)` until it is truthy; returns its value."""
        from selenium.common.exceptions import TimeoutException
        from selenium.webdriver.support.ui import WebDriverWait
        try:
            return WebDriverWait(self.driver, WAIT_S, poll_frequency=0.05).until(condition)
        except TimeoutException:
            raise AssertionError(f"waited {WAIT_S} s for {what}")

    def wait_js(self, script, what, *args):
        return self.wait_for(lambda d: d.execute_script(script, *args), what)

    def next_frames(self, count=2):
        """Returns after `count` animation frames of the page: a redraw scheduled before has run."""
        self.driver.execute_async_script(
            "const done = arguments[1]; let left = arguments[0];"
            "const step = () => (--left <= 0 ? done(true) : requestAnimationFrame(step));"
            "requestAnimationFrame(step);", count)



def decode_png(data_url):
    """(width, height) of a PNG data URL whose chunks all check out (CRC, IHDR first, IEND last)."""
    prefix = "data:image/png;base64,"
    check(data_url.startswith(prefix), f"a PNG data URL: {data_url[:40]!r}")
    png = base64.b64decode(data_url[len(prefix):], validate=True)
    check_equal(png[:8], b"\x89PNG\r\n\x1a\n", "PNG signature")
    at, chunks, size = 8, [], None
    while at < len(png):
        length, kind = struct.unpack(">I4s", png[at:at + 8])
        body = png[at + 8:at + 8 + length]
        (crc,) = struct.unpack(">I", png[at + 8 + length:at + 12 + length])
        check_equal(crc, zlib.crc32(kind + body), f"CRC of the {kind!r} chunk")
        if kind == b"IHDR":
            size = struct.unpack(">II", body[:8])
        chunks.append(kind)
        at += 12 + length
    check(chunks[0] == b"IHDR" and chunks[-1] == b"IEND" and b"IDAT" in chunks, f"PNG chunks {chunks}")
    return size


def read_csv_text(text):
    rows = list(csv.reader(io.StringIO(text)))
    return rows[0], [[float(v) for v in row] for row in rows[1:]]


# --- 1. The trace page ---------------------------------------------------------------------------

def write_step_trace(motwin, out_dir):
    page = os.path.join(out_dir, "trace-step-response.html")
    trace = os.path.join(out_dir, "trace-step-response.csv")
    # From the source tree, so that the page names the program as the README's command does.
    result = subprocess.run(
        [motwin, "run", os.path.relpath(STEP_PROGRAM, SOURCE_ROOT), "--module", "tmcm-1636", "--motor", "default-24v",
         "--for", "300ms", "--sample", "1ms", "--param", ",".join(c[2:] for c in COLUMNS), "--trace",
         os.path.relpath(trace, SOURCE_ROOT), "--plot", os.path.relpath(page, SOURCE_ROOT)],
        cwd=SOURCE_ROOT, stdin=subprocess.DEVNULL, capture_output=True, text=True, timeout=120)
    check_equal(result.returncode, 0, f"motwin run --plot exit status ({result.stderr})")
    with open(trace) as f:
        header, rows = read_csv_text(f.read())
    check_equal(header, ["time_s"] + COLUMNS, "CSV header")
    return page, rows


def plot_data(browser):
    return browser.js("return window.motwinPlot.uplot.data;")


def test_trace_page_in_a_browser(motwin):
    """The step response page: data, zoom, cursor, trigger, exports, narrow window, clean log."""
    out_dir = artefact_dir(motwin)
    page, rows = write_step_trace(motwin, out_dir)
    with Browser() as browser:
        driver = browser.driver
        driver.get("file://" + page)
        browser.wait_js("return window.motwinPlot && window.motwinPlot.uplot.data[0].length > 0", "the plot")

        # The curves hold the run's samples, each on the axis of its unit.
        data = plot_data(browser)
        check_equal(len(data), 1 + len(COLUMNS), "uPlot series: time and the four columns")
        check_equal(len(data[0]), len(rows), "points per curve")
        for k, row in enumerate(rows):
            check(abs(data[0][k] - row[0]) < 1e-12, f"time of sample {k}: {data[0][k]} against {row[0]}")
            for i in range(len(COLUMNS)):
                check_equal(data[i + 1][k], row[i + 1], f"{COLUMNS[i]} at sample {k}")
        labels = browser.js("return window.motwinPlot.uplot.axes.map(a => a.label);")
        check_equal(labels, ["time (s)", "counts", "rpm", "mA"], "axis labels")
        legend = browser.js("return [...document.querySelectorAll('.u-legend .u-series .u-label')]"
                            ".map(e => e.textContent);")
        check_equal(legend[1:], ["AP50 target position", "AP52 actual position", "AP42 actual velocity",
                                 "AP31 actual torque"], "legend labels")
        check_equal(browser.js("return [window.motwinPlot.uplot.scales.x.min, window.motwinPlot.uplot.scales.x.max];"),
                    [0, 0.3], "the whole run in view")
        driver.save_screenshot(os.path.join(out_dir, "trace-step-response.png"))

        # Zoom: drag across a quarter of the plot, in the middle; double-click goes back.
        from selenium.webdriver.common.action_chains import ActionChains
        from selenium.webdriver.common.by import By
        over = driver.find_element(By.CSS_SELECTOR, ".u-over")
        width, height = over.size["width"], over.size["height"]
        ActionChains(driver).move_to_element_with_offset(over, -width // 4, 0).click_and_hold() \
            .move_by_offset(width // 4, 0).release().perform()
        x_range = browser.wait_js(
            "const s = window.motwinPlot.uplot.scales.x; return s.max - s.min < 0.1 ? [s.min, s.max] : null;",
            "the drag to zoom in")
        check(0.06 < x_range[0] < 0.09 and 0.14 < x_range[1] < 0.16, f"zoomed to the dragged quarter: {x_range}")
        check_equal(browser.js("return window.motwinPlot.scope.zoomRange;"), x_range, "the scope keeps the zoom")
        ActionChains(driver).double_click(over).perform()
        browser.wait_js("const s = window.motwinPlot.uplot.scales.x; return s.min === 0 && s.max === 0.3;",
                        "the double click to zoom out")
        check_equal(browser.js("return window.motwinPlot.scope.zoomRange;"), None, "zoom forgotten")

        # Cursor readout: the legend shows every curve's value, with its unit, at the cursor.
        ActionChains(driver).move_to_element_with_offset(over, -width // 2 + width // 10, -height // 4).perform()
        readout = browser.wait_js("return window.motwinPlot.scope.readout();", "the cursor over the plot")
        index = readout["index"]
        check(20 <= index <= 40, f"the cursor a tenth into 0..0.3 s: sample {index}")
        check_equal(readout["values"], rows[index][1:], f"readout at sample {index}")
        shown = browser.wait_js(
            "const v = [...document.querySelectorAll('.u-legend .u-series .u-value')].map(e => e.textContent);"
            "return v[0] !== '–' ? v : null;", "the legend values")
        expected = [f"{readout['time_s']:g} s"] + [f"{int(v)} {u}" for v, u in zip(rows[index][1:], UNITS)]
        check_equal(shown, expected, "legend values at the cursor")

        # Trigger from the toolbar: velocity rising through 1000 rpm; the view centres the first
        # crossing with a quarter of the span before it.
        selects = driver.find_elements(By.CSS_SELECTOR, ".motwin-scope-trigger select")
        from selenium.webdriver.support.ui import Select
        Select(selects[0]).select_by_visible_text("AP42 actual velocity")
        level = driver.find_element(By.CSS_SELECTOR, ".motwin-scope-trigger input")
        level.clear()
        level.send_keys("1000")
        driver.find_element(By.XPATH, "//button[text()='Trigger']").click()
        status = browser.wait_js(
            "const t = window.motwinPlot.scope.triggerStatus(); return t.state === 'triggered' ? t : null;",
            "the trigger")
        crossing = next(k for k in range(1, len(rows)) if rows[k - 1][3] < 1000 <= rows[k][3])
        check_equal(status["time_s"], rows[crossing][0], "trigger time: the first sample at or past the level")
        x_range = browser.js("const s = window.motwinPlot.uplot.scales.x; return [s.min, s.max];")
        check(abs(x_range[0] - (rows[crossing][0] - 0.075)) < 1e-9 and abs(x_range[1] - (rows[crossing][0] + 0.225)) < 1e-9,
              f"trigger window {x_range} around {rows[crossing][0]}")
        check("trigger triggered at" in driver.find_element(By.CSS_SELECTOR, ".motwin-scope-status").text,
              "the status line says so")
        driver.save_screenshot(os.path.join(out_dir, "trace-step-response-trigger.png"))
        driver.find_element(By.XPATH, "//button[text()='Off']").click()
        browser.wait_js("return window.motwinPlot.scope.triggerStatus().state === 'off';", "trigger off")

        # CSV export: the same samples as motwin's own CSV trace.
        header, exported = read_csv_text(browser.js("return window.motwinPlot.scope.exportCsv();"))
        check_equal(header, ["time_s"] + COLUMNS, "exported CSV header")
        check_equal(exported, rows, "exported CSV rows")

        # PNG export: a valid PNG, the plot canvas plus a title line and one line per curve.
        png = browser.js("return window.motwinPlot.scope.exportPng();")
        size = decode_png(png)
        canvas = browser.js("const c = window.motwinPlot.uplot.ctx.canvas; return [c.width, c.height];")
        line = browser.js("return window.motwinPlot.scope.pngLineHeight();")
        check_equal(size, (canvas[0], canvas[1] + line * (1 + len(COLUMNS))), "PNG size")
        check(canvas[0] >= 1000, f"the plot uses the 1280 px window: canvas {canvas}")
        with open(os.path.join(out_dir, "trace-step-response-export.png"), "wb") as f:
            f.write(base64.b64decode(png.split(",", 1)[1]))

        # A narrow window: the plot shrinks to fit, nothing sticks out sideways.
        driver.set_window_size(420, 800)
        browser.wait_js("return window.motwinPlot.uplot.width <= window.innerWidth;", "the plot to fit 420 px")
        browser.next_frames()
        wide = browser.js("return [...document.querySelectorAll('body *')]"
                          ".filter(e => e.getBoundingClientRect().right > window.innerWidth)"
                          ".map(e => e.tagName + '.' + e.className + ' ' + e.textContent.slice(0, 60) + ': ' + e.getBoundingClientRect().right);")
        check_equal(wide, [], "elements beyond the right edge at 420 px")
        driver.save_screenshot(os.path.join(out_dir, "trace-step-response-narrow.png"))

        severe = browser.severe_log_entries()
        check_equal(severe, [], "SEVERE entries in the browser log")


# --- 2. The scope live ---------------------------------------------------------------------------

LIVE_DRIVER_JS = """\
// Drives web/site/scope.js as the console's Scope view will: 4 curves, 25 pushes a second.
"use strict";
const scope = MotwinScope.create(document.getElementById("scope"), {
  title: "live scope",
  windowSeconds: %(window)s,
  series: [
    {name: "sine", label: "sine", unit: "V"},
    {name: "cosine", label: "cosine", unit: "V"},
    {name: "ramp", label: "ramp", unit: "counts"},
    {name: "square", label: "square", unit: "mA"},
  ],
});
const sample = (n) => {
  const t = n * %(period)s;
  return [t, [Math.sin(2 * Math.PI * t), Math.cos(2 * Math.PI * t), n, n %% 10 < 5 ? 100 : -100]];
};
let n = 0;
const timer = setInterval(() => {
  const [t, values] = sample(n++);
  scope.push(t, values);
  if (n >= %(pushes)s) clearInterval(timer);
}, %(period)s * 1000);
window.liveScope = {scope: scope, sample: sample};
"""

LIVE_PAGE_HTML = """\
<!DOCTYPE html>
<html lang="en"><head><meta charset="utf-8"><title>scope.js live test</title>
<link rel="icon" href="data:,">
<link rel="stylesheet" href="file://%(uplot_css)s"><link rel="stylesheet" href="file://%(scope_css)s">
</head><body><div id="scope"></div>
<script src="file://%(uplot_js)s"></script><script src="file://%(scope_js)s"></script>
<script src="live-scope.js"></script></body></html>
"""


def test_scope_keeps_up_live(motwin):
    """25 pushes a second on 4 curves: the plot ends on the last point, redraws coalesce, pause
    holds the view and a live trigger freezes the window around its crossing."""
    out_dir = artefact_dir(motwin)
    with open(os.path.join(out_dir, "live-scope.js"), "w") as f:
        f.write(LIVE_DRIVER_JS % {"window": LIVE_WINDOW_S, "period": LIVE_PERIOD_S, "pushes": LIVE_PUSHES})
    page = os.path.join(out_dir, "live-scope.html")
    with open(page, "w") as f:
        f.write(LIVE_PAGE_HTML % {"uplot_css": UPLOT_CSS, "scope_css": SCOPE_CSS, "uplot_js": UPLOT_JS,
                                  "scope_js": SCOPE_JS})
    with Browser() as browser:
        driver = browser.driver
        driver.get("file://" + page)
        browser.wait_js(f"return window.liveScope && window.liveScope.scope.stats().pushes === {LIVE_PUSHES};",
                        f"{LIVE_PUSHES} pushes")
        last_time = (LIVE_PUSHES - 1) * LIVE_PERIOD_S
        stats = browser.wait_js(
            "const s = window.liveScope.scope.stats();"
            "return s.lastDrawnTime_s === s.lastPushedTime_s ? s : null;", "the last push drawn")
        check(abs(stats["lastPushedTime_s"] - last_time) < 1e-9, f"last push at {last_time}: {stats}")
        check(1 <= stats["redraws"] <= stats["pushes"], f"at most one redraw per push: {stats}")
        u = browser.js("const u = window.liveScope.scope.uplot;"
                       "return {x: u.data[0], last: u.data.map(d => d[d.length - 1]), min: u.scales.x.min, max: u.scales.x.max};")
        check(abs(u["max"] - last_time) < 1e-9 and abs(u["min"] - (last_time - LIVE_WINDOW_S)) < 1e-9,
              f"the window ends at the last push: {u['min']}..{u['max']}")
        expected_last = browser.js(f"return window.liveScope.sample({LIVE_PUSHES - 1});")
        check_equal(u["last"], [expected_last[0]] + expected_last[1], "the last point of every curve")
        check(u["x"][0] <= last_time - LIVE_WINDOW_S, "the curves fill the window")
        driver.save_screenshot(os.path.join(out_dir, "live-scope.png"))

        # Many pushes in one go (one script, no frame between): one redraw for all of them.
        before = browser.js("return window.liveScope.scope.stats();")
        browser.js("for (let n = arguments[0]; n < arguments[0] + 50; n++) {"
                   "  const [t, v] = window.liveScope.sample(n); window.liveScope.scope.push(t, v); }", LIVE_PUSHES)
        browser.next_frames()
        after = browser.wait_js("const s = window.liveScope.scope.stats();"
                                "return s.lastDrawnTime_s === s.lastPushedTime_s ? s : null;", "the burst drawn")
        check_equal(after["pushes"] - before["pushes"], 50, "pushes of the burst")
        check(after["redraws"] - before["redraws"] <= 2, f"redraws for a burst of 50 pushes: {before} -> {after}")

        # Pause: pushes are kept but not drawn until it runs again.
        browser.js("window.liveScope.scope.setPaused(true);"
                   "const [t, v] = window.liveScope.sample(arguments[0]); window.liveScope.scope.push(t, v);",
                   LIVE_PUSHES + 50)
        browser.next_frames()
        paused = browser.js("return window.liveScope.scope.stats();")
        check(paused["lastDrawnTime_s"] < paused["lastPushedTime_s"], f"paused: the new point not drawn {paused}")
        browser.js("window.liveScope.scope.setPaused(false);")
        browser.wait_js("const s = window.liveScope.scope.stats(); return s.lastDrawnTime_s === s.lastPushedTime_s;",
                        "drawn after resuming")

        # A live trigger: the sine falling through 0.5, single shot, 1 s window with a quarter before.
        browser.js("window.liveScope.scope.setTrigger({series: 0, level: 0.5, edge: 'falling', windowSeconds: 1});")
        check_equal(browser.js("return window.liveScope.scope.triggerStatus().state;"), "armed", "armed")
        browser.js("for (let n = arguments[0]; n < arguments[0] + 60; n++) {"
                   "  const [t, v] = window.liveScope.sample(n); window.liveScope.scope.push(t, v); }", LIVE_PUSHES + 51)
        status = browser.wait_js("const t = window.liveScope.scope.triggerStatus();"
                                 "return t.state === 'triggered' ? t : null;", "the live trigger")
        samples = [browser.js("return window.liveScope.sample(arguments[0]);", n)
                   for n in range(LIVE_PUSHES + 50, LIVE_PUSHES + 111)]
        crossing = next(samples[k][0] for k in range(1, len(samples))
                        if samples[k - 1][1][0] > 0.5 >= samples[k][1][0])
        check(abs(status["time_s"] - crossing) < 1e-9, f"triggered at {status['time_s']}, crossing at {crossing}")
        browser.next_frames()
        frozen = browser.js("const u = window.liveScope.scope.uplot; return [u.scales.x.min, u.scales.x.max];")
        check(abs(frozen[0] - (crossing - 0.25)) < 1e-9 and abs(frozen[1] - (crossing + 0.75)) < 1e-9,
              f"frozen window {frozen} around {crossing}")
        browser.js("const [t, v] = window.liveScope.sample(arguments[0]); window.liveScope.scope.push(t, v);",
                   LIVE_PUSHES + 111)
        browser.next_frames()
        check_equal(browser.js("const u = window.liveScope.scope.uplot; return [u.scales.x.min, u.scales.x.max];"),
                    frozen, "a single-shot capture stays after more pushes")
        check(decode_png(browser.js("return window.liveScope.scope.exportPng();"))[0] > 0, "PNG of the live scope")

        # Normal mode: re-armed after each capture, the view moves on to the next completed one
        # (the sine falls through 0.5 once a second).
        start = LIVE_PUSHES + 112
        browser.js("window.liveScope.scope.setTrigger({series: 0, level: 0.5, edge: 'falling', mode: 'normal',"
                   " windowSeconds: 0.4});"
                   "for (let n = arguments[0]; n < arguments[0] + 60; n++) {"
                   "  const [t, v] = window.liveScope.sample(n); window.liveScope.scope.push(t, v); }", start)
        first = browser.js("return window.liveScope.scope.triggerStatus();")
        browser.js("for (let n = arguments[0]; n < arguments[0] + 25; n++) {"
                   "  const [t, v] = window.liveScope.sample(n); window.liveScope.scope.push(t, v); }", start + 60)
        second = browser.js("return window.liveScope.scope.triggerStatus();")
        check(first["state"] == "armed" and second["state"] == "armed", f"normal mode re-arms: {first}, {second}")
        check(abs(second["time_s"] - first["time_s"] - 1.0) < 1e-9,
              f"the next capture one sine period later: {first['time_s']} -> {second['time_s']}")
        severe = browser.severe_log_entries()
        check_equal(severe, [], "SEVERE entries in the browser log")


if __name__ == "__main__":
    run_tests([test_trace_page_in_a_browser, test_scope_keeps_up_live])
