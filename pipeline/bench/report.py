"""Benchmark of aggregate -> compare -> report on synthetic angles tables; prints the timings.

Run ``python -m pipeline bench report [--trials N]``.  The angles are drawn from the model
(loading branch, 4 deg noise, decreasing branch 10 % lower in pressure), 3 actuators per material,
10 kPa steps as in the paper; no photos (the strip then says so).
"""

from __future__ import annotations

import argparse
import tempfile
import time
from collections.abc import Sequence
from pathlib import Path

import numpy as np
import pandas as pd

from pipeline.aggregate import aggregate_hysteresis
from pipeline.compare import compare, model_callables
from pipeline.fileio import write_table
from pipeline.report.build import build_report
from pipeline.report.data import Dataset, ReportInputs

P_MAX_KPA = {"DS20": 110.0, "DS30": 170.0, "SS40": 250.0, "SS50": 250.0}


def synthetic_angles(material: str, trials: int, seed: int) -> pd.DataFrame:
    """angles.csv-shaped rows drawn from the model with noise."""
    from pipeline import model

    rng = np.random.default_rng(seed)
    levels = np.arange(0.0, P_MAX_KPA[material] + 1e-9, 10.0)
    rows = []
    for actuator in ("1", "2", "3"):
        for trial in range(1, trials + 1):
            for direction, order in (("up", levels), ("down", levels[::-1])):
                scale = 1.0 if direction == "up" else 1.1
                psi = model.psi_deg(material, order * scale) + rng.normal(0.0, 4.0, order.size)
                for p, s in zip(order, psi, strict=True):
                    ok = bool(np.isfinite(s))
                    rows.append(
                        {
                            "image": f"{material}_{actuator}_{trial}_{direction}_{p:g}.jpg",
                            "psi_deg": s,
                            "status": "ok" if ok else "failed",
                            "reason": "" if ok else "beyond model",
                            "pressure_kpa": p,
                            "direction": direction,
                            "material": material,
                            "actuator": actuator,
                            "trial": trial,
                        }
                    )
    return pd.DataFrame(rows)


def main(argv: Sequence[str] | None = None) -> int:
    """Time each stage and print one line per stage."""
    parser = argparse.ArgumentParser(
        prog="python -m pipeline bench report", description=__doc__.splitlines()[0]
    )
    parser.add_argument(
        "--trials", type=int, default=6, help="trials per actuator (default 6, as the paper)"
    )
    args = parser.parse_args(argv)
    with tempfile.TemporaryDirectory() as tmp:
        root = Path(tmp)
        datasets, frames = [], []
        for i, m in enumerate(P_MAX_KPA):
            a = synthetic_angles(m, args.trials, seed=i)
            write_table(a, root / f"{m}.csv", float_format=None)
            datasets.append(Dataset(m, root / f"{m}.csv"))
            frames.append(a)
        angles = pd.concat(frames, ignore_index=True)
        t0 = time.perf_counter()
        hyst = aggregate_hysteresis(angles)
        t1 = time.perf_counter()
        model_psi, fit_k_p, psi0 = model_callables()
        table = compare(
            hyst, angles, model_psi=model_psi, fit_k_p=fit_k_p, psi0_deg=psi0, n_boot=200, seed=0
        )
        t2 = time.perf_counter()
        write_table(hyst, root / "h.csv", float_format=None)
        write_table(table, root / "rms.csv", float_format=None)
        result = build_report(ReportInputs(datasets=tuple(datasets), hysteresis=(root / "h.csv",),
                                           rms=(root / "rms.csv",)), root / "report.pdf")
        t3 = time.perf_counter()
        size_kb = (root / "report.pdf").stat().st_size / 1024
    print(
        f"rows: {len(angles)} angles, {len(hyst)} hysteresis levels, 4 materials x 3 actuators x "
        f"{args.trials} trials"
    )
    print(f"aggregate: {1e3 * (t1 - t0):.1f} ms")
    print(f"compare (RMS, crossings, k_P + 200 bootstrap resamples per material): {t2 - t1:.2f} s")
    print(f"report: {t3 - t2:.2f} s for {result.pages} pages, {size_kb:.0f} kB")
    for r in table.itertuples():
        print(
            f"  {r.material}: RMS {r.rms_deg:.1f} deg, k_P {r.k_p_fit:.2f} [{r.k_p_ci_low:.2f}, "
            f"{r.k_p_ci_high:.2f}]"
            f" (model k_P {r.k_p_paper})"
        )
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
