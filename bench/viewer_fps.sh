#!/usr/bin/env bash
# Frame rates of the viewers in headless Chromium, measured RUNS times: the chain viewer's pages
# (tests/viewer_test: 8 pages, 10 to 2046 links) and the many-strand viewer's 10,000 x 32 page
# (tests/strands_viewer_test). Prints each page's frame rates and median beside its target: 20 fps
# for the chain viewer, 30 fps for the many-strand page (issue 14's figure). The tests themselves
# only check that a playing page keeps drawing (5 fps): a frame rate is a property of the machine
# and its load, measured here with nothing else running.
# Usage: bench/viewer_fps.sh [BUILD_DIR] [RUNS]
set -euo pipefail
build=${1:-build}
runs=${2:-3}
log=$(mktemp)
trap 'rm -f "$log"' EXIT
for ((i = 0; i < runs; i++)); do
  "$build/tests/viewer_test" --gtest_filter='*HeadlessChromium*' 2>&1 | sed 's/^/chain:/' >> "$log"
  "$build/tests/strands_viewer_test" --gtest_filter='*HeadlessChromium*' 2>&1 |
    sed 's/^/strands:/' >> "$log"
done
echo "machine: $(nproc) cores, $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | sed 's/^ *//'), load $(cut -d' ' -f1-3 /proc/loadavg)"
# Lines "VIEWER:NAME: fps X ..." (one per page and run).
awk -v runs="$runs" '
  / fps [0-9.]+ / {
    name = $1; sub(/:$/, "", name)
    for (k = 1; k <= NF; k++) if ($k == "fps") { v = $(k + 1); break }
    n[name]++; val[name, n[name]] = v + 0
    if (!(name in order)) { order[name] = ++pages; names[pages] = name }
  }
  END {
    printf "%-22s %-22s %8s %8s\n", "page", "fps (each run)", "median", "target"
    for (p = 1; p <= pages; p++) {
      name = names[p]; m = n[name]
      for (i = 1; i <= m; i++) a[i] = val[name, i]
      for (i = 2; i <= m; i++) for (j = i; j > 1 && a[j - 1] > a[j]; j--) { t = a[j]; a[j] = a[j - 1]; a[j - 1] = t }
      med = (m % 2) ? a[(m + 1) / 2] : (a[m / 2] + a[m / 2 + 1]) / 2
      runsText = ""
      for (i = 1; i <= m; i++) runsText = runsText (i > 1 ? " " : "") val[name, i]
      target = (name ~ /^strands:hair_/) ? 30 : 20
      printf "%-22s %-22s %8.1f %8d %s\n", name, runsText, med, target, (med >= target ? "met" : "NOT MET")
    }
  }' "$log"
