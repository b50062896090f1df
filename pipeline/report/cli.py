"""``python -m pipeline report``: write report.pdf from the results tables.

Datasets are given as aligned lists: the i-th ``--datasets`` name, ``--angles`` file,
``--photosets`` folder and ``--overlays`` folder describe the same photo set.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from pipeline.errors import UserInputError
from pipeline.fileio import check_replaceable_pdf

NONE_MARK = "-"


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """Define the ``report`` options."""
    parser.description = (
        "Write the PDF report on A4 pages: page 1 a summary (per material the range of motion, the "
        "pressure "
        "at psi = 0, the RMS against the model and the fitted k_P beside the paper's values; "
        "ok/flagged/failed "
        "photos with the top reasons; real or synthetic datasets), a Fig. 6-style overview, one "
        "page per "
        "material (psi in deg versus P in kPa, mean +- 1 sd, model dashed; per-actuator curves; "
        "comparison "
        "table; a Fig. 5-style photo strip), the comparison beside the paper, the bench and force "
        "pages when "
        "given, and a last provenance page (software, config and the sha256 of every input).  "
        "Lists are "
        "aligned by dataset; use '-' for a dataset without photos or overlays.  The same inputs "
        "give the same "
        "PDF bytes."
    )
    parser.add_argument(
        "--angles",
        nargs="+",
        type=Path,
        required=True,
        metavar="ANGLES.csv",
        help="angles.csv of each dataset (psi in deg per photo, from 'measure')",
    )
    parser.add_argument(
        "--datasets",
        nargs="+",
        default=None,
        metavar="NAME",
        help="dataset names aligned with --angles (default: each angles.csv's folder name)",
    )
    parser.add_argument(
        "--photosets",
        nargs="+",
        default=None,
        metavar="DIR",
        help="photo-set folder of each dataset (raw photos for the strip when no overlay exists)",
    )
    parser.add_argument(
        "--overlays",
        nargs="+",
        default=None,
        metavar="DIR",
        help="'measure --overlays' folder of each dataset (each photo's path in its set as a "
        ".jpg, e.g. DIR/trial1/IMG_0001.jpg; extracted line drawn)",
    )
    parser.add_argument(
        "--hysteresis",
        nargs="+",
        type=Path,
        default=None,
        metavar="H.csv",
        help="hysteresis.csv file(s) from 'aggregate' (pooled per material; default: recomputed "
        "from --angles at the pressure setpoints in kPa)",
    )
    parser.add_argument(
        "--rms",
        nargs="+",
        type=Path,
        default=None,
        metavar="RMS.csv",
        help="rms.csv from 'compare' (RMS in deg, crossings in kPa, k_P); without it the tables "
        "show n/a",
    )
    parser.add_argument(
        "--model-curves",
        nargs="+",
        type=Path,
        default=None,
        metavar="C.csv",
        help="model curves from 'model curve' (columns material, psi_deg, pressure_kpa), drawn "
        "dashed",
    )
    parser.add_argument(
        "--bench-dir",
        type=Path,
        default=None,
        metavar="DIR",
        help="output folder of 'python -m pipeline bench'; adds its speed/accuracy, stability and "
        "table pages",
    )
    parser.add_argument(
        "--force-dir",
        type=Path,
        default=None,
        metavar="DIR",
        help="output folder of 'python -m pipeline force'; adds the blocked-force, eccentricity "
        "and grasp pages",
    )
    parser.add_argument(
        "--video-dirs",
        nargs="+",
        type=Path,
        default=(),
        metavar="DIR",
        help="'continuous --out-dir' folder of each video dataset (named as the dataset); adds its "
        "page",
    )
    parser.add_argument(
        "--materials-files",
        nargs="+",
        type=Path,
        default=(),
        metavar="YAML",
        help="materials files the model curves were computed from (the run's and the datasets' "
        "own); listed with their sha256 on the provenance page",
    )
    parser.add_argument(
        "--config",
        type=Path,
        default=None,
        metavar="FILE",
        help="workflow config file; its sha256 is printed on the provenance page",
    )
    parser.add_argument(
        "--title",
        default="Circular actuator characterisation",
        help="report title (text, on every page footer)",
    )
    parser.add_argument(
        "--out", type=Path, required=True, metavar="FILE", help="report.pdf to write"
    )


def _aligned(values: list[str] | None, n: int, option: str) -> list[Path | None]:
    if values is None:
        return [None] * n
    if len(values) != n:
        raise UserInputError(
            f"{option} has {len(values)} value(s) but --angles has {n}; give one per dataset in "
            "the same "
            f"order ('{NONE_MARK}' for none)"
        )
    return [None if v == NONE_MARK else Path(v) for v in values]


def default_names(angles: list[Path]) -> list[str]:
    """Dataset names from the angles.csv folders, made unique with a numeric suffix."""
    names: list[str] = []
    for p in angles:
        base = p.resolve().parent.name or p.stem
        name, k = base, 2
        while name in names:
            name, k = f"{base}-{k}", k + 1
        names.append(name)
    return names


def run(args: argparse.Namespace) -> int:
    """Build the report; print a one-line summary and any warnings."""
    from pipeline.report.build import build_report  # matplotlib is imported only when building
    from pipeline.report.data import Dataset, ReportInputs

    check_replaceable_pdf(args.out)  # a person's file is never replaced
    n = len(args.angles)
    names = args.datasets if args.datasets is not None else default_names(args.angles)
    if len(names) != n:
        raise UserInputError(
            f"--datasets has {len(names)} name(s) but --angles has {n}; give one per dataset"
        )
    photos = _aligned(args.photosets, n, "--photosets")
    overlays = _aligned(args.overlays, n, "--overlays")
    inputs = ReportInputs(
        datasets=tuple(
            Dataset(str(nm), a, ph, ov)
            for nm, a, ph, ov in zip(names, args.angles, photos, overlays, strict=True)
        ),
        hysteresis=tuple(args.hysteresis or ()),
        rms=tuple(args.rms or ()),
        model_curves=tuple(args.model_curves or ()),
        bench_dir=args.bench_dir,
        force_dir=args.force_dir,
        video_dirs=tuple(args.video_dirs),
        materials_files=tuple(args.materials_files),
        config=args.config,
        title=args.title,
    )
    result = build_report(inputs, args.out)
    for w in result.warnings:
        print(f"warning: {w}", file=sys.stderr)
    print(
        f"report: {result.pages} pages, materials {', '.join(result.materials) or 'none'}, "
        f"{len(result.warnings)} warning(s) -> {result.path}"
    )
    print(
        f"report: built in {result.load_s + result.pages_s + result.pdf_s:.1f} s (reading inputs "
        f"{result.load_s:.1f} s, drawing pages {result.pages_s:.1f} s, writing the PDF "
        f"{result.pdf_s:.1f} s)"
    )
    return 0
