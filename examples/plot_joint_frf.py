"""
A deck from Python: the blade with a friction damper
====================================================

The bundled deck ``cases/joint/joint.toml`` (the case ``scripts/setup.sh`` runs) loaded
with :func:`frirom.load_deck` and solved with :func:`frirom.frf`. The peak of the tip lies
between the blade's first mode with the damper free (445 Hz) and stuck (469 Hz), and far
below the linear stuck peak: the damper dissipates energy by slipping.
"""

from pathlib import Path

import numpy as np

import frirom
from frirom.plots import plot_frf

try:
    root = Path(__file__).resolve().parents[1]
except NameError:                      # run as a notebook cell
    root = Path.cwd().parent
deck = frirom.load_deck(root / "cases" / "joint" / "joint.toml")
curve = frirom.frf(deck.model(), deck.excitation(), deck.omega_start, deck.omega_end,
                   deck.options(), outputs=deck.solver_outputs)

peak = curve.peak(0)
print(f"{len(curve)} points; tip peak {peak.amplitude:.4e} m at "
      f"{peak.omega / (2 * np.pi):.2f} Hz")
print("solver:", curve.solver_info)

fig = plot_frf(curve, output_names=deck.output_names, title="joint.toml")
