#!/usr/bin/env bash
# Fuzz targets of BUILD (make fuzz-build) over their seed corpora in
# tests/corpus/TARGET (every input there must pass: the regressions), then:
#   fuzz.sh BUILD run SECONDS   fuzz each for SECONDS, new inputs kept in BUILD/corpus/TARGET;
#   fuzz.sh BUILD runs COUNT [TARGET...]
#                               COUNT executions of each target (or of the TARGETs named), split
#                               over FUZZ_JOBS processes (default: one per core) sharing the corpus;
#   fuzz.sh BUILD regress       a fixed number of runs from a fixed seed (CI: the same inputs every time).
# A finding (crash, sanitizer report, timeout over 10 s, more than 2 GiB) is
# written to BUILD/findings/ and makes this exit 1. Prints the executions per
# target. Leaks inside assimp are suppressed (fuzz/lsan.supp).
set -euo pipefail
usage="usage: fuzz.sh BUILD run SECONDS | fuzz.sh BUILD runs COUNT [TARGET...] | fuzz.sh BUILD regress"
build=${1:?$usage}
mode=${2:?$usage}
root="$(cd "$(dirname "$0")/.." && pwd)"
targets=(bsp pk3 path profile scene_spec model)
case "$mode" in
  run) seconds=${3:?$usage} ;;
  runs)
    count=${3:?$usage}
    jobs=${FUZZ_JOBS:-$(nproc)}
    if [[ $# -gt 3 ]]; then targets=("${@:4}"); fi
    ;;
  regress) ;;
  *) echo "$usage" >&2; exit 2 ;;
esac
# regress: runs per target, about 10 s each here (assimp builds its importers per run).
declare -A regress_runs=([bsp]=50000 [pk3]=2000 [path]=50000 [profile]=10000 [scene_spec]=50000 [model]=50)
export LSAN_OPTIONS="suppressions=$root/fuzz/lsan.supp:print_suppressions=0"
# glibc's allocator backs large blocks with transparent huge pages: fuzz_model's
# child zero-fills assimp's 16 MB OBJ buffer in fresh pages per input, and with
# 2 MB pages that costs 8 faults instead of 4096 (twice the inputs per second
# in the UBSan-only build; ASan's allocator ignores it).
export GLIBC_TUNABLES="${GLIBC_TUNABLES:+$GLIBC_TUNABLES:}glibc.malloc.hugetlb=1"
mkdir -p "$build/findings"
status=0
summary=()
for t in "${targets[@]}"; do
  exe="$build/fuzz/fuzz_$t"
  seeds="$root/tests/corpus/$t"
  work="$build/corpus/$t"
  mkdir -p "$work"
  common=(-timeout=10 -rss_limit_mb=2048 -malloc_limit_mb=1024 -artifact_prefix="$build/findings/$t-")
  echo "== fuzz_$t: the seed corpus ($(ls "$seeds" | wc -l) inputs)"
  if ! "$exe" "${common[@]}" -runs=0 "$seeds" >"$build/fuzz-$t-seeds.log" 2>&1; then
    tail -n 40 "$build/fuzz-$t-seeds.log"
    echo "fuzz_$t: an input of $seeds fails" >&2
    status=1
    continue
  fi
  if [[ $mode == run ]]; then
    echo "== fuzz_$t: fuzzing for $seconds s"
    args=(-max_total_time="$seconds" "$work" "$seeds")
  elif [[ $mode == regress ]]; then
    echo "== fuzz_$t: ${regress_runs[$t]} runs from seed 1"
    rm -rf "$work" && mkdir -p "$work" && cp "$seeds"/* "$work"/
    args=(-seed=1 -runs="${regress_runs[$t]}" "$work")
  fi
  verdict="no findings"
  if [[ $mode == runs ]]; then
    echo "== fuzz_$t: $count runs in $jobs processes"
    start=$SECONDS
    pids=()
    for ((j = 0; j < jobs; j++)); do
      "$exe" "${common[@]}" -print_final_stats=1 -runs=$(((count + jobs - 1) / jobs)) "$work" "$seeds" \
        >"$build/fuzz-$t-$j.log" 2>&1 &
      pids+=($!)
    done
    runs=0
    for ((j = 0; j < jobs; j++)); do
      if ! wait "${pids[$j]}"; then
        tail -n 40 "$build/fuzz-$t-$j.log"
        echo "fuzz_$t: finding written to $build/findings/ (add it to $seeds once fixed)" >&2
        verdict="A FINDING"
        status=1
      fi
      n=$(sed -n 's/^stat::number_of_executed_units: *//p' "$build/fuzz-$t-$j.log" | tail -n 1)
      runs=$((runs + ${n:-0}))
    done
    secs=$((SECONDS - start))
    summary+=("fuzz_$t: $runs executions in $secs s ($jobs processes), $verdict; corpus $(ls "$work" | wc -l) inputs")
    continue
  fi
  if ! "$exe" "${common[@]}" -print_final_stats=1 "${args[@]}" >"$build/fuzz-$t.log" 2>&1; then
    tail -n 40 "$build/fuzz-$t.log"
    echo "fuzz_$t: finding written to $build/findings/ (add it to $seeds once fixed)" >&2
    verdict="A FINDING"
    status=1
  fi
  runs=$(sed -n 's/^stat::number_of_executed_units: *//p' "$build/fuzz-$t.log" | tail -n 1)
  secs=$(sed -n 's/^Done [0-9]* runs in \([0-9]*\) second.*/\1/p' "$build/fuzz-$t.log" | tail -n 1)
  summary+=("fuzz_$t: ${runs:-?} executions in ${secs:-?} s, $verdict; corpus $(ls "$work" | wc -l) inputs")
done
printf '%s\n' "${summary[@]}"
exit $status
