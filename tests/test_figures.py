"""Figures for a report (issue 29 item 5): every line and marker named in a legend that
lies inside the figure and off the curves, axis labels not cut, and an amplitude axis not
dragged down by a round-off curve. Checked on the drawn figure's bounding boxes (Agg)."""

from types import SimpleNamespace

import numpy as np
from matplotlib.backends.backend_agg import FigureCanvasAgg

from frirom.plots import plot_frf
from frirom.study_plots import plot_family, plot_peaks


def _boxes(fig):
    FigureCanvasAgg(fig).draw()
    r = fig.canvas.get_renderer()
    return r, fig.bbox


def _inside(inner, outer, tol=1.0):
    return (inner.x0 >= outer.x0 - tol and inner.y0 >= outer.y0 - tol
            and inner.x1 <= outer.x1 + tol and inner.y1 <= outer.y1 + tol)


def _labels(fig):
    return [t.get_text() for lg in fig.legends + [a.get_legend() for a in fig.axes
                                                  if a.get_legend()]
            for t in lg.get_texts()]


# six zipped key paths: the damper load family of issue 29 before item 2
KEYS = [f"contacts[{i}].n0" for i in range(4)] + [f"excitation.load[{i}].amplitude"
                                                   for i in (1, 2)]


def _study(n=5):
    w = 2 * np.pi * np.linspace(400, 520, 60)
    members, frfs, sums = [], [], []
    for i in range(n):
        v = 10.0 * (i + 1)
        a = 1e-4 / (1 + ((w / 2 / np.pi - 450 - 3 * i) / 4) ** 2)
        members.append({"values": {k: v for k in KEYS}})
        frfs.append(SimpleNamespace(omega=w, amp_max=a[:, None], stable=np.ones(60, bool),
                                    __len__=None))
        sums.append({"peaks": [(w[np.argmax(a)], a.max())], "complete": i != 2})
    study = SimpleNamespace(settings=SimpleNamespace(output=0, parameters=[(k, None)
                                                                          for k in KEYS],
                                                     combine="zip"),
                            members=members, raw={"title": "UPD", "outputs": {"dofs":
                                                                            ["tip:x"]}},
                            path=SimpleNamespace(stem="upd"), kind="family")
    return study, frfs, sums


class _FRF(SimpleNamespace):
    def __len__(self):
        return len(self.omega)


def test_family_legend_inside_the_figure_off_the_axes_and_markers_named():
    study, frfs, sums = _study()
    frfs = [_FRF(**vars(f)) for f in frfs]
    lin = {"free": (frfs[0].omega, 2e-4 / (1 + ((frfs[0].omega / 2 / np.pi - 440) / 2) ** 2))}
    fig = plot_family(study, frfs, sums, linear=lin)
    r, fb = _boxes(fig)
    legend = (fig.legends or [fig.axes[0].get_legend()])[0]
    lb = legend.get_window_extent(r)
    assert _inside(lb, fb), (lb, fb)
    assert not lb.overlaps(fig.axes[0].get_window_extent(r))
    names = _labels(fig)
    assert "peak (solved)" in names and "curve stopped here" in names
    assert "linear, contacts free" in names
    assert sum("n0" in t for t in names) >= 5              # one entry per member


def test_peaks_x_label_not_cut():
    study, frfs, sums = _study()
    fig = plot_peaks(study, sums)
    r, fb = _boxes(fig)
    for ax in fig.axes:
        lab = ax.xaxis.label
        if lab.get_text():
            assert _inside(lab.get_window_extent(r), fb), lab.get_text()


def test_linear_figure_names_outputs_and_ignores_round_off():
    # `frirom modes`' linear.png: an empty nonlinear curve and the linear free / stuck
    # curves; one output (platform:y free) is round-off, 1e-22 m. The legend names each
    # output's colour and each line style, and the axis stops four decades below the top.
    w = 2 * np.pi * np.linspace(370, 550, 200)
    big = 1e-3 / (1 + ((w / 2 / np.pi - 445) / 3) ** 2)
    free = np.stack([big, 0.1 * big, 1e-19 * big], axis=1)
    stuck = np.stack([big, 0.05 * big, 0.02 * big], axis=1)
    empty = SimpleNamespace(omega=w[:0], amp_max=np.zeros((0, 3)))
    fig = plot_frf(empty, output_names=["tip:x", "platform:x", "platform:y"],
                   linear={"free": (w, free), "stuck": (w, stuck)}, log=True)
    names = _labels(fig)
    for n in ("tip:x", "platform:x", "platform:y", "linear, contacts free",
              "linear, contacts stuck"):
        assert n in names, names
    lo, hi = fig.axes[0].get_ylim()
    assert lo >= 1e-4 * big.max() / 1.5 * 0.999 and hi <= 1.5 * big.max() * 1.001


def test_paper_flange_markers_named_for_every_load(tmp_path, monkeypatch):
    # fig9_stage1.png drew ROM_II markers for 10, 30 and 100 N in colours the legend never
    # named: colours were named by ROM_I's lines only (here ROM_I ran the quick family 1,
    # 30, 300 N), marker styles by the first F0's. Now every colour of a line or marker
    # has an F0 entry and every marker style a model entry.
    import json

    import matplotlib.colors as mcolors
    from matplotlib.figure import Figure
    import paper_flange as pf
    (tmp_path / "case.json").write_text(json.dumps({"f_stuck": 100.0}))
    f = np.linspace(90, 110, 50)

    def curve(f0):
        a = f0 / (1 + (f - 100) ** 2)
        return {"f": f.tolist(), "amp": [a.tolist(), (0.5 * a).tolist()],
                "peak_amp": [a.max(), 0.5 * a.max()], "f0": f0}
    res = {"rom1": {f"{x:g}": curve(x) for x in pf.F0_QUICK},
           "rom2": {f"{x:g}": curve(x) for x in (10.0, 30.0, 100.0)}}
    figs = []
    real = Figure.savefig
    monkeypatch.setattr(Figure, "savefig", lambda self, *a, **k: (figs.append(self),
                                                                    real(self, *a, **k)))
    paths = pf.figures(tmp_path, False, res)
    assert [p.name for p in paths] == ["fig9_stage1.png", "fig10_stage2.png"]
    for fig in figs:
        ax = fig.axes[0]
        entries = dict(zip([t.get_text() for t in ax.get_legend().get_texts()],
                           ax.get_legend().legend_handles))
        for x in (10, 30, 100):
            assert f"F0 = {x} N" in entries, entries.keys()
        assert "ROM_II (h = 2)" in entries and "ROM_I (line)" in entries
        named = {mcolors.to_hex(h.get_color()) for t, h in entries.items()
                 if t.startswith("F0")}
        for line in ax.get_lines():
            if line.get_xdata().size and line.get_marker() not in ("None", "", None):
                assert mcolors.to_hex(line.get_color()) in named
