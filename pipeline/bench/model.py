"""Speed and accuracy of the model against the quadrature size: ``python -m pipeline bench model``.

Times full P(psi) curves of 4 materials x 400 angles (forward) and 400 pressures (the loading
inverse) at each quadrature grid size, against the error relative to a fine reference grid
(:func:`pipeline.study.model_cost.benchmark_model`); prints figures, asserts nothing.
"""

from __future__ import annotations

import argparse
from collections.abc import Sequence

import pandas as pd

from pipeline.study.model_cost import benchmark_model


def format_benchmark(df: pd.DataFrame) -> str:
    """Human-readable table of :func:`~pipeline.study.model_cost.benchmark_model` (times in ms)."""
    out = df.copy()
    for col in ("forward_seconds", "inverse_seconds", "seconds", "cpu_seconds"):
        out[col.replace("seconds", "ms")] = (out.pop(col) * 1e3).round(3)
    return out.to_string(index=False, float_format=lambda v: f"{v:.3g}")


def main(argv: Sequence[str] | None = None) -> int:
    """Print the benchmark (4 materials x 400 angles forward + 400 pressures inverse)."""
    parser = argparse.ArgumentParser(
        prog="python -m pipeline bench model", description=__doc__.splitlines()[0]
    )
    parser.add_argument("--grid-sizes", type=int, nargs="+", default=[2, 3, 4, 6, 8, 12],
                        help="grid sizes n (n_tau = n, n_phi = 2n nodes); default 2 3 4 6 8 12")
    args = parser.parse_args(argv)
    df = benchmark_model(grid_sizes=args.grid_sizes)
    print(
        "model benchmark: 4 materials x 400 angles (forward) + 400 pressures (loading inverse), "
        "one process"
    )
    print(format_benchmark(df))
    default = df[df.grid_n == 4]
    if len(default):
        print(
            f"default grid (grid_n=4): {1e3 * float(default.seconds.iloc[0]):.2f} ms wall, "
            f"{1e3 * float(default.cpu_seconds.iloc[0]):.2f} ms CPU in total (target < 10 ms)"
        )
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
