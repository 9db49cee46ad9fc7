#!/usr/bin/env bash
# Runs `make test` N times in a row (default 10) in a fresh clone of this
# repository's HEAD, each run with an empty cache folder, and prints one line
# per run and a summary. Exit status 0 only when every run passed. Logs stay
# in the printed folder. Usage: scripts/test-loop.sh [N]
set -uo pipefail
n=${1:-10}
repo=$(cd "$(dirname "$0")/.." && pwd)
work=$(mktemp -d -t occull-test-loop-XXXXXX)
git clone -q "$repo" "$work/occull" || { echo "test-loop: cannot clone $repo" >&2; exit 1; }
cd "$work/occull" || exit 1
echo "test-loop: $n runs of make test in a fresh clone of $(git rev-parse --short HEAD) at $work/occull"
passed=0
for i in $(seq 1 "$n"); do
  start=$(date +%s)
  log="$work/run-$i.log"
  if XDG_CACHE_HOME=$(mktemp -d -t occull-cache-XXXXXX) make test > "$log" 2>&1; then
    status=passed
    passed=$((passed + 1))
  else
    status=FAILED
  fi
  summary=$(grep -E "tests passed|tests failed" "$log" | tail -n 1)
  echo "run $i/$n: $status in $(( $(date +%s) - start )) s — ${summary:-no ctest summary, see $log}"
done
echo "test-loop: $passed of $n runs passed (logs: $work)"
[ "$passed" -eq "$n" ]
