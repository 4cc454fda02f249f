#!/usr/bin/env bash
# Run the whole test suite: pytest (Python layer, against independent references) and
# meson test (one Fortran test program per module). Needs scripts/setup.sh first.
set -euo pipefail
cd "$(dirname "$0")/.."
export OPENBLAS_NUM_THREADS=${OPENBLAS_NUM_THREADS:-1}
.venv/bin/python -c "import frirom._kernels"   # rebuilds build/py if sources changed
.venv/bin/meson test -C build/py --print-errorlogs
.venv/bin/python -m pytest -q tests
