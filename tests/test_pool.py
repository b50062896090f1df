"""The photo pool: results in order, and one BLAS thread in each worker."""

from __future__ import annotations

import os

import pytest

from pipeline.pool import map_photos
from pipeline.worker_env import ONE_THREAD_VARIABLES


def test_workers_run_blas_on_one_thread_and_the_caller_is_left_as_it_was(monkeypatch):
    # BLAS starts one thread per core in every worker unless told otherwise: with two workers
    # on two cores a body photo took twice as long in a worker as in one process, and
    # --jobs 2 was no faster than --jobs 1 (3.2 s against 3.0 s on 40 photos at 720p)
    monkeypatch.setenv("OPENBLAS_NUM_THREADS", "4")
    seen = map_photos(os.getenv, list(ONE_THREAD_VARIABLES) * 2, jobs=2)
    assert seen == ["1"] * (2 * len(ONE_THREAD_VARIABLES))
    assert os.environ["OPENBLAS_NUM_THREADS"] == "4"
    assert map_photos(abs, list(range(-9, 0)), jobs=2) == list(range(9, 0, -1))


@pytest.mark.parametrize("jobs", [1, 2])
def test_without_a_terminal_progress_is_written_as_lines(monkeypatch, capsys, jobs):
    # a Snakemake job's log (stderr to a file) stayed empty until measure ended (customer 33)
    import pipeline.pool

    monkeypatch.setattr(pipeline.pool, "PROGRESS_EVERY_S", 0.0)
    assert map_photos(abs, list(range(-5, 0)), jobs=jobs, desc="measure") == [5, 4, 3, 2, 1]
    lines = capsys.readouterr().err.splitlines()
    assert lines[0].startswith("measure: 1 of 5 done (") and len(lines) == 4, lines
