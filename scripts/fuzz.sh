#!/usr/bin/env bash
# Builds the libFuzzer targets of fuzz/ with clang (ASan + UBSan) in build-fuzz/ and runs them.
#
#   scripts/fuzz.sh TARGET [SECONDS]    one target, default 600 s; its corpus grows in
#                                       build-fuzz/corpus/TARGET (seeds: fuzz/corpus/TARGET)
#   scripts/fuzz.sh all [SECONDS]       every target in turn, SECONDS each (default 600)
#   scripts/fuzz.sh --smoke [SECONDS]   the test command's bounded run: every target from the seeds,
#                                       in a scratch corpus, sharing SECONDS in total (default 150,
#                                       start-up included; at least 3 s per target)
#   scripts/fuzz.sh --campaign SECONDS [RUNS] [TARGET...]
#                                       a recorded long run: every target (or the ones named) in turn
#                                       for SECONDS or RUNS executions (0: no limit), whichever comes
#                                       first, on build-fuzz/corpus/TARGET; each appends a row to the
#                                       campaign table of fuzz/README.md
#   scripts/fuzz.sh --list              the targets
#
# A crash or a violated invariant stops the run with exit status 1 and leaves the input in
# build-fuzz/artifacts/; replay it with `build-fuzz/fuzz_TARGET FILE`. MOTWIN_FUZZ_BUILD names
# another build directory. See fuzz/README.md.
set -euo pipefail
cd "$(dirname "$0")/.."
build=${MOTWIN_FUZZ_BUILD:-build-fuzz}
jobs=$(nproc 2>/dev/null || echo 2)

usage() {
  sed -n '2,19p' "$0" | sed 's/^# \{0,1\}//' >&2
  exit 2
}
[ $# -ge 1 ] || usage
mode=$1
seconds=${2:-}
if [ -n "$seconds" ] && ! [[ $seconds =~ ^[0-9]+$ ]]; then
  echo "fuzz: SECONDS must be a whole number, not '$seconds'" >&2
  exit 2
fi
campaign_runs=0
campaign_targets=()
if [ "$mode" = --campaign ]; then
  [ -n "$seconds" ] || usage
  shift 2
  if [ $# -gt 0 ] && [[ $1 =~ ^[0-9]+$ ]]; then
    campaign_runs=$1
    shift
  fi
  campaign_targets=("$@")
fi

if ! command -v clang++ >/dev/null; then
  echo "fuzz: clang++ is not installed (scripts/install-deps.sh installs it)" >&2
  exit 1
fi
export CCACHE_BASEDIR=${CCACHE_BASEDIR:-$PWD}
cmake -S . -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCMAKE_CXX_COMPILER=clang++ -DMOTWIN_FUZZ=ON \
  -DMOTWIN_BENCH=OFF >/dev/null
if ! cmake --build "$build" -j"$jobs" >"$build/build.log" 2>&1; then
  grep -E -B2 -A8 'error|FAILED' "$build/build.log" | head -60 >&2
  echo "fuzz: the build failed (log $build/build.log)" >&2
  exit 1
fi
mapfile -t targets <"$build/fuzz_targets.txt"

# Leaks are findings too; a slow input (> 10 s) is a hang.
export ASAN_OPTIONS=${ASAN_OPTIONS:-detect_leaks=1}
export UBSAN_OPTIONS=${UBSAN_OPTIONS:-print_stacktrace=1:halt_on_error=1}
mkdir -p "$build/artifacts"

run_target() {  # target seconds corpus-dir
  local target=$1 time=$2 corpus=$3 log
  mkdir -p "$corpus"
  log="$build/artifacts/$target.log"
  local start=$SECONDS
  if "$build/fuzz_$target" -max_total_time="$time" -timeout=10 -rss_limit_mb=2048 -print_final_stats=1 \
      -artifact_prefix="$build/artifacts/$target-" "$corpus" "fuzz/corpus/$target" >"$log" 2>&1; then
    local runs
    runs=$(grep -o 'stat::number_of_executed_units: *[0-9]*' "$log" | grep -o '[0-9]*$' || echo "?")
    printf '  %-22s ok   %8s inputs in %3d s\n' "$target" "$runs" $((SECONDS - start))
    return 0
  fi
  printf '  %-22s FAILED (log %s)\n' "$target" "$log"
  grep -E -A12 'invariant violated|ERROR: |SUMMARY' "$log" | head -40 | sed 's/^/    /'
  grep -o "Test unit written to .*" "$log" | sed "s|Test unit written to |    reproduce: $build/fuzz_$target |"
  return 1
}

# One campaign row: | date | commit | target | seconds | CPU s | executions | exec/s | cov | ft |
# corpus | findings |, appended to the table under "## Campaigns" in fuzz/README.md.
campaign_commit() {
  local commit
  commit=$(git rev-parse --short=10 HEAD 2>/dev/null || echo unknown)
  if ! git diff --quiet HEAD -- src fuzz CMakeLists.txt ":!fuzz/README.md" 2>/dev/null; then commit="$commit+changes"; fi
  echo "$commit"
}

campaign_target() {  # target seconds runs
  local target=$1 time=$2 runs=$3 log corpus findings start elapsed cpu
  corpus="$build/corpus/$target"
  mkdir -p "$corpus" "$build/campaign"
  log="$build/campaign/$target-$(date -u +%Y%m%dT%H%M%S).log"
  start=$(date +%s.%N)
  # -runs counts every execution (seed replay included); -print_final_stats=1 gives the totals and
  # the last status line cov/ft. The sanitizer options and -timeout are the smoke's.
  # -reload=60: parts side by side still take each other's finds, but a part no longer lists and
  # stats the whole shared corpus folder every second (libFuzzer's default), which took 10 % of a
  # tmcm3216_drive part's time once the folder held 24 k files (perf, 2026-11-27).
  local limits=(-max_total_time="$time" -reload=60)
  [ "$runs" -eq 0 ] || limits+=(-runs="$runs")
  /usr/bin/time -f 'cpu_seconds: %U %S' -o "$log.time" "$build/fuzz_$target" "${limits[@]}" -timeout=10 \
    -rss_limit_mb=2048 -print_final_stats=1 -artifact_prefix="$build/artifacts/$target-" "$corpus" \
    "fuzz/corpus/$target" >"$log" 2>&1 || true
  elapsed=$(echo "$(date +%s.%N) - $start" | bc)
  cpu=$(awk '/cpu_seconds/ {printf "%.0f", $2 + $3}' "$log.time" 2>/dev/null || echo "?")
  local executions rate status cov ft corp
  executions=$(grep -o 'stat::number_of_executed_units: *[0-9]*' "$log" | grep -o '[0-9]*$' || true)
  status=$(grep -E '^#[0-9]+' "$log" | tail -1)
  [ -n "$executions" ] || executions=$(echo "$status" | grep -o '^#[0-9]*' | tr -d '#')
  cov=$(echo "$status" | grep -o 'cov: [0-9]*' | grep -o '[0-9]*$' || true)
  ft=$(echo "$status" | grep -o 'ft: [0-9]*' | grep -o '[0-9]*$' || true)
  corp=$(echo "$status" | grep -o 'corp: [0-9]*/[0-9]*[a-zA-Z]*' | sed 's/corp: //' || true)
  rate=$(awk -v n="${executions:-0}" -v s="$elapsed" 'BEGIN {printf "%d", (s > 0 ? n / s : 0)}')
  # The inputs this part saved, as its own log names them (parts of one target running side by side
  # share the artifacts folder, so a listing of it would give one part's crash to the other).
  findings=$(sed -n 's/.*Test unit written to \([^ ]*\).*/\1/p' "$log" | xargs -r -n1 basename | sed 's/^'"$target"'-//' |
    paste -sd ' ' -)
  if [ -n "$findings" ]; then
    findings="$(grep -m1 -oE 'invariant violated at [^ ]*|ERROR: [A-Za-z]+: [a-z-]+|ERROR: libFuzzer: [a-z-]+|runtime error: .{0,50}' "$log" |
      head -1 | tr '|' '/'): $findings"
    cp "$log" "$build/artifacts/$target.log"
  else
    findings=none
  fi
  printf '  %-20s %6.0f s %10s executions %7s/s cov %s ft %s corpus %s, findings: %s\n' "$target" "$elapsed" \
    "${executions:-?}" "$rate" "${cov:-?}" "${ft:-?}" "${corp:-?}" "$findings"
  local row
  row=$(printf '| %s | %s | %s | %.0f | %s | %s | %s | %s | %s | %s | %s |' "$(date -u +%Y-%m-%d)" \
    "$built_commit" "$target" "$elapsed" "$cpu" "${executions:-?}" "$rate" "${cov:-?}" "${ft:-?}" \
    "${corp:-?}" "$findings")
  # Append under the table's last row (the table is the first block of lines starting with '|'
  # after the "## Campaigns" heading). Parts side by side may end together: one appends at a time
  # (the lock), else one part's rewrite of the file drops the other's row (seen 2026-11-27).
  exec 9>"$build/campaign/readme.lock"
  flock 9
  awk -v row="$row" '
    { lines[NR] = $0 }
    /^## Campaigns/ { section = NR }
    END {
      last = 0
      for (i = section + 1; i <= NR && section; ++i) if (lines[i] ~ /^\|/) last = i; else if (last) break
      for (i = 1; i <= NR; ++i) { print lines[i]; if (i == last) print row }
      if (!last) print row
    }' fuzz/README.md >"fuzz/README.md.new.$$" && mv "fuzz/README.md.new.$$" fuzz/README.md
  exec 9>&-
  [ "$findings" = none ]
}

case "$mode" in
  --campaign)
    if [ ${#campaign_targets[@]} -eq 0 ]; then campaign_targets=("${targets[@]}"); fi
    for target in "${campaign_targets[@]}"; do
      if ! printf '%s\n' "${targets[@]}" | grep -qx "$target"; then
        echo "fuzz: no target '$target'; targets: ${targets[*]}" >&2
        exit 2
      fi
    done
    grep -q '^## Campaigns' fuzz/README.md || { echo "fuzz: fuzz/README.md has no '## Campaigns' table" >&2; exit 1; }
    status=0
    built_commit=$(campaign_commit)  # what the targets were built from, whatever happens to the tree later
    printf 'fuzz campaign: %s s%s per target, commit %s\n' "$seconds" \
      "$([ "$campaign_runs" -gt 0 ] && echo " or $campaign_runs executions")" "$built_commit"
    for target in "${campaign_targets[@]}"; do
      campaign_target "$target" "$seconds" "$campaign_runs" || status=1
    done
    exit $status
    ;;
  --list)
    printf '%s\n' "${targets[@]}"
    ;;
  --smoke)
    # SECONDS is the whole run's budget, so adding a target shortens the others instead of
    # lengthening the test command. Each target gets an even share of what is left, less the second
    # or so a libFuzzer process runs beyond -max_total_time (seed replay, final stats, leak check);
    # sharing what is left also absorbs a target that took longer.
    budget=${seconds:-150}
    smoke_share() {  # seconds-left targets-left
      local share=$(($1 / $2 - 1))
      echo $((share < 3 ? 3 : share))
    }
    status=0
    rm -rf "$build/smoke-corpus"
    left=${#targets[@]}
    printf 'fuzz smoke: %d s over %d targets, %d s of fuzzing each (at least 3)\n' "$budget" "$left" \
      "$(smoke_share "$budget" "$left")"
    smoke_start=$SECONDS
    for target in "${targets[@]}"; do
      run_target "$target" "$(smoke_share $((budget - (SECONDS - smoke_start))) "$left")" \
        "$build/smoke-corpus/$target" || status=1
      left=$((left - 1))
    done
    printf 'fuzz smoke: %d s\n' $((SECONDS - smoke_start))
    exit $status
    ;;
  all)
    status=0
    for target in "${targets[@]}"; do
      run_target "$target" "${seconds:-600}" "$build/corpus/$target" || status=1
    done
    exit $status
    ;;
  -*)
    usage
    ;;
  *)
    if ! printf '%s\n' "${targets[@]}" | grep -qx "$mode"; then
      echo "fuzz: no target '$mode'; targets: ${targets[*]}" >&2
      exit 2
    fi
    run_target "$mode" "${seconds:-600}" "$build/corpus/$mode"
    ;;
esac
