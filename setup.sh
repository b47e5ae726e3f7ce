#!/usr/bin/env bash
# Installs the system packages the viewer and its headless tests need at run time.
# Idempotent: installs only what is missing; uses sudo only when not root.
#
#   xvfb, xauth            a virtual X display for headless machines (tests, screenshots)
#   mesa-vulkan-drivers    lavapipe, a CPU Vulkan driver, when there is no GPU
#   libvulkan1             the Vulkan loader wgpu opens
#   libgl1-mesa-dri, libegl1  llvmpipe through GL/EGL, wgpu's fallback backend
#   libx11-6, libx11-xcb1, libxcursor1, libxrandr2, libxi6, libxkbcommon-x11-0
#                          X11 client libraries winit opens at run time (dlopen)
#   imagemagick            to inspect screenshots by hand (identify, compare)
#   python3                scripts/real_rooms.py, run by tests/suite/rooms.rs
#   nodejs, npm            (only when npm is missing) to install and run the glTF validator
#                          and the lightmap readers (scripts/lightmap-view)
set -euo pipefail

packages=(
  xvfb xauth
  mesa-vulkan-drivers libvulkan1
  libgl1-mesa-dri libegl1
  libx11-6 libx11-xcb1 libxcursor1 libxrandr2 libxi6 libxkbcommon-x11-0
  imagemagick
  python3
)

missing=()
for p in "${packages[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done

if [ "$(id -u)" -eq 0 ]; then sudo=(); else sudo=(sudo); fi
export DEBIAN_FRONTEND=noninteractive

# Node.js and npm, for the Khronos glTF validator below (a distribution's nodejs with npm, or
# one that bundles npm, both do).
if ! command -v npm >/dev/null 2>&1; then
  missing+=(nodejs npm)
fi

if [ ${#missing[@]} -eq 0 ]; then
  echo "setup.sh: all system packages present"
else
  echo "setup.sh: installing ${missing[*]}"
  "${sudo[@]}" apt-get update -q
  "${sudo[@]}" apt-get install -y -q --no-install-recommends "${missing[@]}"
fi

# The Khronos glTF validator (npm package gltf-validator, version pinned by the lock file):
# tests/export.rs runs it on exported files, and fails in CI when it is missing.
validator_dir="$(dirname "$0")/scripts/gltf-validator"
if [ -d "$validator_dir/node_modules/gltf-validator" ]; then
  echo "setup.sh: gltf-validator present"
else
  echo "setup.sh: installing gltf-validator (npm)"
  npm ci --prefix "$validator_dir" --no-audit --no-fund
fi

# glTF-Transform and three.js (npm, pinned by the lock file): tests/suite/export.rs reads the
# lightmap atlas with them, as an engine would, and fails in CI when they are missing.
# (playwright-core comes along for scripts/lightmap-view/view.mjs; it downloads no browser.)
lightmap_dir="$(dirname "$0")/scripts/lightmap-view"
if [ -d "$lightmap_dir/node_modules/@gltf-transform/core" ] && [ -d "$lightmap_dir/node_modules/three" ]; then
  echo "setup.sh: lightmap readers present"
else
  echo "setup.sh: installing the lightmap readers (npm)"
  npm ci --prefix "$lightmap_dir" --no-audit --no-fund
fi
