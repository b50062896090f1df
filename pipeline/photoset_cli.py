"""``python -m pipeline photoset {init,check}``: start or validate a photo-set folder."""

from __future__ import annotations

import argparse
import sys

from pipeline import photoset, photoset_init
from pipeline.measure.settings import POSITIVE_TURNS


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """Define ``photoset init`` and ``photoset check``."""
    sub = parser.add_subparsers(dest="photoset_command", metavar="{init,check}", required=True)
    init = sub.add_parser(
        "init",
        help="write a starter manifest.csv and photoset.yaml from the image file names",
        description=(
            "Write manifest.csv (and photoset.yaml when absent) from the names of the photos in DIR. "
            "Fields: {pressure_kpa} (kPa; '12p5' means 12.5), {direction} (up/down, inc/dec), "
            "{trial}, {actuator}, {material}, {step}, {_} or * (ignored). Without {direction}, "
            "photos before the highest pressure of each ramp are 'up', after it 'down'."
        ),
    )
    init.add_argument("folder", metavar="DIR", help="folder holding the photos")
    init.add_argument("--pattern", required=True, help="file-name pattern, e.g. '{material}_{actuator}_t{trial}_{step}_{pressure_kpa}kPa.jpg'")
    init.add_argument("--material", help="material for every photo when the pattern has no {material}")
    init.add_argument("--actuator", help="actuator label when the pattern has no {actuator} (default A1)")
    init.add_argument("--trial", help="trial label when the pattern has no {trial} (default 1)")
    init.add_argument("--l0-mm", type=float, help="length of the marked inextensible layer, mm (written to photoset.yaml)")
    init.add_argument("--mm-per-px", type=float, help="image scale, mm per pixel (optional)")
    init.add_argument("--line-color", default="black", help="marker colour: black, blue, red, green or 'h,s,v-h,s,v' (default black)")
    init.add_argument("--positive-turn", choices=POSITIVE_TURNS, default="ccw", help="turning direction on screen, fixed end to free end, that counts as positive psi (default ccw)")
    init.add_argument("--overwrite", action="store_true", help="replace an existing manifest.csv")
    check = sub.add_parser(
        "check",
        help="validate a photo set and list every bad row with its fix",
        description="Validate manifest.csv, photoset.yaml and every image (decoded with OpenCV). Exit 1 if anything is wrong.",
    )
    check.add_argument("folder", metavar="DIR", help="photo-set folder")
    check.add_argument("--no-decode", action="store_true", help="only check that images exist (faster)")


def run(args: argparse.Namespace) -> int:
    """Run ``photoset init`` or ``photoset check``."""
    if args.photoset_command == "init":
        defaults = {k: getattr(args, k) for k in ("material", "actuator", "trial") if getattr(args, k)}
        settings = {
            "l0_mm": args.l0_mm,
            "mm_per_px": args.mm_per_px,
            "line_color": args.line_color,
            "positive_turn": args.positive_turn,
        }
        df = photoset_init.init_photoset(args.folder, args.pattern, defaults=defaults, settings=settings, overwrite=args.overwrite)
        n_up = int((df["direction"] == "up").sum())
        print(f"wrote {args.folder}/{photoset.MANIFEST}: {len(df)} photos ({n_up} up, {len(df) - n_up} down)")
        if args.l0_mm is None:
            print(f"next: set l0_mm in {args.folder}/{photoset.SETTINGS}, then run 'python -m pipeline photoset check {args.folder}'")
        return 0
    problems = photoset.validate_photoset(args.folder, decode_images=not args.no_decode)
    if problems:
        print(f"{args.folder}: {len(problems)} problem(s)", file=sys.stderr)
        for p in problems:
            print(f"  {p}", file=sys.stderr)
        return 1
    n = len(photoset.read_manifest(args.folder))
    print(f"{args.folder}: OK ({n} photos)")
    return 0
