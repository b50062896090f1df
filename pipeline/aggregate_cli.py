"""``python -m pipeline aggregate``: angles.csv files -> hysteresis.csv (mean/sd psi per level)."""

from __future__ import annotations

import argparse
import io
from pathlib import Path

import pandas as pd

from pipeline.aggregate import aggregate_hysteresis, aggregate_per_actuator, read_angles
from pipeline.fileio import atomic_write_bytes


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """Define the ``aggregate`` options."""
    parser.add_argument(
        "angles", nargs="+", type=Path, metavar="ANGLES.csv",
        help="angles.csv file(s) written by 'measure' (psi in deg, pressure in kPa); rows of all files are pooled",
    )
    parser.add_argument(
        "--out", type=Path, required=True, metavar="FILE",
        help="hysteresis.csv to write: one row per material x direction x pressure level (kPa) with "
        "psi_mean_deg, psi_sd_deg (sample sd, ddof=1), n, n_actuators, n_trials, n_excluded",
    )
    parser.add_argument(
        "--per-actuator-out", type=Path, default=None, metavar="FILE",
        help="also write per-actuator curves (mean/sd psi in deg over each actuator's trials) to FILE",
    )
    parser.add_argument(
        "--bin-kpa", type=float, default=None, metavar="W",
        help="group by measured pressure (measured_pressure_kpa, else the setpoint) rounded to bins "
        "of W kPa instead of by the nominal setpoint pressure_kpa (default: setpoints)",
    )
    parser.add_argument(
        "--include-flagged", action="store_true",
        help="also average rows with status 'flagged' (default: only 'ok'; 'failed' is always excluded)",
    )


def _write_csv(frame: pd.DataFrame, path: Path) -> None:
    buf = io.StringIO()
    frame.to_csv(buf, index=False, float_format="%.6g", lineterminator="\n")
    path.parent.mkdir(parents=True, exist_ok=True)
    atomic_write_bytes(path, buf.getvalue().encode("utf-8"))


def run(args: argparse.Namespace) -> int:
    """Aggregate and write; print a one-line summary."""
    angles = read_angles(args.angles)
    hyst = aggregate_hysteresis(angles, bin_kpa=args.bin_kpa, include_flagged=args.include_flagged)
    _write_csv(hyst, args.out)
    if args.per_actuator_out is not None:
        per = aggregate_per_actuator(angles, bin_kpa=args.bin_kpa, include_flagged=args.include_flagged)
        _write_csv(per, args.per_actuator_out)
    n_used = int(hyst["n"].sum()) if len(hyst) else 0
    n_excl = int(hyst["n_excluded"].sum()) if len(hyst) else 0
    materials = ", ".join(sorted(map(str, hyst["material"].unique()))) if len(hyst) else "none"
    print(
        f"aggregate: {len(angles)} rows from {len(args.angles)} file(s) -> {len(hyst)} levels "
        f"({materials}); {n_used} rows averaged, {n_excl} excluded -> {args.out}"
    )
    return 0
