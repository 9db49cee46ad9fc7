#!/usr/bin/env bash
# A randomized campaign against the promise: N runs, each an adversarial
# scene of a random kind and seed, placed at a random offset from the world's
# origin (0 to 1,000 km), a random path and occlusion query mode, with every
# conservative culler and its variants (cpu_test=on, texels, virtual leaves)
# verified against the ground truth on every frame. Prints a line per run and
# one at the end with the object-frames checked and the misses.
#
#   scripts/conservative-campaign.sh N [--short] [--seed S] [--occull BIN]
#
# --short: fewer objects and frames (make fuzz-regress runs 3 such runs, a
# couple of minutes). --seed: the campaign's own seed (default: from the
# clock; printed, so a failing campaign can be run again). BIN: the occull
# tool (default build/occull, made by make build or make test).
# Exit codes: 0 nothing missed; 1 a run missed a visible object or failed
# (its command and output are printed); 2 bad arguments.
set -euo pipefail
usage="usage: conservative-campaign.sh N [--short] [--seed S] [--occull BIN]"
root="$(cd "$(dirname "$0")/.." && pwd)"
runs=${1:-}
[[ "$runs" =~ ^[0-9]+$ && "$runs" -ge 1 ]] || { echo "$usage" >&2; exit 2; }
shift
short=0
seed=$(date +%s)
occull="$root/build/occull"
while [[ $# -gt 0 ]]; do
  case "$1" in
    --short) short=1 ;;
    --seed) seed=${2:?$usage}; shift ;;
    --occull) occull=${2:?$usage}; shift ;;
    -h|--help) sed -n '2,16p' "$0" | sed 's/^# \{0,1\}//'; exit 0 ;;
    *) echo "$usage" >&2; exit 2 ;;
  esac
  shift
done
[[ "$seed" =~ ^[0-9]+$ ]] || { echo "--seed $seed: a whole number" >&2; exit 2; }
[[ -x "$occull" ]] || { echo "$occull: not built (make build)" >&2; exit 2; }

kinds=(mixed tiny thin coplanar near far farout)
paths=(walk graze far)
modes=(samples any conservative)
cullers="vfc,stopwait,chc,chc:cpu_test=on,chcpp,chcpp:virtual_leaf=0,chcpp:cpu_test=on,nohc,nohc:cpu_test=on,hiz,hiz:texels=2,soc,soc:scale=1:prepass=off,soc:scale=4:prepass=off:threads=1:rest=0,soc:rest=1:rest_triangles=0,auto"
IFS=, read -ra culler_list <<< "$cullers"
culler_count=${#culler_list[@]}
if [[ $short -eq 1 ]]; then objects=600; frames=12; else objects=3000; frames=30; fi

RANDOM=$((seed % 32768))
# Both set a variable rather than print: bash reseeds RANDOM in a command
# substitution's subshell, and --seed would not repeat a campaign.
pick() { local -n a=$1 into=$2; into=${a[$((RANDOM % ${#a[@]}))]}; }
offset_of() {  # 0, or 1 km to 1,000 km either way along x and z
  local -n into=$1
  case $((RANDOM % 4)) in
    0) into=0 ;;
    1) into=$(( (RANDOM % 2 ? 1 : -1) * (1000 + RANDOM % 9000) )) ;;
    2) into=$(( (RANDOM % 2 ? 1 : -1) * (10000 + RANDOM * 3) )) ;;
    *) into=$(( (RANDOM % 2 ? 1 : -1) * (100000 + RANDOM * 27) )) ;;
  esac
}

tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
echo "conservative campaign: $runs runs, seed $seed, $objects objects, $frames frames per run, 320x180"
checked=0
missed=0
for ((r = 1; r <= runs; ++r)); do
  pick kinds kind; pick paths path; pick modes mode; offset_of offset
  scene="adversarial:kind=$kind,seed=$(( (RANDOM * 32768 + RANDOM) % 1000000000 )),objects=$objects,offset=$offset"
  cmd=("$occull" bench --scene "$scene" --path "$path" --query-mode "$mode" --algo "$cullers"
       --frames "$frames" --warmup 2 --size 320x180 --no-report --json "$tmp/run.json")
  set +e
  "${cmd[@]}" > "$tmp/out.txt" 2>&1
  code=$?
  set -e
  if [[ $code -ne 0 && $code -ne 4 ]]; then
    echo "run $r FAILED (exit $code): ${cmd[*]}"; tail -20 "$tmp/out.txt"; exit 1
  fi
  # Per algorithm in the JSON: "truth_object_frames" and "missed_objects" (every culler here is conservative).
  read -r frames_checked misses < <(awk -F'[:,]' '
    /"truth_object_frames"/ { t += $2 }
    /"missed_objects"/ { m += $2 }
    END { printf "%d %d\n", t, m }' "$tmp/run.json")
  checked=$((checked + frames_checked))
  missed=$((missed + misses))
  printf 'run %d: %-60s %-5s %-12s %9d object-frames, %d missed\n' "$r" "$scene" "$path" "$mode" "$frames_checked" "$misses"
  if [[ $code -eq 4 || $misses -gt 0 ]]; then
    echo "run $r MISSED visible objects: ${cmd[*]}"; grep -E "verification|first" "$tmp/out.txt" || true; exit 1
  fi
done
echo "campaign: $runs runs, $checked object-frames checked over $((runs * culler_count)) culler runs, $missed missed (seed $seed)"
