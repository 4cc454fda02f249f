#!/usr/bin/env bash
# Build the documentation into docs/_build/html with warnings as errors: the Markdown
# pages (myst-parser), the API reference from the docstrings (autodoc + numpydoc) and the
# examples gallery, whose scripts (examples/plot_*.py) run during the build. Needs
# scripts/setup.sh first (requirements-dev.txt installs the docs' packages).
# Then FORD (docs/ford.md) writes the Fortran modules' reference, from their `!>` and `!!`
# comments, into docs/_build/html/fortran/ (linked from the API page); a FORD warning
# fails the build as Sphinx's do.
# Extra arguments go to sphinx-build (e.g. `bash scripts/docs.sh -E` to rebuild all).
set -euo pipefail
cd "$(dirname "$0")/.."
export OPENBLAS_NUM_THREADS=${OPENBLAS_NUM_THREADS:-1} MPLBACKEND=Agg
.venv/bin/python -c "import frirom._kernels"   # rebuilds build/py if sources changed
.venv/bin/python -m sphinx -W --keep-going -q -b html docs docs/_build/html "$@"
ford_log=$(cd docs && ../.venv/bin/ford ford.md 2>&1) || { echo "$ford_log"; exit 1; }
if grep -qi "warning\|error" <<<"$ford_log"; then
  echo "$ford_log" | grep -i -A2 "warning\|error"
  echo "docs: FORD warned (docs/ford.md); fix the comments it names" >&2
  exit 1
fi
echo "docs: docs/_build/html/index.html, Fortran: docs/_build/html/fortran/index.html"
