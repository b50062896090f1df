"""Files the stages write and read: atomic writes, and the CSV tables passed between stages.

Every file a stage produces is written atomically (temporary file in the same folder, fsync,
rename), so an interrupted run never leaves a half-written table, photo or report; tables are
written with one float format and read back through :func:`read_table`, which refuses a missing,
unreadable or incomplete file with one clear message.  Tables a person writes (a photo set's
``manifest.csv``, a pressure log, a grasp log) are read by :func:`read_user_csv`, which also takes
what a spreadsheet saves: ``;`` between fields and decimal commas (Excel where the decimal mark is
a comma), tabs, a Windows code page, spaces after the separators.
"""

from __future__ import annotations

import csv
import io
import os
import re
import tempfile
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from pipeline.errors import UserInputError

#: field separators a spreadsheet may save a CSV with: ',' (English locales), ';' (Excel where the
#: decimal mark is a comma: most of Europe), tab ("text, tab delimited")
SEPARATORS = (",", ";", "\t")
#: a cell holding one number with a decimal comma, as such a spreadsheet writes it
_DECIMAL_COMMA = re.compile(r"\s*[+-]?\d*,\d+\s*")


#: how a spreadsheet's own file begins (zip: .xlsx, .ods; OLE: .xls), which is not CSV text
WORKBOOK_SIGNATURES: tuple[bytes, ...] = (b"PK\x03\x04", b"\xd0\xcf\x11\xe0")


def user_path(name: str | os.PathLike[str], folder: str | os.PathLike[str] | None = None) -> Path:
    """A path as a person wrote it: ``~`` is their home folder, and a relative path is taken
    from ``folder`` (an absolute one stays as written).

    Examples
    --------
    >>> user_path("empty.jpg", "set").as_posix(), user_path("/data/a.jpg", "set").as_posix()
    ('set/empty.jpg', '/data/a.jpg')
    >>> user_path("~/a.jpg", "set") == Path.home() / "a.jpg"
    True
    """
    path = Path(os.path.expanduser(os.fspath(name).strip()))
    return path if folder is None or path.is_absolute() else Path(folder) / path


def csv_separator(header: str) -> str:
    """The field separator of a CSV file, judged by its header line: the one of
    :data:`SEPARATORS` that splits it into the most fields (``,`` on a tie).

    Examples
    --------
    >>> csv_separator("image;pressure_kpa;direction"), csv_separator("image,pressure_kpa")
    (';', ',')
    >>> csv_separator('"a;b",c')
    ','
    """
    fields = {sep: len(next(csv.reader([header], delimiter=sep), [])) for sep in SEPARATORS}
    return max(SEPARATORS, key=lambda sep: fields[sep])  # the first of equals: ','


def comma_csv_text(text: str) -> str:
    """``text``, a CSV file's contents, as comma-separated CSV with decimal points.

    A file separated by ``;`` or tabs is rewritten with commas, and in it every cell that is a
    number with a decimal comma (``60,5``) gets a decimal point; quoted fields stay whole.  A
    comma-separated file is returned as it is.

    Examples
    --------
    >>> print(comma_csv_text("image;pressure_kpa;roi\\na.jpg;60,5;[1, 2, 30, 40]\\n"), end="")
    image,pressure_kpa,roi
    a.jpg,60.5,"[1, 2, 30, 40]"
    """
    sep = csv_separator(text.split("\n", 1)[0].rstrip("\r"))
    if sep == ",":
        return text
    try:
        rows = list(csv.reader(io.StringIO(text), delimiter=sep))
    except csv.Error as exc:
        raise pd.errors.ParserError(str(exc)) from None
    out = io.StringIO()
    csv.writer(out, lineterminator="\n").writerows(
        [[c.replace(",", ".") if _DECIMAL_COMMA.fullmatch(c) else c for c in row] for row in rows]
    )
    return out.getvalue()


def read_user_text(path: str | os.PathLike[str]) -> str:
    """The text of a file a person wrote: UTF-8 (a byte-order mark dropped), else the Windows
    code page cp1252 (what an older Notepad or Excel saves), never a decoding error.

    Examples
    --------
    >>> import tempfile, pathlib
    >>> p = pathlib.Path(tempfile.mkdtemp()) / "photoset.yaml"
    >>> _ = p.write_bytes("# Aktor für Versuch 3\\nl0_mm: 255\\n".encode("cp1252"))
    >>> read_user_text(p).splitlines()[0]
    '# Aktor für Versuch 3'
    """
    return _user_text(Path(path).read_bytes())


def _user_text(data: bytes) -> str:
    try:
        return data.decode("utf-8-sig")
    except UnicodeDecodeError:
        return data.decode("cp1252", errors="replace")


def header_line(path: str | os.PathLike[str], names: Sequence[str], within: int = 10) -> int | None:
    """The line (1-based) among the first ``within`` of a CSV file that holds every one of
    ``names`` as a field (any case, spaces or brackets: ``Pressure (kPa)`` for ``pressure_kpa``):
    where its header is when a title or blank lines stand above it; None when no line does.

    Examples
    --------
    >>> import tempfile, pathlib
    >>> p = pathlib.Path(tempfile.mkdtemp()) / "m.csv"
    >>> _ = p.write_text("Ramp of 3 June;;\\n\\nImage;pressure_kpa;trial\\na.jpg;0;1\\n")
    >>> header_line(p, ["image", "pressure_kpa"]), header_line(p, ["step"])
    (3, None)
    """
    try:
        lines = _user_text(Path(path).read_bytes()).splitlines()[:within]
    except OSError:
        return None
    wanted = {plain_name(n) for n in names}
    for number, line in enumerate(lines, start=1):
        fields = next(csv.reader([line], delimiter=csv_separator(line)), [])
        if wanted <= {plain_name(f) for f in fields}:
            return number
    return None


def plain_name(name: str) -> str:
    """A column name as a person may have written it, in the form this package writes names.

    Examples
    --------
    >>> plain_name(" Pressure (kPa)"), plain_name("Fixed end X"), plain_name("image")
    ('pressure_kpa', 'fixed_end_x', 'image')
    """
    return re.sub(r"[^a-z0-9]+", "_", name.strip().lower()).strip("_")


def read_user_csv(path: str | os.PathLike[str], **read_csv: Any) -> pd.DataFrame:
    """Read a CSV file a person wrote or saved from a spreadsheet.

    Besides a plain comma-separated UTF-8 file this reads what spreadsheets save elsewhere: ``;``
    or tab between fields with decimal commas (:func:`comma_csv_text`), a byte-order mark, a
    Windows code page (cp1252, Excel's "CSV (Comma delimited)"), and spaces after the separators
    (in the header as well).

    Parameters
    ----------
    path : path
        The CSV file.
    **read_csv
        Passed to :func:`pandas.read_csv` (e.g. ``dtype``).

    Raises
    ------
    FileNotFoundError, pandas.errors.ParserError, pandas.errors.EmptyDataError
        As :func:`pandas.read_csv` does; ParserError also for a spreadsheet's workbook named
        ``.csv``.

    Examples
    --------
    >>> import tempfile, pathlib
    >>> p = pathlib.Path(tempfile.mkdtemp()) / "m.csv"
    >>> text = "image; pressure_kpa; material\\r\\nä.jpg; 12,5; DS20\\r\\n"
    >>> _ = p.write_bytes(text.encode("cp1252"))
    >>> read_user_csv(p).to_dict("records")
    [{'image': 'ä.jpg', 'pressure_kpa': 12.5, 'material': 'DS20'}]
    >>> _ = p.write_text("time_s,pressure_kpa\\n0,0\\n1,5\\n,\\n,\\n")  # rows a spreadsheet left
    >>> len(read_user_csv(p))
    2
    """
    data = Path(path).read_bytes()
    if data.startswith(WORKBOOK_SIGNATURES):
        raise pd.errors.ParserError(
            "it is a spreadsheet workbook (.xlsx, .xls or .ods) named .csv, not CSV text; "
            "save it again as CSV"
        )
    read_csv.setdefault("skipinitialspace", True)
    df = pd.read_csv(io.StringIO(comma_csv_text(_user_text(data))), **read_csv)
    df.columns = [c.strip() if isinstance(c, str) else c for c in df.columns]
    # the ',,,,' rows a spreadsheet leaves under its data are none (the earlier rows keep their
    # line numbers)
    rows = np.flatnonzero(df.notna().any(axis=1).to_numpy(bool))
    return df.iloc[: int(rows[-1]) + 1 if rows.size else 0]


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
        df = read_user_csv(path, **read_csv)
    except (FileNotFoundError, IsADirectoryError):
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


def atomic_write_bytes(path: str | os.PathLike[str], data: bytes, *, durable: bool = True) -> None:
    """Write ``data`` to ``path`` atomically: temporary file in the same folder, fsync, rename.

    The folder is created when missing; the file gets the usual permissions (umask), not the
    0600 of a temporary file.  ``durable=False`` skips the fsyncs (the file is still whole or
    absent, but a power cut may lose it: for what can be made again, such as a cache entry).

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
            if durable:
                fh.flush()
                os.fsync(fh.fileno())
        os.replace(tmp, path)
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise
    if durable:
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


def check_replaceable_table(
    path: str | os.PathLike[str],
    columns: Sequence[str],
    option: str = "--out",
    example: str | os.PathLike[str] | None = None,
) -> None:
    """Refuse to write a table over a file that is not an earlier one of its kind: an existing
    ``path`` whose first line does not name every one of ``columns`` (a photo, a hand-made
    manifest, another program's file) is a person's data, never replaced.

    Customer 47's ``measure SET --out SET/manifest.csv`` (one tab completion away from
    ``SET/``) replaced its manifest with angles.csv, and ``--out SET/photo.jpg`` a photo,
    without a word.

    Examples
    --------
    >>> import tempfile, pathlib
    >>> d = pathlib.Path(tempfile.mkdtemp())
    >>> _ = (d / "angles.csv").write_text("image,psi_deg,status\\na.jpg,1.0,ok\\n")
    >>> check_replaceable_table(d / "angles.csv", ["psi_deg", "status"])
    >>> _ = (d / "excel.csv").write_text("image;psi_deg;status\\na.jpg;1,0;ok\\n")
    >>> check_replaceable_table(d / "excel.csv", ["psi_deg", "status"])
    >>> check_replaceable_table(d / "new.csv", ["psi_deg", "status"])
    >>> _ = (d / "manifest.csv").write_text("image,pressure_kpa\\na.jpg,0\\n")
    >>> try:
    ...     check_replaceable_table(d / "manifest.csv", ["psi_deg", "status"])
    ... except UserInputError as exc:
    ...     print(str(exc).split(": ", 1)[1][:72])
    exists and is not a table this command wrote (its first line has no psi_
    """
    head = _existing_head(path, option)
    if head is None:
        return
    first = _user_text(head).splitlines()[:1]
    header = first[0] if first else ""
    if not set(columns) <= {n.strip().strip('"') for n in header.split(csv_separator(header))}:
        raise _not_replaced(
            path, f"a table this command wrote (its first line has no {', '.join(columns)})",
            option, example,
        )


def check_replaceable_pdf(path: str | os.PathLike[str], option: str = "--out") -> None:
    """Refuse to write a PDF over an existing ``path`` that is not one (a photo, a table, a
    person's document): as :func:`check_replaceable_table` for a report.

    Examples
    --------
    >>> import tempfile, pathlib
    >>> d = pathlib.Path(tempfile.mkdtemp())
    >>> _ = (d / "report.pdf").write_bytes(b"%PDF-1.4 ...")
    >>> check_replaceable_pdf(d / "report.pdf"); check_replaceable_pdf(d / "new.pdf")
    >>> _ = (d / "manifest.csv").write_text("image,pressure_kpa\\n")
    >>> check_replaceable_pdf(d / "manifest.csv")  # doctest: +IGNORE_EXCEPTION_DETAIL
    Traceback (most recent call last):
    pipeline.errors.UserInputError: --out .../manifest.csv: exists and is not a PDF ...
    """
    head = _existing_head(path, option)
    if head is not None and not head.startswith(b"%PDF-"):
        raise _not_replaced(path, "a PDF this command wrote", option, "report.pdf")


def _existing_head(path: str | os.PathLike[str], option: str) -> bytes | None:
    """The first 64 KiB of an existing output file (None where there is none yet); a folder
    there is refused."""
    path = Path(path)
    if path.is_dir():
        raise UserInputError(f"{option} {path}: is a folder; give a file in it")
    if not path.exists():
        return None
    with open(path, "rb") as fh:
        return fh.read(1 << 16)


def _not_replaced(
    path: str | os.PathLike[str], kind: str, option: str, example: Any = None
) -> UserInputError:
    """The refusal to write over ``path``, a file that is not ``kind``."""
    return UserInputError(
        f"{option} {path}: exists and is not {kind}, so it is not replaced: give a new file"
        + (f", e.g. {example}" if example is not None else "")
    )


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
