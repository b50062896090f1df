"""``python -m pipeline compare``: hysteresis.csv (+ angles.csv) vs the model -> rms.csv."""

from __future__ import annotations

import argparse
import io
import warnings
from pathlib import Path

import pandas as pd

from pipeline.aggregate import read_angles
from pipeline.compare import check_hysteresis, compare, model_callables
from pipeline.errors import UserInputError
from pipeline.model.cli import add_reading_arguments, reading_options
from pipeline.fileio import atomic_write_bytes
from pipeline.fileio import read_table


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """Define the ``compare`` options."""
    parser.add_argument(
        "hysteresis", nargs="+", type=Path, metavar="HYSTERESIS.csv",
        help="hysteresis.csv file(s) from 'aggregate' (psi in deg per pressure level in kPa); pooled",
    )
    parser.add_argument(
        "--angles", nargs="+", type=Path, default=None, metavar="ANGLES.csv",
        help="angles.csv file(s) from 'measure' used to fit k_P (dimensionless) with a bootstrap CI over "
        "actuators; omit to skip the fit",
    )
    parser.add_argument(
        "--out", type=Path, required=True, metavar="FILE",
        help="rms.csv to write: per material RMS model error (deg; both directions, up, down), pressures "
        "(kPa) at psi=0 and psi=-psi0, range of motion (deg), hysteresis width (deg), k_P fit + CI, paper values",
    )
    parser.add_argument(
        "--materials", type=str, default=None, metavar="PATH",
        help="materials YAML for the model (default: the packaged DS20/DS30/SS40/SS50 file)",
    )
    parser.add_argument("--seed", type=int, default=0, help="seed of the k_P bootstrap (integer; default 0)")
    parser.add_argument(
        "--bootstrap", "--n-boot", dest="n_boot", type=int, default=200, metavar="N",
        help="bootstrap resamples of actuators for the k_P 95%% interval (default 200; 0 = no interval)",
    )
    parser.add_argument(
        "--datasets", nargs="+", default=None, metavar="NAME",
        help="dataset names, one per HYSTERESIS.csv in the same order (used in messages only)",
    )
    parser.add_argument(
        "--include-flagged", action="store_true",
        help="also fit k_P on rows with status 'flagged' (default: only 'ok')",
    )
    model_group = parser.add_argument_group("model readings (as in 'python -m pipeline model'; default: the calibrated reading)")
    add_reading_arguments(model_group)


def read_hysteresis(paths: list[Path]) -> pd.DataFrame:
    """Read and concatenate hysteresis.csv files (checked with :func:`check_hysteresis`)."""
    frames = []
    for p in paths:
        df = read_table(p, "a hysteresis.csv written by 'aggregate'")
        check_hysteresis(df, str(p))
        frames.append(df)
    return pd.concat(frames, ignore_index=True)


def run(args: argparse.Namespace) -> int:
    """Compare and write rms.csv; print a one-line summary."""
    if args.datasets is not None and len(args.datasets) != len(args.hysteresis):
        raise UserInputError(
            f"--datasets names {len(args.datasets)} dataset(s) but {len(args.hysteresis)} HYSTERESIS.csv "
            "file(s) were given; pass one name per file, in the same order"
        )
    if args.n_boot < 0:
        raise UserInputError(f"--bootstrap must be >= 0 resamples, got {args.n_boot}")
    hyst = read_hysteresis(args.hysteresis)
    angles = read_angles(args.angles) if args.angles else None
    model_psi, fit_k_p, psi0 = model_callables(args.materials, **reading_options(args))
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        table = compare(
            hyst, angles, model_psi=model_psi, fit_k_p=fit_k_p, psi0_deg=psi0,
            n_boot=args.n_boot, seed=args.seed, include_flagged=args.include_flagged,
        )
    for w in caught:
        print(f"warning: {w.message}")
    buf = io.StringIO()
    table.to_csv(buf, index=False, float_format="%.6g", lineterminator="\n")
    args.out.parent.mkdir(parents=True, exist_ok=True)
    atomic_write_bytes(args.out, buf.getvalue().encode("utf-8"))
    parts = [f"{r.material} RMS {r.rms_deg:.1f} deg" for r in table.itertuples()]
    print(f"compare: {len(table)} material(s): {'; '.join(parts) or 'none'} -> {args.out}")
    return 0
