"""The deck's ``[fold_locus]`` table: the folds of the curve followed in a second
parameter (frirom.bifurcations.fold_locus)."""

from __future__ import annotations

from dataclasses import dataclass

from .fields import Context, number, string, unknown


@dataclass(frozen=True)
class FoldLocusSettings:
    """``[fold_locus]``.

    levels : tuple of float
        Factors on the scaled part of the excitation, one frequency run each (> 0).
    part : {'dynamic', 'static'}
        'dynamic': the excitation level (harmonics >= 1); 'static': the static load
        (harmonic 0: a normal preload, a damper's load).
    """

    levels: tuple
    part: str = "dynamic"


def parse_fold_locus(ctx: Context, raw: dict) -> FoldLocusSettings | None:
    """``[fold_locus]`` of the deck, None when absent."""
    if "fold_locus" not in raw:
        return None
    t = raw["fold_locus"]
    if not isinstance(t, dict):
        raise ctx.error("fold_locus", "a table", t)
    unknown(ctx, t, {"levels", "part"}, "fold_locus")
    lv = t.get("levels")
    if not isinstance(lv, list) or not lv:
        raise ctx.error("fold_locus.levels", "a non-empty list of positive numbers", lv)
    levels = tuple(float(number(ctx, {"v": v}, "v", f"fold_locus.levels[{i}]",
                                positive=True, required=True)) for i, v in enumerate(lv))
    part = string(ctx, t, "part", "fold_locus.part", default="dynamic",
                  choices=("dynamic", "static"))
    return FoldLocusSettings(levels, part)
