#!/usr/bin/env bash
# Set up (first time, with test needs) and run the whole test suite.
# GUI tests run in a real window on Xvfb (pytest-xvfb starts it).
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh --test
export MESOFORGE_AUTOSAVE_DIR="${MESOFORGE_AUTOSAVE_DIR:-$(mktemp -d)}"
.venv/bin/lint-imports
if [ "$#" -gt 0 ]; then
  exec .venv/bin/python -m pytest -q "$@"
fi
# The window tests run in their own process: the Dask clusters and worker
# processes of the study tests must not share a process with the VTK/X
# render windows (a segfault creating a render window was seen otherwise).
.venv/bin/python -m pytest -q --ignore=tests/ui
exec .venv/bin/python -m pytest -q -p xvfb tests/ui
