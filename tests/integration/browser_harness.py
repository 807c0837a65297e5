"""Headless Chromium for the browser tests (test_web_browser.py, test_web_program.py,
test_web_world.py, test_web_datalogger.py, test_plot_page.py): Debian's chromium and
chromium-driver driven by python3-selenium, a fresh profile per browser, the page's console log
recorded; the web console's page with the helpers every view's test uses, and the start-up of a
browser and a `motwin serve --web` beside it. A browser that cannot start is a skip
(motwin_harness.Skipped, exit status 77), never a failure; everything else is the test's to check.
Flags and paths: docs/web-console.md."""

import contextlib
import os
import shutil
import tempfile

import motwin_harness as mh

try:  # without Selenium, HeadlessChromium skips the test before any of these is used
    from selenium.webdriver.common.by import By
    from selenium.webdriver.common.keys import Keys
    from selenium.webdriver.support.ui import WebDriverWait
except ImportError:  # pragma: no cover - reported as a skip
    pass

CHROMIUM = "/usr/lib/chromium/chromium"  # the binary itself: /usr/bin/chromium is a shell wrapper
CHROMEDRIVER = "/usr/bin/chromedriver"   # named, so that Selenium never looks for (or downloads) another
WINDOW = (1280, 800)
WAIT_S = 60.0  # an upper bound for a condition on a loaded machine, never a pause


def artefact_dir(motwin, name):
    """<build>/test-artefacts/NAME: screenshots and pages a browser test keeps."""
    path = os.path.join(os.path.dirname(motwin), "test-artefacts", name)
    os.makedirs(path, exist_ok=True)
    return path


class HeadlessChromium:
    """`self.driver`, a Selenium Chrome driver at 1280x800 (device scale 1, so that screenshots and
    exported PNGs have the CSS pixel sizes); a context manager that quits it and removes its profile."""

    def __init__(self):
        try:
            from selenium import webdriver
            from selenium.common.exceptions import WebDriverException
            from selenium.webdriver.chrome.service import Service
        except ImportError as error:
            raise mh.Skipped(f"python3-selenium is not installed ({error}; scripts/install-deps.sh installs it)")
        binary = CHROMIUM if os.access(CHROMIUM, os.X_OK) else shutil.which("chromium")
        if binary is None or not os.access(CHROMEDRIVER, os.X_OK):
            raise mh.Skipped("chromium or chromium-driver is not installed (scripts/install-deps.sh installs them)")
        self.profile = tempfile.mkdtemp(prefix="motwin-chromium-")
        options = webdriver.ChromeOptions()
        options.binary_location = binary
        for flag in ("--headless=new", "--no-sandbox", "--disable-dev-shm-usage", "--disable-gpu",
                     "--disable-background-networking", "--disable-component-update", "--disable-sync",
                     "--no-first-run", "--disable-quic", f"--window-size={WINDOW[0]},{WINDOW[1]}",
                     "--force-device-scale-factor=1", f"--user-data-dir={self.profile}"):
            options.add_argument(flag)
        options.set_capability("goog:loggingPrefs", {"browser": "ALL"})
        try:
            self.driver = webdriver.Chrome(service=Service(CHROMEDRIVER), options=options)
        except (WebDriverException, OSError) as error:
            shutil.rmtree(self.profile, ignore_errors=True)
            raise mh.Skipped(f"headless Chromium does not start: {str(error).splitlines()[0]}")
        self.log = []

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        try:
            self.driver.quit()
        finally:
            shutil.rmtree(self.profile, ignore_errors=True)

    def js(self, script, *args):
        return self.driver.execute_script(script, *args)

    def severe_log_entries(self):
        """The SEVERE entries of the page's console log so far (errors, failed loads)."""
        self.log += self.driver.get_log("browser")
        return [entry for entry in self.log if entry.get("level") == "SEVERE"]


class ConsolePage(HeadlessChromium):
    """The web console's page (web/site/): waits for conditions, finds elements by CSS selector,
    shows a view by its tab. Screenshots go to <build>/test-artefacts/ARTEFACTS/."""

    ARTEFACTS = "web-browser"

    def wait(self, description, condition):
        try:
            return WebDriverWait(self.driver, WAIT_S, poll_frequency=0.02).until(lambda d: condition())
        except Exception as error:  # noqa: BLE001 - the condition's own failure is the message
            raise mh.TestFailure(f"waited {WAIT_S} s for {description}: {type(error).__name__}") from None

    def find(self, css):
        return self.driver.find_element(By.CSS_SELECTOR, css)

    def finds(self, css):
        return self.driver.find_elements(By.CSS_SELECTOR, css)

    def open_console(self, url):
        """Loads the page from `url` and waits until it has connected to the console."""
        self.driver.get(url)
        self.wait("the page to connect", lambda: self.find("body").get_attribute("data-state") == "connected")

    def show(self, view):
        self.find(f'#tabs [data-view="{view}"]').click()
        self.wait(f"the {view} view", lambda: self.find(f"#view-{view}").is_displayed())

    def screenshot(self, motwin, name):
        path = os.path.join(artefact_dir(motwin, self.ARTEFACTS), name + ".png")
        mh.check(self.driver.save_screenshot(path), f"screenshot {path}")

    # The Parameters view and the direct-mode console, what every module's page has.
    def value_of(self, key):
        elements = self.finds(f'input[data-key="{key}"]')
        return elements[0].get_attribute("value") if elements else None

    def reply_of(self, key):
        elements = self.finds(f'tr[data-key="{key}"] td.reply')
        return elements[0].text if elements else ""

    def set_filter(self, text):
        field = self.find("#filter")
        field.click()
        field.send_keys(Keys.CONTROL, "a")
        field.send_keys(Keys.BACKSPACE)  # an input event, which clear() does not send
        if text:
            field.send_keys(text)

    def console_lines(self):
        return [item.text for item in self.finds("#console-log li")]

    def type_command(self, text):
        field = self.find("#console-input")
        field.send_keys(text)
        field.send_keys(Keys.ENTER)

    def check_log_clean(self):
        severe = self.severe_log_entries()
        mh.check(not severe, f"SEVERE entries in the browser's log: {severe!r}")


@contextlib.contextmanager
def browser_and_server(page_class, server_class, motwin, *server_args):
    """A `page_class` browser, then `server_class(motwin, state_dir, *server_args)` started on a
    fresh state directory: yields (page, server). The browser comes first, so that a browser that
    cannot start skips the test before any serve runs; the page is the test's to open."""
    with page_class() as page, mh.TempDir() as state, server_class(motwin, state, *server_args).start() as server:
        yield page, server
