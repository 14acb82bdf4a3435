#!/usr/bin/env bash
# Creates .venv and installs Mesoforge (and, with --test, its test needs),
# installing the system libraries Qt, VTK, Xvfb and Mesa EGL need when run as
# root; otherwise it names the apt line to run.  Safe to run repeatedly.
set -euo pipefail
cd "$(dirname "$0")/.."

want_test=0
[ "${1:-}" = "--test" ] && want_test=1

SYS_PKGS="xvfb xauth libxcb-icccm4 libxcb-keysyms1 libxcb-image0 libxcb-render-util0 libxcb-xinerama0 \
libxcb-randr0 libxcb-shape0 libxcb-xkb1 libxcb-cursor0 libxkbcommon-x11-0 libxkbcommon0 libegl1 libgl1 \
libgl1-mesa-dri libglx-mesa0 libxrender1 libxext6 libsm6 libice6 libfontconfig1 libdbus-1-3 libglib2.0-0"

missing=""
if command -v dpkg-query >/dev/null 2>&1; then
  for p in $SYS_PKGS; do
    dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing="$missing $p"
  done
fi
if [ -n "$missing" ]; then
  if [ "$(id -u)" = "0" ] && command -v apt-get >/dev/null 2>&1; then
    echo "[setup] installing system packages:$missing"
    export DEBIAN_FRONTEND=noninteractive
    apt-get update -qq
    apt-get install -y -qq --no-install-recommends $missing >/dev/null
  else
    echo "[setup] missing system packages; run:"
    echo "  sudo apt-get install -y$missing"
  fi
fi

PY="${PYTHON:-python3}"
if [ ! -x .venv/bin/python ]; then
  echo "[setup] creating .venv"
  "$PY" -m venv .venv
fi
stamp=".venv/.mesoforge-installed"
extra=""
[ $want_test = 1 ] && extra="[test]"
# Every package is installed at the version requirements.lock pins (the
# versions the test suite passed with), the build backend of the editable
# install included; pyproject.toml keeps the ranges.
lock="requirements.lock"
sig="$(cat pyproject.toml "$lock" | sha256sum | cut -c1-16)$extra"
if [ ! -f "$stamp" ] || ! grep -qxF -- "$sig" "$stamp"; then
  echo "[setup] installing Python packages from $lock (first run takes a few minutes)"
  .venv/bin/python -m pip install -q -c "$lock" --upgrade pip
  .venv/bin/python -m pip install -q -c "$lock" --build-constraint "$lock" -e ".$extra"
  echo "$sig" >> "$stamp"
fi
