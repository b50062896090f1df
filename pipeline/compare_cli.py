"""``python -m pipeline compare``: hysteresis.csv (+ angles.csv) vs the model -> rms.csv."""

from __future__ import annotations

import argparse
import warnings
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from pipeline.aggregate import read_angles
from pipeline.compare import check_hysteresis, compare, file_model, model_callables
from pipeline.errors import UserInputError
from pipeline.fileio import FLOAT_FORMAT, check_replaceable_table, read_table, write_table
from pipeline.model.cli import add_reading_arguments, reading_options
from pipeline.photoset import TRUTH


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """Define the ``compare`` options."""
    parser.add_argument(
        "hysteresis",
        nargs="+",
        type=Path,
        metavar="HYSTERESIS.csv",
        help="hysteresis.csv file(s) from 'aggregate' (psi in deg per pressure level in kPa); "
        "pooled",
    )
    parser.add_argument(
        "--angles",
        nargs="+",
        type=Path,
        default=None,
        metavar="ANGLES.csv",
        help="angles.csv file(s) from 'measure' used to fit k_P (dimensionless) with a bootstrap "
        "CI over "
        "actuators; omit to skip the fit",
    )
    parser.add_argument(
        "--out",
        type=Path,
        required=True,
        metavar="FILE",
        help="rms.csv to write: per material RMS model error (deg; both directions, up, down), "
        "pressures "
        "(kPa) at psi=0 and psi=-psi0, range of motion (deg), hysteresis width (deg), k_P fit + "
        "CI, paper values",
    )
    parser.add_argument(
        "--materials",
        type=str,
        default=None,
        metavar="PATH",
        help="materials YAML for the model (default: the packaged DS20/DS30/SS40/SS50 file)",
    )
    parser.add_argument(
        "--dataset-materials",
        nargs="+",
        default=None,
        metavar="PATH",
        help="each dataset's own materials YAML, same order as --datasets ('-' for --materials): "
        "that dataset is compared against its file's model (Ogden terms, k_P, k_t, geometry; l0 "
        "unless its angles.csv has l0_mm), in rows of its own",
    )
    parser.add_argument(
        "--seed", type=int, default=0, help="seed of the k_P bootstrap (integer; default 0)"
    )
    parser.add_argument(
        "--bootstrap",
        "--n-boot",
        dest="n_boot",
        type=int,
        default=200,
        metavar="N",
        help="bootstrap resamples of actuators for the k_P 95%% interval (default 200; 0 = no "
        "interval)",
    )
    parser.add_argument(
        "--datasets",
        nargs="+",
        default=None,
        metavar="NAME",
        help="dataset names, one per HYSTERESIS.csv in the same order (default: each file's folder "
        "name); "
        "with as many ANGLES.csv, the i-th angles file belongs to the i-th dataset",
    )
    parser.add_argument(
        "--photosets",
        nargs="+",
        default=None,
        metavar="DIR",
        help="photo-set folder of each dataset, same order ('-' for unknown): a set holding "
        "truth.csv was "
        "rendered by 'synth' from this model, so its RMS is a self-check, not a validation",
    )
    parser.add_argument(
        "--curves",
        type=Path,
        default=None,
        metavar="FILE",
        help="also write the model curve of every rms.csv row (curve, material, l0_mm in mm, "
        "materials_file, psi_deg, pressure_kpa in kPa, reason): the curve each RMS was computed "
        "against",
    )
    parser.add_argument(
        "--include-flagged",
        action="store_true",
        help="also fit k_P on rows with status 'flagged' (default: only 'ok')",
    )
    model_group = parser.add_argument_group(
        "model readings (as in 'python -m pipeline model'; default: the derived reading of "
        "docs/model.md). "
        "--l0-mm is the model's l0 for datasets whose angles.csv has no l0_mm; a dataset's own "
        "l0_mm wins"
    )
    add_reading_arguments(model_group)


def read_hysteresis(paths: list[Path]) -> pd.DataFrame:
    """Read and concatenate hysteresis.csv files (checked with :func:`check_hysteresis`)."""
    frames = []
    for p in paths:
        df = read_table(p, "a hysteresis.csv written by 'aggregate'")
        check_hysteresis(df, str(p))
        frames.append(df)
    return pd.concat(frames, ignore_index=True)


def dataset_names(paths: list[Path], given: list[str] | None) -> list[str]:
    """``given``, or each file's folder name made unique with a numeric suffix."""
    if given is not None:
        if len(given) != len(paths):
            raise UserInputError(
                f"--datasets names {len(given)} dataset(s) but {len(paths)} HYSTERESIS.csv "
                "file(s) were given; pass one name per file, in the same order"
            )
        return [str(g) for g in given]
    names: list[str] = []
    for p in paths:
        base = p.resolve().parent.name or p.stem
        name, k = base, 2
        while name in names:
            name, k = f"{base}-{k}", k + 1
        names.append(name)
    return names


def data_source(folder: str) -> str:
    """``synthetic`` if the photo set was rendered by ``synth`` (it holds truth.csv), else
    ``measured``.

    Only the file's presence is checked (truth.csv itself is for tests and benchmarks);
    ``"-"`` or a missing folder give ``unknown``.
    """
    if folder == "-" or not Path(folder).is_dir():
        return "unknown"
    return "synthetic" if (Path(folder) / TRUTH).is_file() else "measured"


def model_fit_text(options: dict[str, Any]) -> str:
    """What in the model is fitted to the paper's numbers, for rms.csv's ``model_fit``."""
    from pipeline.model import make_options

    opts = make_options(**options)
    if opts.l0_factor == "fitted_scale":
        how = (
            f"given as {opts.eq12_scale:g}"
            if opts.eq12_scale is not None
            else "fitted for these readings"
        )
        return f"eq12_scale fitted to the paper's two model results (l0_factor=fitted_scale, {how})"
    return "none (derived reading; k_P and k_t are the paper's)"


#: ``materials_file`` of rows compared against the packaged materials (no machine path in rms.csv)
PACKAGED = "packaged (pipeline/model/materials.yaml)"


def own_files(args: argparse.Namespace, names: list[str], pooled: bool) -> dict[str, str]:
    """Dataset name -> its own materials file, from ``--dataset-materials`` ('-': none)."""
    given = args.dataset_materials
    if given is None:
        return {}
    if len(given) != len(names):
        raise UserInputError(
            f"--dataset-materials has {len(given)} file(s) but {len(names)} HYSTERESIS.csv "
            "file(s) were given; pass one per dataset in the same order ('-' for the run's "
            "--materials)"
        )
    out = {n: f for n, f in zip(names, given, strict=True) if f != "-"}
    if out and pooled:
        raise UserInputError(
            "--dataset-materials needs one ANGLES.csv per dataset (--angles in the order of the "
            "HYSTERESIS.csv files): otherwise the angles cannot be told apart by dataset"
        )
    return out


def run(args: argparse.Namespace) -> int:
    """Compare and write rms.csv (and the model curves); print a one-line summary per row."""
    from pipeline import model

    check_replaceable_table(args.out, ("rms_deg",))  # a person's file is never replaced
    names = dataset_names(args.hysteresis, args.datasets)
    if args.n_boot < 0:
        raise UserInputError(f"--bootstrap must be >= 0 resamples, got {args.n_boot}")
    if args.photosets is not None and len(args.photosets) != len(names):
        raise UserInputError(
            f"--photosets has {len(args.photosets)} folder(s) but {len(names)} HYSTERESIS.csv "
            "file(s) were "
            "given; pass one per dataset in the same order ('-' for unknown)"
        )
    frames = []
    for name, path in zip(names, args.hysteresis, strict=True):
        frames.append(read_hysteresis([path]).assign(dataset=name))
    hyst = pd.concat(frames, ignore_index=True)
    angles = None
    pooled = bool(args.angles) and len(args.angles) != len(names)
    own = own_files(args, names, pooled)
    if args.angles:
        if len(args.angles) == len(names):  # the i-th angles.csv belongs to the i-th dataset
            angles = pd.concat(
                [
                    read_angles([a]).assign(dataset=n)
                    for a, n in zip(args.angles, names, strict=True)
                ],
                ignore_index=True,
            )
        else:  # cannot tell which angles belong to which hysteresis: one pool
            angles = read_angles(args.angles)
            hyst["dataset"] = "all"
            angles["dataset"] = "all"
    options = reading_options(args)
    model_psi, fit_k_p, psi0 = model_callables(args.materials, **options)
    table_m = model.load_materials(args.materials)
    given_l0 = options.get("l0_mm")
    default_l0 = {
        n: float(given_l0) if given_l0 is not None else m.l0_mm for n, m in table_m.items()
    }
    sources = (
        dict(zip(names, [data_source(f) for f in args.photosets], strict=True))
        if args.photosets
        else {}
    )
    files = {f: file_model(f, **options) for f in sorted(set(own.values()))}
    tables = {"": table_m, **{f: model.load_materials(f) for f in files}}
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        table = compare(
            hyst,
            angles,
            model_psi=model_psi,
            fit_k_p=fit_k_p,
            psi0_deg=psi0,
            default_l0_mm=default_l0,
            default_l0_source="--l0-mm" if given_l0 is not None else "materials file",
            data_sources=sources,
            model_fit=model_fit_text(options),
            n_boot=args.n_boot,
            seed=args.seed,
            include_flagged=args.include_flagged,
            materials_file=args.materials or PACKAGED,
            dataset_models={n: files[f] for n, f in own.items()},
        )
    for w in caught:
        print(f"warning: {w.message}")
    write_table(table, args.out)
    if args.curves is not None:
        readings = {k: v for k, v in options.items() if k != "l0_mm"}
        own_file = {
            r.curve: r.materials_file if r.materials_file in files else ""
            for r in table.itertuples()
        }
        curves = [
            model.model_curve(
                tables[own_file[r.curve]][r.material], l0_mm=r.l0_mm, **readings
            ).assign(curve=r.curve, materials_file=r.materials_file)
            for r in table.itertuples()
            if r.material in tables[own_file[r.curve]] and np.isfinite(r.l0_mm)
        ]
        columns = [
            "curve",
            "material",
            "l0_mm",
            "materials_file",
            "psi_deg",
            "pressure_kpa",
            "reason",
        ]
        out = (
            pd.concat(curves, ignore_index=True)[columns]
            if curves
            else pd.DataFrame(columns=columns)
        )
        write_table(out, args.curves)
    for r in table.itertuples():
        print(
            f"compare: {r.curve} [{r.datasets}; l0 from {r.l0_source}; "
            f"materials {r.materials_file}; {r.rms_kind}]: RMS "
            # as written to rms.csv and read back by the report (101.85 there, 101.8500x here)
            f"{float(FLOAT_FORMAT % r.rms_deg):.1f} deg"
        )
    print(
        f"compare: {len(table)} comparison(s) -> {args.out}"
        + (f", curves -> {args.curves}" if args.curves else "")
    )
    return 0
