"""Speed/accuracy and stability study of the angle methods and the model (issue "bench").

Modules: :mod:`grids` (the scenes: one condition swept at a time), :mod:`run` (render and
measure with every method side by side), :mod:`analysis` (tables: speed/accuracy with the
Pareto front, stability, breakdown points, repeatability, adaptive model choice, model cost),
:mod:`charts` (figures), :mod:`pages` (``figures(bench_dir)`` for the report) and :mod:`cli`
(``python -m pipeline bench``).  Findings: ``docs/bench.md``.
"""
