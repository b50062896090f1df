"""``python -m pipeline continuous ANGLES.csv --out-dir DIR``: loops, settling curves, step
responses of a video."""

from __future__ import annotations

import argparse
from pathlib import Path


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """Options of the ``continuous`` subcommand."""
    parser.add_argument("angles", type=Path, metavar="ANGLES.csv",
                        help="angles.csv of a video photo set (one row per frame, from 'measure')")
    parser.add_argument(
        "--out-dir",
        type=Path,
        required=True,
        metavar="DIR",
        help="folder for loops.csv (psi per pressure bin, per cycle and direction), cycles.csv "
             "(rates in "
        "kPa/s, loop width in deg and area in deg kPa), steps.csv (rise, settling time in s, "
        "overshoot in "
        "%% per pressure step), settling.csv (psi against time since each step) and timeline.csv",
    )
    parser.add_argument(
        "--bin-kpa",
        type=float,
        default=None,
        metavar="W",
        help="pressure bin of the loops (kPa, default 5); the measured pressure when logged",
    )
    parser.add_argument("--include-flagged", action="store_true",
                        help="also use frames whose status is 'flagged' (default: only 'ok')")
    parser.add_argument(
        "--overlays",
        type=Path,
        default=None,
        metavar="DIR",
        help="the 'measure --overlays' folder: also write strip.jpg, frames across the recording",
    )


def run(args: argparse.Namespace) -> int:
    """Compute and write the tables; print a one-line summary."""
    from pipeline.fileio import read_table
    from pipeline.video.continuous import BIN_KPA, write_continuous

    angles = read_table(args.angles, "an angles.csv of a video photo set, written by 'measure'",
                        dtype={"actuator": str, "trial": str, "image": str, "reason": str})
    tables = write_continuous(
        angles, args.out_dir, bin_kpa=args.bin_kpa or BIN_KPA, include_flagged=args.include_flagged
    )
    if args.overlays is not None:
        from pipeline.video.pages import write_strip

        write_strip(angles, args.overlays, args.out_dir)
    steps, cycles = tables["steps.csv"], tables["cycles.csv"]
    settled = int(steps["settling_time_s"].notna().sum()) if len(steps) else 0
    print(
        f"continuous: {int(angles['frame'].notna().sum())} frames -> {len(cycles)} cycle(s), "
        f"{len(steps)} step(s) "
        f"({settled} settled within their hold) -> {args.out_dir}"
    )
    return 0
