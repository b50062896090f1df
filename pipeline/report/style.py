"""Page geometry, fonts and colours shared by every report page (one place, so pages match)."""

from __future__ import annotations

import contextlib
from collections.abc import Iterator, Sequence

import matplotlib as mpl
from matplotlib.colors import to_rgb

#: A4 portrait, inches
PAGE_SIZE_IN: tuple[float, float] = (8.27, 11.69)
#: A4 landscape, inches
LANDSCAPE_SIZE_IN: tuple[float, float] = (11.69, 8.27)
#: pixels per inch for embedded photos (plots stay vector)
PHOTO_DPI = 150

#: fonts shipped with matplotlib, so every machine renders (and embeds) the same glyphs
RC: dict[str, object] = {
    "font.family": "DejaVu Sans",
    "font.size": 9.0,
    "axes.titlesize": 10.0,
    "axes.labelsize": 9.0,
    "xtick.labelsize": 8.0,
    "ytick.labelsize": 8.0,
    "legend.fontsize": 7.5,
    "figure.titlesize": 12.0,
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

#: material -> colour (the paper's four silicones; others get the tab10 colours in name order)
MATERIAL_COLORS: dict[str, str] = {"DS20": "#1f77b4", "DS30": "#ff7f0e", "SS40": "#2ca02c", "SS50": "#d62728"}
_OTHER_COLORS = ("#9467bd", "#8c564b", "#e377c2", "#7f7f7f", "#bcbd22", "#17becf")


@contextlib.contextmanager
def report_style() -> Iterator[None]:
    """Context in which every report figure is created and saved."""
    with mpl.rc_context(RC):
        yield


def material_colors(materials: Sequence[str]) -> dict[str, tuple[float, float, float]]:
    """Colour of every material: fixed for the paper's four, deterministic for the others."""
    out: dict[str, tuple[float, float, float]] = {}
    others = sorted(m for m in set(materials) if m not in MATERIAL_COLORS)
    for m in materials:
        if m in MATERIAL_COLORS:
            out[m] = to_rgb(MATERIAL_COLORS[m])
        else:
            out[m] = to_rgb(_OTHER_COLORS[others.index(m) % len(_OTHER_COLORS)])
    return out


def lighter(color: tuple[float, float, float], amount: float = 0.55) -> tuple[float, float, float]:
    """Blend ``color`` with white (``amount`` = share of white)."""
    r, g, b = color
    return (r + (1 - r) * amount, g + (1 - g) * amount, b + (1 - b) * amount)
