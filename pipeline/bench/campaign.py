"""Accuracy of a finished run on its synthetic photo sets: angles.csv against truth.csv.

``python -m pipeline bench campaign [RESULTS_DIR]`` prints, per dataset whose photo set has a
``truth.csv`` (synthetic sets under ``RESULTS_DIR/photosets/`` and committed sets such as
``sample_images/``), the status counts and the median / 95th-percentile / largest absolute error
of the ``ok`` rows, against the angle seen in the image (``psi_image_deg``, which includes the
camera tilt) and against the physical angle (``psi_deg``).
"""

from __future__ import annotations

import argparse
import sys
from collections.abc import Sequence
from pathlib import Path

import pandas as pd
import yaml

from pipeline.errors import UserInputError


def campaign_errors(angles: pd.DataFrame, truth: pd.DataFrame) -> dict[str, float]:
    """Error statistics of the ``ok`` rows of one dataset.

    Parameters
    ----------
    angles : pandas.DataFrame
        angles.csv (image, psi_deg, status).
    truth : pandas.DataFrame
        truth.csv (image, psi_deg and, when present, psi_image_deg).

    Returns
    -------
    dict
        n, n_ok, n_flagged, n_failed, median/p95/max absolute error vs the image angle and
        median/p95 vs the physical angle (deg), and n_ok_over_5deg.

    Examples
    --------
    >>> a = pd.DataFrame({"image": ["x", "y"], "psi_deg": [10.5, 0.0], "status": ["ok", "failed"]})
    >>> t = pd.DataFrame({"image": ["x", "y"], "psi_deg": [10.0, 3.0]})
    >>> campaign_errors(a, t)["median_deg"]
    0.5
    """
    seen = "psi_image_deg" if "psi_image_deg" in truth.columns else "psi_deg"
    # a video: per frame
    keys = (
        ["image", "frame"] if "frame" in truth.columns and "frame" in angles.columns else ["image"]
    )
    m = angles.merge(
        truth[keys + ["psi_deg"] + ([seen] if seen != "psi_deg" else [])],
        on=keys,
        suffixes=("", "_true"),
    )
    ok = m[m["status"] == "ok"]
    err = (ok["psi_deg"] - ok[seen if seen != "psi_deg" else "psi_deg_true"]).abs()
    err_phys = (ok["psi_deg"] - ok["psi_deg_true"]).abs()
    counts = m["status"].value_counts()
    return {
        "n": len(m),
        "n_ok": int(counts.get("ok", 0)),
        "n_flagged": int(counts.get("flagged", 0)),
        "n_failed": int(counts.get("failed", 0)),
        "median_deg": float(err.median()),
        "p95_deg": float(err.quantile(0.95)),
        "max_deg": float(err.max()),
        "median_physical_deg": float(err_phys.median()),
        "p95_physical_deg": float(err_phys.quantile(0.95)),
        "n_ok_over_5deg": int((err > 5).sum()),
    }


def run_accuracy(results_dir: Path, config_path: Path | None = None) -> pd.DataFrame:
    """One row per dataset of a finished run that has ground truth.

    A relative photo-set path in the config is relative to the run's working folder (the one
    holding ``results_dir``), wherever this is called from.
    """
    path = config_path or Path(results_dir) / "config.resolved.yaml"
    if not path.is_file():
        raise UserInputError(
            f"{path}: not found; pass the results folder of a finished run (snakemake writes it "
            "there)"
        )
    config = yaml.safe_load(path.read_text())
    results_dir = Path(results_dir)
    configured = Path(config.get("results_dir", "results"))
    depth = len(configured.parts)
    relative = not configured.is_absolute() and len(results_dir.parts) >= depth
    workdir = results_dir.parents[depth - 1] if relative else Path(".")
    rows = []
    for ds in config["datasets"]:
        synthetic = ds["source"] in ("synthetic", "synthetic_video")
        folder = (
            results_dir / "photosets" / ds["name"] if synthetic else workdir / ds.get("path", "")
        )
        angles = results_dir / "datasets" / ds["name"] / "angles.csv"
        if (folder / "truth.csv").is_file() and angles.is_file():
            stats = campaign_errors(pd.read_csv(angles), pd.read_csv(folder / "truth.csv"))
            rows.append({"dataset": ds["name"], **stats})
    return pd.DataFrame(rows)


def main(argv: Sequence[str] | None = None) -> int:
    """Print the accuracy table of a finished run."""
    parser = argparse.ArgumentParser(
        prog="python -m pipeline bench campaign", description=__doc__.splitlines()[0]
    )
    parser.add_argument(
        "results_dir",
        nargs="?",
        default="results",
        type=Path,
        help="results folder of a finished run",
    )
    args = parser.parse_args(argv)
    table = run_accuracy(args.results_dir)
    if table.empty:
        print(f"no dataset with truth.csv in {args.results_dir}", file=sys.stderr)
        return 1
    print(table.to_string(index=False, float_format=lambda v: f"{v:.3f}"))
    return 0


if __name__ == "__main__":
    sys.exit(main())
