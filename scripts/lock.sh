#!/usr/bin/env bash
# Refresh requirements.lock: resolve pyproject.toml's ranges afresh in a
# throw-away venv (with the test extras), then pin every installed package.
# Run the README's test command afterwards: the lock is only as good as the
# suite that passed on it.
set -euo pipefail
cd "$(dirname "$0")/.."
PY="${PYTHON:-python3}"
tmp="$(mktemp -d)"
trap 'rm -rf "$tmp"' EXIT
"$PY" -m venv "$tmp/venv"
"$tmp/venv/bin/python" -m pip install -q --upgrade pip
"$tmp/venv/bin/python" -m pip install -q -e ".[test]"
# the build backend pyproject.toml asks for, pinned for the editable build too
"$tmp/venv/bin/python" -m pip install -q --upgrade "setuptools>=77"
{
  echo "# Pinned versions of every package scripts/setup.sh installs (the test extras"
  echo "# and the build backend included); pyproject.toml keeps the ranges.  Made by scripts/lock.sh with"
  echo "# $("$tmp/venv/bin/python" --version) on $(uname -m); refresh with: bash scripts/lock.sh"
  echo "pip==$("$tmp/venv/bin/python" -m pip --version | cut -d' ' -f2)"
  echo "setuptools==$("$tmp/venv/bin/python" -c 'import setuptools; print(setuptools.__version__)')"
  "$tmp/venv/bin/python" -m pip freeze --exclude-editable | grep -v '^setuptools==' | LC_ALL=C sort -f
} > requirements.lock.new
mv requirements.lock.new requirements.lock
echo "[lock] wrote requirements.lock ($(grep -vc '^#' requirements.lock) packages)"
