"""``python -m pipeline measure PHOTOSET_DIR --out angles.csv [--method NAME] [--overlays DIR]
[--jobs N]``."""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

from pipeline.fileio import check_replaceable_table
from pipeline.folders import staged_folder
from pipeline.measure.core import DEFAULT_METHOD
from pipeline.measure.estimators import METHODS


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """Options of the ``measure`` subcommand."""
    parser.add_argument(
        "photoset",
        metavar="PHOTOSET_DIR",
        help="photo-set folder (manifest.csv + photoset.yaml + images, or videos with their "
             "pressure logs: one row per frame)",
    )
    parser.add_argument(
        "--out",
        required=True,
        help="angles.csv to write: psi_deg (deg), kappa_per_mm (1/mm), length_mm (mm), status per "
             "photo",
    )
    parser.add_argument(
        "--method",
        default=DEFAULT_METHOD,
        choices=sorted(METHODS),
        help=f"curvature estimator (default {DEFAULT_METHOD}); 'paper' is the paper's biased "
             "unsigned average, kept for comparison",
    )
    parser.add_argument(
        "--overlays",
        metavar="DIR",
        default=None,
        help="also write per-photo overlays (<= 640 px wide) and contact sheets per ramp into DIR",
    )
    parser.add_argument(
        "--jobs",
        type=int,
        default=1,
        help="worker processes (photos measured in parallel; default 1)",
    )
    parser.add_argument(
        "--cache",
        metavar="DIR",
        default=None,
        help="keep each photo's measurement in DIR: a run cut off resumes, and only photos "
             "changed since the last run (or all, after a setting or the program changed) are "
             "measured again; one folder per photo set",
    )
    parser.add_argument(
        "--no-ramp-check",
        dest="ramp_check",
        action="store_false",
        help="do not check each photo's psi against its ramp's trend (flagging jumps, re-trusting "
             "cosmetic flags)",
    )


def run(args: argparse.Namespace) -> int:
    """Measure the set, write angles.csv, print a one-line summary."""
    from pipeline.photoset import load_photoset, measurement_doubts, newer_spreadsheet_problems
    from pipeline.photoset_measure import measure_photoset, summary, write_angles

    t0 = time.perf_counter()
    folder = Path(args.photoset)
    check_replaceable_table(  # before minutes of measuring
        args.out, ("psi_deg", "status"), example=folder.parent / f"{folder.name}_angles.csv"
    )
    ps = load_photoset(args.photoset)
    kw = {
        "method": args.method, "jobs": args.jobs, "ramp_check": args.ramp_check,
        "cache_dir": args.cache,
    }
    if args.overlays is None:
        angles = measure_photoset(ps, **kw)
    else:  # the overlay folder appears only when complete
        with staged_folder(args.overlays, marker="contact_*.jpg") as overlays:
            angles = measure_photoset(ps, overlays_dir=overlays, **kw)
    write_angles(angles, args.out)
    doubts = newer_spreadsheet_problems(Path(args.photoset))
    doubts += measurement_doubts(ps)
    for problem in doubts:
        print(problem, file=sys.stderr)
    used = sorted(set(angles["method"].dropna().astype(str)) - {args.method})
    took = f" (rows say which it took: {', '.join(used)})" if used else ""
    if angles.attrs.get("from_cache"):
        took += f"; {angles.attrs['from_cache']} as measured by an earlier run (--cache)"
    print(
        f"{summary(angles)} in {time.perf_counter() - t0:.1f} s, method {args.method}{took} -> "
        f"{args.out}"
    )
    return 0
