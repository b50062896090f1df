"""Imported first by the pool's forkserver: one BLAS/OpenMP thread in every worker process.

numpy's and scipy's BLAS start as many threads as the machine has cores when they are loaded.
In a pool of ``jobs`` workers that is ``jobs`` x cores threads on ``cores`` cores: on 2 cores
each photo of a body set took twice as long in a worker as in one process, so ``--jobs 2`` was
no faster than ``--jobs 1``.  BLAS reads these variables once, when it is loaded, so they are
set here, in the forkserver, before it preloads numpy; the workers it forks inherit them.  The
process that starts the pool is not changed.
"""

from __future__ import annotations

import os

#: The thread-count variables of OpenBLAS, OpenMP, MKL, Accelerate and numexpr.
ONE_THREAD_VARIABLES = (
    "OPENBLAS_NUM_THREADS",
    "OMP_NUM_THREADS",
    "MKL_NUM_THREADS",
    "VECLIB_MAXIMUM_THREADS",
    "NUMEXPR_NUM_THREADS",
)

for _name in ONE_THREAD_VARIABLES:
    os.environ[_name] = "1"
