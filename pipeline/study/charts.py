"""Pages of the study, drawn from its tables: one A4 :class:`~matplotlib.figure.Figure` each.

* :func:`speed_accuracy_figure`: per method, time per image and 95th-percentile error on two
  axes side by side (a dot plot: methods with the same error cannot print over each other),
  the 2 deg breakdown threshold labelled, the Pareto front ringed, the figures in a table and
  the conclusions in words.
* :func:`stability_figure`: one panel per condition, p95 error against the sweep value per
  method, failures marked, and in words where each method breaks down.
* :func:`tables_figure`: breakdown points, repeatability and the adaptive estimators' model
  choices, typeset.
* :func:`model_cost_figure`: model quadrature grid size against error and time, with its table.

Every page uses the report's style (:mod:`pipeline.layout.style`), so it is A4 with fonts of at
least 7 pt whether it is printed in the report or saved alone by :func:`save`.
"""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pandas as pd
from matplotlib import ticker, transforms
from matplotlib.figure import Figure
from matplotlib.lines import Line2D

from pipeline.layout.style import (
    A4_LANDSCAPE_IN,
    FOOTER_PT,
    MARGIN_PT,
    page,
    report_style,
    text_page,
)
from pipeline.layout.typeset import NA, Column, Flow, Table, fmt, table_height_pt
from pipeline.study.analysis import BREAKDOWN_P95_DEG, NOMINAL, SILENT_WRONG_DEG, breakdown
from pipeline.study.grids import GRIDS

#: axis label of every condition (from the grids)
LABELS: dict[str, str] = {s.name: s.label for g in GRIDS.values() for s in g.sweeps}
#: smallest error drawn on log axes (deg); smaller errors are drawn at this floor
ERROR_FLOOR_DEG = 1e-3
_COLOURS = (
    "#1f77b4",
    "#d62728",
    "#2ca02c",
    "#9467bd",
    "#ff7f0e",
    "#17becf",
    "#8c564b",
    "#e377c2",
    "#7f7f7f",
)
#: methods whose nominal p95 is within this factor of the best count as "as accurate as the best"
SAME_ACCURACY = 1.05
LANDSCAPE_W_PT = 72.0 * A4_LANDSCAPE_IN[0]


def method_colours(methods: list[str] | pd.Series) -> dict[str, str]:
    """A fixed colour per method, in order of first appearance."""
    names = list(dict.fromkeys(methods))
    return {m: _COLOURS[i % len(_COLOURS)] for i, m in enumerate(names)}


def _floor(x: pd.Series | np.ndarray) -> np.ndarray:
    return np.maximum(np.asarray(x, dtype=float), ERROR_FLOOR_DEG)


def plain_log_axis(axis: object) -> None:
    """Log-axis tick labels as plain numbers (0.1, 1, 10), never 10^x; no minor ticks."""
    axis.set_major_formatter(ticker.FuncFormatter(lambda v, _pos: f"{v:g}"))  # type: ignore[attr-defined]
    axis.set_minor_locator(ticker.NullLocator())  # type: ignore[attr-defined]


# ---------------------------------------------------------------------------------------------
# speed against accuracy


def speed_accuracy_words(nominal: pd.DataFrame) -> list[str]:
    """What the nominal rows of ``speed_accuracy.csv`` say, in sentences."""
    ok = nominal[np.isfinite(nominal["p95_abs_error_deg"].astype(float))]
    if ok.empty:
        return ["No method gave an angle on the nominal scenes."]
    best = float(ok["p95_abs_error_deg"].min())
    tied = ok[ok["p95_abs_error_deg"] <= best * SAME_ACCURACY].sort_values(
        "median_ms_per_image", kind="stable"
    )
    fastest = tied.iloc[0]
    out = [
        (f"On the nominal scenes {len(tied)} method{'s' if len(tied) > 1 else ''} reach a p95 "
         f"error within {100 * (SAME_ACCURACY - 1):.0f} % "
        f"of the best ({best:.2f}°): {', '.join(tied['method'])}; the fastest of them is "
        f"{fastest['method']} "
        f"at {fastest['median_ms_per_image']:.1f} ms per image.")
    ]
    front = nominal[nominal["pareto"].astype(bool)].sort_values(
        "median_ms_per_image", kind="stable"
    )
    if len(front):
        out.append(
            "Pareto front (no other method is both faster and more accurate): "
            f"{', '.join(front['method'])}."
        )
    broken = ok[ok["p95_abs_error_deg"] > BREAKDOWN_P95_DEG]
    for r in broken.itertuples():
        out.append(f"{r.method} misses the {BREAKDOWN_P95_DEG:g}° threshold even on nominal scenes "
                   f"(p95 {r.p95_abs_error_deg:.3g}°).")
    slow = ok.sort_values("median_ms_per_image", kind="stable").iloc[-1]
    if slow["method"] != fastest["method"] and fastest["median_ms_per_image"] > 0:
        out.append(
            f"The slowest, {slow['method']}, takes {slow['median_ms_per_image']:.1f} ms "
            f"({slow['median_ms_per_image'] / fastest['median_ms_per_image']:.1f} x "
            f"{fastest['method']})."
        )
    return out


def nominal_table(nominal: pd.DataFrame) -> Table:
    """The nominal figures of every method, typeset."""
    rows = tuple(
        (
            str(r.method),
            fmt(r.median_ms_per_image, 1),
            fmt(r.median_decode_ms, 1),
            fmt(r.median_abs_error_deg, 3),
            fmt(r.p95_abs_error_deg, 3),
            fmt(r.max_abs_error_deg, 3),
            fmt(100 * r.failure_rate, 0),
            fmt(100 * r.flagged_rate, 0),
            fmt(100 * r.silent_wrong_rate, 0),
            "yes" if bool(r.pareto) else "",
        )
        for r in nominal.itertuples()
    )
    return Table(
        columns=(
            Column("method", "left"),
            Column("time per image\n(ms)"),
            Column("of which decode\n(ms)"),
            Column("median error\n(deg)"),
            Column("p95 error\n(deg)"),
            Column("max error\n(deg)"),
            Column("failed\n(%)"),
            Column("flagged\n(%)"),
            Column(f"silent wrong,\nok but > {SILENT_WRONG_DEG:g}° (%)"),
            Column("Pareto\nfront", "center"),
        ),
        rows=rows,
        title="Nominal scenes (|ψ| ≤ 300°, every other condition nominal)",
        size=7.5,
        notes=(
            ("Errors are |ψ measured - ψ true| over the images that gave an angle; failed images "
             "count in "
            "'failed' only, so a method cannot look accurate by failing on hard images.  Time: "
            "median per "
            "image on one core, file read + JPEG decode + measurement."),
        ),
    )


@report_style()
def speed_accuracy_figure(table: pd.DataFrame) -> Figure:
    """Time per image (ms) and 95th-percentile absolute error (deg) of every method, side by side.

    Parameters
    ----------
    table : DataFrame
        ``speed_accuracy.csv`` (see :func:`pipeline.study.analysis.speed_accuracy`).
    """
    colours = method_colours(table["method"])
    nominal = table[table["condition"] == NOMINAL].copy()
    rounded = nominal["p95_abs_error_deg"].map(
        lambda v: float(f"{v:.3g}") if np.isfinite(v) else np.inf
    )
    nominal = (
        nominal.assign(_e=rounded)
        .sort_values(["_e", "median_ms_per_image"], kind="stable")
        .drop(columns="_e")
    )
    other = table[table["condition"] != NOMINAL]
    width = LANDSCAPE_W_PT - 2 * MARGIN_PT
    words = speed_accuracy_words(nominal) + [
        ("Large dots: the nominal scenes, value printed above; small dots: one per swept condition "
         "(its p95 and "
        "time); ringed: on the Pareto front.  Rows are sorted by nominal p95 error, then time.")
    ]
    tab = nominal_table(nominal)
    flow_probe = Flow(text_page(landscape=True), width_pt=width)
    for w in words:
        flow_probe.text(w, size=8.0)
    words_h = flow_probe.y - MARGIN_PT
    top_h = 30.0 + words_h + 10.0
    bottom_h = table_height_pt(tab, width) + 8.0
    fig = page(landscape=True, label="speed-accuracy", top_pt=top_h, bottom_pt=bottom_h)
    flow = Flow(fig, top_pt=24.0, width_pt=width)
    flow.text("Speed against accuracy of the angle methods", size=12.0, weight="bold")
    flow.space(2.0)
    for w in words:
        flow.text(w, size=8.0)
    ax_t, ax_e = fig.subplots(1, 2, sharey=True)
    methods = list(nominal["method"])
    y = {m: len(methods) - 1 - i for i, m in enumerate(methods)}
    for ax, key, fn in (
        (ax_t, "median_ms_per_image", np.asarray),
        (ax_e, "p95_abs_error_deg", _floor),
    ):
        for m in methods:
            c = colours[m]
            sub = other[other["method"] == m]
            ax.scatter(
                fn(sub[key].astype(float)),
                np.full(len(sub), y[m]),
                s=14,
                color=c,
                alpha=0.35,
                linewidths=0,
                zorder=2,
            )
            nom = nominal[nominal["method"] == m].iloc[0]
            value = float(nom[key])
            if not np.isfinite(value):
                ax.text(
                    0.02,
                    y[m],
                    NA,
                    transform=transforms.blended_transform_factory(ax.transAxes, ax.transData),
                    va="center",
                    fontsize=7.5,
                )
                continue
            ax.scatter(
                [fn(np.array([value]))[0]],
                [y[m]],
                s=60,
                color=c,
                edgecolors="black",
                linewidths=0.8,
                zorder=4,
            )
            if bool(nom["pareto"]):
                ax.scatter(
                    [fn(np.array([value]))[0]],
                    [y[m]],
                    s=190,
                    facecolors="none",
                    edgecolors="black",
                    linewidths=1.1,
                    zorder=5,
                )
            label = f"{value:.1f} ms" if key == "median_ms_per_image" else f"{value:.3g}°"
            ax.text(
                fn(np.array([value]))[0],
                y[m],
                label,
                ha="center",
                va="bottom",
                fontsize=7.5,
                zorder=6,
                transform=transforms.offset_copy(ax.transData, fig=fig, y=7.5, units="points"),
            )
        ax.grid(True, axis="x", which="major", alpha=0.4)
        ax.grid(False, axis="y")
    ax_t.set_xlim(
        left=0.0, right=1.12 * float(np.nanmax(table["median_ms_per_image"].astype(float)))
    )
    ax_t.set_xlabel("median time per image (ms, one core: file read + JPEG decode + measurement)")
    ax_t.set_title("Time per image")
    ax_t.set_yticks(
        range(len(methods)),
        [
            m + ("  (Pareto front)" if bool(p) else "")
            for m, p in zip(methods[::-1], nominal["pareto"].iloc[::-1], strict=True)
        ],
    )
    ax_t.set_ylim(-0.6, len(methods) - 0.1)
    ax_e.set_xscale("log")
    plain_log_axis(ax_e.xaxis)
    ax_e.axvline(BREAKDOWN_P95_DEG, color="0.3", linestyle="--", linewidth=0.9, zorder=1)
    ax_e.text(
        BREAKDOWN_P95_DEG * 1.08,
        len(methods) - 0.45,
        f"breakdown threshold: p95 = {BREAKDOWN_P95_DEG:g}°",
        fontsize=7.5,
        va="center",
        ha="left",
        color="0.2",
    )
    ax_e.set_xlabel("95th-percentile |ψ error| (deg, log scale)")
    ax_e.set_title("Accuracy")
    flow2 = Flow(
        fig, top_pt=72.0 * fig.get_figheight() - FOOTER_PT - bottom_h + 4.0, width_pt=width
    )
    flow2.table(tab)
    return fig


# ---------------------------------------------------------------------------------------------
# stability


def value_text(condition: str, value: float) -> str:
    """A sweep value in words with its unit, e.g. ``camera tilt 12 deg``.

    Examples
    --------
    >>> value_text("tilt", 12.0), value_text("contrast", 0.25), value_text("clutter", 5.0)
    ('camera tilt 12 deg', 'line contrast 0.25', '5 grey distractor marks')
    """
    label = LABELS.get(condition, condition)
    m = re.fullmatch(r"(.*?)\s*\((.*)\)", label)
    name, unit = (m.group(1), m.group(2)) if m else (label, "")
    if unit == "count":
        return f"{value:g} {name}"
    if re.fullmatch(r"[a-z ]+", unit):
        return f"{name} {value:g} {unit}"
    return f"{name} {value:g}"


def breakdown_words(bd: pd.DataFrame) -> list[str]:
    """Where each method breaks down, one sentence per group of methods that break alike.

    Examples
    --------
    >>> bd = pd.DataFrame({"condition": ["tilt", "noise"], "method": ["hyper", "hyper"],
    ...                    "nominal": [1.0, 2.5],
    ...                    "breakdown_value": [12.0, np.nan], "reason": ["p95 > 2 deg", ""],
    ...                    "last_good_value": [5.0, np.nan]})
    >>> breakdown_words(bd)
    ['hyper: breaks at camera tilt 12 deg (fine at 5); holds over the whole sweep of noise.']
    """
    if bd.empty:
        return []
    phrases: dict[str, str] = {}
    for method, g in bd.groupby("method", sort=False):
        at_nominal, breaks, holds = [], [], []
        for r in g.itertuples():
            notes = ["images fail"] if r.reason == "failure" else []
            if not np.isfinite(r.breakdown_value):
                holds.append(str(r.condition))
            elif r.breakdown_value == r.nominal:
                at_nominal.append(str(r.condition) + (" (images fail)" if notes else ""))
            else:
                if np.isfinite(r.last_good_value):
                    notes.insert(0, f"fine at {r.last_good_value:g}")
                text = value_text(str(r.condition), r.breakdown_value)
                breaks.append(text + (f" ({', '.join(notes)})" if notes else ""))
        parts = []
        if at_nominal:
            parts.append(
                f"already beyond {BREAKDOWN_P95_DEG:g}° at the nominal value of "
                f"{', '.join(at_nominal)}"
            )
        if breaks:
            parts.append(f"breaks at {', '.join(breaks)}")
        if holds:
            parts.append(f"holds over the whole sweep of {', '.join(holds)}")
        phrases[str(method)] = "; ".join(parts)
    groups: dict[str, list[str]] = {}
    for method, text in phrases.items():
        groups.setdefault(text, []).append(method)
    out = []
    for text, methods in groups.items():
        if len(methods) > 1:  # plural verbs for a group
            text = text.replace("breaks at", "break at").replace("holds over", "hold over")
        out.append(f"{', '.join(methods)}: {text}.")
    return out


@report_style()
def stability_figure(stab: pd.DataFrame, *, ncols: int = 4) -> Figure:
    """One panel per condition: p95 absolute error (deg) against the sweep value per method.

    Sweep values where a method failed on at least one image are marked with an ``x`` at the
    top of the panel (in the method's colour); the dashed line is the breakdown threshold.
    Under the panels, in words, where each method breaks down.

    Parameters
    ----------
    stab : DataFrame
        ``stability.csv`` (see :func:`pipeline.study.analysis.stability`).
    """
    conditions = list(dict.fromkeys(stab["condition"]))
    colours = method_colours(stab["method"])
    width = LANDSCAPE_W_PT - 2 * MARGIN_PT
    words = breakdown_words(breakdown(stab))
    failures = bool((stab["failure_rate"] > 0).any())
    heading = (
        f"Where each method breaks down: the first swept value, outward from nominal, with p95 > "
        f"{BREAKDOWN_P95_DEG:g}° or a failed image (coinciding lines above hide each other; "
        "methods that "
        "break alike share a sentence)"
    )
    probe = Flow(text_page(landscape=True), width_pt=width)
    probe.text(heading, size=9.0, weight="bold")
    probe.bullets(words, size=7.5)
    words_h = probe.y - MARGIN_PT + 6.0
    fig = page(landscape=True, label="stability", bottom_pt=words_h, top_pt=6.0)
    fig.suptitle(
        "Stability: one condition swept, the others nominal (p95 |ψ error| against the swept "
        "value)",
        fontsize=11.0,
    )
    nrows = max(int(np.ceil((len(conditions) + 1) / ncols)), 1)
    axes = list(fig.subplots(nrows, ncols, squeeze=False).flat)
    for ax, cond in zip(axes, conditions, strict=False):
        sub = stab[stab["condition"] == cond]
        top = transforms.blended_transform_factory(ax.transData, ax.transAxes)
        for m, c in colours.items():
            g = sub[sub["method"] == m].sort_values("value")
            if g.empty:
                continue
            ax.plot(
                g["value"],
                _floor(g["p95_abs_error_deg"]),
                marker="o",
                markersize=2.5,
                linewidth=1.0,
                color=c,
            )
            bad = g[g["failure_rate"] > 0]
            ax.scatter(
                bad["value"],
                np.full(len(bad), 0.97),
                marker="x",
                s=18,
                color=c,
                transform=top,
                clip_on=False,
            )
        ax.axhline(BREAKDOWN_P95_DEG, color="0.3", linestyle="--", linewidth=0.8)
        ax.axvline(float(sub["nominal"].iloc[0]), color="0.3", linestyle=":", linewidth=0.8)
        ax.set_yscale("log")
        plain_log_axis(ax.yaxis)
        drawn = np.append(_floor(sub["p95_abs_error_deg"].dropna()), BREAKDOWN_P95_DEG)
        few = np.log10(drawn.max() / drawn.min()) < 1.5  # under 1.5 decades: label 1-2-5 steps
        ax.yaxis.set_major_locator(
            ticker.LogLocator(subs=(1.0, 2.0, 5.0) if few else (1.0,), numticks=6)
        )
        ax.set_xlabel(LABELS.get(cond, cond))
        ax.set_title(cond, fontsize=8.5)
        ax.grid(True, which="major", alpha=0.3)
    for k, ax in enumerate(axes[:len(conditions)]):
        if k % ncols == 0:
            ax.set_ylabel("p95 |ψ error| (deg)")
    legend_ax = axes[len(conditions)] if len(axes) > len(conditions) else None
    for ax in axes[len(conditions):]:
        ax.set_axis_off()
    handles = [Line2D([], [], color=c, marker="o", markersize=2.5) for c in colours.values()]
    labels = list(colours)
    handles += [Line2D([], [], color="0.3", linestyle="--", linewidth=0.8),
                Line2D([], [], color="0.3", linestyle=":", linewidth=0.8),
                Line2D([], [], color="0.3", marker="x", linestyle="none")]
    labels += [f"breakdown threshold {BREAKDOWN_P95_DEG:g}°", "nominal value",
               "an image failed" + ("" if failures else " (none in this run)")]
    if legend_ax is not None:
        legend_ax.legend(handles, labels, loc="center", frameon=False, ncols=1)
    else:
        fig.legend(handles, labels, loc="outside right center", frameon=False)
    flow = Flow(fig, top_pt=72.0 * fig.get_figheight() - FOOTER_PT - words_h + 2.0, width_pt=width)
    flow.text(heading, size=9.0, weight="bold")
    flow.bullets(words, size=7.5)
    return fig


# ---------------------------------------------------------------------------------------------
# tables


def breakdown_table(bd: pd.DataFrame) -> Table:
    """Breakdown value per condition (rows) and method (columns)."""
    methods = list(dict.fromkeys(bd["method"]))
    rows = []
    for cond, g in bd.groupby("condition", sort=False):
        by = {str(r.method): r for r in g.itertuples()}
        nominal = float(g["nominal"].iloc[0])
        cells = []
        for m in methods:
            r = by.get(m)
            if r is None:
                cells.append(NA)
            elif not np.isfinite(r.breakdown_value):
                cells.append("holds")
            elif r.breakdown_value == nominal:
                cells.append("nominal")
            else:
                cells.append(
                    f"{r.breakdown_value:g}" + (" (fails)" if r.reason == "failure" else "")
                )
        rows.append((LABELS.get(str(cond), str(cond)), f"{nominal:g}", *cells))
    return Table(
        columns=(
            Column("condition (unit)", "left"),
            Column("nominal"),
            *(Column(m.replace("_", "_\n")) for m in methods),
        ),
        rows=tuple(rows),
        size=7.5,
        title="Breakdown point: first swept value, outward from nominal, with p95 > "
              f"{BREAKDOWN_P95_DEG:g}° or a failure",
        notes=(
            (
                "holds: never over the sweep; nominal: already at the nominal value; (fails): an "
                "image failed there."
            ),
        ),
    )


def repeatability_table(rep: pd.DataFrame) -> Table:
    """Bias and spread of every method over noise seeds of one scene."""
    rows = tuple(
        (
            fmt(r.psi_true_deg, 0),
            str(r.method),
            str(int(r.n_seeds)),
            str(int(r.n_failed)),
            fmt(r.bias_deg, 3),
            fmt(r.sd_deg, 3),
            fmt(r.robust_sd_deg, 3),
        )
        for r in rep.itertuples()
    )
    return Table(
        columns=(
            Column("true ψ (deg)"),
            Column("method", "left"),
            Column("seeds"),
            Column("failed"),
            Column("bias (deg)"),
            Column("sd (deg)"),
            Column("robust sd (deg)"),
        ),
        rows=rows,
        size=7.5,
        title="Repeatability: the same scene rendered with different noise seeds",
        notes=("robust sd: 1.4826 x median absolute deviation (insensitive to one outlier).",),
    )


def choice_table(choice: pd.DataFrame) -> Table:
    """Share of images an adaptive estimator gave a richer curve model than an arc."""
    share = _choice_table(choice)
    rows = tuple((str(idx), *(fmt(100 * v, 0) for v in share.loc[idx])) for idx in share.index)
    return Table(
        columns=(Column("condition", "left"), *(Column(f"{m} (%)") for m in share.columns)),
        rows=rows,
        size=7.5,
        title="Adaptive estimators: share of images given a richer curve model than a "
              "constant-curvature arc",
        notes=(
            ("Per condition over all its swept values; the bulge sweep per value (bulge 0 is a "
             "true arc, "
            "so a richer model there is an over-fit)."),
        ),
    )


@report_style()
def tables_figure(bd: pd.DataFrame, choice: pd.DataFrame, rep: pd.DataFrame) -> Figure:
    """Portrait page: breakdown points, repeatability, model choices (typeset tables)."""
    fig = text_page(label="bench-tables")
    flow = Flow(fig, top_pt=36.0)
    flow.text("Angle methods: breakdown, repeatability and model choice", size=12.0, weight="bold")
    flow.space(4.0)
    for table, make, missing in (
        (bd, breakdown_table, "No breakdown table in this bench run."),
        (rep, repeatability_table, "No repeatability block in this bench run."),
        (choice, choice_table, "No adaptive estimator in this bench run."),
    ):
        if table.empty:
            flow.text(missing, size=8.0)
        else:
            flow.table(make(table))
        flow.space(8.0)
    return fig


def _choice_table(choice: pd.DataFrame) -> pd.DataFrame:
    """Share of images given a richer model, rows = condition (bulge: per value), cols = method."""
    label = np.where(choice["condition"] == "bulge", "bulge " + choice["value"].map("{:g}".format),
                     choice["condition"])
    c = choice.assign(row=label, richer=choice["share_richer"] * choice["n"])
    agg = c.groupby(["row", "method"], sort=False)[["richer", "n"]].sum()
    share = (agg["richer"] / agg["n"]).unstack("method")
    return share.reindex(
        index=list(dict.fromkeys(label)), columns=list(dict.fromkeys(choice["method"]))
    )


# ---------------------------------------------------------------------------------------------
# model cost


@report_style()
def model_cost_figure(cost: pd.DataFrame) -> Figure:
    """Model quadrature grid size against max relative error (log) and time (ms), with the table.

    Parameters
    ----------
    cost : DataFrame
        ``model_cost.csv``: columns ``grid_n, seconds, max_rel_error`` (more are shown when
        present).
    """
    fig = text_page(label="model-cost")
    flow = Flow(fig, top_pt=36.0)
    flow.text("Model: accuracy against cost of the quadrature grid", size=12.0, weight="bold")
    flow.space(4.0)
    if cost.empty:
        flow.text("The model benchmark was not run (bench study --no-model).", size=8.5)
        return fig
    c = cost.sort_values("grid_n")
    err = np.maximum(c["max_rel_error"].astype(float), 1e-16)
    ms = 1e3 * c["seconds"].astype(float)
    good = c[err < 1e-6]
    if len(good):
        g0 = good.iloc[0]
        flow.text(
            f"Grid {int(g0['grid_n'])} is the smallest whose P(ψ) is within 1e-6 (relative) of the "
            "finest "
            f"reference, at {1e3 * float(g0['seconds']):.0f} ms for the benchmark curves; each "
            "larger grid "
            f"costs more time for digits that no measurement resolves.",
            size=8.5,
        )
    ax = flow.axes(330.0, right_pad_pt=52.0, top_pad_pt=20.0)
    ax.plot(c["grid_n"], err, marker="o", color="#1f77b4")
    ax.set_yscale("log")
    ax.yaxis.set_major_formatter(ticker.FuncFormatter(lambda v, _p: f"{v:.0e}"))
    ax.yaxis.set_minor_locator(ticker.NullLocator())
    ax.set_xticks(c["grid_n"].astype(int).tolist(), [str(int(v)) for v in c["grid_n"]])
    ax.set_xlabel("quadrature grid size (points per axis)")
    ax.set_ylabel("max relative error of P(ψ) (-)", color="#1f77b4")
    ax2 = ax.twinx()
    ax2.spines["right"].set_visible(True)
    ax2.plot(c["grid_n"], ms, marker="s", color="#d62728")
    ax2.set_ylim(0.0, 1.1 * float(ms.max()))
    ax2.set_ylabel("time for the benchmark curves (ms)", color="#d62728")
    ax2.grid(False)
    ax.set_title("Error (blue, left, log scale) and time (red, right) against the grid size")
    flow.space(8.0)
    extra = [
        k
        for k in ("nodes", "forward_seconds", "inverse_seconds", "inverse_max_abs_error_deg")
        if k in c
    ]
    columns = [
        Column("grid (points per axis)"),
        Column("time (ms)"),
        Column("max relative error (-)"),
    ]
    columns += [
        Column(
            {
                "nodes": "nodes",
                "forward_seconds": "forward (ms)",
                "inverse_seconds": "inverse (ms)",
                "inverse_max_abs_error_deg": "inverse max error (deg)",
            }[k]
        )
        for k in extra
    ]
    rows = []
    for r in c.to_dict("records"):
        cells = [str(int(r["grid_n"])), fmt(1e3 * r["seconds"], 1), f"{r['max_rel_error']:.1e}"]
        for k in extra:
            v = r[k]
            cells.append(
                str(int(v))
                if k == "nodes"
                else fmt(1e3 * v, 1)
                if k.endswith("seconds")
                else f"{v:.1e}"
            )
        rows.append(tuple(cells))
    flow.table(
        Table(columns=tuple(columns), rows=tuple(rows), size=7.5, title="Grid sizes measured")
    )
    return fig


def save(fig: Figure, stem: Path) -> list[Path]:
    """Write ``stem.pdf`` (vector) and ``stem.png`` (150 dpi) without time stamps.

    Returns
    -------
    list of Path
        The files written.
    """
    stem = Path(stem)
    pdf, png = stem.with_suffix(".pdf"), stem.with_suffix(".png")
    with report_style():
        fig.savefig(pdf, metadata={"CreationDate": None, "ModDate": None})
        fig.savefig(png, dpi=150, metadata={"Software": None})
    return [pdf, png]

