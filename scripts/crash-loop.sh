#!/usr/bin/env bash
# Runs N adversarial benches in a row (default 100) with the five
# conservative cullers, as the runs in which the driver crash was seen
# (docs/performance.md, "A crash in the driver"), and counts the runs that
# died of a signal. The environment passes through, so the same loop tells
# configurations apart, e.g. LP_NUM_THREADS=0 (llvmpipe rasterizes on the
# calling thread) or MALLOC_CHECK_=3 (glibc checks the heap on every call).
# Logs of the runs that crashed stay in the printed folder.
# Usage: scripts/crash-loop.sh [N] [OCCULL]   (OCCULL: default build/occull)
set -uo pipefail
n=${1:-100}
occull=${2:-build/occull}
work=$(mktemp -d -t occull-crash-loop-XXXXXX)
cases=("adversarial:kind=tiny walk" "adversarial:kind=near graze" "adversarial:kind=thin far")
crashes=0
echo "crash-loop: $n benches with $occull (LP_NUM_THREADS=${LP_NUM_THREADS:-unset}, MALLOC_CHECK_=${MALLOC_CHECK_:-unset}); logs in $work"
for i in $(seq 1 "$n"); do
  read -r scene path <<< "${cases[$(( (i - 1) % ${#cases[@]} ))]}"
  log="$work/run-$i.log"
  XDG_CACHE_HOME="$work/cache" "$occull" bench --scene "$scene" --path "$path" \
    --algo stopwait,chc,chcpp,chcpp:virtual_leaf=0,nohc --frames 40 --size 320x180 --report "$work/report" \
    > "$log" 2>&1
  rc=$?
  if [ "$rc" -ge 128 ]; then
    crashes=$((crashes + 1))
    echo "run $i/$n ($scene / $path): died of signal $((rc - 128)) (log: $log)"
  else
    [ "$rc" -eq 0 ] || echo "run $i/$n ($scene / $path): exit $rc (log: $log)"
    rm -f "$log"
  fi
done
echo "crash-loop: $crashes crashes in $n benches"
[ "$crashes" -eq 0 ]
