"""Measure every photo of a photo set into the angles.csv table (one row per manifest row).

Photos are measured in a process pool (``jobs``); workers import only OpenCV/numpy/scipy
(:mod:`pipeline.measure.worker`) and each photo is decoded once, at reduced size for large JPEGs.
One bad photo never stops the set: it becomes a ``failed`` row with the reason.
"""

from __future__ import annotations

import multiprocessing
import os
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

import cv2
import numpy as np
import pandas as pd

from pipeline.errors import UserInputError
from pipeline.measure.core import DEFAULT_METHOD
from pipeline.measure.estimators import METHODS
from pipeline.measure.extract import resolve_ranges
from pipeline.measure.worker import Task, init_worker, run_task
from pipeline.photoset import OVERRIDE_COLUMNS, atomic_write_bytes, load_photoset

#: angles.csv: the measurement columns, in this order, then the manifest's own columns
#: (``degree``: curve-model complexity the estimator used, see :class:`~pipeline.measure.AngleResult`;
#: empty on failed rows)
RESULT_COLUMNS: tuple[str, ...] = (
    "image", "psi_deg", "kappa_per_mm", "length_mm", "method", "residual_px", "status", "reason", "seconds",
    "degree",
)
#: manifest columns carried over first (when present), then any others
CARRIED_FIRST: tuple[str, ...] = ("pressure_kpa", "direction", "material", "actuator", "trial", "step")


def _tasks(folder: Path, manifest: pd.DataFrame, method: str, overlays_dir: Path | None) -> list[Task]:
    tasks = []
    for _, row in manifest.iterrows():
        line = int(row["manifest_line"])
        l0 = row["l0_mm"]
        if pd.isna(l0):
            raise UserInputError(f"{folder / 'manifest.csv'} line {line}: no l0_mm (set it in photoset.yaml or the row)")
        try:
            ranges = resolve_ranges(row["line_color"])
        except UserInputError as exc:
            raise UserInputError(f"{folder / 'manifest.csv'} line {line}: {exc}") from exc
        fx, fy = row["fixed_end_x"], row["fixed_end_y"]
        fixed = None if pd.isna(fx) or pd.isna(fy) else (float(fx), float(fy))
        mpp = None if pd.isna(row["mm_per_px"]) else float(row["mm_per_px"])
        image = str(row["image"])
        overlay = None if overlays_dir is None else str(overlays_dir / f"{Path(image).stem}.jpg")
        title = f"{image}  {row['pressure_kpa']:g} kPa {row['direction']}"
        tasks.append(Task(str(folder / image), float(l0), mpp, ranges, fixed, str(row["positive_turn"]), method, overlay, title))
    return tasks


def measure_photoset(
    folder: str | os.PathLike[str],
    *,
    method: str = DEFAULT_METHOD,
    jobs: int = 1,
    overlays_dir: str | os.PathLike[str] | None = None,
) -> pd.DataFrame:
    """Measure psi on every photo of a photo set.

    Parameters
    ----------
    folder : path
        Photo-set folder (manifest.csv + photoset.yaml + images).
    method : str
        Estimator, a key of :data:`pipeline.measure.METHODS`.
    jobs : int
        Worker processes (1 = measure in this process).
    overlays_dir : path, optional
        Write ``<image stem>.jpg`` overlays and ``contact_<material>_<actuator>_<trial>.jpg``.

    Returns
    -------
    pandas.DataFrame
        The angles.csv table: :data:`RESULT_COLUMNS`, then the manifest's columns
        (pressure_kpa, direction, material, actuator, trial, step, and any others such as
        measured_pressure_kpa, timestamp or force columns) and ``l0_mm``, the marked length
        each photo was measured with (the row's or the folder's setting).  One row per manifest
        row, same order.

    Raises
    ------
    UserInputError
        If the photo set is invalid or the method unknown.
    """
    if method not in METHODS:
        raise UserInputError(f"--method {method!r} is unknown; use one of {sorted(METHODS)}")
    if jobs < 1:
        raise UserInputError(f"--jobs {jobs} must be at least 1")
    ps = load_photoset(folder)
    manifest = ps.manifest
    odir = None if overlays_dir is None else Path(overlays_dir)
    if odir is not None:
        odir.mkdir(parents=True, exist_ok=True)
    tasks = _tasks(ps.folder, manifest, method, odir)
    if jobs == 1 or len(tasks) <= 1:
        rows = [run_task(t) for t in tasks]
    else:
        # forkserver (never plain fork: forking a process that runs OpenCV / BLAS threads can
        # deadlock); the server preloads the light worker module once, so workers start fast
        methods = multiprocessing.get_all_start_methods()
        ctx = multiprocessing.get_context("forkserver" if "forkserver" in methods else "spawn")
        if "forkserver" in methods:
            ctx.set_forkserver_preload(["pipeline.measure.worker"])
        chunk = max(1, len(tasks) // (4 * jobs))
        with ProcessPoolExecutor(max_workers=jobs, mp_context=ctx, initializer=init_worker) as pool:
            rows = list(pool.map(run_task, tasks, chunksize=chunk))
    result = pd.DataFrame(rows, index=manifest.index)
    result["degree"] = result["degree"].astype("Int64")
    result.insert(0, "image", manifest["image"].astype(str))
    # per-row settings are not carried, except l0_mm: compare models each photo's own actuator
    drop = {"image", "manifest_line", *OVERRIDE_COLUMNS} - {"l0_mm"}
    carried = [c for c in CARRIED_FIRST if c in manifest.columns]
    carried += [c for c in manifest.columns if c not in drop and c not in carried]
    out = pd.concat([result[list(RESULT_COLUMNS)], manifest[carried]], axis=1).reset_index(drop=True)
    if odir is not None:
        write_contact_sheets(out, odir)
    return out


def write_contact_sheets(angles: pd.DataFrame, overlays_dir: Path) -> list[Path]:
    """One ``contact_<material>_<actuator>_<trial>.jpg`` per ramp, photos in manifest order."""
    from pipeline.measure.overlay import contact_sheet

    written = []
    for (material, actuator, trial), g in angles.groupby(["material", "actuator", "trial"], sort=False):
        paths = [overlays_dir / f"{Path(str(i)).stem}.jpg" for i in g["image"]]
        sheet = contact_sheet(paths)
        ok, buf = cv2.imencode(".jpg", sheet, [cv2.IMWRITE_JPEG_QUALITY, 85])
        if ok:
            path = overlays_dir / f"contact_{material}_{actuator}_{trial}.jpg"
            atomic_write_bytes(path, buf.tobytes())
            written.append(path)
    return written


def write_angles(angles: pd.DataFrame, out: str | os.PathLike[str]) -> None:
    """Write angles.csv atomically (failed rows have an empty psi_deg)."""
    path = Path(out)
    path.parent.mkdir(parents=True, exist_ok=True)
    text = angles.to_csv(index=False, lineterminator="\n", float_format="%.6g")
    atomic_write_bytes(path, text.encode())


def summary(angles: pd.DataFrame) -> str:
    """One-line summary of a measured set."""
    counts = angles["status"].value_counts()
    sec = float(np.nansum(angles["seconds"]))
    return (
        f"measured {len(angles)} photos: {counts.get('ok', 0)} ok, {counts.get('flagged', 0)} flagged, "
        f"{counts.get('failed', 0)} failed ({sec:.1f} s of work)"
    )
