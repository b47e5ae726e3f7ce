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
set -euo pipefail

packages=(
  xvfb xauth
  mesa-vulkan-drivers libvulkan1
  libgl1-mesa-dri libegl1
  libx11-6 libx11-xcb1 libxcursor1 libxrandr2 libxi6 libxkbcommon-x11-0
  imagemagick
)

missing=()
for p in "${packages[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done

if [ ${#missing[@]} -eq 0 ]; then
  echo "setup.sh: all system packages present"
  exit 0
fi

if [ "$(id -u)" -eq 0 ]; then sudo=(); else sudo=(sudo); fi
echo "setup.sh: installing ${missing[*]}"
export DEBIAN_FRONTEND=noninteractive
"${sudo[@]}" apt-get update -q
"${sudo[@]}" apt-get install -y -q --no-install-recommends "${missing[@]}"
