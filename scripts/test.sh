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
# One process per window-test file. PySide 6.11 sometimes segfaults in
# Shiboken's releaseWrapper while Qt deletes a closed window's widget tree
# (a known open defect, see docs/known_issues.md): a file whose process dies by
# a signal is run once more, loudly; a failing test is never retried.
status=0
for f in tests/ui/test_*.py; do
  rc=0; .venv/bin/python -m pytest -q -p xvfb "$f" || rc=$?
  if [ "$rc" -ge 128 ]; then
    echo "!! $f: the test process died by signal $((rc - 128)); running the file once more" >&2
    rc=0; .venv/bin/python -m pytest -q -p xvfb "$f" || rc=$?
  fi
  if [ "$rc" -ne 0 ]; then status=$rc; fi
done
exit "$status"
