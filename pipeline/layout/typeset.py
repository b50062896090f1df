"""Text and tables set in points on a page: headings, wrapped paragraphs, typeset tables.

A :class:`Flow` places blocks top-down from a point of the page, measuring every string with
the font's own metrics (no renderer, so the layout is the same on every machine), so nothing it
places overlaps.  A :class:`Table` is drawn with rules above and below the header and at the end
(no grid), numbers right-aligned, units in the column headers and ``n/a`` where a value is
missing (:func:`fmt`).

Examples
--------
>>> from pipeline.layout.style import report_style, text_page
>>> with report_style():
...     fig = text_page()
...     flow = Flow(fig)
...     flow.heading("Results")
...     columns = (Column("material", "left"), Column("RMS (deg)"))
...     flow.table(Table(columns, (("DS20", fmt(47.04, 1)),)))
>>> [t.get_text() for t in fig.texts]
['Results', 'material', 'RMS (deg)', 'DS20', '47.0']
"""

from __future__ import annotations

import dataclasses
import functools
import math
import re
from collections.abc import Sequence
from dataclasses import dataclass, field

from matplotlib import ft2font
from matplotlib.axes import Axes
from matplotlib.figure import Figure
from matplotlib.font_manager import FontProperties, findfont, get_font
from matplotlib.lines import Line2D
from matplotlib.patches import Rectangle
from matplotlib.transforms import Affine2D, Transform

from pipeline.layout.style import FOOTER_PT, MARGIN_PT, MIN_FONT_PT, Color

#: what a missing value reads as, everywhere in the report
NA = "n/a"
#: line height as a multiple of the font size
LINE_SPACING = 1.32
#: horizontal gap between table columns (pt)
COLUMN_GAP_PT = 9.0
MONO = "DejaVu Sans Mono"


def fmt(value: object, digits: int = 0, unit: str = "") -> str:
    """A number as table text: :data:`NA` for missing, NaN or infinite values.

    Examples
    --------
    >>> fmt(3.14159, 2), fmt(float("nan")), fmt(None), fmt(49.4, 0, " kPa")
    ('3.14', 'n/a', 'n/a', '49 kPa')
    """
    try:
        x = float(value)  # type: ignore[arg-type]
    except (TypeError, ValueError):
        return NA
    if not math.isfinite(x):
        return NA
    text = f"{x:.{digits}f}"
    if text.lstrip("-").strip("0.") == "":  # -0 and -0.0 read as 0
        text = text.lstrip("-")
    return text + unit


#: unhinted glyph outlines, as in the PDF (``LoadFlags`` from matplotlib 3.10 on)
_NO_HINTING = (
    ft2font.LoadFlags.NO_HINTING
    if hasattr(ft2font, "LoadFlags")
    else ft2font.LOAD_NO_HINTING  # type: ignore[attr-defined]  # matplotlib < 3.10; stubs: 3.10+
)
#: size (pt) at which widths are measured; advance widths of unhinted outlines scale linearly with
#: size
_REFERENCE_PT = 10.0


@functools.lru_cache(maxsize=32768)
def _reference_width(text: str, weight: str, family: str) -> float:
    font = get_font(findfont(FontProperties(family=family, weight=weight)))
    font.set_size(_REFERENCE_PT, 72.0)
    font.set_text(text, 0.0, flags=_NO_HINTING)
    return font.get_width_height()[0] / 64.0


def text_width_pt(
    text: str, size: float, weight: str = "normal", family: str = "DejaVu Sans"
) -> float:
    """Width of one line of text at ``size`` pt, from the font's (unhinted) metrics."""
    return _reference_width(text, weight, family) * size / _REFERENCE_PT if text else 0.0


def wrap(
    text: str, width_pt: float, size: float, weight: str = "normal", family: str = "DejaVu Sans"
) -> list[str]:
    """Greedy word wrap of ``text`` to lines no wider than ``width_pt``.

    A word wider than the line is broken after a ``/`` (file paths), else kept whole.

    Examples
    --------
    >>> wrap("results/datasets/DS20/angles.csv", 60.0, 8.0)
    ['results/', 'datasets/', 'DS20/', 'angles.csv']
    """
    space = text_width_pt(" ", size, weight, family)
    out: list[str] = []
    for paragraph in text.split("\n"):
        tokens: list[tuple[str, str]] = []  # (piece, what joins it to the previous piece)
        for word in paragraph.split(" "):
            parts = [word]
            if "/" in word and text_width_pt(word, size, weight, family) > width_pt:
                parts = [p for p in re.split(r"(?<=/)", word) if p]
            tokens += [(p, " " if k == 0 else "") for k, p in enumerate(parts)]
        line, used = "", 0.0
        for piece, glue in tokens:
            w = text_width_pt(piece, size, weight, family)
            extra = w + (space if glue and line else 0.0)
            if line and used + extra > width_pt:
                out.append(line)
                line, used = piece, w
            else:
                line, used = (line + glue + piece if line else piece), used + extra
        out.append(line)
    return out


@dataclass(frozen=True)
class Column:
    """One table column.

    Attributes
    ----------
    header : str
        Header text with the unit, e.g. ``"RMS (deg)"``; ``"\\n"`` breaks it.
    align : str
        ``"left"``, ``"right"`` (numbers) or ``"center"``.
    wrap_pt : float or None
        Cells wider than this are wrapped onto several lines.
    family : str
        Font of the cells (e.g. :data:`MONO` for hex digests).
    """

    header: str
    align: str = "right"
    wrap_pt: float | None = None
    family: str = "DejaVu Sans"


@dataclass(frozen=True)
class Table:
    """A table to typeset (see module docstring).

    Attributes
    ----------
    columns : tuple of Column
    rows : tuple of tuple of str
        Cell texts, already formatted (use :func:`fmt`).
    title : str
        Bold line above the table.
    groups : tuple of (str, int)
        Optional spanning headers over consecutive columns: (label, number of columns); ``""``
        leaves the span blank.
    notes : tuple of str
        Small print under the table.
    size : float
        Font size (pt) of the cells.
    row_colors : tuple
        Text colour of each row's first cell (``None`` = black), e.g. the material's colour.
    """

    columns: tuple[Column, ...]
    rows: tuple[tuple[str, ...], ...]
    title: str = ""
    groups: tuple[tuple[str, int], ...] = ()
    notes: tuple[str, ...] = ()
    size: float = 8.0
    row_colors: tuple[Color | str | None, ...] = field(default=())


class Flow:
    """Places blocks top-down on a figure, in points from its top-left corner.

    Parameters
    ----------
    fig : Figure
    left_pt, top_pt : float
        Where the first block starts.
    width_pt : float, optional
        Width of the column of text (default: the page width minus both margins).
    bottom_pt : float, optional
        Lowest point a block may reach, measured from the page bottom (default: above the footer).
    """

    def __init__(self, fig: Figure, *, left_pt: float = MARGIN_PT, top_pt: float = MARGIN_PT,
                 width_pt: float | None = None, bottom_pt: float = FOOTER_PT + 6.0) -> None:
        self.fig = fig
        self.page_w = 72.0 * fig.get_figwidth()
        self.page_h = 72.0 * fig.get_figheight()
        self.x = left_pt
        self.y = top_pt
        self.width = self.page_w - 2 * left_pt if width_pt is None else width_pt
        self.bottom = self.page_h - bottom_pt
        self.transform: Transform = (
            Affine2D().scale(1 / 72.0, -1 / 72.0).translate(0.0, fig.get_figheight())
            + fig.dpi_scale_trans
        )

    @property
    def remaining_pt(self) -> float:
        """Height left down to the bottom limit."""
        return self.bottom - self.y

    def space(self, pt: float) -> None:
        """Leave ``pt`` of vertical space."""
        self.y += pt

    def _line(
        self,
        x: float,
        text: str,
        size: float,
        *,
        weight: str = "normal",
        color: object = "black",
        family: str = "DejaVu Sans",
        ha: str = "left",
        style: str = "normal",
    ) -> None:
        self.fig.text(
            x,
            self.y,
            text,
            transform=self.transform,
            fontsize=size,
            fontweight=weight,
            color=color,
            family=family,
            ha=ha,
            va="top",
            fontstyle=style,
        )

    def text(self, text: str, *, size: float = 8.5, weight: str = "normal", color: object = "black",
             indent_pt: float = 0.0, family: str = "DejaVu Sans", style: str = "normal",
             hanging_pt: float = 0.0) -> None:
        """A paragraph wrapped to the flow's width (``hanging_pt``: indent of the following
        lines)."""
        size = max(size, MIN_FONT_PT)
        first = True
        for line in wrap(text, self.width - indent_pt - hanging_pt, size, weight, family):
            x = self.x + indent_pt + (0.0 if first else hanging_pt)
            self._line(x, line, size, weight=weight, color=color, family=family, style=style)
            self.y += size * LINE_SPACING
            first = False

    def heading(self, text: str, *, size: float = 10.5, before_pt: float = 6.0) -> None:
        """A bold heading."""
        self.space(before_pt)
        self.text(text, size=size, weight="bold")
        self.space(1.5)

    def bullets(self, items: Sequence[str], *, size: float = 8.0, color: object = "black") -> None:
        """A list with hanging indent."""
        for item in items:
            self._line(self.x, "•", size, color=color)
            self.text(item, size=size, indent_pt=9.0, color=color)

    def axes(self, height_pt: float, *, left_pad_pt: float = 48.0, bottom_pad_pt: float = 34.0,
             top_pad_pt: float = 16.0, right_pad_pt: float = 8.0, width_pt: float | None = None,
             x_pt: float | None = None) -> Axes:
        """Axes filling the next ``height_pt`` (pads leave room for tick and axis labels)."""
        width = self.width if width_pt is None else width_pt
        x = self.x if x_pt is None else x_pt
        left = (x + left_pad_pt) / self.page_w
        bottom = (self.page_h - (self.y + height_pt - bottom_pad_pt)) / self.page_h
        ax = self.fig.add_axes((left, bottom, (width - left_pad_pt - right_pad_pt) / self.page_w,
                                (height_pt - top_pad_pt - bottom_pad_pt) / self.page_h))
        self.y += height_pt
        return ax

    def table(self, table: Table) -> None:
        """Typeset ``table`` at the current position (see :class:`Table`)."""
        layout = _layout(table, self.width)
        size, widths, cells, headers = layout
        n = len(table.columns)
        line_h = size * LINE_SPACING
        if table.title:
            self.text(table.title, size=size + 1.0, weight="bold")
            self.space(1.0)
        edges = [self.x]
        for w in widths:
            edges.append(edges[-1] + w + COLUMN_GAP_PT)
        total = edges[-1] - COLUMN_GAP_PT - self.x
        self._rule(self.x, self.x + total, 0.8)
        self.space(2.5)
        if any(label for label, _ in table.groups):
            col = 0
            for label, span in table.groups:
                if label:
                    x0, x1 = edges[col], edges[col + span] - COLUMN_GAP_PT
                    self._line((x0 + x1) / 2, label, size, weight="bold", ha="center")
                    self.y += line_h
                    self._rule(x0, x1, 0.4)
                    self.y -= line_h
                col += span
            self.y += line_h + 2.0
        depth = max(len(h) for h in headers)
        top = self.y
        for c, lines in enumerate(headers):
            self.y = top + (depth - len(lines)) * line_h  # headers sit on a common baseline
            for line in lines:
                self._cell(edges[c], widths[c], table.columns[c].align, line, size, weight="bold")
                self.y += line_h
        self.y = top + depth * line_h
        self._rule(self.x, self.x + total, 0.5)
        self.space(2.5)
        for r, row in enumerate(cells):
            height = max(len(c) for c in row) * line_h
            if r % 2 == 1 and len(cells) > 3:
                self.fig.patches.append(
                    Rectangle(
                        (self.x - 2.0, self.y - 1.2),
                        total + 4.0,
                        height + 0.4,
                        transform=self.transform,
                        facecolor="#f1f1f1",
                        edgecolor="none",
                        zorder=-1,
                    )
                )
            top = self.y
            for c in range(n):
                self.y = top
                color = (
                    table.row_colors[r]
                    if c == 0 and r < len(table.row_colors) and table.row_colors[r]
                    else "black"
                )
                for line in row[c]:
                    self._cell(edges[c], widths[c], table.columns[c].align, line, size,
                               weight="bold" if color != "black" else "normal", color=color,
                               family=table.columns[c].family)
                    self.y += line_h
            self.y = top + height
        self.space(1.0)
        self._rule(self.x, self.x + total, 0.8)
        self.space(3.0)
        note_size = max(size - 1.0, MIN_FONT_PT)
        for note in table.notes:
            self.text(note, size=note_size, color="0.25")

    def _cell(
        self,
        x0: float,
        width: float,
        align: str,
        text: str,
        size: float,
        *,
        weight: str = "normal",
        color: object = "black",
        family: str = "DejaVu Sans",
    ) -> None:
        if not text:
            return
        x = {"left": x0, "right": x0 + width, "center": x0 + width / 2}[align]
        self._line(x, text, size, weight=weight, ha=align, color=color, family=family)

    def _rule(self, x0: float, x1: float, linewidth: float) -> None:
        self.fig.add_artist(
            Line2D(
                [x0, x1],
                [self.y, self.y],
                transform=self.transform,
                color="black",
                linewidth=linewidth,
            )
        )


def table_height_pt(table: Table, width_pt: float) -> float:
    """Height (pt) :meth:`Flow.table` will take for ``table`` at ``width_pt``."""
    size, _widths, cells, headers = _layout(table, width_pt)
    line_h = size * LINE_SPACING
    height = (size + 1.0) * LINE_SPACING + 1.0 if table.title else 0.0
    height += 2.5 + (line_h + 2.0 if any(label for label, _ in table.groups) else 0.0)
    height += max(len(h) for h in headers) * line_h + 2.5
    height += sum(max(len(c) for c in row) * line_h for row in cells) + 4.0
    note_size = max(size - 1.0, MIN_FONT_PT)
    for note in table.notes:
        height += len(wrap(note, width_pt, note_size)) * note_size * LINE_SPACING
    return height


def rows_that_fit(table: Table, width_pt: float, height_pt: float) -> int:
    """How many of the table's rows (from the top) fit in ``height_pt`` (at least one)."""
    lo, hi = 1, len(table.rows)
    while lo < hi:
        mid = (lo + hi + 1) // 2
        if (
            table_height_pt(dataclasses.replace(table, rows=table.rows[:mid]), width_pt)
            <= height_pt
        ):
            lo = mid
        else:
            hi = mid - 1
    return lo


def _layout(
    table: Table, width_pt: float
) -> tuple[float, list[float], list[list[list[str]]], list[list[str]]]:
    """Font size, column widths and the wrapped lines of every cell, fitted to ``width_pt``.

    The font shrinks (not below :data:`MIN_FONT_PT`) until the table fits; if it still does not,
    the widest wrappable (left-aligned) column is wrapped.
    """
    n = len(table.columns)
    for row in table.rows:
        if len(row) != n:
            raise ValueError(f"table {table.title!r}: a row has {len(row)} cells for {n} columns")
    size = table.size
    wraps = [c.wrap_pt for c in table.columns]
    while True:
        headers = [c.header.split("\n") for c in table.columns]
        fonts = [c.family for c in table.columns]
        cells = [[wrap(str(v), wp, size, "bold", font) if wp else str(v).split("\n")
                  for v, wp, font in zip(row, wraps, fonts)] for row in table.rows]
        widths = []
        for c in range(n):
            w = max(text_width_pt(h, size, "bold") for h in headers[c])
            for wrapped in cells:
                w = max([w] + [text_width_pt(line, size, "bold", fonts[c]) for line in wrapped[c]])
            widths.append(w)
        col = 0
        for label, span in table.groups:  # a spanning header widens the columns under it if needed
            have = sum(widths[col:col + span]) + COLUMN_GAP_PT * (span - 1)
            need = text_width_pt(label, size, "bold")
            for c in range(col, col + span):
                widths[c] += max(need - have, 0.0) / span
            col += span
        total = sum(widths) + COLUMN_GAP_PT * (n - 1)
        if total <= width_pt:
            return size, widths, cells, headers
        if size > MIN_FONT_PT:
            size = max(MIN_FONT_PT, size - 0.5)
            continue
        left = [c for c in range(n) if table.columns[c].align == "left"]
        if not left:
            return size, widths, cells, headers
        widest = max(left, key=lambda c: widths[c])
        target = widths[widest] - (total - width_pt)
        wrap_now = wraps[widest]
        if target < 40.0 or (wrap_now is not None and wrap_now <= target):
            return size, widths, cells, headers
        wraps[widest] = target
