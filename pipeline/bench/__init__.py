"""Every benchmark, in one home with one entry point: ``python -m pipeline bench WHAT [options]``.

Benchmarks print figures (ratios side by side in one run); they are not timed tests.  Each
module is one benchmark with a ``main(argv)`` (also runnable as ``python -m pipeline.bench.WHAT``);
:mod:`pipeline.bench.cli` lists them.  This package sits above everything it measures and
nothing of the pipeline imports it.
"""
