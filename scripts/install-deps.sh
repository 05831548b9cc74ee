#!/usr/bin/env bash
# Installs, with Debian's/Ubuntu's apt, what lodkit needs on a machine and is missing:
#   (default)  the software GPU (lavapipe: mesa-vulkan-drivers, libvulkan1) and a TrueType font
#              for the demo's plots;
#   --ci       also the reference compilers (glslang-tools, spirv-tools), the GL software path
#              (libegl1, libegl-mesa0, libgl1-mesa-dri), Chromium, Node.js and npm, and Xvfb
#              (lodkit_bevy's window test).
# Nothing is installed when everything is present. Uses sudo when not run as root.
set -euo pipefail

ci=0
for arg in "$@"; do
  case "$arg" in
    --ci) ci=1 ;;
    *) echo "usage: $0 [--ci]" >&2; exit 2 ;;
  esac
done

need=()
# ldconfig lives in /sbin, off a normal user's PATH; read its list once (no pipe into grep -q,
# which would trip pipefail).
libs=$(PATH="$PATH:/sbin:/usr/sbin" ldconfig -p 2>/dev/null || true)
ls /usr/share/vulkan/icd.d/lvp_icd.*.json >/dev/null 2>&1 || need+=(mesa-vulkan-drivers)
grep -q 'libvulkan.so.1' <<<"$libs" || need+=(libvulkan1)
[ -f /usr/share/fonts/truetype/dejavu/DejaVuSans.ttf ] || need+=(fonts-dejavu-core)
if [ "$ci" -eq 1 ]; then
  command -v glslangValidator >/dev/null || need+=(glslang-tools)
  command -v spirv-val >/dev/null || need+=(spirv-tools)
  grep -q 'libEGL.so.1' <<<"$libs" || need+=(libegl1)
  grep -q 'libEGL_mesa.so.0' <<<"$libs" || need+=(libegl-mesa0 libgl1-mesa-dri)
  command -v chromium >/dev/null || need+=(chromium)
  command -v npm >/dev/null || need+=(nodejs npm)
  command -v Xvfb >/dev/null || need+=(xvfb)
  # What winit loads for an X11 window.
  grep -q 'libX11.so.6' <<<"$libs" || need+=(libx11-6)
  grep -q 'libXcursor.so.1' <<<"$libs" || need+=(libxcursor1)
  grep -q 'libXrandr.so.2' <<<"$libs" || need+=(libxrandr2)
  grep -q 'libXi.so.6' <<<"$libs" || need+=(libxi6)
  grep -q 'libxkbcommon-x11.so.0' <<<"$libs" || need+=(libxkbcommon-x11-0)
fi

if [ ${#need[@]} -eq 0 ]; then
  exit 0
fi
if ! command -v apt-get >/dev/null; then
  echo "error: missing ${need[*]} (Debian package names) and there is no apt-get here;" \
       "install the equivalents with your system's package manager" >&2
  exit 1
fi
sudo=""
if [ "$(id -u)" -ne 0 ]; then
  if ! command -v sudo >/dev/null; then
    echo "error: missing ${need[*]}; run this as root or install sudo" >&2
    exit 1
  fi
  sudo="sudo"
fi
echo "installing ${need[*]}"
$sudo apt-get update -qq
DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -qq --no-install-recommends "${need[@]}"
