"""Files the stages write and read: atomic writes, and the CSV tables passed between stages.

Every file a stage produces is written atomically (temporary file in the same folder, fsync,
rename), so an interrupted run never leaves a half-written table, photo or report; tables are
written with one float format and read back through :func:`read_table`, which refuses a missing,
unreadable or incomplete file with one clear message.
"""

from __future__ import annotations

import os
import tempfile
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import pandas as pd

from pipeline.errors import UserInputError


def read_table(
    path: str | os.PathLike[str],
    what: str,
    *,
    required: Sequence[str] = (),
    hint: str = "",
    **read_csv: Any,
) -> pd.DataFrame:
    """Read a CSV table, refusing a missing, unreadable or incomplete file with a clear message.

    Parameters
    ----------
    path : path
        The CSV file.
    what : str
        What the file should be, for messages, e.g. ``"an angles.csv written by 'measure'"``.
    required : sequence of str
        Columns that must be present.
    hint : str
        Extra advice appended when a column is missing.
    **read_csv
        Passed to :func:`pandas.read_csv` (e.g. ``dtype``).

    Returns
    -------
    pandas.DataFrame

    Raises
    ------
    UserInputError
        Naming the file and the fix.

    Examples
    --------
    >>> import tempfile, pathlib
    >>> p = pathlib.Path(tempfile.mkdtemp()) / "t.csv"
    >>> _ = p.write_text("a,b\\n1,2\\n")
    >>> read_table(p, "a table", required=["a"]).shape
    (1, 2)
    """
    try:
        df = pd.read_csv(path, **read_csv)
    except FileNotFoundError:
        raise UserInputError(f"{path}: file not found; pass {what}") from None
    except (pd.errors.ParserError, pd.errors.EmptyDataError, UnicodeDecodeError) as exc:
        raise UserInputError(
            f"{path}: not a readable CSV ({exc}); fix or regenerate {what}"
        ) from None
    missing = [c for c in required if c not in df.columns]
    if missing:
        raise UserInputError(
            f"{path}: missing column(s) {missing}; pass {what}" + (f" ({hint})" if hint else "")
        )
    return df


#: float format of every CSV table the pipeline writes (6 significant digits)
FLOAT_FORMAT = "%.6g"


def atomic_write_bytes(path: str | os.PathLike[str], data: bytes) -> None:
    """Write ``data`` to ``path`` atomically: temporary file in the same folder, fsync, rename.

    The folder is created when missing; the file gets the usual permissions (umask), not the
    0600 of a temporary file.

    Examples
    --------
    >>> import tempfile, pathlib
    >>> p = pathlib.Path(tempfile.mkdtemp()) / "sub" / "x.txt"
    >>> atomic_write_bytes(p, b"hello")
    >>> p.read_bytes()
    b'hello'
    """
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=f".{path.name}.", suffix=".tmp")
    try:
        os.fchmod(fd, 0o666 & ~_current_umask())
        with os.fdopen(fd, "wb") as fh:
            fh.write(data)
            fh.flush()
            os.fsync(fh.fileno())
        os.replace(tmp, path)
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise
    _fsync_dir(path.parent)


def _current_umask() -> int:
    mask = os.umask(0o022)
    os.umask(mask)
    return mask


def _fsync_dir(folder: Path) -> None:
    try:
        fd = os.open(folder, os.O_RDONLY)
    except OSError:
        return
    try:
        os.fsync(fd)
    except OSError:
        pass
    finally:
        os.close(fd)


def table_bytes(table: pd.DataFrame, float_format: str | None = FLOAT_FORMAT) -> bytes:
    """The CSV bytes of a table as every stage writes it (no index, ``\\n`` line ends)."""
    return table.to_csv(index=False, lineterminator="\n", float_format=float_format).encode()


def write_table(
    table: pd.DataFrame, path: str | os.PathLike[str], float_format: str | None = FLOAT_FORMAT
) -> None:
    """Write a table as CSV atomically (folder created, :data:`FLOAT_FORMAT` floats).

    ``float_format=None`` keeps every digit (tables later stages compute on, inputs as given).

    Examples
    --------
    >>> import tempfile, pathlib
    >>> p = pathlib.Path(tempfile.mkdtemp()) / "t.csv"
    >>> write_table(pd.DataFrame({"psi_deg": [1 / 3]}), p)
    >>> p.read_text()
    'psi_deg\\n0.333333\\n'
    """
    atomic_write_bytes(path, table_bytes(table, float_format))
