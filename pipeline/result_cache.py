"""Each photo's measurement kept on disk, so that an interrupted ``measure`` resumes and a set
with one photo changed measures that photo only.

An entry is named by the sha256 of everything the measurement depends on: the photo's bytes, the
row's resolved settings (an empty scene by its bytes, not its path), the method, the overlay's
title, and the code that measures (every source file of the package and the versions of OpenCV,
NumPy and SciPy), so a changed photo, setting or program is measured again and an entry is
never stale.  Each photo's entry is written by the worker that measured it, as soon as it is
done (atomically: a run cut off leaves whole entries only).  ``measure --cache DIR`` uses one;
the workflow keeps one per dataset under ``results/cache/``.
"""

from __future__ import annotations

import functools
import hashlib
import json
import pickle
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any

import numpy as np

from pipeline.fileio import atomic_write_bytes
from pipeline.measure.worker import Task, run_task

#: the suffixes of an entry's files: its fields, and its overlay when one was drawn
FIELDS, OVERLAY = ".json", ".jpg"


@dataclass(frozen=True)
class CachedTask:
    """A :class:`~pipeline.measure.worker.Task` with the cache entry that holds (or will hold)
    its result: ``entry`` is a path without suffix, None for no cache."""

    task: Task
    entry: str | None = None


@functools.lru_cache(maxsize=1)
def code_fingerprint() -> str:
    """sha256 of the package's source files and the versions of the libraries that measure."""
    import cv2
    import scipy

    root = Path(__file__).resolve().parent
    h = hashlib.sha256()
    for path in sorted(root.rglob("*.py")):
        h.update(path.relative_to(root).as_posix().encode())
        h.update(path.read_bytes())
    h.update(f"{cv2.__version__} {np.__version__} {scipy.__version__}".encode())
    return h.hexdigest()


def _file_digest(path: str) -> str:
    h = hashlib.sha256()
    with open(path, "rb") as fh:
        for block in iter(lambda: fh.read(1 << 20), b""):
            h.update(block)
    return h.hexdigest()


def task_key(task: Task) -> str | None:
    """The name of ``task``'s entry (see the module docstring); None where its photo or empty
    scene cannot be read (it is measured, and fails, every time)."""
    settings = task.settings
    try:
        photo = _file_digest(task.path) if settings is not None else ""
        if settings is not None and settings.background_path is not None:
            settings = replace(settings, background_path=_file_digest(settings.background_path))
    except OSError:
        return None
    h = hashlib.sha256(code_fingerprint().encode())
    h.update(photo.encode())
    h.update(pickle.dumps((settings, task.method, task.title, task.reason)))
    return h.hexdigest()


def cached_tasks(tasks: list[Task], cache_dir: Path | None) -> list[CachedTask]:
    """``tasks`` with their entries in ``cache_dir`` (none without one)."""
    if cache_dir is None:
        return [CachedTask(t) for t in tasks]
    cache_dir.mkdir(parents=True, exist_ok=True)
    out = []
    for t in tasks:
        key = task_key(t)
        out.append(CachedTask(t, None if key is None else str(cache_dir / key)))
    return out


def _encode(value: Any) -> Any:
    if isinstance(value, np.ndarray):
        return {"array": value.tolist(), "shape": list(value.shape)}
    if isinstance(value, (np.floating, np.integer)):
        return value.item()
    return value


def _decode(value: Any) -> Any:
    if isinstance(value, dict) and "array" in value:
        return np.asarray(value["array"], float).reshape(value["shape"])
    return value


def run_cached(item: CachedTask) -> dict[str, Any]:
    """:func:`~pipeline.measure.worker.run_task`, or its result kept in the entry: read back,
    overlay copied, with ``from_cache`` True."""
    task, entry = item.task, item.entry
    if entry is not None:
        fields = Path(entry + FIELDS)
        overlay = Path(entry + OVERLAY)
        if fields.is_file() and (task.overlay_path is None or overlay.is_file()):
            try:
                row = {k: _decode(v) for k, v in json.loads(fields.read_text()).items()}
                if task.overlay_path is not None:
                    Path(task.overlay_path).parent.mkdir(parents=True, exist_ok=True)
                    atomic_write_bytes(task.overlay_path, overlay.read_bytes(), durable=False)
                return {**row, "from_cache": True}
            except (OSError, ValueError):
                pass  # a damaged entry: measured again
    row = run_task(task)
    if entry is not None:  # (an entry without an overlay serves a run that asks for none)
        if task.overlay_path is not None and Path(task.overlay_path).is_file():
            atomic_write_bytes(
                entry + OVERLAY, Path(task.overlay_path).read_bytes(), durable=False
            )
        else:
            Path(entry + OVERLAY).unlink(missing_ok=True)
        text = json.dumps({k: _encode(v) for k, v in row.items()}, allow_nan=True)
        atomic_write_bytes(entry + FIELDS, text.encode(), durable=False)  # last: it is whole
    return {**row, "from_cache": False}


def prune(cache_dir: Path, used: list[CachedTask]) -> None:
    """Delete the entries of ``cache_dir`` that no task of this run used (photos changed or
    gone, settings or code changed): the cache holds one set's current results only."""
    keep = {Path(c.entry).name for c in used if c.entry is not None}
    for path in cache_dir.iterdir():
        stray = path.name.startswith(".") and path.suffix == ".tmp"  # a worker killed mid-write
        if stray or (path.suffix in (FIELDS, OVERLAY) and path.stem not in keep):
            path.unlink(missing_ok=True)
