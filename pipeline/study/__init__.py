"""Speed/accuracy and stability study of the angle methods and the model (issue "bench").

Modules: :mod:`grids` (the scenes: one condition swept at a time), :mod:`run` (render and
measure with every method side by side), :mod:`analysis` (tables: speed/accuracy with the
Pareto front, stability, breakdown points, repeatability, adaptive model choice, model cost),
:mod:`model_cost` (the model's time and error against its quadrature grid), :mod:`charts`
(figures) and :mod:`pages` (``figures(bench_dir)`` for the report).  It runs as
``python -m pipeline bench study`` (:mod:`pipeline.bench.study`); it lives below the report,
which draws its pages, while the benchmarks' home :mod:`pipeline.bench` sits above everything it
measures.  Findings: ``docs/bench.md``.
"""
