#!/usr/bin/env bash
# Run the whole test suite: meson test (one Fortran test program per module, and the C
# interface) and pytest (Python layer, against independent references), the tests marked
# slow included; pytest lists the ten slowest. Needs scripts/setup.sh first.
# Extra arguments go to pytest (e.g. `bash scripts/test.sh -m "not slow"`, the fast loop:
# under two minutes on two cores, every feature still covered; the whole suite stays
# under ten). The test files run side by side on every core (pytest-xdist, up to four
# processes; FRIROM_TEST_WORKERS=1 runs them one after another): each test keeps its
# files in its own temporary folder, so none depends on another's order or process.
set -euo pipefail
cd "$(dirname "$0")/.."
export OPENBLAS_NUM_THREADS=${OPENBLAS_NUM_THREADS:-1}
.venv/bin/python -c "import frirom._kernels"   # rebuilds build/py if sources changed
.venv/bin/meson test -C build/py --print-errorlogs
if [ $# -eq 0 ]; then
    echo 'scripts/test.sh: the whole suite, slow tests included (several minutes); the fast' \
         'loop while you work: bash scripts/test.sh -m "not slow"' >&2
fi
workers=${FRIROM_TEST_WORKERS:-$(nproc)}
[ "$workers" -gt 4 ] && workers=4
if [ "$workers" -gt 1 ]; then
    .venv/bin/python -m pytest -q --durations=10 -n "$workers" --dist loadfile tests "$@"
else
    .venv/bin/python -m pytest -q --durations=10 tests "$@"
fi
