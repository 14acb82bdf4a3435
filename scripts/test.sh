#!/usr/bin/env bash
# Set up (first time, with test needs) and run the whole test suite.
# GUI tests run in a real window on Xvfb (pytest-xvfb starts it).
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh --test
export MESOFORGE_AUTOSAVE_DIR="${MESOFORGE_AUTOSAVE_DIR:-$(mktemp -d)}"
.venv/bin/lint-imports
exec .venv/bin/python -m pytest -q "$@"
