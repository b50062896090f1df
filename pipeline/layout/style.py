"""The one style of every printed page: A4 geometry, fonts, colours, the footer band.

Every page of the report (its own pages and the bench and force pages) is made by :func:`page`,
inside :func:`report_style`, so the whole PDF has one paper size (A4, portrait or landscape),
fonts of at least :data:`MIN_FONT_PT` at print size (figures are drawn at their printed size, so a
font size here is the printed size) and one colour per material (:func:`material_colors`).
"""

from __future__ import annotations

import contextlib
from collections.abc import Iterator, Sequence
from typing import TYPE_CHECKING

import matplotlib as mpl
from matplotlib.colors import to_rgb
from matplotlib.figure import Figure
from matplotlib.layout_engine import ConstrainedLayoutEngine

if TYPE_CHECKING:
    from matplotlib.typing import RcKeyType  # for the type checker only

MM_PER_IN = 25.4
#: A4 portrait and landscape, inches (210 x 297 mm)
A4_PORTRAIT_IN: tuple[float, float] = (210.0 / MM_PER_IN, 297.0 / MM_PER_IN)
A4_LANDSCAPE_IN: tuple[float, float] = (297.0 / MM_PER_IN, 210.0 / MM_PER_IN)
#: pixels per inch for embedded photos (plots stay vector)
PHOTO_DPI = 150
#: smallest font on any page (pt at print size)
MIN_FONT_PT = 7.0
#: height of the band at the bottom of every page that holds only the footer (pt)
FOOTER_PT = 22.0
#: page margin used by text pages and bands (pt)
MARGIN_PT = 42.0

PSI_LABEL = "Bending angle ψ (deg)"
P_LABEL = "Input pressure P (kPa)"

#: fonts shipped with matplotlib, so every machine renders (and embeds) the same glyphs
RC: dict[RcKeyType, object] = {
    "font.family": "DejaVu Sans",
    "font.size": 8.5,
    "axes.titlesize": 9.5,
    "axes.labelsize": 8.5,
    "xtick.labelsize": 7.5,
    "ytick.labelsize": 7.5,
    "legend.fontsize": 7.5,
    "legend.title_fontsize": 7.5,
    "figure.titlesize": 12.0,
    "axes.formatter.use_mathtext": False,
    "pdf.fonttype": 42,
    "pdf.compression": 6,
    "savefig.dpi": PHOTO_DPI,
    "axes.grid": True,
    "grid.linewidth": 0.4,
    "grid.alpha": 0.5,
    "axes.spines.top": False,
    "axes.spines.right": False,
    "lines.linewidth": 1.4,
    "svg.hashsalt": "pipeline-report",
}

#: material -> colour (the paper's four silicones; others get the colours below in name order)
MATERIAL_COLORS: dict[str, str] = {
    "DS20": "#1f77b4",
    "DS30": "#ff7f0e",
    "SS40": "#2ca02c",
    "SS50": "#d62728",
}
_OTHER_COLORS = ("#9467bd", "#8c564b", "#e377c2", "#7f7f7f", "#bcbd22", "#17becf")

Color = tuple[float, float, float]


@contextlib.contextmanager
def report_style() -> Iterator[None]:
    """Context in which every report figure is created and saved."""
    with mpl.rc_context(RC):
        yield


def footer_fraction(size_in: tuple[float, float]) -> float:
    """Share of the page height taken by the footer band."""
    return FOOTER_PT / (72.0 * size_in[1])


def page(
    landscape: bool = False, *, label: str = "", bottom_pt: float = 0.0, top_pt: float = 0.0
) -> Figure:
    """A new A4 page; constrained layout places its axes above the footer band.

    Parameters
    ----------
    landscape : bool
        A4 landscape instead of portrait.
    label : str
        Name of the page (``Figure.get_label()``), e.g. ``"summary"``; tests find pages by it.
    bottom_pt, top_pt : float
        Extra bands (pt) kept free of axes at the bottom (above the footer) and at the top, for
        text or tables placed with :class:`pipeline.layout.typeset.Flow`.

    Returns
    -------
    matplotlib.figure.Figure
    """
    size = A4_LANDSCAPE_IN if landscape else A4_PORTRAIT_IN
    height_pt = 72.0 * size[1]
    bottom = (FOOTER_PT + bottom_pt) / height_pt
    top = top_pt / height_pt
    fig = Figure(
        figsize=size, layout=ConstrainedLayoutEngine(rect=(0.0, bottom, 1.0, 1.0 - bottom - top))
    )
    fig.set_label(label)
    return fig


def text_page(landscape: bool = False, *, label: str = "") -> Figure:
    """A new A4 page without a layout engine (text, tables and hand-placed axes)."""
    fig = Figure(figsize=A4_LANDSCAPE_IN if landscape else A4_PORTRAIT_IN)
    fig.set_label(label)
    return fig


def material_colors(materials: Sequence[str]) -> dict[str, Color]:
    """Colour of every material: fixed for the paper's four, deterministic for the others.

    Examples
    --------
    >>> c = material_colors(["SS50", "MyGel", "DS20"])
    >>> c["DS20"] == material_colors(["DS20"])["DS20"], len(set(c.values()))
    (True, 3)
    """
    out: dict[str, Color] = {}
    others = sorted(m for m in set(materials) if m not in MATERIAL_COLORS)
    for m in materials:
        if m in MATERIAL_COLORS:
            out[m] = to_rgb(MATERIAL_COLORS[m])
        else:
            out[m] = to_rgb(_OTHER_COLORS[others.index(m) % len(_OTHER_COLORS)])
    return out


def actuator_colors() -> list[Color]:
    """Colours that tell the actuators of one material apart: the paper's four materials', then
    the others' (no grey: the model's lines are grey)."""
    return [to_rgb(c) for c in (*MATERIAL_COLORS.values(), *_OTHER_COLORS) if c != "#7f7f7f"]


def lighter(color: Color, amount: float = 0.55) -> Color:
    """Blend ``color`` with white (``amount`` = share of white)."""
    r, g, b = color
    return (r + (1 - r) * amount, g + (1 - g) * amount, b + (1 - b) * amount)
