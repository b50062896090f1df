"""``python -m pipeline model ...``: P(psi) curves, single values, anchor table (its benchmark:
``python -m pipeline bench model``)."""

from __future__ import annotations

import argparse
import math
import sys
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from pipeline.errors import UserInputError
from pipeline.fileio import write_table
from pipeline.model.materials import Material, load_materials
from pipeline.model.options import CHOICES, ModelOptions, make_options

_DEFAULTS = ModelOptions()

_OPTION_HELP = {
    "eq5": "reading of Eq. 5 (arc_length: A0/(2 phi_m t) - t/2 = a0/sin phi_m; "
    "as_printed has no root)",
    "kt_scaling": "Dragon Skin thickness scaling (one_minus: t (1 - k_t|psi-psi0|/psi0); "
    "as_printed: t k_t (1 - |psi-psi0|/psi0))",
    "jacobian": "Eq. 12 wall area element (none: as printed; deformed_angle: integrated over phi', "
    "times 2 phi_m/pi; deformed: times (2 phi_m/pi)(t/t0))",
    "l0_factor": "Eq. 12 l0 prefactor (metres: as printed, l0 in m; none: dropped; fitted_scale: "
    "replaced by a number FITTED to the paper's two model results, see --eq12-scale)",
    "pressure_area": "Eq. 13 area (half_disc: as printed; segment: real chamber cut by the base)",
    "thickness_phi": "Eq. 4 stretch over phi (mean: averaged; crown: at phi = 0)",
    "thickness_pass": "Eq. 4 stretch on the undeformed section (first: as printed) or once more "
    "on the deformed one (recalculated)",
    "stress": "Eq. 12 stress (cauchy: as printed; nominal: Cauchy / lambda_1, per undeformed area)",
    "base_width": "Eq. 12 base width (two_sides: 2 (a0 + t0) as printed; one_side: a0 + t0)",
    "wall_coords": "Eq. 12 wall coordinates (scaled: tau', phi' as defined; unscaled: tau, phi, "
    "contradicts the text, diagnostic only)",
}


def add_reading_arguments(parser: argparse.ArgumentParser | argparse._ArgumentGroup) -> None:
    """Add one ``--<option>`` flag per model reading, plus ``--l0-mm`` and ``--eq12-scale``
    (to a parser or to an argument group of one).

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
        help="number standing for Eq. 12's l0 prefactor with --l0-factor fitted_scale "
        "(dimensionless); default: fitted to the paper's two model results for the readings and l0 "
        "in use",
    )


def reading_options(args: argparse.Namespace) -> dict[str, Any]:
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
        "--psi-max", type=float, default=None, help="first angle (deg); default the material's psi0"
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
    p = sub.add_parser(
        "calibrate",
        parents=[parent],
        help="print the selection protocol, the in-sample table (the paper's two model results) "
        "and the out-of-sample table (Section III measurements) for a reading",
    )
    p.add_argument(
        "--search",
        action="store_true",
        help="also rerun the search of the protocol over every derived reading (about 15 s)",
    )
    p = sub.add_parser(
        "snaps", parents=[parent], help="print snap-through regions of P(psi) per material"
    )
    p.add_argument("--material", default=None, help="one material (default: all)")


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
    from pipeline.model import model_curve, pressure_kpa, psi_deg, snap_regions

    cmd = args.model_command
    opts = reading_options(args)
    if cmd == "curve":
        mat = _material(args, args.material)
        if args.n < 2:
            raise UserInputError("--n must be at least 2")
        top = mat.psi0_deg if args.psi_max is None else args.psi_max
        df = model_curve(mat, np.linspace(top, args.psi_min, args.n), **opts)
        write_table(df, args.out, float_format=None)
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
        print(format_calibration(load_materials(args.materials), opts, search=args.search))
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


def _reading_text(opts: ModelOptions) -> str:
    """The readings of ``opts`` that differ from the printed text, as ``key=value`` pairs."""
    from pipeline.model.options import PRINTED

    parts = [
        f"{k}={getattr(opts, k)}"
        for k in CHOICES
        if k not in PRINTED or getattr(opts, k) != PRINTED[k]
    ]
    return ", ".join(parts)


def _anchor_lines(df: pd.DataFrame) -> list[str]:
    lines = [f"  {'':34s} {'paper':>22s} {'ours':>22s} {'off':>22s}"]
    for r in df.itertuples():
        if r.unit == "kPa":
            paper, ours = f"{r.paper:.0f} kPa", f"{r.ours:.0f} kPa"
            off = f"{r.pct_off:+.1f} %"
        else:
            paper = f"{r.paper:.0f} deg (range {r.paper_range_deg:.0f})"
            ours = f"{r.ours:.0f} deg (range {r.ours_range_deg:.0f})"
            off = f"{r.off:+.1f} deg (range {r.pct_off:+.1f} %)"
        if not np.isfinite(r.ours):
            ours, off = "undefined", "n/a"
        lines.append(f"  {r.anchor:34s} {paper:>22s} {ours:>22s} {off:>22s}")
    return lines


def format_calibration(
    table: dict[str, Material],
    options: dict[str, Any],
    *,
    search: bool = False,
    search_keys: tuple[str, ...] | None = None,
) -> str:
    """What ``model calibrate`` prints: protocol, in-sample and out-of-sample tables, verdict.

    Parameters
    ----------
    table : dict of str to Material
        Materials (needs SS40 and SS50 for the in-sample part).
    options : dict
        Model options given on the command line (the default reading when empty).
    search : bool
        Also run :func:`pipeline.model.search_readings` and print its passing readings and choice.
    search_keys : tuple of str, optional
        Options the search varies (default: all of ``DERIVED_KEYS``); the other options given
        are held fixed.
    """
    from pipeline.model.anchors import MODEL_BAR_PCT, PAPER_RMS_DEG
    from pipeline.model.calibrate import (
        DERIVED_KEYS,
        NOT_DERIVED,
        PROTOCOL,
        anchor_table,
        fit_eq12_scale,
        fit_l0,
        l0_interval_meeting_bar,
        scores,
        search_readings,
        select_reading,
    )
    from pipeline.model.forward import l0_in_use, resolve_scale

    opts = make_options(**options)
    out = [*PROTOCOL, ""]
    derived = all(getattr(opts, k) not in v for k, v in NOT_DERIVED.items())
    out.append(f"Reading: {_reading_text(opts)} (the other options as printed)")
    if not derived:
        out.append("  NOT a derivation of the printed text (fitted_scale, wall_coords=unscaled or "
                   "eq5=as_printed): not a candidate of the protocol")
    has_paper = {"SS40", "SS50"} <= set(table)
    ref = table["SS50"] if has_paper else next(iter(table.values()))
    l0 = l0_in_use(ref, opts)
    source = "--l0-mm" if opts.l0_mm is not None else "materials file"
    if opts.l0_factor == "fitted_scale":
        scale = resolve_scale(opts, l0).eq12_scale if has_paper else math.nan
        given = "given" if opts.eq12_scale is not None else "FITTED to the two model results"
        out.append(f"Constants fitted to the paper's numbers: eq12_scale = {scale:.4f} ({given}); "
                   "with it fitted the in-sample agreement is by construction up to the ratio of "
                   "the two model results, and l0 is not fitted.")
        if has_paper:
            out.append(f"  eq12_scale fitted to the two model results with these readings and l0: "
                       f"{fit_eq12_scale(table, **{**options, 'l0_mm': l0}):.4f}")
        out.append(f"l0 in use: {l0:g} mm ({source})")
    else:
        out.append("Constants fitted to the paper's numbers: none (k_P, k_t and Table I are the "
                   "paper's; l0 is the one physical parameter the two model results may fix).")
        if has_paper:
            fitted = fit_l0(table, **options)
            lo, hi = l0_interval_meeting_bar(table, **options)
            if not math.isfinite(lo):
                span = f"no l0 in 170-270 mm meets +-{MODEL_BAR_PCT:g} %"
            elif lo == hi:
                span = f"both within +-{MODEL_BAR_PCT:g} % only at l0 = {lo:.0f} mm (1 mm steps)"
            else:
                span = f"both within +-{MODEL_BAR_PCT:g} % for l0 = {lo:.0f}-{hi:.0f} mm"
            out.append(f"l0 in use: {l0:g} mm ({source}); the two model results fix l0 = "
                       f"{fitted:.1f} mm for this reading (170-270 mm); {span}")
            if abs(fitted - l0) > 0.5:
                out.append(f"  the tables below are at the l0 in use; to see this reading at "
                           f"its own l0 pass --l0-mm {fitted:.1f}")
        else:
            out.append(f"l0 in use: {l0:g} mm ({source})")
    df = anchor_table(table, **options)
    model, measured = df[df.group == "model"], df[df.group == "measured"]
    if has_paper:
        sc = scores(df)
        out += ["", "In sample: the paper's model results (they fixed the parameter above)"]
        out += _anchor_lines(model)
        met = sc["model_worst_pct"] <= MODEL_BAR_PCT
        out.append(f"  both within +-{MODEL_BAR_PCT:g} %: {'yes' if met else 'NO'} "
                   f"(SS50 {sc['ss50_pct']:+.1f} %, SS40 {sc['ss40_pct']:+.1f} %)")
    else:
        out += ["", "In sample: n/a (needs SS40 and SS50 in the materials file)"]
    if len(measured):
        sc = scores(df)
        out += ["", "Out of sample: Section III measurements (chose nothing)"]
        out += _anchor_lines(measured)
        out.append(f"  RMS: psi = 0 pressures {sc['exp_pressure_rms_pct']:.1f} %; angles "
                   f"{sc['exp_psi_rms_deg']:.1f} deg; ranges of motion "
                   f"{sc['exp_range_rms_pct']:.1f} %; undefined {sc['undefined_anchors']}")
    rms = "/".join(f"{v:g}" for v in PAPER_RMS_DEG.values())
    out.append(f"  (the paper's RMS of model vs mean data, {rms} deg for "
               f"{'/'.join(PAPER_RMS_DEG)}, needs measured curves: see "
               "'python -m pipeline compare')")
    if has_paper:
        out.append(_area_line(table["SS40"], opts, l0))
    if search:
        keys = tuple(search_keys or DERIVED_KEYS)
        fixed = {k: v for k, v in options.items() if k not in keys and k != "l0_mm"}
        res = search_readings(keys, materials=table, **fixed)
        passing = res[res["passes"]]
        out += ["", (f"Search (steps 1-4): {len(res)} derived readings, {len(passing)} meet "
                     f"+-{MODEL_BAR_PCT:g} % on both model results at their l0:")]
        cols = [*keys, "departures", "l0_fit_mm", "ss50_pct", "ss40_pct",
                "exp_pressure_rms_pct", "exp_psi_rms_deg", "exp_range_rms_pct"]
        shown = (passing if len(passing) else res.head(5))[cols]
        out.append(shown.to_string(index=False, float_format=lambda v: f"{v:.1f}"))
        choice = select_reading(res, keys)
        if choice is None:
            best = res.sort_values("model_worst_pct", kind="stable").iloc[0]
            which = ", ".join(f"{k}={best[k]}" for k in keys)
            out.append(f"No derived reading meets +-{MODEL_BAR_PCT:g} % on both model results; the "
                       f"best derived reading is {which} (worst {best['model_worst_pct']:.1f} % at "
                       f"l0 = {best['l0_fit_mm']:.1f} mm).")
        else:
            is_default = all(getattr(ModelOptions(), k) == choice[k] for k in keys)
            out.append("Protocol's choice: " + ", ".join(f"{k}={choice[k]}" for k in keys)
                       + f" at l0 = {choice['l0_mm']:.1f} mm"
                       + (" (the default reading)" if is_default else " (NOT the default reading)"))
    return "\n".join(out)


def _area_line(mat: Material, opts: ModelOptions, l0: float) -> str:
    """The wall area the reading's Eq. 12 element integrates to, against A0 (area consistency)."""
    from pipeline.model.forward import resolve_scale
    from pipeline.model.geometry import deformed_section
    from pipeline.model.moments import wall_area_mm2

    o = resolve_scale(opts, l0)
    psi = np.radians(np.linspace(mat.psi0_deg, -mat.psi0_deg, 101))
    with np.errstate(all="ignore"):
        area = wall_area_mm2(mat, deformed_section(mat, psi, l0, o), o) / 100.0
    area = area[np.isfinite(area)]
    a0 = mat.area0_mm2 / 100.0
    if area.size == 0:
        return "  wall area: undefined for this reading"
    consistent = float(np.max(np.abs(area / a0 - 1.0))) < 1e-6
    return (f"  wall area of this reading's Eq. 12 element, psi0..-psi0: {area.min():.2f}-"
            f"{area.max():.2f} cm^2 against A0 = {a0:.3f} cm^2 "
            + ("(area-consistent)" if consistent
               else "(NOT area-consistent; jacobian=deformed is)"))
