"""Pages contributed by other stages (bench, force), fetched defensively.

A stage whose module is not installed simply adds no pages (an info line says so).  An error
*inside* a stage's ``figures()`` (or while importing it) is never swallowed silently: the report
is still written, and the summary page carries a warning line with the exception.
"""

from __future__ import annotations

import importlib
import sys
import traceback
from dataclasses import dataclass, field
from pathlib import Path

from matplotlib.figure import Figure


@dataclass
class ExtraPages:
    """Figures from one contributing module, with what happened."""

    figures: list[Figure] = field(default_factory=list)
    warnings: list[str] = field(default_factory=list)
    infos: list[str] = field(default_factory=list)


def extra_pages(module_name: str, directory: Path | None) -> ExtraPages:
    """Call ``<module_name>.figures(directory)``.

    Parameters
    ----------
    module_name : str
        e.g. ``"pipeline.bench.pages"``; must expose ``figures(dir: Path) -> list[Figure]``.
    directory : Path or None
        The stage's output folder; ``None`` means the stage was not asked for.

    Returns
    -------
    ExtraPages
    """
    out = ExtraPages()
    if directory is None:
        return out
    if not directory.is_dir():
        out.warnings.append(f"{module_name}: folder {directory} does not exist; no pages added")
        return out
    try:
        module = importlib.import_module(module_name)
    except ModuleNotFoundError as exc:
        if exc.name is not None and (module_name == exc.name or module_name.startswith(exc.name + ".")):
            out.infos.append(f"{module_name} is not installed: no pages from {directory}")
            return out
        out.warnings.append(f"{module_name}: import failed: {type(exc).__name__}: {exc}")
        traceback.print_exc(file=sys.stderr)
        return out
    except Exception as exc:  # noqa: BLE001 - reported in the PDF and on stderr, never hidden
        out.warnings.append(f"{module_name}: import failed: {type(exc).__name__}: {exc}")
        traceback.print_exc(file=sys.stderr)
        return out
    figures_fn = getattr(module, "figures", None)
    if not callable(figures_fn):
        out.warnings.append(f"{module_name} has no figures(dir) function; no pages added")
        return out
    try:
        figs = list(figures_fn(directory))
    except Exception as exc:  # noqa: BLE001 - reported in the PDF and on stderr, never hidden
        out.warnings.append(f"{module_name}.figures({directory}) raised {type(exc).__name__}: {exc}")
        traceback.print_exc(file=sys.stderr)
        return out
    for i, fig in enumerate(figs):
        if isinstance(fig, Figure):
            out.figures.append(fig)
        else:
            out.warnings.append(f"{module_name}.figures returned a {type(fig).__name__} at position {i}, not a Figure")
    out.infos.append(f"{len(out.figures)} page(s) from {module_name} ({directory})")
    return out
