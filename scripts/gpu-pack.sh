#!/usr/bin/env bash
# Packs occull to run on a machine with a GPU and no package registry (for
# example a cloud node with only the NVIDIA driver): a Release build of the
# occull binary, the shared libraries it needs beyond the C/C++ runtime and
# the GL driver, the GL vendor-neutral dispatch libraries (libglvnd: libEGL,
# libOpenGL) as Debian packages, the OpenArena maps when fetched, and
# gpu-run.sh, which runs it there.
#
#   scripts/gpu-pack.sh [DEST]        (DEST: .gpu by default; also: make gpu-pack)
#
# Copy DEST to the GPU machine (or carry it with the checkout) and run, from
# the checkout's root or any folder:
#   bash DEST/gpu-run.sh occull info
#   bash DEST/gpu-run.sh occull bench --suite default --size 1920x1080 --json out.json
# The target needs x86-64 Linux with glibc >= this machine's (Debian 12: 2.36).
# Exit codes: 0 packed; 1 a step failed (named); 2 bad usage.
set -euo pipefail
dest=${1:-.gpu}
[ $# -le 1 ] || { sed -n '2,17p' "$0" >&2; exit 2; }
[ -f CMakeLists.txt ] && [ -d src/cull ] || { echo "gpu-pack: run it from occull's root folder" >&2; exit 2; }
fail() { echo "gpu-pack: $*" >&2; exit 1; }

echo "gpu-pack: building occull (Release)"
[ -f build/CMakeCache.txt ] || cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build build -j"$(nproc)" --target occull_cli >/dev/null || fail "the build failed (make build shows why)"
bin=build/occull
[ -x "$bin" ] || fail "no $bin after the build"

rm -rf "$dest"
mkdir -p "$dest/lib" "$dest/debs"
cp "$bin" "$dest/occull"
strip "$dest/occull" 2>/dev/null || true
# Libraries the binary links beyond what every Linux with a GPU driver has:
# glibc, the C++ runtime and the GL/EGL libraries (those come from libglvnd
# below, dispatching to the machine's own driver).
ldd "$bin" | awk '$2 == "=>" && $3 ~ /^\// {print $3}' | while read -r lib; do
  case $(basename "$lib") in
    libc.so.* | libm.so.* | libpthread.so.* | libdl.so.* | librt.so.* | ld-linux* | libgcc_s.so.* | libstdc++.so.*) ;;
    libEGL.so.* | libOpenGL.so.* | libGL.so.* | libGLX.so.* | libGLdispatch.so.*) ;;
    *) cp -L "$lib" "$dest/lib/" ;;
  esac
done

echo "gpu-pack: downloading the GL dispatch libraries (libglvnd)"
lists=$(mktemp -d)
trap 'rm -rf "$lists"' EXIT
apt=(-o APT::Architecture=amd64 -o APT::Architectures=amd64 -o Dir::State::Lists="$lists")
mkdir -p "$lists/partial"
apt-get "${apt[@]}" update >/dev/null 2>&1 || true
(cd "$dest/debs" && apt-get "${apt[@]}" download libglvnd0 libegl1 libopengl0 >/dev/null 2>&1) ||
  fail "apt-get download of libglvnd0 libegl1 libopengl0 failed (is a Debian mirror reachable?)"

if [ -f data/openarena/pak1-maps.pk3 ]; then
  cp data/openarena/pak1-maps.pk3 "$dest/"
else
  echo "gpu-pack: no OpenArena maps (make data fetches them); suites will skip the q3 entries"
fi
cp scripts/gpu-run.sh "$dest/"
{
  echo "occull $(git rev-parse --short=12 HEAD 2>/dev/null || echo unknown) packed $(date -u +%Y-%m-%dT%H:%MZ)"
  (cd "$dest" && find . -type f | sort | xargs ls -l | awk '{print $5, $9}')
} >"$dest/MANIFEST"
# Keep the pack out of git when it lies inside the checkout.
if [[ $dest != /* ]] && [ -d .git ] && ! grep -qxF "/$dest/" .git/info/exclude 2>/dev/null; then
  mkdir -p .git/info
  echo "/$dest/" >>.git/info/exclude
fi
size=$(du -sm "$dest" | cut -f1)
echo "gpu-pack: $dest holds ${size} MB; run there: bash $dest/gpu-run.sh occull bench ..."
[ "$size" -le 64 ] || echo "gpu-pack: note: more than 64 MB (leave the maps out if your transfer is limited)"
