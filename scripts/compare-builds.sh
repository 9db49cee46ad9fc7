#!/usr/bin/env bash
# Compares two builds of occull on the same bench, interleaved so that the
# shared machine's drift hits both alike: OLD NEW NEW OLD OLD NEW ...
#
#   scripts/compare-builds.sh OLD_BINARY NEW_BINARY ROUNDS [bench options...]
#
# e.g. scripts/compare-builds.sh /tmp/old/build/occull build/occull 3 \
#        --scene city --path street --algo none,vfc --frames 30 --verify off
#
# NEW_ARGS (environment) adds options for the new build only (options the
# old one does not know, e.g. NEW_ARGS="--malloc system").
#
# Prints, per algorithm, the median over rounds of each build's mean and
# median frame time and their ratio new/old. Needs python3.
set -euo pipefail
if [ $# -lt 3 ]; then
  sed -n '2,15p' "$0" >&2
  exit 2
fi
old=$1 new=$2 rounds=$3
shift 3
dir=$(mktemp -d)
trap 'rm -rf "$dir"' EXIT
for ((r = 0; r < rounds; r++)); do
  if ((r % 2 == 0)); then order="old new"; else order="new old"; fi
  for which in $order; do
    bin=$old extra=()
    if [ "$which" = new ]; then bin=$new; read -r -a extra <<<"${NEW_ARGS:-}"; fi
    echo "round $((r + 1))/$rounds: $which ($bin)" >&2
    "$bin" bench "$@" "${extra[@]}" --no-report --json "$dir/$which-$r.json" >/dev/null 2>"$dir/$which-$r.log" ||
      { cat "$dir/$which-$r.log" >&2; exit 1; }
  done
done
python3 - "$dir" "$rounds" <<'PY'
import json, statistics, sys
d, rounds = sys.argv[1], int(sys.argv[2])
runs = {w: [json.load(open(f"{d}/{w}-{r}.json")) for r in range(rounds)] for w in ("old", "new")}
names = [a["name"] for a in runs["new"][0]["algorithms"]]
print(f"{'algorithm':<12} {'old mean':>9} {'new mean':>9} {'new/old':>8} {'old med':>9} {'new med':>9} {'new/old':>8}")
for n in names:
    def med(w, key):
        return statistics.median(a["frame_ms"][key] for run in runs[w] for a in run["algorithms"] if a["name"] == n)
    om, nm, oq, nq = med("old", "mean"), med("new", "mean"), med("old", "median"), med("new", "median")
    print(f"{n:<12} {om:>9.2f} {nm:>9.2f} {nm / om:>8.2f} {oq:>9.2f} {nq:>9.2f} {nq / oq:>8.2f}")
PY
