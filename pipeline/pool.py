"""One way to map a function over the photos of a set in worker processes.

Workers are started by a forkserver (never plain ``fork``: forking a process that runs OpenCV or
BLAS threads can deadlock), which preloads the light worker modules once so each worker starts
fast; each worker runs OpenCV and BLAS on one thread (the pool is the parallelism; see
:mod:`pipeline.worker_env`).  Results come back in
task order; a progress bar is shown on an interactive terminal only.  On Ctrl-C the workers are
stopped at once (:meth:`multiprocessing.pool.Pool.terminate`), never waited for.
"""

from __future__ import annotations

import multiprocessing
from collections.abc import Callable, Sequence
from typing import TypeVar

T = TypeVar("T")
R = TypeVar("R")


def init_worker() -> None:
    """Pool initialiser: one OpenCV thread per process, and Ctrl-C left to the parent (which
    stops the workers: each printed a KeyboardInterrupt traceback)."""
    import signal

    import cv2

    cv2.setNumThreads(1)
    signal.signal(signal.SIGINT, signal.SIG_IGN)


def map_photos(
    func: Callable[[T], R],
    tasks: Sequence[T],
    *,
    jobs: int = 1,
    preload: Sequence[str] = (),
    desc: str = "photos",
) -> list[R]:
    """``[func(t) for t in tasks]``, in ``jobs`` worker processes when ``jobs > 1``.

    Parameters
    ----------
    func : callable
        A module-level function (picklable); it should not raise for one bad task.
    tasks : sequence
        Picklable task objects.
    jobs : int
        Worker processes; 1 runs in this process.
    preload : sequence of str
        Modules the forkserver imports once for all workers (e.g. ``pipeline.measure.worker``).
    desc : str
        Label of the progress bar.

    Returns
    -------
    list
        One result per task, in order.

    Examples
    --------
    >>> map_photos(abs, [-1, 2, -3])
    [1, 2, 3]
    """
    from tqdm import tqdm

    bar = {"total": len(tasks), "desc": desc, "unit": "photo", "disable": None, "leave": False}
    if jobs <= 1 or len(tasks) <= 1:
        return [func(t) for t in tqdm(tasks, **bar)]  # type: ignore[call-overload]
    methods = multiprocessing.get_all_start_methods()
    ctx = multiprocessing.get_context("forkserver" if "forkserver" in methods else "spawn")
    if "forkserver" in methods:
        ctx.set_forkserver_preload(["pipeline.worker_env", *preload])
    chunk = max(1, len(tasks) // (4 * jobs))
    pool = ctx.Pool(processes=jobs, initializer=init_worker)
    try:
        out = list(tqdm(pool.imap(func, tasks, chunksize=chunk), **bar))  # type: ignore[call-overload]
    except BaseException:
        # Ctrl-C (or any error): the workers are stopped, not waited for.  A process pool shut
        # down by waiting after a KeyboardInterrupt hung now and then with a worker still
        # waiting for work (a Snakemake run's measure job did not stop within 120 s of Ctrl-C)
        pool.terminate()
        pool.join()
        raise
    pool.close()
    pool.join()
    return out
