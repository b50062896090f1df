"""``python -m pipeline model ...``: P(psi) curves, single values, anchor table, benchmark."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np
import pandas as pd

from pipeline.errors import UserInputError
from pipeline.model.materials import Material, load_materials
from pipeline.model.options import CHOICES, ModelOptions, make_options

_DEFAULTS = ModelOptions()

_OPTION_HELP = {
    "eq5": "reading of Eq. 5 (arc_length: A0/(2 phi_m t) - t/2 = a0/sin phi_m; "
    "as_printed has no root)",
    "kt_scaling": "Dragon Skin thickness scaling (one_minus: t (1 - k_t|psi-psi0|/psi0); "
    "as_printed: t k_t (1 - |psi-psi0|/psi0))",
    "jacobian": "Eq. 12 wall area element (none: as printed; deformed: times (2 phi_m/pi)(t/t0))",
    "l0_factor": "Eq. 12 l0 prefactor (calibrated: replaced by --eq12-scale, fitted to the "
    "paper's two model results; metres: as printed, l0 in m; none: dropped)",
    "pressure_area": "Eq. 13 area (half_disc: as printed; segment: real chamber cut by the base)",
    "thickness_phi": "Eq. 4 stretch over phi (mean: averaged; crown: at phi = 0)",
    "thickness_pass": "Eq. 4 stretch on the undeformed section (first: as printed) or once more "
    "on the deformed one (recalculated)",
    "stress": "Eq. 12 stress (cauchy: as printed; nominal: Cauchy / lambda_1, per undeformed area)",
    "base_width": "Eq. 12 base width (two_sides: 2 (a0 + t0) as printed; one_side: a0 + t0)",
    "wall_coords": "Eq. 12 wall coordinates (scaled: tau', phi' as defined; unscaled: tau, phi, "
    "contradicts the text, diagnostic only)",
}


def add_reading_arguments(parser: argparse.ArgumentParser) -> None:
    """Add one ``--<option>`` flag per model reading, plus ``--l0-mm`` and ``--eq12-scale``.

    Shared by ``model`` and ``compare``; :func:`reading_options` collects what was given.
    """
    for key, choices in CHOICES.items():
        parser.add_argument(
            f"--{key.replace('_', '-')}",
            dest=key,
            choices=choices,
            default=None,
            help=f"{_OPTION_HELP[key]}; default {getattr(_DEFAULTS, key)}",
        )
    parser.add_argument(
        "--l0-mm",
        type=float,
        default=None,
        help="override the inextensible-layer length l0 (mm); default from the materials file",
    )
    parser.add_argument(
        "--eq12-scale",
        type=float,
        default=None,
        help="number standing for Eq. 12's l0 prefactor with --l0-factor calibrated "
        f"(dimensionless); default {_DEFAULTS.eq12_scale}",
    )


def reading_options(args: argparse.Namespace) -> dict[str, object]:
    """The model options given on the command line (readings, l0, eq12_scale, k_P, unloading)."""
    keys = [*CHOICES, "l0_mm", "k_p", "eq12_scale", "unload_from_kpa"]
    return {k: getattr(args, k) for k in keys if getattr(args, k, None) is not None}


def _reading_parent() -> argparse.ArgumentParser:
    parent = argparse.ArgumentParser(add_help=False)
    parent.add_argument(
        "--materials",
        metavar="PATH",
        type=Path,
        default=None,
        help="materials YAML (default: the packaged pipeline/model/materials.yaml)",
    )
    add_reading_arguments(parent)
    parent.add_argument(
        "--k-p", type=float, default=None, help="override the pressure scale k_P (dimensionless)"
    )
    return parent


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """Add the ``model`` sub-subcommands to ``parser``."""
    parent = _reading_parent()
    sub = parser.add_subparsers(dest="model_command", metavar="ACTION", required=True)
    p = sub.add_parser(
        "curve", parents=[parent], help="write P(psi) (kPa) over an angle range to CSV"
    )
    p.add_argument("--material", required=True, help="material name, e.g. DS20, DS30, SS40, SS50")
    p.add_argument(
        "--out",
        type=Path,
        required=True,
        help="output CSV: material, psi_deg, pressure_kpa, reason",
    )
    p.add_argument(
        "--psi-max", type=float, default=None, help="first angle (deg); default psi0 = 210"
    )
    p.add_argument("--psi-min", type=float, default=-360.0, help="last angle (deg); default -360")
    p.add_argument("--n", type=int, default=400, help="number of angles (default 400)")
    p = sub.add_parser(
        "pressure", parents=[parent], help="print the pressure (kPa) needed for an angle"
    )
    p.add_argument("--material", required=True, help="material name")
    p.add_argument(
        "--psi-deg", type=float, required=True, nargs="+", help="bending angle(s) psi in degrees"
    )
    p = sub.add_parser("psi", parents=[parent], help="print the angle (deg) reached at a pressure")
    p.add_argument("--material", required=True, help="material name")
    p.add_argument(
        "--pressure-kpa", type=float, required=True, nargs="+", help="input pressure(s) in kPa"
    )
    p.add_argument(
        "--branch",
        choices=("loading", "unloading"),
        default="loading",
        help="rising (loading) or falling (unloading) pressure; default loading",
    )
    p.add_argument(
        "--unload-from-kpa",
        type=float,
        default=None,
        help="unloading only: start from the loading state at this peak pressure (kPa); "
        "default: from psi_min_deg = -360",
    )
    sub.add_parser(
        "calibrate", parents=[parent], help="print the paper's anchors: paper value, ours, %% off"
    )
    p = sub.add_parser(
        "snaps", parents=[parent], help="print snap-through regions of P(psi) per material"
    )
    p.add_argument("--material", default=None, help="one material (default: all)")
    p = sub.add_parser(
        "bench", help="print time (ms) per quadrature grid size and convergence error"
    )
    p.add_argument(
        "--grid-sizes",
        type=int,
        nargs="+",
        default=[2, 3, 4, 6, 8, 12],
        help="grid sizes n (n_tau = n, n_phi = 2n nodes); default 2 3 4 6 8 12",
    )


def _material(args: argparse.Namespace, name: str) -> Material:
    table = load_materials(args.materials)
    if name not in table:
        raise UserInputError(
            f"--material {name!r} is not in {args.materials or 'the packaged materials'}; "
            f"choose one of {sorted(table)}"
        )
    return table[name]


def run(args: argparse.Namespace) -> int:
    """Run one ``model`` action; returns the exit code."""
    from pipeline.model import anchor_table, model_curve, pressure_kpa, psi_deg, snap_regions
    from pipeline.model.calibrate import fit_eq12_scale

    cmd = args.model_command
    if cmd == "bench":
        from pipeline.model.bench import benchmark_model, format_benchmark

        df = benchmark_model(grid_sizes=args.grid_sizes)
        print(format_benchmark(df))
        return 0
    opts = reading_options(args)
    if cmd == "curve":
        mat = _material(args, args.material)
        if args.n < 2:
            raise UserInputError("--n must be at least 2")
        top = mat.psi0_deg if args.psi_max is None else args.psi_max
        df = model_curve(mat, np.linspace(top, args.psi_min, args.n), **opts)
        args.out.parent.mkdir(parents=True, exist_ok=True)
        df.to_csv(args.out, index=False)
        print(
            f"wrote {len(df)} angles to {args.out} ({int(df.pressure_kpa.isna().sum())} undefined)"
        )
    elif cmd == "pressure":
        mat = _material(args, args.material)
        for psi, p in zip(args.psi_deg, pressure_kpa(mat, args.psi_deg, **opts), strict=True):
            print(f"{p:.6g}" if len(args.psi_deg) == 1 else f"psi_deg={psi:g} pressure_kpa={p:.6g}")
    elif cmd == "psi":
        mat = _material(args, args.material)
        out = psi_deg(mat, args.pressure_kpa, branch=args.branch, **opts)
        for p, psi in zip(args.pressure_kpa, out, strict=True):
            print(
                f"{psi:.6g}"
                if len(args.pressure_kpa) == 1
                else f"pressure_kpa={p:g} psi_deg={psi:.6g}"
            )
    elif cmd == "calibrate":
        df = anchor_table(load_materials(args.materials), **opts)
        with pd.option_context("display.width", 200, "display.max_colwidth", 60):
            print(
                df.drop(columns=["group"]).to_string(index=False, float_format=lambda v: f"{v:.1f}")
            )
        in_use = make_options(**opts)
        table = load_materials(args.materials)
        if {"SS40", "SS50"} <= set(table):
            fitted = f"{fit_eq12_scale(table, **opts):.4f}"
        else:  # a user's own file without the paper's materials: nothing to fit to
            fitted = "n/a (needs SS40 and SS50 in the materials file)"
        print(
            f"\neq12_scale fitted to the two model results with these readings and l0: {fitted}"
            f" (l0_factor={in_use.l0_factor}, eq12_scale in use {in_use.eq12_scale:.4f})"
        )
    elif cmd == "snaps":
        table = load_materials(args.materials)
        names = [args.material] if args.material else list(table)
        frames = [snap_regions(_material(args, n), **opts) for n in names]
        df = pd.concat(frames, ignore_index=True) if frames else pd.DataFrame()
        print("no snap-through: P(psi) is monotonic" if df.empty else df.to_string(index=False))
    else:  # pragma: no cover - argparse enforces the choices
        print(f"unknown action {cmd}", file=sys.stderr)
        return 2
    return 0
