#!/usr/bin/env bash
# Build the documentation into docs/_build/html with warnings as errors: the Markdown
# pages (myst-parser), the API reference from the docstrings (autodoc + numpydoc) and the
# examples gallery, whose scripts (examples/plot_*.py) run during the build. Needs
# scripts/setup.sh first (requirements-dev.txt installs the docs' packages).
# Extra arguments go to sphinx-build (e.g. `bash scripts/docs.sh -E` to rebuild all).
set -euo pipefail
cd "$(dirname "$0")/.."
export OPENBLAS_NUM_THREADS=${OPENBLAS_NUM_THREADS:-1} MPLBACKEND=Agg
.venv/bin/python -c "import frirom._kernels"   # rebuilds build/py if sources changed
.venv/bin/python -m sphinx -W --keep-going -q -b html docs docs/_build/html "$@"
echo "docs: docs/_build/html/index.html"
