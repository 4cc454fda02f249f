"""``[analysis]``: what a deck computes. ``kind = "forced_response"`` (the default: the
FRF over ``[frequency]`` under ``[excitation]``) or ``kind = "nonlinear_mode"`` (the
backbone of one mode by the extended periodic motion concept, frirom.nonlinear_mode) or
``kind = "from_backbone"`` (the forced response over ``[frequency]`` under the harmonic-1
loads of ``[excitation]`` synthesised from that backbone by single nonlinear mode theory,
frirom.nlm_synthesis).

A nonlinear-mode deck needs no ``[frequency]``; its ``[excitation]`` may hold static
loads (harmonic 0, a preload) only.
"""

from __future__ import annotations

from dataclasses import dataclass

from .fields import Context, dof_ref, number, string, unknown

KINDS = ("forced_response", "nonlinear_mode", "from_backbone")


@dataclass(frozen=True)
class AnalysisSettings:
    """``[analysis]``.

    kind : 'forced_response', 'nonlinear_mode' or 'from_backbone'
    mode : int
        The linear mode the nonlinear mode starts from, 1 = the lowest with a nonzero
        frequency (of the stuck or free structure).
    start : 'stuck' or 'free'
        The linear limit of that mode: contacts stuck (their stick stiffness) or free.
    amplitudes : (float, float)
        Modal amplitudes (harmonic 1 mass-normalised, sqrt(kg) m) from and to; log steps.
    output : DofRef or None
        The DoF whose amplitude the backbone figure and table also give (first of
        [outputs] dofs when None; given, it is put first there).
    """

    kind: str = "forced_response"
    mode: int = 1
    start: str = "stuck"
    amplitudes: tuple = (1e-6, 1e-2)
    output: object = None

    @property
    def nonlinear_mode(self) -> bool:
        return self.kind == "nonlinear_mode"

    @property
    def from_backbone(self) -> bool:
        return self.kind == "from_backbone"


def parse_analysis(ctx: Context, raw: dict, fe: bool, labels: bool) -> AnalysisSettings:
    """The deck's [analysis] table (the default forced response when absent)."""
    an = raw.get("analysis", {})
    if not isinstance(an, dict):
        raise ctx.error("analysis", "a table [analysis]", an)
    kind = string(ctx, an, "kind", "analysis.kind", default="forced_response", choices=KINDS)
    if kind == "forced_response" and set(an) <= {"kind"}:
        return AnalysisSettings()
    # a forced response accepts (and does not use) the nonlinear mode's keys, so that a
    # study can switch analysis.kind between from_backbone and forced_response
    unknown(ctx, an, {"kind", "mode", "start", "amplitudes", "output"}, "analysis")
    mode = number(ctx, an, "mode", "analysis.mode", default=1, integer=True, minimum=1)
    start = string(ctx, an, "start", "analysis.start", default="stuck",
                   choices=("stuck", "free"))
    amps = an.get("amplitudes", [1e-6, 1e-2])
    if (not isinstance(amps, list) or len(amps) != 2
            or any(isinstance(a, bool) or not isinstance(a, (int, float)) for a in amps)
            or not all(0 < a < float("inf") for a in amps) or amps[0] == amps[1]):
        raise ctx.error("analysis.amplitudes", "two different positive modal amplitudes "
                        "[from, to]", amps)
    output = None
    if "output" in an:
        output = dof_ref(ctx, an["output"], "analysis.output", fe, labels)
    return AnalysisSettings(kind=kind, mode=int(mode), start=start,
                            amplitudes=(float(amps[0]), float(amps[1])), output=output)
