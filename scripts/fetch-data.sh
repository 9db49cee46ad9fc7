#!/usr/bin/env bash
# Fetches the OpenArena maps (Debian package openarena-081-maps, GPL-2+)
# into data/ without installing the game: apt-get download + dpkg-deb -x.
# Idempotent: does nothing when the archive is already there.
set -euo pipefail
cd "$(dirname "$0")/.."
target=data/openarena/pak1-maps.pk3
if [[ -f "$target" ]]; then
  echo "fetch-data: $target present"
  exit 0
fi
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
echo "fetch-data: downloading openarena-081-maps (about 38 MB)"
(cd "$tmp" && apt-get download -q openarena-081-maps 2>&1 | grep -v "^W: Download is performed unsandboxed" || true)
deb=$(ls "$tmp"/openarena-081-maps_*.deb 2>/dev/null | head -n 1 || true)
if [[ -z "$deb" ]]; then
  echo "fetch-data: apt-get download openarena-081-maps failed (is a Debian mirror reachable? try apt-get update)" >&2
  exit 1
fi
dpkg-deb -x "$deb" "$tmp/x"
mkdir -p data/openarena
cp "$tmp/x/usr/share/games/openarena/baseoa/pak1-maps.pk3" "$target"
cp "$tmp/x/usr/share/doc/openarena-081-maps/copyright" data/openarena/COPYRIGHT 2>/dev/null || true
echo "fetch-data: $target ($(du -h "$target" | cut -f1))"
