"""Each photo's measurement kept on disk, so that an interrupted ``measure`` resumes and a set
with one photo changed measures that photo only.

An entry is named by the sha256 of everything the measurement depends on: the photo's bytes (as
the worker read them to measure), the row's resolved settings (an empty scene by its bytes, not
its path), the method, the overlay's title, and the code that measures (every source file of the
package and the versions of OpenCV, NumPy and SciPy), so a changed photo, setting or program is
measured again and an entry is never stale.  Each photo's entry is written by the worker that
measured it, as soon as it is done (atomically: a run cut off leaves whole entries only; one that
cannot be written is skipped, the cache being only a saving).  ``measure --cache DIR`` uses one:
a folder of its own, outside the photo set, as :func:`prune` deletes the entries least recently
used beyond twice the set's; the workflow keeps one per dataset under ``results/cache/``.
"""

from __future__ import annotations

import functools
import hashlib
import json
import os
import pickle
import re
import time
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any

import numpy as np

from pipeline.errors import UserInputError
from pipeline.fileio import atomic_write_bytes
from pipeline.measure.worker import Task, run_task

#: the suffixes of an entry's files: its fields, and its overlay when one was drawn
FIELDS, OVERLAY = ".json", ".jpg"
#: an entry's file (what :func:`prune` may delete), and one left half-written by a worker killed
ENTRY = re.compile(r"^[0-9a-f]{64}\.(json|jpg)$")
STRAY = re.compile(r"^\.[0-9a-f]{64}\.(json|jpg)\..*\.tmp$")
#: a half-written file is deleted once older than this (s): younger, another run may be writing it
STRAY_AGE_S = 600.0


@dataclass(frozen=True)
class CachedTask:
    """A :class:`~pipeline.measure.worker.Task` with the cache folder its entry lives in and the
    digest of all but its photo (:func:`settings_key`); None for no cache."""

    task: Task
    folder: str | None = None
    settings_key: str | None = None


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


def settings_key(task: Task, digests: dict[str, str] | None = None) -> str | None:
    """The digest of everything ``task``'s result depends on but its photo (see the module
    docstring); None for a row that cannot be measured or whose empty scene cannot be read (it
    is measured, and fails, every time).  ``digests`` keeps each empty scene's digest over the
    tasks of one run (read once, not once per photo: 84 reads of one 12 MP photo)."""
    settings = task.settings
    if settings is None:
        return None
    known = {} if digests is None else digests
    try:
        if (path := settings.background_path) is not None:
            if path not in known:
                known[path] = _file_digest(path)
            settings = replace(settings, background_path=known[path])
    except OSError:
        return None
    h = hashlib.sha256(code_fingerprint().encode())
    h.update(pickle.dumps((settings, task.method, task.title, task.reason)))
    return h.hexdigest()


def entry_name(key: str, photo: np.ndarray) -> str:
    """The entry of a task of :func:`settings_key` ``key`` measuring ``photo`` (its bytes)."""
    return hashlib.sha256(key.encode() + hashlib.sha256(photo.tobytes()).digest()).hexdigest()


def cached_tasks(tasks: list[Task], cache_dir: Path | None) -> list[CachedTask]:
    """``tasks`` with the cache folder ``cache_dir`` (none without one)."""
    if cache_dir is None:
        return [CachedTask(t) for t in tasks]
    cache_dir.mkdir(parents=True, exist_ok=True)
    digests: dict[str, str] = {}
    return [CachedTask(t, str(cache_dir), settings_key(t, digests)) for t in tasks]


def check_cache_dir(cache_dir: Path, photoset_dir: Path) -> None:
    """Refuse a cache folder that is the photo set's folder or lies inside it: :func:`prune`
    deletes what it does not need there (a customer's review: ``--cache SET`` deleted the set's
    photos).

    Raises
    ------
    UserInputError
        Naming both folders and the fix.
    """
    cache, folder = cache_dir.resolve(), photoset_dir.resolve()
    if cache == folder or folder in cache.parents:
        raise UserInputError(
            f"--cache {cache_dir} lies in the photo set {photoset_dir}: give a folder of its own "
            "outside it (the cache deletes the entries it no longer needs), e.g. "
            f"{photoset_dir.name}_cache beside it"
        )


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
    overlay copied.  The row says whether it came from the cache (``from_cache``) and names its
    entry (``cache_entry``, None without one) for :func:`prune`."""
    task = item.task
    if item.folder is None or item.settings_key is None:
        return {**run_task(task), "from_cache": False, "cache_entry": None}
    try:
        photo = np.fromfile(task.path, dtype=np.uint8)
    except OSError:
        return {**run_task(task), "from_cache": False, "cache_entry": None}
    name = entry_name(item.settings_key, photo)
    entry = Path(item.folder) / name
    fields, overlay = entry.with_suffix(FIELDS), entry.with_suffix(OVERLAY)
    try:
        if fields.is_file() and (task.overlay_path is None or overlay.stat().st_size > 0):
            row = {k: _decode(v) for k, v in json.loads(fields.read_text()).items()}
            if task.overlay_path is not None:
                atomic_write_bytes(task.overlay_path, overlay.read_bytes(), durable=False)
            return {**row, "from_cache": True, "cache_entry": name}
    except (OSError, ValueError):
        pass  # a damaged or missing entry: measured again
    row = run_task(task, photo)
    try:  # (an entry without an overlay serves a run that asks for none)
        if task.overlay_path is not None and Path(task.overlay_path).is_file():
            atomic_write_bytes(overlay, Path(task.overlay_path).read_bytes(), durable=False)
        else:
            overlay.unlink(missing_ok=True)
        text = json.dumps({k: _encode(v) for k, v in row.items()}, allow_nan=True)
        atomic_write_bytes(fields, text.encode(), durable=False)  # last: the entry is whole
    except OSError:
        pass  # a full or read-only disk: this photo is measured again next time
    return {**row, "from_cache": False, "cache_entry": name}


#: a run keeps the entries it did not use (another setting's, a photo's before it was re-shot, an
#: earlier program's) up to this many for each it used, the least recently used deleted first: a
#: setting changed and changed back is read back (customer 33's set was measured again in full)
KEEP_UNUSED_PER_USED = 2


def prune(cache_dir: Path, used: set[str]) -> None:
    """Mark the entries of ``cache_dir`` that this run used as just used, and delete the least
    recently used of the others beyond :data:`KEEP_UNUSED_PER_USED` for each used one, and files
    a killed worker left half-written.  Files that are not entries are never touched."""
    now = time.time()
    unused: dict[str, list[Path]] = {}
    for path in cache_dir.iterdir():
        try:
            if ENTRY.match(path.name):
                if path.stem in used:
                    os.utime(path, (now, now))
                else:
                    unused.setdefault(path.stem, []).append(path)
            elif STRAY.match(path.name) and now - path.stat().st_mtime > STRAY_AGE_S:
                path.unlink(missing_ok=True)
        except OSError:
            continue

    def last_used(stem: str) -> float:
        try:
            return max(p.stat().st_mtime for p in unused[stem])
        except OSError:
            return 0.0

    newest_first = sorted(unused, key=lambda stem: (-last_used(stem), stem))
    for stem in newest_first[KEEP_UNUSED_PER_USED * len(used) :]:
        for path in unused[stem]:
            path.unlink(missing_ok=True)
