"""Folders as units: write one whole or not at all, and tell when any file in one has changed.

:func:`staged_folder` lets a stage write its output folder under a temporary name beside it and
renames it into place only when the stage finished, so Ctrl-C, a kill or a crash never leaves a
half-written photo set, overlay folder or benchmark behind.  :func:`update_folder_digest` keeps a
small file whose bytes change exactly when the bytes of a folder's files change (a file replaced,
added or removed); the workflow makes a folder's measure job depend on it.

Examples
--------
>>> import tempfile, pathlib
>>> root = pathlib.Path(tempfile.mkdtemp())
>>> with staged_folder(root / "set", marker="manifest.csv") as tmp:
...     _ = (tmp / "manifest.csv").write_text("image\\n")
...     (root / "set").exists()
False
>>> sorted(p.name for p in root.iterdir())
['set']
"""

from __future__ import annotations

import hashlib
import json
import os
import shutil
from collections.abc import Iterator, Sequence
from contextlib import contextmanager
from pathlib import Path

from pipeline.errors import UserInputError

#: bytes read at a time while hashing
_CHUNK = 1 << 20


def _partial(final: Path) -> Path:
    return final.with_name(f".{final.name}.partial")


def _old(final: Path) -> Path:
    return final.with_name(f".{final.name}.old")


@contextmanager
def staged_folder(final: str | os.PathLike[str], *, marker: str) -> Iterator[Path]:
    """Yield a fresh temporary folder that replaces ``final`` when the block completes.

    The temporary folder is ``.<name>.partial`` beside ``final`` (same file system, so the rename
    is cheap).  On any exception -- including ``KeyboardInterrupt`` and the ``SystemExit`` that
    :func:`pipeline.cli.main` raises on SIGTERM -- it is deleted and ``final`` is left as it was.
    A temporary folder left by a killed run is deleted on the next call.

    Parameters
    ----------
    final : path
        The folder to produce.
    marker : str
        File name (or glob pattern) that a previous output of the same stage holds: an existing
        non-empty ``final`` without it is refused instead of replaced, so a user's own folder is
        never deleted.

    Yields
    ------
    pathlib.Path
        The temporary folder to write into.

    Raises
    ------
    UserInputError
        If ``final`` exists, is not empty and holds no ``marker``.
    """
    final = Path(final)
    ours = final.is_dir() and (not any(final.iterdir()) or any(final.glob(marker)))
    if final.exists() and not ours:
        raise UserInputError(
            f"{final}: exists and is not an output of this command (no {marker} in it), so it is "
            "not replaced; choose a new or empty folder"
        )
    tmp, old = _partial(final), _old(final)
    for stale in (tmp, old):
        if stale.exists():
            shutil.rmtree(stale)
    tmp.mkdir(parents=True)
    try:
        yield tmp
    except BaseException:
        shutil.rmtree(tmp, ignore_errors=True)
        raise
    if final.exists():
        final.rename(old)
    tmp.rename(final)
    shutil.rmtree(old, ignore_errors=True)


def _sha256(path: Path) -> str:
    h = hashlib.sha256()
    with open(path, "rb") as fh:
        while chunk := fh.read(_CHUNK):
            h.update(chunk)
    return h.hexdigest()


def folder_files(folder: str | os.PathLike[str]) -> list[Path]:
    """Every regular file under ``folder`` (recursively), skipping hidden names; sorted.

    Hidden names (``.DS_Store``, ``.x.tmp``, ``.<name>.partial``) are editor, system and
    temporary files, never photos.
    """
    folder = Path(folder)
    out = []
    for root, dirs, files in os.walk(folder):
        dirs[:] = sorted(d for d in dirs if not d.startswith("."))
        out += [Path(root) / f for f in files if not f.startswith(".")]
    return sorted(out)


def folder_sha256(folder: str | os.PathLike[str]) -> tuple[str, int]:
    """SHA-256 over every file of ``folder`` (each file's content hash, size and path relative to
    it, as :func:`update_folder_digest` lists them, so the two agree for a folder that names no file
    outside it), and the number of files.

    Examples
    --------
    >>> import tempfile, pathlib
    >>> d = pathlib.Path(tempfile.mkdtemp())
    >>> _ = (d / "a.jpg").write_bytes(b"one")
    >>> digest, n = folder_sha256(d)
    >>> n, digest == update_folder_digest(d, d / ".state" / "a.sha256").read_text().split()[0]
    (1, True)
    """
    folder = Path(folder)
    files = folder_files(folder) if folder.is_dir() else []
    text = "".join(
        f"{_sha256(p)}  {p.stat().st_size:>12d}  {p.relative_to(folder).as_posix()}\n"
        for p in files
    )
    return hashlib.sha256(text.encode()).hexdigest(), len(files)


def update_folder_digest(
    folder: str | os.PathLike[str],
    digest_file: str | os.PathLike[str],
    extra_files: Sequence[str | os.PathLike[str]] = (),
) -> Path:
    """Write ``digest_file`` with a SHA-256 over every file of ``folder`` (and ``extra_files``, the
    files outside it that it names: :func:`pipeline.photoset.referenced_files`), only when it
    changed.

    The digest covers each file's path (relative to ``folder``), size and content hash, so it
    changes exactly when a file is replaced, added, removed or renamed; touching a file (same
    bytes) leaves it alone.  Content hashes are cached in ``<digest_file>.cache.json`` keyed by
    size, mtime and ctime, so only new or changed files are read again: a re-run over thousands
    of photos costs one ``stat`` each.  Both files are written atomically.

    Parameters
    ----------
    folder : path
        The folder (a missing folder has the digest of an empty one).
    digest_file : path
        Where to keep the digest; its modification time is what a Snakemake rule sees.

    Returns
    -------
    pathlib.Path
        ``digest_file``.

    Examples
    --------
    >>> import tempfile, pathlib, os
    >>> d = pathlib.Path(tempfile.mkdtemp())
    >>> _ = (d / "a.jpg").write_bytes(b"one")
    >>> digest = update_folder_digest(d, d / ".state" / "a.sha256")
    >>> before = digest.read_text()
    >>> os.utime(d / "a.jpg", (1, 1))            # touched: same bytes, same digest
    >>> update_folder_digest(d, digest).read_text() == before
    True
    >>> _ = (d / "a.jpg").write_bytes(b"two")     # replaced: new digest
    >>> update_folder_digest(d, digest).read_text() == before
    False
    """
    folder, digest_file = Path(folder), Path(digest_file)
    cache_file = digest_file.with_name(digest_file.name + ".cache.json")
    try:
        cache = json.loads(cache_file.read_text())
    except (OSError, ValueError):
        cache = {}
    new_cache: dict[str, list[object]] = {}
    lines = []
    inside = folder_files(folder) if folder.is_dir() else []
    outside = sorted({Path(f).resolve() for f in extra_files})
    # a file outside the folder under its absolute path (no relative name can clash with it)
    named = [(p, p.relative_to(folder).as_posix()) for p in inside]
    named += [(p, p.as_posix()) for p in outside if p.is_file()]
    for path, rel in named:
        st = path.stat()
        key = [st.st_size, st.st_mtime_ns, st.st_ctime_ns]
        hit = cache.get(rel)
        known = isinstance(hit, list) and len(hit) == 4 and hit[:3] == key
        sha = hit[3] if known else _sha256(path)
        new_cache[rel] = [*key, sha]
        lines.append(f"{sha}  {st.st_size:>12d}  {rel}\n")
    text = "".join(lines)
    digest = hashlib.sha256(text.encode()).hexdigest()
    body = f"{digest}\n{text}"
    if not digest_file.is_file() or digest_file.read_text().split("\n", 1)[0] != digest:
        _write_atomic(digest_file, body)
    if new_cache != cache:
        _write_atomic(cache_file, json.dumps(new_cache, sort_keys=True))
    return digest_file


def _write_atomic(path: Path, text: str) -> None:
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = path.with_name(f".{path.name}.{os.getpid()}.tmp")
    tmp.write_text(text)
    os.replace(tmp, path)
