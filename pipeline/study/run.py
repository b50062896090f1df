"""Render every scene of a grid and measure it with every angle method the way the pipeline does.

For each :class:`~pipeline.study.grids.Case` one worker renders the photo with
:func:`pipeline.synth.render_actuator`, writes its JPEG bytes (the scene's quality) to a file and
measures that file once per method of :data:`pipeline.measure.METHODS` through
:func:`pipeline.measure.worker.run_task` -- the very function
:func:`pipeline.measure.measure_photoset` runs per photo: file read, reduced (grey for a black
line) JPEG decode, extraction on a halved copy refined on the decoded image, and the fall-back
to the decoded-size path when that is not ``ok``.  ``seconds`` is that call's own timing (the
``seconds`` column of angles.csv: read + decode + measurement); ``decode_seconds`` is the first
decode alone (:func:`pipeline.measure.core.decode_for_work`, timed once per image, already
contained in ``seconds``).  The methods run side by side on the same file, their order rotating
from one image to the next so that no method always runs first on a cold cache.  Workers run
single-threaded OpenCV (``cv2.setNumThreads(1)``), so ``--jobs N`` uses N cores and times are
per core.

``degree`` is the complexity of the curve model the method used (``AngleResult.degree``,
the angles.csv column: 1 = circular arc; more only for the adaptive ``turning`` / ``auto``);
NaN when the photo failed.
"""

from __future__ import annotations

import tempfile
import time
from collections.abc import Callable, Sequence
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from pipeline.study.grids import Case

#: columns of the per-image results table, in order
RESULT_COLUMNS: tuple[str, ...] = (
    "case_id", "kind", "condition", "value", "nominal", "psi_true_deg", "bulge", "seed",
    "width_px", "line_length_px", "method", "psi_deg", "error_deg", "abs_error_deg", "status",
    "reason", "degree", "residual_px", "seconds", "decode_seconds", "render_seconds",
)


def _init_worker() -> None:
    from pipeline.pool import init_worker

    init_worker()


def render_case(case: Case) -> tuple[Any, Any]:
    """The scene and the rendered photo of one case (deterministic in the case).

    Returns
    -------
    scene : pipeline.synth.SceneParams
    rendered : pipeline.synth.RenderedImage
        ``jpeg_bytes`` (the photo file), ``fixed_end_px`` (clamp pixel) among others.
    """
    from pipeline.synth import render_actuator, scene_from

    scene = scene_from(case.preset, **dict(case.overrides))
    return scene, render_actuator(case.psi_deg, case.l0_mm, scene, seed=case.seed, bulge=case.bulge)


def measure_case(case: Case, methods: Sequence[str], workdir: str | Path) -> list[dict[str, Any]]:
    """Render one case, write it as a JPEG file and measure the file with every method.

    Parameters
    ----------
    case : Case
    methods : sequence of str
        Keys of :data:`pipeline.measure.METHODS`.
    workdir : path
        Existing folder for the photo file (removed again before returning).

    Returns
    -------
    list of dict
        Rows with the keys of :data:`RESULT_COLUMNS`, in the order of ``methods``.
    """
    from pipeline.measure.core import decode_for_work, decodes_grey
    from pipeline.measure.settings import resolve_settings
    from pipeline.measure.worker import Task, run_task

    t0 = time.perf_counter()
    scene, rendered = render_case(case)
    render_s = time.perf_counter() - t0
    path = Path(workdir) / f"case_{case.case_id:06d}.jpg"
    path.write_bytes(rendered.jpeg_bytes)
    settings = resolve_settings(  # as measure_photoset hands the settings to its workers
        l0_mm=case.l0_mm, mm_per_px=scene.mm_per_px, line_color=scene.line_color,
        fixed_end=[float(v) for v in rendered.fixed_end_px], positive_turn="ccw",
    )
    t1 = time.perf_counter()
    decode_for_work(np.frombuffer(rendered.jpeg_bytes, dtype=np.uint8), grey=decodes_grey(settings))
    decode_s = time.perf_counter() - t1
    k = case.case_id % max(len(methods), 1)
    order = list(methods[k:]) + list(methods[:k])
    out: dict[str, dict[str, Any]] = {}
    try:
        for method in order:
            row = run_task(Task(str(path), settings, method))
            err = row["psi_deg"] - case.psi_deg
            out[method] = {
                "case_id": case.case_id,
                "kind": case.kind,
                "condition": case.condition,
                "value": case.value,
                "nominal": case.nominal,
                "psi_true_deg": case.psi_deg,
                "bulge": case.bulge,
                "seed": case.seed,
                "width_px": scene.width,
                "line_length_px": case.l0_mm / scene.mm_per_px,
                "method": method,
                "psi_deg": row["psi_deg"],
                "error_deg": err,
                "abs_error_deg": abs(err),
                "status": row["status"],
                "reason": row["reason"],
                "degree": np.nan if row["degree"] is None else float(row["degree"]),
                "residual_px": row["residual_px"],
                "seconds": row["seconds"],
                "decode_seconds": decode_s,
                "render_seconds": render_s,
            }
    finally:
        path.unlink(missing_ok=True)
    return [out[m] for m in methods]


def _measure_chunk(chunk: list[Case], methods: tuple[str, ...]) -> list[dict[str, Any]]:
    with tempfile.TemporaryDirectory(prefix="pipeline_bench_") as workdir:
        return [row for case in chunk for row in measure_case(case, methods, workdir)]


def run_grid(
    cases: Sequence[Case],
    *,
    methods: Sequence[str] | None = None,
    jobs: int = 1,
    progress: Callable[[int, int], None] | None = None,
) -> pd.DataFrame:
    """Render and measure every case, with ``jobs`` worker processes.

    Parameters
    ----------
    cases : sequence of Case
        From :func:`pipeline.study.grids.cases`.
    methods : sequence of str, optional
        Methods to compare (default: every key of :data:`pipeline.measure.METHODS`).
    jobs : int
        Worker processes (1 = run in this process).
    progress : callable, optional
        Called as ``progress(done, total)`` after each chunk of images.

    Returns
    -------
    DataFrame
        One row per case and method, columns :data:`RESULT_COLUMNS`, ordered by case then
        method (deterministic except for the timing columns).
    """
    from pipeline.measure import METHODS

    methods = tuple(METHODS) if methods is None else tuple(methods)
    unknown = [m for m in methods if m not in METHODS]
    if unknown:
        raise ValueError(f"unknown method(s) {unknown}; use {sorted(METHODS)}")
    # small chunks, interleaved so that every worker gets a mix of cheap and costly scenes
    size = 4
    chunks = [list(cases[i:i + size]) for i in range(0, len(cases), size)]
    rows: list[dict[str, Any]] = []
    if jobs <= 1:
        _init_worker()
        for i, chunk in enumerate(chunks):
            rows.extend(_measure_chunk(chunk, methods))
            if progress:
                progress(min((i + 1) * size, len(cases)), len(cases))
    else:
        with ProcessPoolExecutor(max_workers=jobs, initializer=_init_worker) as pool:
            futures = [pool.submit(_measure_chunk, chunk, methods) for chunk in chunks]
            for i, fut in enumerate(futures):
                rows.extend(fut.result())
                if progress:
                    progress(min((i + 1) * size, len(cases)), len(cases))
    return pd.DataFrame(rows, columns=list(RESULT_COLUMNS))
