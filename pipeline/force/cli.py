"""``python -m pipeline force ...``: blocked force, eccentricity and grasp logs.

Sub-commands::

    force synth OUT_DIR --material DS20 [...]          synthetic blocked-force photo set
    force measure PHOTOSET_DIR --out eccentricity.csv  eccentricity of every photo
    force aggregate ECC.csv [...] --out FORCE_DIR/force_summary.csv
    force grasp LOG.csv --out FORCE_DIR/grasp_summary.csv
    force pages FORCE_DIR --out force_pages.pdf        the report pages on their own

A *force directory* (``FORCE_DIR``) is what the report reads through
:func:`pipeline.force.pages.figures`; it holds (each optional):

- ``force_summary.csv``        force (N) mean/sd against pressure (kPa) per material, direction;
- ``eccentricity_summary.csv`` eccentricity at the maximum pressure per material (+ photo path);
- ``grasp_summary.csv``        heaviest mass held (g) against pressure (kPa).

``aggregate`` writes the first two side by side (``--eccentricity-out`` defaults to
``eccentricity_summary.csv`` next to ``--out``); ``grasp`` writes the third.
"""

from __future__ import annotations

import argparse
from pathlib import Path

from pipeline.errors import UserInputError
from pipeline.fileio import write_table


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """Define the ``force`` sub-commands and their options."""
    sub = parser.add_subparsers(dest="force_command", metavar="ACTION", required=True)

    s = sub.add_parser(
        "synth", help="render a synthetic blocked-force photo set with known eccentricity and force"
    )
    s.add_argument(
        "out_dir",
        type=Path,
        help="folder to write (images, manifest.csv, photoset.yaml, truth.csv)",
    )
    s.add_argument(
        "--material",
        required=True,
        help="DS20, DS30, SS40 or SS50 (sets the force/eccentricity curves)",
    )
    s.add_argument("--actuators", type=int, default=3, help="actuators to simulate (default 3)")
    s.add_argument("--trials", type=int, default=3, help="pressure ramps per actuator (default 3)")
    s.add_argument(
        "--seed", type=int, default=1, help="random seed; same seed, same files (default 1)"
    )
    s.add_argument(
        "--scene",
        default="lab",
        help="scene preset of the renderer: clean, lab or hard (default lab)",
    )
    s.add_argument("--set", dest="scene_set", action="append", default=[], metavar="KEY=VALUE",
                   help="override a scene knob, e.g. --set noise_sigma=4 (repeatable)")
    s.add_argument(
        "--step-kpa", type=float, default=10.0, help="pressure step of the ramp in kPa (default 10)"
    )
    s.add_argument(
        "--max-kpa",
        type=float,
        default=None,
        help="top of the ramp in kPa (default: the material's, 105-210 kPa as in the paper)",
    )
    s.add_argument(
        "--l0-mm", type=float, default=270.0, help="length of the marked line in mm (default 270)"
    )
    s.add_argument(
        "--force-samples",
        type=int,
        default=10,
        help="load-cell samples averaged per step (default 10)",
    )
    s.add_argument(
        "--arc-fraction",
        type=float,
        default=0.58,
        help="fraction of the ellipse perimeter the line covers, 0-1 (default 0.58 ~ 210 deg)",
    )
    s.add_argument(
        "--gap-deg",
        type=float,
        default=0.0,
        help="where the opening sits on the ellipse, parametric angle in deg (0: major-axis end)",
    )

    m = sub.add_parser(
        "measure", help="measure the eccentricity of every photo of a blocked-force photo set"
    )
    m.add_argument(
        "photoset",
        type=Path,
        help="photo-set folder (manifest.csv with force_n columns + photoset.yaml)",
    )
    m.add_argument(
        "--out", type=Path, required=True, help="eccentricity.csv to write (one row per photo)"
    )
    m.add_argument("--jobs", type=int, default=1, help="worker processes (default 1)")
    m.add_argument(
        "--refine",
        choices=("auto", "always", "never"),
        default="auto",
        help="geometric (orthogonal-distance) refinement of the direct ellipse fit: on partial "
             "arcs "
        "(auto, default), always or never",
    )
    m.add_argument(
        "--min-arc-fraction",
        type=float,
        default=0.4,
        help="flag photos whose line covers less than this fraction of the ellipse (default 0.4)",
    )
    m.add_argument("--max-eccentricity-sd", type=float, default=0.02,
                   help="flag photos whose eccentricity standard error exceeds this (default 0.02)")
    m.add_argument(
        "--max-residual-px",
        type=float,
        default=3.0,
        help="flag photos whose RMS distance to the ellipse exceeds this many pixels (default 3)",
    )

    a = sub.add_parser(
        "aggregate",
        help="force (N) against pressure (kPa) mean +- sd, eccentricity at max pressure",
    )
    a.add_argument(
        "tables",
        type=Path,
        nargs="+",
        help="eccentricity.csv files (or blocked manifest.csv files)",
    )
    a.add_argument(
        "--out",
        type=Path,
        required=True,
        help="force_summary.csv to write (put it in the force directory)",
    )
    a.add_argument("--eccentricity-out", type=Path, default=None,
                   help="eccentricity_summary.csv to write (default: next to --out)")

    g = sub.add_parser(
        "grasp",
        help="validate a grasp log and summarise the heaviest mass held (g) against pressure (kPa)",
    )
    g.add_argument(
        "log",
        type=Path,
        nargs="?",
        default=None,
        help="grasp-log CSV (columns material, object, side, diameter_mm, mass_g, pressure_kpa, "
             "held)",
    )
    g.add_argument(
        "--example",
        action="store_true",
        help="use the example log shipped with the package (values from the paper's text)",
    )
    g.add_argument(
        "--out",
        type=Path,
        required=True,
        help="grasp_summary.csv to write (put it in the force directory)",
    )
    g.add_argument(
        "--figure", type=Path, default=None, help="also save the Fig. 8B-style plot (png/pdf/svg)"
    )

    p = sub.add_parser("pages", help="write the force report pages of a force directory to one PDF")
    p.add_argument(
        "force_dir",
        type=Path,
        help="folder with force_summary.csv / eccentricity_summary.csv / grasp_summary.csv",
    )
    p.add_argument("--out", type=Path, required=True, help="PDF to write")


def run(args: argparse.Namespace) -> int:
    """Run the chosen ``force`` sub-command; return the exit code."""
    return {
        "synth": _synth,
        "measure": _measure,
        "aggregate": _aggregate,
        "grasp": _grasp,
        "pages": _pages,
    }[args.force_command](args)


def _scene_overrides(pairs: list[str]) -> dict[str, str]:
    out = {}
    for pair in pairs:
        if "=" not in pair:
            raise UserInputError(f"--set {pair!r}: write KEY=VALUE, e.g. --set noise_sigma=4")
        k, v = pair.split("=", 1)
        out[k.strip()] = v.strip()
    return out


def _synth(args: argparse.Namespace) -> int:
    from pipeline.force.synth_blocked import render_blocked_photoset

    manifest = render_blocked_photoset(
        args.out_dir,
        args.material,
        actuators=args.actuators,
        trials=args.trials,
        seed=args.seed,
        scene=args.scene,
        scene_overrides=_scene_overrides(args.scene_set),
        step_kpa=args.step_kpa,
        max_kpa=args.max_kpa,
        l0_mm=args.l0_mm,
        force_samples=args.force_samples,
        arc_fraction=args.arc_fraction,
        gap_deg=args.gap_deg,
    )
    print(
        f"force synth: {len(manifest)} blocked-force photos of {args.material} written to "
        f"{args.out_dir}"
    )
    return 0


def _measure(args: argparse.Namespace) -> int:
    from pipeline.force.blocked import measure_blocked_photoset

    table = measure_blocked_photoset(
        args.photoset,
        jobs=args.jobs,
        refine=args.refine,
        min_arc_fraction=args.min_arc_fraction,
        max_eccentricity_sd=args.max_eccentricity_sd,
        max_residual_px=args.max_residual_px,
    )
    write_table(table, args.out, float_format=None)
    counts = table["status"].value_counts()
    print(
        f"force measure: {len(table)} photos, {counts.get('ok', 0)} ok, {counts.get('flagged', 0)} "
        "flagged, "
        f"{counts.get('failed', 0)} failed -> {args.out}"
    )
    return 0


def _aggregate(args: argparse.Namespace) -> int:
    from pipeline.force.aggregate_force import (
        eccentricity_at_max_pressure,
        force_vs_pressure,
        read_tables,
    )

    table = read_tables(args.tables)
    force = force_vs_pressure(table)
    ecc = eccentricity_at_max_pressure(table)
    ecc_out = args.eccentricity_out or args.out.with_name("eccentricity_summary.csv")
    write_table(force, args.out, float_format=None)
    write_table(ecc, ecc_out, float_format=None)
    parts = [
        f"{r.material} e={r.eccentricity_mean:.3f} at {r.pressure_kpa:g} kPa"
        for r in ecc.itertuples()
    ]
    print(
        f"force aggregate: {len(force)} pressure levels of {force['material'].nunique()} "
        f"material(s) -> {args.out}; "
        + ("; ".join(parts) if parts else "no eccentricity")
        + f" -> {ecc_out}"
    )
    return 0


def _grasp(args: argparse.Namespace) -> int:
    from pipeline.force.grasp import EXAMPLE_LOG, heaviest_held, read_grasp_log
    from pipeline.force.pages import grasp_figure

    if args.example == (args.log is not None):
        raise UserInputError(
            "force grasp: give either a grasp-log CSV or --example (not both, not neither)"
        )
    path = EXAMPLE_LOG if args.example else args.log
    log = read_grasp_log(path)
    summary = heaviest_held(log)
    write_table(summary, args.out, float_format=None)
    if args.figure is not None:
        args.figure.parent.mkdir(parents=True, exist_ok=True)
        grasp_figure(summary).savefig(args.figure)
    print(
        f"force grasp: {len(log)} attempts, {int(log['held'].sum())} held, {len(summary)} summary "
        f"rows -> {args.out}"
    )
    return 0


def _pages(args: argparse.Namespace) -> int:
    from matplotlib.backends.backend_pdf import PdfPages

    from pipeline.force.pages import figures

    if not args.force_dir.is_dir():
        raise UserInputError(
            f"{args.force_dir}: not a folder; give the force directory written by 'force aggregate'"
        )
    figs = figures(args.force_dir)
    if not figs:
        raise UserInputError(
            f"{args.force_dir}: holds no force_summary.csv, eccentricity_summary.csv or "
            "grasp_summary.csv; "
            "run 'force aggregate' or 'force grasp' first"
        )
    args.out.parent.mkdir(parents=True, exist_ok=True)
    with PdfPages(args.out) as pdf:
        for fig in figs:
            pdf.savefig(fig)
    print(f"force pages: {len(figs)} page(s) -> {args.out}")
    return 0
