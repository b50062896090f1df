"""What a page really draws as text: every string with its size and extent, before saving.

:func:`drawn_texts` draws a figure once with a recording Agg renderer and returns each text
actually drawn (tick labels outside the view, empty or invisible texts are not drawn, so they
are not returned) with its bounding box in points.  The report's tests use it to check that no
two labels overlap, that no font is below the minimum size and that nothing but the footer sits
in the footer band.
"""

from __future__ import annotations

import contextlib
from collections.abc import Iterator
from dataclasses import dataclass
from typing import Any

import matplotlib as mpl
from matplotlib.backends.backend_agg import FigureCanvasAgg, RendererAgg
from matplotlib.figure import Figure
from matplotlib.text import Text
from matplotlib.transforms import Bbox

#: gid of the footer text (page number line) drawn on every page
FOOTER_GID = "report-footer"


@dataclass(frozen=True)
class DrawnText:
    """One drawn text.

    Attributes
    ----------
    text : str
    size_pt : float
        Font size at print size.
    box : Bbox
        Extent in points from the page's bottom-left corner.
    gid : str or None
    page_pt : (float, float)
        The page's width and height in points.
    """

    text: str
    size_pt: float
    box: Bbox
    gid: str | None
    page_pt: tuple[float, float] = (0.0, 0.0)


class _RecordingRenderer(RendererAgg):
    """An Agg renderer that remembers the Text artists it draws."""

    def __init__(self, width: float, height: float, dpi: float) -> None:
        super().__init__(width, height, dpi)
        self.drawn: dict[int, Text] = {}
        self.current: Text | None = None  # the Text being drawn (see _recording)

    def draw_text(self, gc, x, y, s, prop, angle, ismath=False, mtext=None):  # type: ignore[no-untyped-def]
        if mtext is not None and s.strip():
            self.drawn[id(mtext)] = mtext
        elif self.current is not None and s.strip():
            # a text of several lines draws each without naming itself (mtext is None)
            self.drawn[id(self.current)] = self.current
        return super().draw_text(gc, x, y, s, prop, angle, ismath=ismath, mtext=mtext)


@contextlib.contextmanager
def _naming_texts(renderer: _RecordingRenderer) -> Iterator[None]:
    """While drawing, ``renderer.current`` is the Text being drawn: matplotlib draws each line of
    a text of several lines without naming the Text, which would leave such titles unchecked."""
    original = Text.draw

    def draw(self: Text, r: Any, *args: Any, **kwargs: Any) -> Any:
        if r is not renderer:
            return original(self, r, *args, **kwargs)
        outer, renderer.current = renderer.current, self
        try:
            return original(self, r, *args, **kwargs)
        finally:
            renderer.current = outer

    Text.draw = draw  # type: ignore[method-assign,assignment]
    try:
        yield
    finally:
        Text.draw = original  # type: ignore[method-assign]


def drawn_texts(fig: Figure, dpi: float = 100.0) -> list[DrawnText]:
    """Draw ``fig`` once and return every text it drew, in drawing order.

    The drawing uses unhinted glyphs, as the PDF does (hinting at screen resolution widens small
    text by up to a tenth).  The figure keeps the layout of this drawing (constrained layout
    starts from the current axes positions), so save a freshly made figure for byte-exact output.

    Parameters
    ----------
    fig : Figure
    dpi : float
        Resolution of the test drawing (extents are returned in points whatever it is).

    Returns
    -------
    list of DrawnText
    """
    saved_dpi, saved_canvas = fig.dpi, fig.canvas
    FigureCanvasAgg(fig)
    fig.dpi = dpi
    try:
        with mpl.rc_context({"text.hinting": "no_hinting"}):
            w, h = fig.get_size_inches() * dpi
            renderer = _RecordingRenderer(int(w), int(h), dpi)
            with _naming_texts(renderer):
                fig.draw(renderer)
            scale = 72.0 / dpi
            out = []
            for t in renderer.drawn.values():
                b = t.get_window_extent(renderer)
                out.append(
                    DrawnText(
                        t.get_text(),
                        float(t.get_fontsize()),
                        Bbox.from_extents(b.x0 * scale, b.y0 * scale, b.x1 * scale, b.y1 * scale),
                        t.get_gid(),
                        (72.0 * fig.get_figwidth(), 72.0 * fig.get_figheight()),
                    )
                )
            return out
    finally:
        fig.dpi = saved_dpi
        fig.set_canvas(saved_canvas)


def outside_page(texts: list[DrawnText], tolerance_pt: float = 0.5) -> list[str]:
    """The texts that run past an edge of their page (cut off in the PDF)."""
    return [
        t.text
        for t in texts
        if t.box.x0 < -tolerance_pt
        or t.box.y0 < -tolerance_pt
        or t.box.x1 > t.page_pt[0] + tolerance_pt
        or t.box.y1 > t.page_pt[1] + tolerance_pt
    ]


def overlapping_texts(texts: list[DrawnText], tolerance_pt: float = 0.5) -> list[tuple[str, str]]:
    """Pairs of texts whose boxes overlap by more than ``tolerance_pt`` in both directions."""
    pairs = []
    for i, a in enumerate(texts):
        for b in texts[i + 1:]:
            dx = min(a.box.x1, b.box.x1) - max(a.box.x0, b.box.x0)
            dy = min(a.box.y1, b.box.y1) - max(a.box.y0, b.box.y0)
            if dx > tolerance_pt and dy > tolerance_pt:
                pairs.append((a.text, b.text))
    return pairs
