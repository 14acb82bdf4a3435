#!/usr/bin/env bash
# Set up (first time) and launch Mesoforge with an example project open.
# With no display, renders the example headlessly and prints where the PNG and mesh went.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
exec .venv/bin/mesoforge "$@"
