"""One way to map a function over the photos of a set in worker processes.

Workers are started by a forkserver (never plain ``fork``: forking a process that runs OpenCV or
BLAS threads can deadlock), which preloads the light worker modules once so each worker starts
fast; each worker runs OpenCV and BLAS on one thread (the pool is the parallelism; see
:mod:`pipeline.worker_env`).  Results come back in
task order; a progress bar is shown on an interactive terminal, and elsewhere (a Snakemake job's
log) a line of progress every :data:`PROGRESS_EVERY_S`.  On Ctrl-C the workers are stopped at
once (:meth:`multiprocessing.pool.Pool.terminate`), never waited for.
"""

from __future__ import annotations

import multiprocessing
import sys
import time
from collections.abc import Callable, Iterable, Iterator, Sequence
from typing import TextIO, TypeVar

T = TypeVar("T")
R = TypeVar("R")

#: without a terminal, a line of progress at most this often (s): a measure job's log stayed
#: empty until it ended (customer 33), so a long one could not be watched
PROGRESS_EVERY_S = 30.0


def progress_lines(
    results: Iterable[R], total: int, desc: str, every_s: float, out: TextIO
) -> Iterator[R]:
    """``results``, writing ``"<desc>: i of total done (s s)"`` to ``out`` at most every
    ``every_s`` seconds (never for the last one: the caller's summary follows).

    Examples
    --------
    >>> import io
    >>> log = io.StringIO()
    >>> list(progress_lines(range(3), 3, "photos", 0.0, log)), log.getvalue()
    ([0, 1, 2], 'photos: 1 of 3 done (0 s)\\nphotos: 2 of 3 done (0 s)\\n')
    """
    start = last = time.monotonic()
    for i, result in enumerate(results, 1):
        now = time.monotonic()
        if i < total and now - last >= every_s:
            print(f"{desc}: {i} of {total} done ({now - start:.0f} s)", file=out, flush=True)
            last = now
        yield result


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

    def shown(results: Iterable[R]) -> Iterable[R]:
        if sys.stderr.isatty():
            bar = {"total": len(tasks), "desc": desc, "unit": "photo", "leave": False}
            return tqdm(results, **bar)  # type: ignore[call-overload,no-any-return]
        return progress_lines(results, len(tasks), desc, PROGRESS_EVERY_S, sys.stderr)

    if jobs <= 1 or len(tasks) <= 1:
        return list(shown(func(t) for t in tasks))
    methods = multiprocessing.get_all_start_methods()
    ctx = multiprocessing.get_context("forkserver" if "forkserver" in methods else "spawn")
    if "forkserver" in methods:
        ctx.set_forkserver_preload(["pipeline.worker_env", *preload])
    chunk = max(1, len(tasks) // (4 * jobs))
    pool = ctx.Pool(processes=jobs, initializer=init_worker)
    try:
        out = list(shown(pool.imap(func, tasks, chunksize=chunk)))
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
