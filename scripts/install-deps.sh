#!/usr/bin/env bash
# Installs every Debian package patchcull needs to build, run and test (Debian 12).
# Nothing else is downloaded at build time.
set -euo pipefail
SUDO=""
if [ "$(id -u)" -ne 0 ]; then SUDO="sudo"; fi
PACKAGES=(
  g++ cmake make ninja-build pkg-config  # scripts/test.sh builds with Ninja
  libegl-dev libgl-dev libopengl-dev libegl-mesa0 libgl1-mesa-dri libepoxy-dev glslang-tools
  libosd-dev libstb-dev libtbb-dev libhwy-dev libcli11-dev nlohmann-json3-dev
  libgtest-dev libbenchmark-dev
  libglfw3-dev xvfb xauth  # the window context; its test runs under xvfb-run
  libimgui-dev  # the viewer's panel (Dear ImGui with its GLFW and OpenGL 3 backends)
  python3-matplotlib  # scripts/plot_figures.py
  assimp-testmodels  # third-party OBJ files for the unseen-models test
  clang-14 libclang-rt-14-dev  # libFuzzer for the fuzz targets (scripts/fuzz.sh)
  libvulkan-dev mesa-vulkan-drivers vulkan-validationlayers  # the Vulkan passes (patchcull_vk) and their tests on lavapipe
)
missing=()
for p in "${PACKAGES[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ "${#missing[@]}" -eq 0 ]; then
  echo "install-deps: all ${#PACKAGES[@]} packages present"
  exit 0
fi
echo "install-deps: installing ${missing[*]}"
$SUDO apt-get update -qq
DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y --no-install-recommends "${missing[@]}"
