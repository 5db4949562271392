#!/usr/bin/env bash
# Runs the libFuzzer targets of fuzz/ (docs/fuzzing.md), each for SECONDS, as many at once as
# FUZZ_JOBS (default: the cores), and prints a table: target, seconds, executions, cov, ft, result. Called by `make fuzz` and
# `make test-fuzz` after they built BUILD (-DFLEXKIN_FUZZ=ON).
#
#   scripts/fuzz.sh [--fresh] BUILD SECONDS [TARGET...]
#
# The committed seeds (fuzz/corpus/<target>/) and regressions (fuzz/regressions/<target>/) are
# read, never written: new units go to BUILD/fuzz-run/corpus/<target>/ (kept between runs, emptied
# first with --fresh), and what a target finds to BUILD/fuzz-run/artifacts/<target>/ (crash-*,
# leak-*, timeout-*, oom-*), its log to BUILD/fuzz-run/<target>.log. Exits 1 if any target found
# something.
set -uo pipefail
fresh=0
if [ "${1:-}" = "--fresh" ]; then fresh=1; shift; fi
build=${1:?usage: scripts/fuzz.sh [--fresh] BUILD SECONDS [TARGET...]}
seconds=${2:?usage: scripts/fuzz.sh [--fresh] BUILD SECONDS [TARGET...]}
shift 2
root=$(cd "$(dirname "$0")/.." && pwd)
targets=("$@")
[ ${#targets[@]} -gt 0 ] || targets=(scenario robot groom result urdf gltf)

# The largest input each reader is given: a few times its largest seed.
declare -A max_len=([scenario]=16384 [robot]=16384 [groom]=16384 [result]=65536 [urdf]=16384 [gltf]=65536)

work="$build/fuzz-run"
mkdir -p "$work"
jobs=${FUZZ_JOBS:-$(nproc)}
for t in "${targets[@]}"; do
  bin="$build/fuzz/${t}_fuzzer"
  [ -x "$bin" ] || { echo "fuzz.sh: no $bin (build with -DFLEXKIN_FUZZ=ON)" >&2; exit 2; }
done

# One target: its row of the table into $work/$t.row; exits 1 if it found something.
fuzz_one() {
  local t=$1 bin="$build/fuzz/${1}_fuzzer"
  local corpus="$work/corpus/$t" artifacts="$work/artifacts/$t"
  [ $fresh -eq 1 ] && rm -rf "$corpus"
  mkdir -p "$corpus" "$artifacts"
  local dirs=("$corpus" "$root/fuzz/corpus/$t")
  [ -d "$root/fuzz/regressions/$t" ] && dirs+=("$root/fuzz/regressions/$t")
  local dict=()
  [ -f "$root/fuzz/$t.dict" ] && dict=(-dict="$root/fuzz/$t.dict")
  local log="$work/$t.log"
  echo "fuzz: $t for $seconds s (log $log)"
  local start
  start=$(date +%s)
  # The targets' temporary files (npz, glTF) in a folder of the run: libFuzzer may end without
  # running their clean-up.
  local tmp="$work/tmp/$t"
  rm -rf "$tmp" && mkdir -p "$tmp"
  TMPDIR="$tmp" ASAN_OPTIONS=${ASAN_OPTIONS:-detect_leaks=1} \
    UBSAN_OPTIONS=${UBSAN_OPTIONS:-print_stacktrace=1} "$bin" -max_total_time="$seconds" -timeout=10 \
    -rss_limit_mb=2048 -max_len="${max_len[$t]:-16384}" -print_final_stats=1 -artifact_prefix="$artifacts/" "${dict[@]}" "${dirs[@]}" \
    > "$log" 2>&1
  local rc=$?
  rm -rf "$tmp"
  local elapsed=$(($(date +%s) - start))
  local execs cov ft result found
  execs=$(grep -o 'stat::number_of_executed_units: *[0-9]*' "$log" | tail -1 | grep -o '[0-9]*$')
  cov=$(grep -o 'cov: [0-9]*' "$log" | tail -1 | grep -o '[0-9]*$')
  ft=$(grep -o 'ft: [0-9]*' "$log" | tail -1 | grep -o '[0-9]*$')
  if [ $rc -eq 0 ]; then
    result=ok
  else
    found=$(grep -o "Test unit written to [^ ]*" "$log" | tail -1 | sed 's/Test unit written to //')
    result="FOUND (exit $rc) ${found:-see $log}"
    grep -m1 -E 'ERROR: (AddressSanitizer|LeakSanitizer|libFuzzer)|runtime error|terminate called' \
      "$log" | sed 's/^/  /'
  fi
  printf '%-9s %8s %12s %7s %7s  %s\n' "$t" "$elapsed" "${execs:--}" "${cov:--}" "${ft:--}" \
    "$result" > "$work/$t.row"
  [ $rc -eq 0 ]
}

failed=0
running=0
for t in "${targets[@]}"; do
  rm -f "$work/$t.row"
  if [ $running -ge "$jobs" ]; then
    wait -n || failed=1
    running=$((running - 1))
  fi
  fuzz_one "$t" &
  running=$((running + 1))
done
while [ $running -gt 0 ]; do
  wait -n || failed=1
  running=$((running - 1))
done
printf '\n%-9s %8s %12s %7s %7s  %s\n' target seconds executions cov ft result
for t in "${targets[@]}"; do
  if [ -f "$work/$t.row" ]; then cat "$work/$t.row"; else echo "$t: no result"; failed=1; fi
done
exit $failed
