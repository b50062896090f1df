"""``python -m pipeline bench study``: the speed/accuracy and stability study, tables and charts.

Renders the grid's synthetic scenes (exact ground truth), writes each as a JPEG file and
measures that file with every angle method through the per-photo function of
``python -m pipeline measure`` (:func:`pipeline.measure.worker.run_task`; times include the file
read and decode; :mod:`pipeline.study`), and writes into ``--out``:

``results.csv``         one row per image and method (truth, psi, error, status, degree, times)
``speed_accuracy.csv``  per method and condition: median/p95 error, failure rate, ms per image,
Pareto ``stability.csv``       per method, condition and sweep value: the same against the sweep
``breakdown.csv``       per method and condition: first value (outward from nominal) that breaks it
``repeatability.csv``   per method: sd and bias over one scene rendered with 20 noise seeds
``model_choice.csv``    curve model chosen by the adaptive ``turning`` estimator per sweep value
``model_cost.csv``      model quadrature grid size against error and time ``*.pdf``, ``*.png``
speed_accuracy, stability, tables, model_cost charts

and prints a summary of the figures.
"""

from __future__ import annotations

import argparse
import sys
import time
from collections.abc import Sequence
from pathlib import Path
from typing import TYPE_CHECKING

import pandas as pd

from pipeline.errors import UserInputError
from pipeline.fileio import write_table
from pipeline.folders import staged_folder

if TYPE_CHECKING:
    from pipeline.study.grids import Grid


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """Options of ``python -m pipeline bench study``."""
    parser.add_argument("--grid", default="default", choices=("default", "full"),
                        help="scene grid: 'default' (~170 images, < 60 s on 2 cores) or 'full' "
                             "(~900 images with fine sweeps, minutes) (default: %(default)s)")
    parser.add_argument("--jobs", type=int, default=1,
                        help="worker processes, one core each (count, default: %(default)s)")
    parser.add_argument(
        "--out",
        type=Path,
        default=Path("results/bench"),
        help="output directory for the CSV tables and charts (default: %(default)s)",
    )
    parser.add_argument("--methods", default=None,
                        help="comma-separated angle methods to compare (default: every method of "
                             "pipeline.measure.METHODS)")
    parser.add_argument("--seed", type=int, default=1,
                        help="base seed of the rendered scenes (integer, default: %(default)s)")
    parser.add_argument("--no-model", action="store_true",
                        help="skip the model quadrature benchmark (model_cost.csv is then empty)")


def summary(sa: pd.DataFrame, bd: pd.DataFrame, rep: pd.DataFrame, choice: pd.DataFrame,
            cost: pd.DataFrame) -> str:
    """Human-readable summary of the study's figures (what ``bench study`` prints)."""
    from pipeline.study.analysis import NOMINAL, model_choice_summary

    lines = [
        "Nominal scenes (lab preset, |psi| <= 300 deg): error (deg), failures, time per image (ms)"
    ]
    nom = sa[sa["condition"] == NOMINAL][
        [
            "method",
            "n",
            "median_abs_error_deg",
            "p95_abs_error_deg",
            "failure_rate",
            "silent_wrong_rate",
            "median_ms_per_image",
            "median_decode_ms",
            "pareto",
        ]
    ]
    lines.append(nom.to_string(index=False, float_format=lambda v: f"{v:.3g}"))
    if not bd.empty:
        lines += [
            "",
            (
                "Breakdown point (first sweep value outward from nominal with p95 > 2 deg or a "
                "failure; - = none)"
            ),
        ]
        piv = bd.pivot(index="condition", columns="method", values="breakdown_value")
        piv = piv.reindex(
            index=list(dict.fromkeys(bd["condition"])), columns=list(dict.fromkeys(bd["method"]))
        )
        lines.append(piv.to_string(na_rep="-", float_format=lambda v: f"{v:g}"))
    if not rep.empty:
        lines += ["", "Repeatability (same scene, noise seeds): sd / bias of psi (deg)"]
        lines.append(
            rep[
                [
                    "psi_true_deg",
                    "method",
                    "n_seeds",
                    "n_failed",
                    "sd_deg",
                    "robust_sd_deg",
                    "sd_ok_deg",
                    "bias_deg",
                ]
            ].to_string(index=False, float_format=lambda v: f"{v:.3g}")
        )
    if not choice.empty:
        lines += ["", "Adaptive estimators: share of images given a richer curve model than an arc"]
        for _, s in model_choice_summary(choice).iterrows():
            lines.append(
                f"  {s['method']}: {100 * s['richer_on_constant']:.1f} % of {int(s['n_constant'])} "
                f"constant-curvature images, {100 * s['richer_on_bulged']:.1f} % of "
                f"{int(s['n_bulged'])} "
                "bulged images"
            )
    if not cost.empty:
        lines += [
            "",
            (
                "Model: quadrature grid size vs max relative error and time (all 4 materials, "
                "forward + inverse)"
            ),
        ]
        c = (
            cost[["grid_n", "seconds", "max_rel_error"]]
            .assign(ms=lambda d: 1e3 * d["seconds"])
            .drop(columns="seconds")
        )
        lines.append(c.to_string(index=False, float_format=lambda v: f"{v:.3g}"))
    return "\n".join(lines)


def run(args: argparse.Namespace) -> int:
    """Run the study and write the tables and charts; 0 on success."""
    t_start = time.perf_counter()
    from pipeline.study import grids

    if args.jobs < 1:
        raise UserInputError(f"--jobs {args.jobs}: give a number of worker processes >= 1")
    grid = grids.get_grid(args.grid)
    methods = None
    if args.methods:
        from pipeline.measure import METHODS

        methods = [m.strip() for m in args.methods.split(",") if m.strip()]
        unknown = [m for m in methods if m not in METHODS]
        if unknown:
            raise UserInputError(
                f"--methods: unknown method(s) {unknown}; use some of {sorted(METHODS)}"
            )
    with staged_folder(args.out, marker="results.csv") as out:  # appears only when complete
        return _run_into(out, args, grid, methods, t_start)


def _run_into(out: Path, args: argparse.Namespace, grid: Grid, methods: list[str] | None,
              t_start: float) -> int:
    """Render, measure and analyse ``grid`` into the folder ``out``."""
    from pipeline.study import analysis, charts, grids
    from pipeline.study.run import run_grid

    cases = grids.cases(grid, base_seed=args.seed)

    def progress(done: int, total: int) -> None:
        if done == total or done % 40 == 0:
            print(f"  {done}/{total} images", file=sys.stderr, flush=True)

    results = run_grid(cases, methods=methods, jobs=args.jobs, progress=progress)
    t_measured = time.perf_counter()
    sa = analysis.speed_accuracy(results)
    stab = analysis.stability(results)
    bd = analysis.breakdown(stab)
    rep = analysis.repeatability(results)
    choice = analysis.model_choice(results)
    cost = (
        pd.DataFrame(columns=["grid_n", "seconds", "max_rel_error"])
        if args.no_model
        else analysis.model_cost()
    )
    tables = {
        "results.csv": results,
        "speed_accuracy.csv": sa,
        "stability.csv": stab,
        "breakdown.csv": bd,
        "repeatability.csv": rep,
        "model_choice.csv": choice,
        "model_cost.csv": cost,
    }
    for name, table in tables.items():
        write_table(table, out / name, float_format="%.8g")
    figs = {
        "speed_accuracy": charts.speed_accuracy_figure(sa),
        "stability": charts.stability_figure(stab),
        "tables": charts.tables_figure(bd, choice, rep),
        "model_cost": charts.model_cost_figure(cost),
    }
    for stem, fig in figs.items():
        charts.save(fig, out / stem)
    print(summary(sa, bd, rep, choice, cost))
    total = time.perf_counter() - t_start
    print(
        f"\nbench study --grid {grid.name}: {len(cases)} images x {results['method'].nunique()} "
        "methods, "
        f"jobs={args.jobs}: render+measure {t_measured - t_start:.1f} s, total {total:.1f} s -> "
        f"{args.out}"
    )
    return 0


def main(argv: Sequence[str] | None = None) -> int:
    """``python -m pipeline bench study [options]``."""
    parser = argparse.ArgumentParser(
        prog="python -m pipeline bench study", description=__doc__.splitlines()[0]
    )
    add_arguments(parser)
    return run(parser.parse_args(argv))


if __name__ == "__main__":
    raise SystemExit(main())
