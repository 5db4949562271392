#!/usr/bin/env bash
# Runs the libFuzzer targets of fuzz/ (docs/fuzzing.md), one after another, each for SECONDS, and
# prints a table: target, seconds, executions, cov, ft, result. Called by `make fuzz` and
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
rows=()
failed=0
for t in "${targets[@]}"; do
  bin="$build/fuzz/${t}_fuzzer"
  [ -x "$bin" ] || { echo "fuzz.sh: no $bin (build with -DFLEXKIN_FUZZ=ON)" >&2; exit 2; }
  corpus="$work/corpus/$t"
  artifacts="$work/artifacts/$t"
  [ $fresh -eq 1 ] && rm -rf "$corpus"
  mkdir -p "$corpus" "$artifacts"
  dirs=("$corpus" "$root/fuzz/corpus/$t")
  [ -d "$root/fuzz/regressions/$t" ] && dirs+=("$root/fuzz/regressions/$t")
  dict=()
  [ -f "$root/fuzz/$t.dict" ] && dict=(-dict="$root/fuzz/$t.dict")
  log="$work/$t.log"
  echo "fuzz: $t for $seconds s (log $log)"
  start=$(date +%s)
  # The targets' temporary files (npz, glTF) in a folder of the run: libFuzzer may end without
  # running their clean-up.
  tmp="$work/tmp/$t"
  rm -rf "$tmp" && mkdir -p "$tmp"
  TMPDIR="$tmp" ASAN_OPTIONS=${ASAN_OPTIONS:-detect_leaks=1} \
    UBSAN_OPTIONS=${UBSAN_OPTIONS:-print_stacktrace=1} "$bin" -max_total_time="$seconds" -timeout=10 \
    -rss_limit_mb=2048 -max_len="${max_len[$t]:-16384}" -print_final_stats=1 -artifact_prefix="$artifacts/" "${dict[@]}" "${dirs[@]}" \
    > "$log" 2>&1
  rc=$?
  rm -rf "$tmp"
  elapsed=$(($(date +%s) - start))
  execs=$(grep -o 'stat::number_of_executed_units: *[0-9]*' "$log" | tail -1 | grep -o '[0-9]*$')
  cov=$(grep -o 'cov: [0-9]*' "$log" | tail -1 | grep -o '[0-9]*$')
  ft=$(grep -o 'ft: [0-9]*' "$log" | tail -1 | grep -o '[0-9]*$')
  if [ $rc -eq 0 ]; then
    result=ok
  else
    failed=1
    found=$(grep -o "Test unit written to [^ ]*" "$log" | tail -1 | sed 's/Test unit written to //')
    result="FOUND (exit $rc) ${found:-see $log}"
    grep -m1 -E 'ERROR: (AddressSanitizer|LeakSanitizer|libFuzzer)|runtime error|terminate called' \
      "$log" | sed 's/^/  /'
  fi
  rows+=("$(printf '%-9s %8s %12s %7s %7s  %s' "$t" "$elapsed" "${execs:--}" "${cov:--}" "${ft:--}" \
    "$result")")
done
printf '\n%-9s %8s %12s %7s %7s  %s\n' target seconds executions cov ft result
printf '%s\n' "${rows[@]}"
exit $failed
