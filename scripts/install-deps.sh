#!/usr/bin/env bash
# Installs what occull needs to build, test and run on Debian 12, with
# apt-get, only for packages that are missing. Idempotent: a second run
# installs nothing. Runs as root, or through sudo when it is available.
# --fuzz adds the fuzzing toolchain (make fuzz).
set -euo pipefail

packages=(
  # toolchain
  g++ cmake ninja-build make pkg-config git
  # headless OpenGL 4.5: EGL + GLVND + Mesa (llvmpipe works without a GPU)
  libegl-dev libopengl-dev libgl1-mesa-dri libegl1
  # libraries
  libglm-dev libfmt-dev libcli11-dev nlohmann-json3-dev libstb-dev libtinyxml2-dev
  libminizip-dev libassimp-dev
  # Highway: the CPU occlusion buffer's inner loops (soc), SIMD with run-time dispatch
  libhwy-dev
  # OpenSceneGraph: occull_osg (a culling group inside OSG) and `occull osg`, which measures it
  # beside OSG's own osg::OcclusionQueryNode in one viewer; openscenegraph brings its file plugins
  libopenscenegraph-dev openscenegraph
  # occull view: a window (GLFW) with Dear ImGui; tested under a virtual X server
  libglfw3-dev libimgui-dev xvfb xauth
  # occull::vk, the Vulkan renderer: Mesa's lavapipe (a Vulkan 1.3 device without a GPU), the
  # loader and headers, volk (loads the Vulkan entry points per device), glslc (the shaders are
  # compiled to SPIR-V at build time) and the Khronos validation layers (its tests fail on any error)
  mesa-vulkan-drivers libvulkan-dev libvulkan-volk-dev glslc vulkan-validationlayers
  # tests and benchmarks
  libgtest-dev libgmock-dev
)
# --fuzz: also what make fuzz needs (clang and its libFuzzer runtime).
if [[ "${1:-}" == "--fuzz" ]]; then
  packages+=(clang-14 libclang-rt-14-dev)
fi

missing=()
for p in "${packages[@]}"; do
  status=$(dpkg-query -W -f='${Status}' "$p" 2>/dev/null || true)
  [[ "$status" == "install ok installed" ]] || missing+=("$p")
done

if [[ ${#missing[@]} -eq 0 ]]; then
  echo "install-deps: all ${#packages[@]} packages present"
  exit 0
fi

if [[ $(id -u) -eq 0 ]]; then
  sudo=()
elif command -v sudo >/dev/null 2>&1; then
  sudo=(sudo)
else
  echo "install-deps: missing packages: ${missing[*]}" >&2
  echo "install-deps: not root and no sudo: install them as root with apt-get install" >&2
  exit 1
fi

echo "install-deps: installing ${missing[*]}"
export DEBIAN_FRONTEND=noninteractive
# Refresh the package lists when they are missing or older than a day.
if [[ -z "$(find /var/lib/apt/lists -maxdepth 1 -name '*Packages*' -mtime -1 2>/dev/null | head -n 1)" ]]; then
  "${sudo[@]}" apt-get update -q
fi
"${sudo[@]}" apt-get install -y -q --no-install-recommends "${missing[@]}"
