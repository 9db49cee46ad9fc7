#!/usr/bin/env bash
# Runs a packed occull (scripts/gpu-pack.sh) on a machine with a GPU:
#   bash PACK/gpu-run.sh occull bench --scene city --size 1920x1080 ...
#   bash PACK/gpu-run.sh COMMAND ...      (any command, with the environment below)
# It unpacks the GL dispatch libraries into PACK/root (no root rights
# needed), puts them and the packed libraries first on LD_LIBRARY_PATH,
# points EGL at the NVIDIA vendor library when one is installed
# (OCCULL_EGL_VENDOR=FILE names another vendor JSON), keeps occull's cache in
# PACK/cache, and links data/openarena/pak1-maps.pk3 to the packed maps when
# the current folder has none, so `--suite default` finds them. $MAPS names
# the packed map archive for --scene q3:$MAPS:oasago2.
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
[ $# -ge 1 ] || { sed -n '2,12p' "$0" >&2; exit 2; }
if [ ! -d "$here/root" ]; then
  for deb in "$here"/debs/*.deb; do dpkg-deb -x "$deb" "$here/root"; done
fi
libs=$here/lib
for d in "$here/root/usr/lib/x86_64-linux-gnu" "$here/root/lib/x86_64-linux-gnu"; do
  [ -d "$d" ] && libs=$libs:$d
done
export LD_LIBRARY_PATH=$libs${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}
vendor=${OCCULL_EGL_VENDOR:-}
if [ -z "$vendor" ]; then
  for f in /usr/share/glvnd/egl_vendor.d/10_nvidia.json /etc/glvnd/egl_vendor.d/10_nvidia.json \
           /usr/local/nvidia/share/glvnd/egl_vendor.d/10_nvidia.json; do
    [ -f "$f" ] && { vendor=$f; break; }
  done
fi
[ -n "$vendor" ] && export __EGL_VENDOR_LIBRARY_FILENAMES=$vendor
export XDG_CACHE_HOME=${XDG_CACHE_HOME:-$here/cache}
if [ -f "$here/pak1-maps.pk3" ]; then
  export MAPS=$here/pak1-maps.pk3
  if [ ! -e data/openarena/pak1-maps.pk3 ]; then
    mkdir -p data/openarena && ln -s "$MAPS" data/openarena/pak1-maps.pk3
  fi
fi
echo "gpu-run: EGL vendor ${vendor:-(system default)}, libraries from $here" >&2
if [ "$1" = occull ]; then
  shift
  set -- "$here/occull" "$@"
fi
exec "$@"
