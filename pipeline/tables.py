"""Reading the CSV tables the stages pass to each other, with one clear error for bad input."""

from __future__ import annotations

import os
from collections.abc import Sequence
from typing import Any

import pandas as pd

from pipeline.errors import UserInputError


def read_table(
    path: str | os.PathLike[str], what: str, *, required: Sequence[str] = (), hint: str = "", **read_csv: Any
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
        raise UserInputError(f"{path}: not a readable CSV ({exc}); fix or regenerate {what}") from None
    missing = [c for c in required if c not in df.columns]
    if missing:
        raise UserInputError(f"{path}: missing column(s) {missing}; pass {what}" + (f" ({hint})" if hint else ""))
    return df
