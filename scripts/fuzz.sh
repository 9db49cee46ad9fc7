#!/usr/bin/env bash
# Fuzz targets of BUILD (make fuzz-build) over their seed corpora in
# tests/corpus/TARGET (every input there must pass: the regressions), then:
#   fuzz.sh BUILD run SECONDS   fuzz each for SECONDS, new inputs kept in BUILD/corpus/TARGET;
#   fuzz.sh BUILD regress       a fixed number of runs from a fixed seed (CI: the same inputs every time).
# A finding (crash, sanitizer report, timeout over 10 s, more than 2 GiB) is
# written to BUILD/findings/ and makes this exit 1. Prints the executions per
# target. Leaks inside assimp are suppressed (fuzz/lsan.supp).
set -euo pipefail
usage="usage: fuzz.sh BUILD run SECONDS | fuzz.sh BUILD regress"
build=${1:?$usage}
mode=${2:?$usage}
root="$(cd "$(dirname "$0")/.." && pwd)"
case "$mode" in
  run) seconds=${3:?$usage} ;;
  regress) ;;
  *) echo "$usage" >&2; exit 2 ;;
esac
targets=(bsp pk3 path profile scene_spec model)
# regress: runs per target, about 10 s each here (assimp builds its importers per run).
declare -A regress_runs=([bsp]=50000 [pk3]=2000 [path]=50000 [profile]=10000 [scene_spec]=50000 [model]=50)
export LSAN_OPTIONS="suppressions=$root/fuzz/lsan.supp:print_suppressions=0"
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
  else
    echo "== fuzz_$t: ${regress_runs[$t]} runs from seed 1"
    rm -rf "$work" && mkdir -p "$work" && cp "$seeds"/* "$work"/
    args=(-seed=1 -runs="${regress_runs[$t]}" "$work")
  fi
  verdict="no findings"
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
