"""Charts of the study, drawn from its tables (matplotlib ``Figure`` objects, no pyplot state).

* :func:`speed_accuracy_figure`: time per image against 95th-percentile error, one point per
  method and condition, the nominal scenes highlighted and their Pareto front drawn.
* :func:`stability_figure`: one panel per condition, p95 error against the sweep value per
  method, failures marked, the 2 deg breakdown threshold drawn.
* :func:`model_cost_figure`: model quadrature grid size against error and time.
* :func:`tables_figure`: breakdown points and the adaptive estimator's model choices as text.

:func:`save` writes a figure as vector PDF and PNG with no time stamps (same tables, same files).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd
from matplotlib import transforms
from matplotlib.figure import Figure

from pipeline.bench.analysis import BREAKDOWN_P95_DEG, NOMINAL
from pipeline.bench.grids import GRIDS

#: axis label of every condition (from the grids)
LABELS: dict[str, str] = {s.name: s.label for g in GRIDS.values() for s in g.sweeps}
#: smallest error drawn on log axes (deg); smaller errors are drawn at this floor
ERROR_FLOOR_DEG = 1e-3
_COLOURS = ("#1f77b4", "#d62728", "#2ca02c", "#9467bd", "#ff7f0e", "#17becf", "#8c564b", "#e377c2", "#7f7f7f")


def method_colours(methods: list[str] | pd.Series) -> dict[str, str]:
    """A fixed colour per method, in order of first appearance."""
    names = list(dict.fromkeys(methods))
    return {m: _COLOURS[i % len(_COLOURS)] for i, m in enumerate(names)}


def _floor(x: pd.Series | np.ndarray) -> np.ndarray:
    return np.maximum(np.asarray(x, dtype=float), ERROR_FLOOR_DEG)


def speed_accuracy_figure(table: pd.DataFrame) -> Figure:
    """Time per image (ms) against 95th-percentile absolute error (deg), Pareto front marked.

    Parameters
    ----------
    table : DataFrame
        ``speed_accuracy.csv`` (see :func:`pipeline.bench.analysis.speed_accuracy`).
    """
    fig = Figure(figsize=(8.0, 5.5))
    ax = fig.add_subplot()
    colours = method_colours(table["method"])
    other = table[table["condition"] != NOMINAL]
    nominal = table[table["condition"] == NOMINAL]
    for m, c in colours.items():
        sub = other[other["method"] == m]
        ax.scatter(sub["median_ms_per_image"], _floor(sub["p95_abs_error_deg"]), s=14, color=c, alpha=0.35,
                   linewidths=0)
        nom = nominal[nominal["method"] == m]
        ax.scatter(nom["median_ms_per_image"], _floor(nom["p95_abs_error_deg"]), s=70, color=c,
                   edgecolors="black", linewidths=0.8, label=m, zorder=3)
    front = nominal[nominal["pareto"].astype(bool)].sort_values("median_ms_per_image")
    ax.scatter(front["median_ms_per_image"], _floor(front["p95_abs_error_deg"]), s=220, facecolors="none",
               edgecolors="black", linewidths=1.2, zorder=4)
    if len(front):
        ax.step(front["median_ms_per_image"], _floor(front["p95_abs_error_deg"]), where="post", color="black",
                linewidth=1.2, zorder=2, label="Pareto front (nominal, ringed)")
    for _, r in nominal.iterrows():
        if np.isfinite(r["p95_abs_error_deg"]):
            ax.annotate(r["method"], (r["median_ms_per_image"], max(r["p95_abs_error_deg"], ERROR_FLOOR_DEG)),
                        textcoords="offset points", xytext=(6, 4), fontsize=8)
    ax.axhline(BREAKDOWN_P95_DEG, color="grey", linestyle="--", linewidth=0.8)
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel("median time per image (ms, one core: file read + JPEG decode + measurement)")
    ax.set_ylabel("95th-percentile |psi error| (deg)")
    ax.set_title("Speed against accuracy: large points = nominal scenes, small = one per sweep condition",
                 fontsize=10)
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=8, loc="best")
    fig.tight_layout()
    return fig


def stability_figure(stab: pd.DataFrame, *, ncols: int = 3) -> Figure:
    """One panel per condition: p95 absolute error (deg) against the sweep value per method.

    Sweep values where a method failed on at least one image are marked with an ``x`` at the
    top of the panel (in the method's colour); the dashed line is the breakdown threshold.

    Parameters
    ----------
    stab : DataFrame
        ``stability.csv`` (see :func:`pipeline.bench.analysis.stability`).
    """
    conditions = list(dict.fromkeys(stab["condition"]))
    nrows = max(int(np.ceil(len(conditions) / ncols)), 1)
    fig = Figure(figsize=(4.0 * ncols, 2.9 * nrows))
    colours = method_colours(stab["method"])
    axes = [fig.add_subplot(nrows, ncols, i + 1) for i in range(len(conditions))]
    for ax, cond in zip(axes, conditions):
        sub = stab[stab["condition"] == cond]
        top = transforms.blended_transform_factory(ax.transData, ax.transAxes)
        for m, c in colours.items():
            g = sub[sub["method"] == m].sort_values("value")
            if g.empty:
                continue
            ax.plot(g["value"], _floor(g["p95_abs_error_deg"]), marker="o", markersize=2.5, linewidth=1.0,
                    color=c, label=m)
            bad = g[g["failure_rate"] > 0]
            ax.scatter(bad["value"], np.full(len(bad), 0.97), marker="x", s=18, color=c, transform=top,
                       clip_on=False)
        ax.axhline(BREAKDOWN_P95_DEG, color="grey", linestyle="--", linewidth=0.8)
        nominal = float(sub["nominal"].iloc[0])
        ax.axvline(nominal, color="grey", linestyle=":", linewidth=0.8)
        ax.set_yscale("log")
        ax.set_xlabel(LABELS.get(cond, cond), fontsize=8)
        ax.set_ylabel("p95 |psi error| (deg)", fontsize=8)
        ax.set_title(cond, fontsize=9)
        ax.tick_params(labelsize=7)
        ax.grid(True, which="major", alpha=0.3)
    if axes:
        handles, labels = axes[0].get_legend_handles_labels()
        fig.legend(handles, labels, loc="lower right", fontsize=8, ncols=2)
    fig.suptitle("Stability: one condition swept, the others nominal (x = failures; dotted = nominal; "
                 f"dashed = {BREAKDOWN_P95_DEG:g} deg)", fontsize=10)
    fig.tight_layout()
    return fig


def model_cost_figure(cost: pd.DataFrame) -> Figure:
    """Model quadrature grid size against max relative error and time (both log axes).

    Parameters
    ----------
    cost : DataFrame
        ``model_cost.csv``: columns ``grid_n, seconds, max_rel_error``.
    """
    fig = Figure(figsize=(7.0, 4.2))
    ax = fig.add_subplot()
    if cost.empty:
        ax.text(0.5, 0.5, "model benchmark not available", ha="center", va="center", transform=ax.transAxes)
        ax.set_axis_off()
        return fig
    c = cost.sort_values("grid_n")
    ax.plot(c["grid_n"], np.maximum(c["max_rel_error"].astype(float), 1e-16), marker="o", color="#1f77b4")
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel("quadrature grid size (points per axis)")
    ax.set_ylabel("max relative error of P(psi) (-)", color="#1f77b4")
    ax2 = ax.twinx()
    ax2.plot(c["grid_n"], 1e3 * c["seconds"].astype(float), marker="s", color="#d62728")
    ax2.set_yscale("log")
    ax2.set_ylabel("time for the benchmark curves (ms)", color="#d62728")
    ax.grid(True, which="both", alpha=0.3)
    ax.set_title("Model: accuracy against cost", fontsize=10)
    fig.tight_layout()
    return fig


def tables_figure(bd: pd.DataFrame, choice: pd.DataFrame, rep: pd.DataFrame) -> Figure:
    """Text page: breakdown points per condition and method, repeatability, model choices."""
    fig = Figure(figsize=(8.27, 11.69))
    lines = ["Breakdown point per condition (first sweep value, outward from nominal, with p95 error",
             f"> {BREAKDOWN_P95_DEG:g} deg or a failure; '-' = never over the sweep)", ""]
    if not bd.empty:
        piv = bd.pivot(index="condition", columns="method", values="breakdown_value")
        piv = piv.reindex(index=list(dict.fromkeys(bd["condition"])), columns=list(dict.fromkeys(bd["method"])))
        lines.append(piv.to_string(na_rep="-", float_format=lambda v: f"{v:g}"))
    lines += ["", "Repeatability: same scene, 20 noise seeds (sd and bias of psi, deg)", ""]
    if not rep.empty:
        lines.append(rep[["psi_true_deg", "method", "n_seeds", "n_failed", "bias_deg", "sd_deg", "robust_sd_deg"]]
                     .to_string(index=False, float_format=lambda v: f"{v:.3f}"))
    lines += ["", "Adaptive estimators: share of images given a richer curve model than a constant-curvature",
              "arc (degree 1); per condition over all its sweep values, the bulge sweep per value", ""]
    if not choice.empty:
        lines.append(_choice_table(choice).to_string(float_format=lambda v: f"{v:.2f}"))
    fig.text(0.04, 0.97, "\n".join(lines), family="monospace", fontsize=7.5, va="top")
    return fig


def _choice_table(choice: pd.DataFrame) -> pd.DataFrame:
    """Share of images given a richer model, rows = condition (bulge: per value), cols = method."""
    label = np.where(choice["condition"] == "bulge", "bulge " + choice["value"].map("{:g}".format),
                     choice["condition"])
    c = choice.assign(row=label, richer=choice["share_richer"] * choice["n"])
    agg = c.groupby(["row", "method"], sort=False)[["richer", "n"]].sum()
    share = (agg["richer"] / agg["n"]).unstack("method")
    return share.reindex(index=list(dict.fromkeys(label)), columns=list(dict.fromkeys(choice["method"])))


def save(fig: Figure, stem: Path) -> list[Path]:
    """Write ``stem.pdf`` (vector) and ``stem.png`` (150 dpi) without time stamps.

    Returns
    -------
    list of Path
        The files written.
    """
    stem = Path(stem)
    pdf, png = stem.with_suffix(".pdf"), stem.with_suffix(".png")
    fig.savefig(pdf, metadata={"CreationDate": None, "ModDate": None})
    fig.savefig(png, dpi=150, metadata={"Software": None})
    return [pdf, png]
