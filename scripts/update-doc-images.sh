#!/usr/bin/env bash
# Regenerates the pictures in docs/images/ from the browser tests, never by hand:
# docs/images/trace-step-response.png is the screenshot tests/integration/test_plot_page.py takes
# of the page `motwin run --plot` writes for a TMCM-1636 position step, docs/images/web-scope.png
# the one tests/integration/test_web_browser.py takes of the console's Scope view with a triggered
# capture of a motion, docs/images/web-canopen.png the one of the CANopen view of a TMCM-3216
# (docs/web-console.md), docs/images/web-datalogger.png the one tests/integration/test_web_datalogger.py
# takes of a TMCM-1636 velocity step captured by the datalogger at 2 kHz, and
# docs/images/web-world.png the one tests/integration/test_web_world.py takes of the World view of
# a TMCM-142.
#   scripts/update-doc-images.sh [BUILD_DIR]   (default build; needs Chromium, see the README)
set -euo pipefail
cd "$(dirname "$0")/.."
build_dir="${1:-build}"
/usr/bin/python3 tests/integration/test_plot_page.py --motwin "$build_dir/motwin" --only test_trace_page_in_a_browser
mkdir -p docs/images
cp "$build_dir/test-artefacts/plot-page/trace-step-response.png" docs/images/trace-step-response.png
/usr/bin/python3 tests/integration/test_web_browser.py --motwin "$build_dir/motwin" --only test_scope
cp "$build_dir/test-artefacts/web-browser/scope-trigger.png" docs/images/web-scope.png
/usr/bin/python3 tests/integration/test_web_browser.py --motwin "$build_dir/motwin" --only test_canopen_view
cp "$build_dir/test-artefacts/web-browser/canopen.png" docs/images/web-canopen.png
/usr/bin/python3 tests/integration/test_web_datalogger.py --motwin "$build_dir/motwin" --only test_datalogger_in_browser
cp "$build_dir/test-artefacts/web-datalogger/datalogger-step.png" docs/images/web-datalogger.png
echo "updated docs/images/web-datalogger.png"
/usr/bin/python3 tests/integration/test_web_world.py --motwin "$build_dir/motwin" --only test_world_view
cp "$build_dir/test-artefacts/web-browser/world-view.png" docs/images/web-world.png
echo "updated docs/images/trace-step-response.png docs/images/web-scope.png docs/images/web-canopen.png" \
  "docs/images/web-world.png"
