#!/usr/bin/env bash
# Installs what strata needs on a Debian machine: a Vulkan loader + driver
# (Mesa lavapipe, software Vulkan) when none is present, Xvfb and the X11 client
# libraries for the `strata view` tests when missing, and a Rust toolchain when
# cargo is missing. Idempotent; prints what it does.
set -euo pipefail

say() { echo "[strata setup] $*" >&2; }
as_root() { if [ "$(id -u)" = 0 ]; then "$@"; elif command -v sudo >/dev/null; then sudo "$@"; else say "need root for: $*"; return 1; fi; }

# The loader library may be found by ldconfig (not on PATH for every user, so
# try /sbin too) or directly in the multiarch library directories.
has_vulkan_loader() {
  local ldc
  for ldc in ldconfig /sbin/ldconfig /usr/sbin/ldconfig; do
    if command -v "$ldc" >/dev/null 2>&1 && "$ldc" -p 2>/dev/null | grep -q 'libvulkan.so.1'; then return 0; fi
  done
  compgen -G '/usr/lib/*/libvulkan.so.1' >/dev/null || compgen -G '/usr/lib/libvulkan.so.1' >/dev/null \
    || compgen -G '/lib/*/libvulkan.so.1' >/dev/null
}
has_vulkan_icd() {
  compgen -G '/usr/share/vulkan/icd.d/*.json' >/dev/null || compgen -G '/etc/vulkan/icd.d/*.json' >/dev/null
}
has_vulkan() { has_vulkan_loader && has_vulkan_icd; }

if has_vulkan; then
  say "Vulkan loader and driver found"
else
  say "no Vulkan driver found: installing Mesa's lavapipe (mesa-vulkan-drivers, libvulkan1)"
  as_root apt-get update -qq
  DEBIAN_FRONTEND=noninteractive as_root apt-get install -y -qq mesa-vulkan-drivers libvulkan1 >/dev/null
  if ! has_vulkan; then
    has_vulkan_loader || say "libvulkan.so.1 not found (ldconfig and /usr/lib/*/)"
    has_vulkan_icd || say "no ICD json in /usr/share/vulkan/icd.d or /etc/vulkan/icd.d"
    say "Vulkan still not found after install"; exit 1
  fi
fi

# Debian 12's lavapipe (Mesa 22.3) leaks about 1 KB per triangle drawn by every
# deep-G-buffer pass of layer >= 1 (about 5 MB per frame on atrium with two
# layers; docs/reliability.md). Mesa 25 from bookworm-backports does not: on
# bookworm, install it from there (same apt mirror as the system's).
apt_mirror() {
  local uri
  uri=$(grep -h -E '^URIs:' /etc/apt/sources.list.d/*.sources 2>/dev/null | awk '{print $2}' | grep -v security | head -n 1)
  [ -n "$uri" ] || uri=$(grep -h -E '^deb ' /etc/apt/sources.list 2>/dev/null | awk '$3 == "bookworm" {print $2; exit}')
  printf '%s' "$uri"
}
codename=$( (. /etc/os-release 2>/dev/null && printf '%s' "${VERSION_CODENAME:-}") || true)
mesa_version=$(dpkg-query -W -f='${Version}' mesa-vulkan-drivers 2>/dev/null || true)
if [ "$codename" = bookworm ] && [ -n "$mesa_version" ] && dpkg --compare-versions "$mesa_version" lt 23; then
  mirror=$(apt_mirror)
  if [ -z "$mirror" ]; then
    say "lavapipe $mesa_version leaks memory with >= 2 deep-G-buffer layers, and no apt mirror was found to fetch Mesa from bookworm-backports"
  else
    say "lavapipe $mesa_version leaks memory with >= 2 deep-G-buffer layers: installing Mesa from bookworm-backports"
    echo "deb $mirror bookworm-backports main" | as_root tee /etc/apt/sources.list.d/strata-bookworm-backports.list >/dev/null
    as_root apt-get update -qq
    DEBIAN_FRONTEND=noninteractive as_root apt-get install -y -qq -t bookworm-backports mesa-vulkan-drivers >/dev/null
    say "lavapipe now $(dpkg-query -W -f='${Version}' mesa-vulkan-drivers)"
  fi
fi

# `strata view`'s tests open real windows on a virtual X server (Xvfb); winit loads
# libX11/libxcursor/libxkbcommon-x11 at run time.
has_x_libs() {
  compgen -G '/usr/lib/*/libX11-xcb.so.1' >/dev/null && compgen -G '/usr/lib/*/libxkbcommon-x11.so.0' >/dev/null \
    && compgen -G '/usr/lib/*/libXcursor.so.1' >/dev/null && compgen -G '/usr/lib/*/libXi.so.6' >/dev/null
}
# xdotool sends real X key and mouse events to the viewer's window in one test.
if command -v Xvfb >/dev/null 2>&1 && command -v xdotool >/dev/null 2>&1 && has_x_libs; then
  say "Xvfb, xdotool and the X11 client libraries found"
else
  say "installing Xvfb, xdotool and X11 client libraries for the strata view tests (xvfb, xdotool, libx11-xcb1, libxkbcommon-x11-0, libxcursor1, libxi6, libxrandr2)"
  as_root apt-get update -qq
  DEBIAN_FRONTEND=noninteractive as_root apt-get install -y -qq xvfb xdotool libx11-xcb1 libxkbcommon-x11-0 libxcursor1 libxi6 libxrandr2 >/dev/null
  command -v Xvfb >/dev/null 2>&1 || { say "Xvfb still not found after install"; exit 1; }
fi

if ! command -v cargo >/dev/null 2>&1; then
  if [ -x "$HOME/.cargo/bin/cargo" ]; then
    export PATH="$HOME/.cargo/bin:$PATH"
  else
    say "cargo not found: installing a stable Rust toolchain with rustup"
    as_root apt-get install -y -qq curl ca-certificates build-essential >/dev/null
    curl -sSf https://sh.rustup.rs | sh -s -- -y --profile minimal >&2
    export PATH="$HOME/.cargo/bin:$PATH"
  fi
fi
say "$(cargo --version)"

# Mesa's loader wants a runtime dir; headless machines often lack one.
if [ -z "${XDG_RUNTIME_DIR:-}" ]; then
  export XDG_RUNTIME_DIR="${TMPDIR:-/tmp}/strata-xdg-$(id -u)"
  mkdir -p "$XDG_RUNTIME_DIR" && chmod 700 "$XDG_RUNTIME_DIR"
fi
