"""``python -m pipeline aggregate``: angles.csv files -> hysteresis.csv (mean/sd psi per level)."""

from __future__ import annotations

import argparse
from pathlib import Path

from pipeline.aggregate import aggregate_hysteresis, aggregate_per_actuator, read_angles
from pipeline.fileio import check_replaceable_table, write_table


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """Define the ``aggregate`` options."""
    parser.add_argument(
        "angles",
        nargs="+",
        type=Path,
        metavar="ANGLES.csv",
        help="angles.csv file(s) written by 'measure' (psi in deg, pressure in kPa); rows of all "
             "files are pooled",
    )
    parser.add_argument(
        "--out",
        type=Path,
        required=True,
        metavar="FILE",
        help="hysteresis.csv to write: one row per material x direction x pressure level (kPa) "
             "with "
        "psi_mean_deg, psi_sd_deg (sample sd, ddof=1), n, n_actuators, n_trials, n_excluded",
    )
    parser.add_argument(
        "--per-actuator-out",
        type=Path,
        default=None,
        metavar="FILE",
        help="also write per-actuator curves (mean/sd psi in deg over each actuator's trials) to "
             "FILE",
    )
    parser.add_argument(
        "--bin-kpa",
        type=float,
        default=None,
        metavar="W",
        help="group by measured pressure (measured_pressure_kpa, else the setpoint) rounded to "
             "bins of W kPa instead of by the nominal setpoint pressure_kpa (default: setpoints "
             "for photos; the frames of a video by 5 kPa of measured pressure, a stepped video's "
             "only at the end of each hold)",
    )
    parser.add_argument(
        "--include-flagged",
        action="store_true",
        help="also average rows with status 'flagged' (default: only 'ok'; 'failed' is always "
             "excluded)",
    )


def run(args: argparse.Namespace) -> int:
    """Aggregate and write; print a one-line summary."""
    check_replaceable_table(args.out, ("psi_mean_deg", "n_excluded"))  # a person's file stays
    angles = read_angles(args.angles)
    hyst = aggregate_hysteresis(angles, bin_kpa=args.bin_kpa, include_flagged=args.include_flagged)
    write_table(hyst, args.out)
    if args.per_actuator_out is not None:
        per = aggregate_per_actuator(
            angles, bin_kpa=args.bin_kpa, include_flagged=args.include_flagged
        )
        write_table(per, args.per_actuator_out)
    n_used = int(hyst["n"].sum()) if len(hyst) else 0
    n_excl = int(hyst["n_excluded"].sum()) if len(hyst) else 0
    materials = ", ".join(sorted(map(str, hyst["material"].unique()))) if len(hyst) else "none"
    print(
        f"aggregate: {len(angles)} rows from {len(args.angles)} file(s) -> {len(hyst)} levels "
        f"({materials}); {n_used} rows averaged, {n_excl} excluded -> {args.out}"
    )
    return 0
