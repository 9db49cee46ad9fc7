#!/usr/bin/env bash
# The README's debug-view pictures: occull render --view for the seeds'
# figures, and one occull view window under a virtual X server.
#   scripts/debug-views.sh [BUILD [OUT]]   (default: build, docs)
set -euo pipefail
build=${1:-build}
out=${2:-docs}
occull="$build/occull"
mkdir -p "$out"
size=640x360
common=(--size "$size" --fps 30 --frame 60 --frames 61)
run() {
  local name=$1
  shift
  echo "== $name"
  "$occull" render "$@" --png "$out/$name.png"
}
run views-queries-chc --scene city --algo chc --view queries "${common[@]}"
run views-multiqueries-chcpp --scene city --path turn --algo chcpp --view multiqueries "${common[@]}"
run views-batches-chcpp --scene city --algo chcpp --view batches "${common[@]}"
run views-overview-chcpp --scene city --algo chcpp --view overview "${common[@]}"
run views-cells-grid --scene city --algo grid --view cells "${common[@]}"
run views-tiles --scene tiles_city --path grazing --algo tiles --view tiles "${common[@]}"
if command -v xvfb-run >/dev/null; then
  echo "== view-window"
  xvfb-run -a -s "-screen 0 1280x720x24" "$occull" view --scene city --algo chc --view queries --verify \
    --size "$size" --frames 61 --fps 30 --screenshot "$out/view-window.png"
fi
