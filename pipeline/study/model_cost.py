"""Time and error of the model against its quadrature grid size: the study's ``model_cost.csv``.

``python -m pipeline bench model`` prints the table (:mod:`pipeline.bench.model`).
"""

from __future__ import annotations

import time
from collections.abc import Sequence
from typing import Any

import numpy as np
import pandas as pd

from pipeline.model.forward import pressure_core
from pipeline.model.inverse import psi_deg
from pipeline.model.materials import Material, load_materials
from pipeline.model.options import make_options

MATERIALS: tuple[str, ...] = ("DS20", "DS30", "SS40", "SS50")


def grid_options(grid_n: int) -> dict[str, int]:
    """Node counts of grid size ``grid_n``: n_tau = n, n_phi = 2n, n_beta = max(2, 3n // 4).

    ``grid_n = 4`` is the default (4, 8, 3).
    """
    return {
        "n_tau": int(grid_n),
        "n_phi": 2 * int(grid_n),
        "n_beta": max(2, (3 * int(grid_n)) // 4),
    }


def _best_time(fn: Any, repeats: int) -> tuple[float, float]:
    """Best wall-clock and best process-CPU time of ``repeats`` calls (s)."""
    wall, cpu = np.inf, np.inf
    for _ in range(repeats):
        t, c = time.perf_counter(), time.process_time()
        fn()
        wall = min(wall, time.perf_counter() - t)
        cpu = min(cpu, time.process_time() - c)
    return float(wall), float(cpu)


def benchmark_model(
    grid_sizes: Sequence[int] = (2, 3, 4, 6, 8, 12),
    n_angles: int = 400,
    n_pressures: int = 400,
    reference_n: int = 32,
    repeats: int = 7,
    materials: Sequence[str] = MATERIALS,
    **options: Any,
) -> pd.DataFrame:
    """Time full P(psi) curves and the loading inverse for every material at several grid sizes.

    Parameters
    ----------
    grid_sizes : sequence of int
        Quadrature sizes, see :func:`grid_options`.
    n_angles : int
        Angles per forward curve (psi0 down to -360 deg).
    n_pressures : int
        Pressures per inverse (0 up to the pressure at -360 deg on the reference grid).
    reference_n : int
        Grid size of the reference solution the errors are measured against.
    repeats : int
        Timings are the best of this many runs.
    materials : sequence of str
    **options
        Model readings (see :class:`pipeline.model.options.ModelOptions`).

    Returns
    -------
    pandas.DataFrame
        One row per grid size: ``grid_n``, ``n_tau``, ``n_phi``, ``n_beta``, ``nodes`` (wall nodes
        per angle), ``forward_seconds`` (all materials, ``n_angles`` each), ``inverse_seconds``
        (all materials, ``n_pressures`` each), ``seconds`` (sum; wall clock, best of ``repeats``),
        ``cpu_seconds`` (same, process CPU time: robust when other jobs share the cores),
        ``max_rel_error`` (forward P vs
        the reference grid, over all materials and angles), ``inverse_max_abs_error_deg``.
    """
    table = load_materials()
    mats: list[Material] = [table[m] for m in materials]
    psi = {m.name: np.linspace(m.psi0_deg, -360.0, n_angles) for m in mats}
    ref_kw = {**options, **grid_options(reference_n)}
    ref_p = {}
    pressures = {}
    ref_psi = {}
    for m in mats:
        ref_p[m.name], _ = pressure_core(m, np.radians(psi[m.name]), make_options(**ref_kw))
        top = float(np.nanmax(ref_p[m.name])) if np.isfinite(ref_p[m.name]).any() else 0.0
        pressures[m.name] = np.linspace(0.0, top, n_pressures)
        ref_psi[m.name] = psi_deg(m, pressures[m.name], **ref_kw)
    rows = []
    for n in grid_sizes:
        kw = {**options, **grid_options(n)}

        def forward(kw: dict[str, Any] = kw) -> None:
            for m in mats:
                pressure_core(m, np.radians(psi[m.name]), make_options(**kw))

        def inverse(kw: dict[str, Any] = kw) -> None:
            for m in mats:
                psi_deg(m, pressures[m.name], **kw)

        t_fwd, c_fwd = _best_time(forward, repeats)
        t_inv, c_inv = _best_time(inverse, repeats)
        rel, dpsi = 0.0, 0.0
        for m in mats:
            p, _ = pressure_core(m, np.radians(psi[m.name]), make_options(**kw))
            ok = np.isfinite(p) & np.isfinite(ref_p[m.name]) & (np.abs(ref_p[m.name]) > 1e-9)
            if ok.any():
                rel = max(rel, float(np.max(np.abs(p[ok] / ref_p[m.name][ok] - 1.0))))
            q = psi_deg(m, pressures[m.name], **kw)
            ok = np.isfinite(q) & np.isfinite(ref_psi[m.name])
            if ok.any():
                dpsi = max(dpsi, float(np.max(np.abs(q[ok] - ref_psi[m.name][ok]))))
        g = grid_options(n)
        rows.append(
            {
                "grid_n": int(n),
                **g,
                "nodes": g["n_tau"] * g["n_phi"],
                "forward_seconds": t_fwd,
                "inverse_seconds": t_inv,
                "seconds": t_fwd + t_inv,
                "cpu_seconds": c_fwd + c_inv,
                "max_rel_error": rel,
                "inverse_max_abs_error_deg": dpsi,
            }
        )
    return pd.DataFrame(rows)
