#!/usr/bin/env bash
# Set up frirom on a fresh Debian 12 machine and run the main job on a bundled case.
#   bash scripts/setup.sh            # system packages (apt-get), .venv, build, demo
#   FRIROM_SKIP_APT=1 bash scripts/setup.sh   # when the packages are already there
set -euo pipefail
cd "$(dirname "$0")/.."

apt_packages=(
  gfortran pkg-config libopenblas-dev libarpack2-dev libfftw3-dev   # Fortran core
  libmumps-seq-dev                                                  # sparse LDL^T (eigen)
  fypp                                                              # Fortran templates
  calculix-ccx                                                      # FE reference
  libglu1-mesa libgl1 libxcursor1 libxft2 libxinerama1              # gmsh wheel
)
if [ -z "${FRIROM_SKIP_APT:-}" ]; then
  sudo=""; [ "$(id -u)" = 0 ] || sudo="sudo"
  $sudo apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -qq --no-install-recommends \
    "${apt_packages[@]}" >/dev/null
fi

python3 -m venv .venv
.venv/bin/python -m pip install -q --upgrade pip
.venv/bin/python -m pip install -q -r requirements-dev.txt
# Editable install: meson-python rebuilds the Fortran core on import when sources change.
.venv/bin/python -m pip install -q --no-build-isolation -Cbuild-dir=build/py \
    -Csetup-args=-Dnative=true -e .

# The main job: the forced response of a blade with a platform friction damper (bundled
# deck), written to results/joint/; then the contact-element demo into results/demo/.
.venv/bin/frirom run cases/joint/joint.toml --out results/joint
.venv/bin/frirom demo --out results/demo
