"""Headless Chromium for the browser tests (test_web_browser.py, test_plot_page.py): Debian's
chromium and chromium-driver driven by python3-selenium, a fresh profile per browser, the page's
console log recorded. A browser that cannot start is a skip (motwin_harness.Skipped, exit status
77), never a failure; everything else is the test's to check. Flags and paths: docs/web-console.md."""

import os
import shutil
import tempfile

import motwin_harness as mh

CHROMIUM = "/usr/lib/chromium/chromium"  # the binary itself: /usr/bin/chromium is a shell wrapper
CHROMEDRIVER = "/usr/bin/chromedriver"   # named, so that Selenium never looks for (or downloads) another
WINDOW = (1280, 800)


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
