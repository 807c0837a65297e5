#!/usr/bin/env bash
# The performance report: builds Motwin in Release (build-release/), runs every benchmark in
# bench/ (bench/*.cpp, so benchmarks added later are picked up), measures the core's code size
# with -Os -fno-exceptions -fno-rtti (build-minsize/) and what its bytes are (scripts/core_size.py),
# and writes a markdown report to stdout and
# build-release/report.md. docs/PERFORMANCE.md explains how to read it.
#
#   scripts/bench.sh                 # the report (a few minutes)
#   scripts/bench.sh --quick         # shorter runs (rough figures, for trying the script)
#   scripts/bench.sh --update-docs   # also puts the report into docs/PERFORMANCE.md, between
#                                    # its "bench.sh report" markers (the prose around them stays)
#   MOTWIN_BENCH_BUILD=DIR scripts/bench.sh    # another build directory
#
# Exit status 1 when a benchmark failed (the report is still written, with the row marked).
set -euo pipefail
cd "$(dirname "$0")/.."
build=${MOTWIN_BENCH_BUILD:-build-release}
minsize=${MOTWIN_BENCH_MINSIZE_BUILD:-build-minsize}
jobs=$(nproc 2>/dev/null || echo 2)
quick=0
update_docs=0
for argument in "$@"; do
  case "$argument" in
    --quick) quick=1 ;;
    --update-docs) update_docs=1 ;;
    *) echo "bench: unknown option '$argument' (--quick, --update-docs)" >&2; exit 2 ;;
  esac
done
failed=()

log() { echo "bench: $*" >&2; }

mapfile -t benches < <(for f in bench/*.cpp; do basename "$f" .cpp; done)
log "building Release in $build: motwin ${benches[*]}"
# Release at -O2, the optimisation of the default build: at -O3 GCC 12 reports false
# -Wrestrict and -Wmaybe-uninitialized inside std::string (GCC bugs 105329, 107138), which
# -Werror turns into errors.
cmake -S . -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=Release "-DCMAKE_CXX_FLAGS_RELEASE=-O2 -DNDEBUG" -DMOTWIN_BENCH=ON \
  >/dev/null
cmake --build "$build" -j"$jobs" --target motwin "${benches[@]}" >"$build/bench-build.log" 2>&1 ||
  { tail -40 "$build/bench-build.log" >&2; exit 1; }
log "building motwin_core and core_all_modules (its firmware-like image) with -Os in $minsize"
cmake -S . -B "$minsize" -G Ninja -DCMAKE_BUILD_TYPE=MinSizeRel -DMOTWIN_BENCH=OFF >/dev/null
cmake --build "$minsize" -j"$jobs" --target motwin_core core_all_modules >"$minsize/build.log" 2>&1 ||
  { tail -40 "$minsize/build.log" >&2; exit 1; }

logs="$build/bench-logs"
rm -rf "$logs"
mkdir -p "$logs"
for bench in "${benches[@]}"; do
  log "running $bench"
  args=()
  case "$bench" in
    bench_tcp_roundtrip) [ $quick = 1 ] && args=(--requests 3000) ;;
    bench_module_footprint) ;;
    bench_bus_scale) [ $quick = 1 ] && args=(--quick) ;;
    bench_web_pages) [ $quick = 1 ] && args=(--rounds 1 --seconds 1 --requests 1000) ;;
    *)
      # Google Benchmark programs; the others ignore unknown options only if they say so.
      if grep -q 'benchmark/benchmark.h' "bench/$bench.cpp"; then
        if [ $quick = 1 ]; then args=(--benchmark_min_time=0.1); else args=(--benchmark_repetitions=3); fi
      fi
      ;;
  esac
  if ! "$build/bench/$bench" "${args[@]}" >"$logs/$bench.txt" 2>"$logs/$bench.err"; then
    log "$bench failed (exit status $?); its output is in $logs/"
    echo "(failed: see $logs/$bench.err)" >>"$logs/$bench.txt"
    failed+=("$bench")
  fi
done

# The firmware images under qemu (docs/firmware.md, "Per-tick figures"): skipped, with the reason
# in the report, without qemu-system-arm or the ARM toolchain.
log "building the firmware images (build-cortex-m/) and measuring them under qemu"
MOTWIN_JOBS=$jobs scripts/build-firmware.sh >"$logs/firmware-build.log" 2>&1 ||
  { tail -40 "$logs/firmware-build.log" >&2; failed+=(firmware_images); }
firmware_ticks=2000
[ $quick = 1 ] && firmware_ticks=500
status=0
/usr/bin/python3 bench/firmware_figures.py --ticks $firmware_ticks --profile 12 --json-file "$logs/firmware_figures.json" \
  >"$logs/firmware_figures.txt" 2>"$logs/firmware_figures.err" || status=$?
if [ $status != 0 ] && [ $status != 77 ]; then
  log "bench/firmware_figures.py failed (exit status $status); its output is in $logs/"
  echo "(failed: see $logs/firmware_figures.err)" >>"$logs/firmware_figures.txt"
  failed+=(firmware_figures)
fi

size -t "$minsize/libmotwin_core.a" >"$logs/core_size.txt"
/usr/bin/python3 scripts/core_size.py "$minsize" --symbols 15 --image "$minsize/core_all_modules.map" \
  >"$logs/core_breakdown.txt" ||
  echo "(scripts/core_size.py failed)" >"$logs/core_breakdown.txt"

/usr/bin/python3 - "$logs" "$build/report.md" "${benches[@]}" <<'PYTHON'
import datetime
import os
import platform
import re
import subprocess
import sys

logs, out_path, benches = sys.argv[1], sys.argv[2], sys.argv[3:]


def text(name):
    try:
        with open(os.path.join(logs, name + ".txt")) as f:
            return f.read()
    except OSError:
        return ""


def summary(output):
    """What a benchmark prints after Google Benchmark's table (its own figures against its
    baseline), or the whole output for programs without such a table."""
    lines = output.splitlines()
    table_end = None
    for i, line in enumerate(lines):
        if re.match(r"^-{20,}$", line):
            table_end = i
    if table_end is None:
        return output.strip()
    rest = lines[table_end + 1:]
    # Skip the table rows: up to the first blank line.
    while rest and rest[0].strip():
        rest = rest[1:]
    return "\n".join(rest).strip()


def cpu_model():
    try:
        with open("/proc/cpuinfo") as f:
            for line in f:
                if line.startswith("model name"):
                    return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return platform.processor() or "unknown"


rows = []  # (figure, value, baseline in the same run, ratio or note)

tcp = text("bench_tcp_roundtrip")
bare = re.search(r"bare 9-byte server.*?([\d.]+) us\s+([\d.]+) us", tcp)
serve = re.search(r"motwin serve.*?([\d.]+) us\s+([\d.]+) us", tcp)
ratio = re.search(r"ratio motwin / bare\s+([\d.]+)x\s+([\d.]+)x", tcp)
if bare and serve and ratio:
    rows.append(("TMCL round trip over TCP (GAP, median / p99)", f"{serve.group(1)} / {serve.group(2)} us",
                 f"bare TCP echo {bare.group(1)} / {bare.group(2)} us", f"{ratio.group(1)}x / {ratio.group(2)}x"))
else:
    rows.append(("TMCL round trip over TCP", "n/a", "bare TCP echo", "bench_tcp_roundtrip failed or missing"))
flooded = re.search(r"motwin serve, (\d+) flooding\s+([\d.]+) us\s+([\d.]+) us\s+\(flood: (\d+) frames/s", tcp)
flooded_ratio = re.search(r"ratio flooded / idle\s+([\d.]+)x\s+([\d.]+)x", tcp)
if serve and flooded and flooded_ratio:
    rows.append((f"TMCL round trip over TCP while {flooded.group(1)} other connections flood the serve "
                 "(GAP, median / p99)",
                 f"{flooded.group(2)} / {flooded.group(3)} us ({flooded.group(4)} flood frames/s)",
                 f"idle serve {serve.group(1)} / {serve.group(2)} us",
                 f"{flooded_ratio.group(1)}x / {flooded_ratio.group(2)}x"))

can = text("bench_can_roundtrip")
can_row = r"\s+([\d.]+) us\s+([\d.]+) us\s+(\d+)\s+([\d.]+)x"
can_bare = re.search(r"bare socketcand echo[^\n]*?" + can_row, can)
can_found = False
for label, pattern in (("SDO upload round trip over socketcand (TMCM-3216, median / p99)", r"motwin SDO upload[^\n]*?"),
                       ("TMCL over CAN round trip via socketcand (TMCM-1636, median / p99)", r"motwin TMCL GAP over CAN[^\n]*?")):
    m = re.search(pattern + can_row, can)
    if m and can_bare:
        can_found = True
        rows.append((label, f"{m.group(1)} / {m.group(2)} us ({m.group(3)}/s)",
                     f"bare socketcand echo {can_bare.group(1)} / {can_bare.group(2)} us ({can_bare.group(3)}/s)",
                     f"{m.group(4)}x"))
if not can_found:
    rows.append(("SDO round trip over socketcand", "n/a", "bare socketcand echo",
                 "bench_can_roundtrip failed or missing"))

dispatch = text("bench_tmcl_dispatch")
base = re.search(r"Relative to checksum_baseline \(([\d.]+) ns\)", dispatch)
for m in re.finditer(r"serve_serial_frame/(\S+ \d+)[^\n]*?([\d.]+) ns\s+([\d.]+)x baseline\s+([\d.]+) M frames/s", dispatch):
    rows.append((f"TMCL frames per second, core only ({m.group(1)})", f"{m.group(4)} M/s ({m.group(2)} ns)",
                 f"checksum only {base.group(1) if base else '?'} ns", f"{m.group(3)}x"))

for name in benches:
    output = text(name)
    header = re.search(r"Real-time factor[^\n]*\n((?:\s+\S+\s+[\d.]+x[^\n]*\n?)+)", output)
    if not header:
        continue
    lines = header.group(1).strip().splitlines()
    baseline = next((l.split() for l in lines if "baseline" in l.split()[0]), None)
    for line in lines:
        parts = line.split()
        if baseline and parts[0] == baseline[0]:
            continue
        rows.append((f"simulation real-time factor, {name.replace('bench_', '')}: {parts[0]}", parts[1],
                     f"{baseline[0]} {baseline[1]}" if baseline else "", " ".join(parts[2:]).replace("(", "").replace(")", "").strip()))

interpreter = text("bench_interpreter")
for m in re.finditer(r"^\s+(\S+)\s+([\d.]+) ms wall\s+([\d.]+)x real time\s+(?:([\d.]+)x baseline)?", interpreter, re.M):
    rows.append((f"TMCM-1636 module in fast pacing, interpreter: {m.group(1)}", f"{m.group(3)}x real time",
                 "idle_module_baseline" if m.group(4) else "(baseline)", f"{m.group(4)}x" if m.group(4) else ""))

bus = text("bench_bus_scale")
bus_row = r"\s+(\d+)\s+(idle|full)\s+([\d.]+)\s+([\d.]+)\s+(\d+)\s+(\d+)\s+(kept|LAGS)"
for module in ("TMCM-3216", "TMCM-1636"):
    one = re.search(module + r"\s+1\s+idle\s+([\d.]+)", bus)
    full = re.search(module + r"\s+127\s+full\s+([\d.]+)\s+([\d.]+)\s+(\d+)\s+(\d+)\s+(kept|LAGS)", bus)
    per_node = re.search(r"idle cost per node, " + module + r": ([\d.]+) ms CPU per simulated second \(([\d.]+) %", bus)
    traffic = ("heartbeats, SDO polling, 1 kHz SYNC with 3 RPDOs + 3 TPDOs to 8" if module == "TMCM-3216"
               else "TMCL over CAN, a GAP every ms to 8 in turn")
    if full:
        rows.append((f"one serve with 127 {module} nodes ({traffic}): CPU per simulated second",
                     f"{full.group(1)} s", f"1 idle node {one.group(1) if one else '?'} s",
                     f"sim/wall {full.group(2)}, {'kept real time' if full.group(5) == 'kept' else 'fell behind'}"))
    if per_node:
        rows.append((f"idle {module} node on a bus (slope of 1..127 nodes)", f"{per_node.group(1)} ms CPU per sim s",
                     "", f"{per_node.group(2)} % of a core"))
if not bus.strip():
    rows.append(("one serve with 127 nodes on a bus", "n/a", "", "bench_bus_scale failed or missing"))

web = text("bench_web_pages")
web_fast = re.search(r"--speed fast.*?\n\s+no page\s+[\d.]+\s+[\d.]+\s+([\d.]+)x\n\s+(\d+) pages\s+[\d.]+\s+[\d.]+\s+([\d.]+)x"
                     r".*?pages / no page: ([\d.]+)x", web, re.S)
web_rtt = re.search(r"round trip over TCP.*?\n\s+no page\s+([\d.]+) us\s+([\d.]+) us\n\s+\d+ pages\s+([\d.]+) us\s+([\d.]+) us"
                    r".*?pages / no page: ([\d.]+)x / ([\d.]+)x", web, re.S)
if web_fast:
    rows.append((f"TMCM-1636 (physical motor) real-time factor, --speed fast, with {web_fast.group(2)} web-console pages at "
                 "full rate", f"{web_fast.group(3)}x", f"no page {web_fast.group(1)}x",
                 f"{web_fast.group(4)}x (goal: at least 0.90x)"))
if web_rtt:
    rows.append((f"TMCL round trip over TCP with {web_fast.group(2) if web_fast else 4} web-console pages at full rate "
                 "(median / p99)", f"{web_rtt.group(3)} / {web_rtt.group(4)} us",
                 f"no page {web_rtt.group(1)} / {web_rtt.group(2)} us",
                 f"{web_rtt.group(5)}x / {web_rtt.group(6)}x (goal: at most 1.10x)"))
if not web_fast or not web_rtt:
    rows.append(("web-console pages against none", "n/a", "", "bench_web_pages failed or missing"))

sizes = text("core_size")
total = re.search(r"^\s*(\d+)\s+(\d+)\s+(\d+)\s+\d+\s+\S+\s+\(TOTALS\)", sizes, re.M)
if total:
    text_bytes = int(total.group(1))
    rows.append(("core code size (-Os -fno-exceptions -fno-rtti, no unwind tables, libmotwin_core.a)",
                 f"{text_bytes} B text ({text_bytes / 1024:.1f} KiB)",
                 f"{total.group(2)} B data, {total.group(3)} B bss",
                 f"goal at most 128 KiB of text: {'met' if text_bytes <= 128 * 1024 else 'NOT met'}"))
image = re.search(r"firmware image.*?\*\*total\*\* \| \*\*(\d+)\*\*", text("core_breakdown"), re.S)
if image:
    image_bytes = int(image.group(1))
    rows.append(("core in a firmware image of all three modules (same flags, --gc-sections)",
                 f"{image_bytes} B text ({image_bytes / 1024:.1f} KiB)",
                 f"the archive's {text_bytes} B" if total else "", "what the modules reach; the goal is judged by the archive"))

firmware_json = os.path.join(logs, "firmware_figures.json")
if os.path.exists(firmware_json):
    import json
    with open(firmware_json) as f:
        for image in json.load(f):
            rest, moving = image["rest"], image["moving"]
            rows.append((f"{image['module']} firmware image (Cortex-M4F, qemu): instructions per 50 us control tick "
                         "while moving (mean / max)", f"{moving['mean']:,.0f} / {moving['max']:,}",
                         f"at rest {rest['mean']:,.0f} / {rest['max']:,}",
                         f"at least {100 * moving['mean'] / 3600:.0f} % of a 72 MHz part, "
                         f"{100 * moving['mean'] / 8400:.0f} % of a 168 MHz part"))
            rows.append((f"{image['module']} firmware image: flash / RAM / stack high-water mark",
                         f"{image['text'] + image['data']:,} B / {image['data'] + image['bss']:,} B / "
                         f"{image['stack_used']:,} B", "", "text + data / data + bss / deepest stack seen"))
else:
    rows.append(("firmware images under qemu", "n/a", "", text("firmware_figures").strip().replace("|", "/")
                 or "bench/firmware_figures.py failed or missing"))

footprint = text("bench_module_footprint")

now = datetime.datetime.now(datetime.timezone.utc).strftime("%Y-%m-%d %H:%M UTC")
commit = subprocess.run(["git", "rev-parse", "--short", "HEAD"], capture_output=True, text=True).stdout.strip()
dirty = subprocess.run(["git", "status", "--porcelain", "--untracked-files=no"], capture_output=True, text=True).stdout
load = os.getloadavg()[0]
report = [f"# Motwin performance report", "",
          f"{now}, commit {commit or '?'}{' (with uncommitted changes)' if dirty.strip() else ''}; "
          f"{os.cpu_count()} CPUs, {cpu_model()}; load average {load:.1f} at the end; Release build.", "",
          "Every figure comes with its baseline measured in the same run; compare ratios across machines "
          "(docs/PERFORMANCE.md).", "",
          "| figure | value | baseline (same run) | ratio / note |", "|---|---|---|---|"]
report += [f"| {a} | {b} | {c} | {d} |" for a, b, c, d in rows]
report += ["", "## Memory per module instance and whole-module simulation speed", "",
           footprint.strip() or "(bench_module_footprint missing)", ""]
report += ["## The firmware images on a Cortex-M4F (qemu)", "",
           text("firmware_figures").strip() or "(bench/firmware_figures.py missing)", ""]
report += ["## What the core's text is", "", text("core_breakdown").strip() or "(scripts/core_size.py missing)", ""]
report += ["## Each benchmark's own summary", ""]
for name in benches:
    if name == "bench_module_footprint":
        continue
    report += [f"### {name}", "", "```", summary(text(name)) or "(no output)", "```", ""]
result = "\n".join(report) + "\n"
with open(out_path, "w") as f:
    f.write(result)
sys.stdout.write(result)
PYTHON
log "report written to $build/report.md"

if [ $update_docs = 1 ]; then
  /usr/bin/python3 - "$build/report.md" docs/PERFORMANCE.md <<'PYTHON'
import sys

report_path, doc_path = sys.argv[1], sys.argv[2]
start, end = "<!-- bench.sh report: start -->", "<!-- bench.sh report: end -->"
with open(report_path) as f:
    report = f.read().splitlines()
body = "\n".join(report[1:]).strip()  # without the report's own title
with open(doc_path) as f:
    doc = f.read()
if doc.count(start) != 1 or doc.count(end) != 1 or doc.index(start) > doc.index(end):
    sys.exit(f"bench: {doc_path} needs one '{start}' line before one '{end}' line")
before, rest = doc.split(start)
after = rest.split(end)[1]
# Headings of the report go one level down, under the document's own section.
body = "\n".join("#" + line if line.startswith("## ") or line.startswith("### ") else line for line in body.splitlines())
with open(doc_path + ".tmp", "w") as f:
    f.write(before + start + "\n\n" + body + "\n\n" + end + after)
import os
os.replace(doc_path + ".tmp", doc_path)
PYTHON
  log "report put into docs/PERFORMANCE.md"
fi

if [ ${#failed[@]} -gt 0 ]; then
  log "failed: ${failed[*]}"
  exit 1
fi
