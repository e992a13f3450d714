#!/usr/bin/env bash
# Installs what Ressort needs on a fresh Debian machine: the system packages of the plugin shell
# (ALSA, JACK, X11, GL), Python's venv for the VST3 host tests, Ardour for the DAW export
# test, and the crates of the workspace. Safe to run again: it installs only what is missing.
set -euo pipefail
cd "$(dirname "$0")/.."

packages=(
  pkg-config
  libasound2-dev
  libjack-jackd2-dev
  libx11-dev
  libx11-xcb-dev
  libxcb1-dev
  libxcb-icccm4-dev
  libxcb-dri2-0-dev
  libxcursor-dev
  libxrandr-dev
  libxi-dev
  libgl1-mesa-dev
  # The editor check: a virtual X server and Mesa's software OpenGL.
  xvfb
  libgl1-mesa-dri
  # A real DAW for the VST3 tests: Ardour 7.3 exports an automated session headlessly.
  ardour
)
# The VST3 host tests run pedalboard and DawDreamer (PyPI) in a virtual environment.
if ! command -v python3 >/dev/null; then
  packages+=(python3 python3-venv python3-pip)
elif ! python3 -m venv --help >/dev/null 2>&1; then
  packages+=(python3-venv)
fi
missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q 'install ok installed' || missing+=("$p")
done
if [ ${#missing[@]} -gt 0 ]; then
  echo "setup: installing ${missing[*]}"
  SUDO=""
  [ "$(id -u)" -ne 0 ] && SUDO="sudo"
  $SUDO apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
fi

command -v cargo >/dev/null || { echo "setup: cargo is required (https://rustup.rs)" >&2; exit 1; }
cargo fetch --locked -q
