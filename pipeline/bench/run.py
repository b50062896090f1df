"""Render every scene of a grid and measure it with every angle method, side by side.

For each :class:`~pipeline.bench.grids.Case` one worker renders the photo with
:func:`pipeline.synth.render_actuator`, encodes it as JPEG with the scene's quality, decodes it
once (timed on its own: ``decode_seconds``) and runs every method of
:data:`pipeline.measure.METHODS` through :func:`pipeline.measure.measure_image` on that *same*
decoded image (each call timed: ``seconds``).  The order of the methods rotates from one image
to the next so that no method always runs first on a cold cache.  Workers run single-threaded
OpenCV (``cv2.setNumThreads(1)``), so ``--jobs N`` uses N cores and times are per core.

The adaptive estimators' chosen model (``turning`` and ``auto``: complexity of the curve model,
1 = constant curvature) is read from ``AngleResult.degree`` by :func:`chosen_degree`.
"""

from __future__ import annotations

import time
from collections.abc import Callable, Sequence
from concurrent.futures import ProcessPoolExecutor
from dataclasses import asdict
from typing import Any

import numpy as np
import pandas as pd

from pipeline.bench.grids import Case

#: columns of the per-image results table, in order
RESULT_COLUMNS: tuple[str, ...] = (
    "case_id", "kind", "condition", "value", "nominal", "psi_true_deg", "bulge", "seed",
    "width_px", "line_length_px", "method", "psi_deg", "error_deg", "abs_error_deg", "status",
    "reason", "degree", "residual_px", "seconds", "decode_seconds", "render_seconds",
)


def _init_worker() -> None:
    import cv2

    cv2.setNumThreads(1)


#: methods whose curve model is adaptive (their chosen degree is recorded)
ADAPTIVE_METHODS: tuple[str, ...] = ("turning", "auto")


def chosen_degree(res: Any) -> float:
    """Curve-model degree an estimator chose on a photo (1 = constant curvature).

    Parameters
    ----------
    res : pipeline.measure.AngleResult
        The measurement.

    Returns
    -------
    float
        ``res.degree``; NaN when the measurement failed.
    """
    return float("nan") if res.status == "failed" else float(res.degree)


def measure_case(case: Case, methods: Sequence[str]) -> list[dict[str, Any]]:
    """Render one case and measure it with every method; one result row per method.

    Parameters
    ----------
    case : Case
    methods : sequence of str
        Keys of :data:`pipeline.measure.METHODS`.

    Returns
    -------
    list of dict
        Rows with the keys of :data:`RESULT_COLUMNS`.
    """
    import cv2

    from pipeline.measure import measure_image
    from pipeline.synth import render_actuator, scene_from

    t0 = time.perf_counter()
    scene = scene_from(case.preset, **dict(case.overrides))
    rendered = render_actuator(case.psi_deg, case.l0_mm, scene, seed=case.seed, bulge=case.bulge)
    data = np.frombuffer(rendered.jpeg_bytes, dtype=np.uint8)
    t1 = time.perf_counter()
    image = cv2.imdecode(data, cv2.IMREAD_COLOR)
    decode_s = time.perf_counter() - t1
    render_s = t1 - t0
    k = case.case_id % max(len(methods), 1)
    order = list(methods[k:]) + list(methods[:k])
    out: dict[str, dict[str, Any]] = {}
    for method in order:
        t = time.perf_counter()
        res = measure_image(
            image, l0_mm=case.l0_mm, mm_per_px=scene.mm_per_px, line_color=scene.line_color,
            fixed_end_px=rendered.fixed_end_px, positive_turn="ccw", method=method,
        )
        seconds = time.perf_counter() - t
        degree = chosen_degree(res) if method in ADAPTIVE_METHODS else None
        err = res.psi_deg - case.psi_deg
        out[method] = {
            "case_id": case.case_id, "kind": case.kind, "condition": case.condition, "value": case.value,
            "nominal": case.nominal, "psi_true_deg": case.psi_deg, "bulge": case.bulge, "seed": case.seed,
            "width_px": scene.width, "line_length_px": case.l0_mm / scene.mm_per_px, "method": method,
            "psi_deg": res.psi_deg, "error_deg": err, "abs_error_deg": abs(err), "status": res.status,
            "reason": res.reason, "degree": np.nan if degree is None else float(degree),
            "residual_px": res.residual_px, "seconds": seconds, "decode_seconds": decode_s,
            "render_seconds": render_s,
        }
    return [out[m] for m in methods]


def _measure_chunk(chunk: list[Case], methods: tuple[str, ...]) -> list[dict[str, Any]]:
    return [row for case in chunk for row in measure_case(case, methods)]


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
        From :func:`pipeline.bench.grids.cases`.
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


def cases_table(cases: Sequence[Case]) -> pd.DataFrame:
    """The cases as a table (what was rendered), for the record."""
    return pd.DataFrame([{**asdict(c), "overrides": ";".join(f"{k}={v}" for k, v in c.overrides)} for c in cases])
