#!/usr/bin/env bash
# Peak and sampled memory of a large `flexkin run`: a straight 3D chain of LINKS links pulled along
# +x in STEPS leader steps, recording every EVERY-th step, written as OUTPUT (.npz or .json).
# The resident set size is sampled every 0.5 s: flat over the run means memory linear in the
# chain, not in the chain times the frames.
# Usage: bench/run_memory.sh [FLEXKIN] [LINKS] [STEPS] [EVERY] [OUTPUT]
set -euo pipefail
flexkin=${1:-build/apps/flexkin}
links=${2:-1000000}
steps=${3:-3000}
every=${4:-1000}
dir=$(mktemp -d)
trap 'rm -rf "$dir"' EXIT
output=${5:-$dir/result.npz}
cat > "$dir/scenario.json" <<JSON
{"curve": {"shape": "line", "start": [0, 0, 0], "direction": [-1, 0, 0.1], "links": $links, "link_length": 0.3},
 "leader": {"pull": [$(awk "BEGIN{print 0.01 * $steps}"), 0.005, 0], "steps": $steps},
 "record": {"every": $every}}
JSON
"$flexkin" validate "$dir/scenario.json"
start=$(date +%s.%N)
"$flexkin" run -q --max-output-size 0 "$dir/scenario.json" -o "$output" &
pid=$!
samples=()
while kill -0 "$pid" 2>/dev/null; do
  rss=$(awk '/VmRSS/ {print $2}' "/proc/$pid/status" 2>/dev/null || true)
  [ -n "$rss" ] && samples+=("$rss")
  sleep 0.5
done
wait "$pid"
end=$(date +%s.%N)
echo "links $links, leader steps $steps, recording every $every: $(awk "BEGIN{print $end - $start}") s," \
     "output $(stat -c %s "$output") bytes"
printf '%s\n' "${samples[@]}" | awk '{ mb = $1 / 1024; if (mb > peak) peak = mb; s = s sprintf(" %.0f", mb) }
  END { print "resident MB every 0.5 s:" s; print "peak resident MB: " sprintf("%.0f", peak) }'
