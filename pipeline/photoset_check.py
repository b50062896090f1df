"""``photoset check`` of any photo set: the format's problems and, for a video set, its videos'.

:mod:`pipeline.photoset` checks the format (``photoset.yaml``, the manifest rows, the settings,
the images and calibrations); :mod:`pipeline.video.clips` checks the videos and pressure logs of a
video set.  :func:`check_photoset` loads the set once and asks both.
"""

from __future__ import annotations

import os

from pipeline.model.materials import load_materials
from pipeline.photo_log import logged_row_doubts
from pipeline.photoset import MANIFEST, PhotoSet, Problem, file_problems, load_checked
from pipeline.ramp_check import pressure_order_breaks
from pipeline.video.clips import clip_problems


def check_photoset(
    folder: str | os.PathLike[str],
    *,
    decode_images: bool = True,
    require_images: bool = True,
    warnings: bool = False,
) -> list[Problem]:
    """Every problem of a photo set (of images or videos), each naming the file, line and fix.

    Parameters are those of :func:`pipeline.photoset.validate_photoset`; for a video set
    ``decode_images`` reads every frame and ``require_images`` reports missing videos and logs.

    Returns
    -------
    list of Problem
        Empty when the set is valid (and, with ``warnings``, nothing is doubtful).
    """
    ps, problems = load_checked(folder)
    if ps is not None:
        if ps.is_video:
            problems += clip_problems(ps, decode=decode_images, require_files=require_images)
        problems += file_problems(ps, decode_images=decode_images, require_images=require_images)
        problems += material_problems(ps)
        problems += pressure_order_problems(ps)
        problems += logged_pressure_problems(ps)
    return [p for p in problems if warnings or not p.warning]


def material_problems(ps: PhotoSet) -> list[Problem]:
    """A warning for each material of the set that the model's packaged materials file does not
    have: the report then compares it with the model only when a materials file named in the
    run's config has it (customer 24 learnt it from the finished PDF)."""
    known = load_materials()
    materials = ps.manifest["material"].dropna().astype(str)
    out = []
    for m in sorted(set(materials) - set(known)):
        line = ps.manifest.loc[materials[materials == m].index[0], "manifest_line"]
        out.append(Problem(
            str(ps.folder / MANIFEST),
            int(line),
            f"material {m} is not one of the model's materials ({', '.join(sorted(known))}): "
            "its angles are measured and reported, but not compared with the model",
            f"to compare, add {m} (its Ogden terms, k_P and geometry) to a materials file named "
            "in config.yaml (model.materials_file); else nothing to do",
            warning=True,
        ))
    return out


def logged_pressure_problems(ps: PhotoSet) -> list[Problem]:
    """Warnings for photos ``init`` placed on a pressure log, said again at each check
    (:func:`pipeline.photo_log.logged_row_doubts`): customer 40's sign warning was said once,
    and check said OK after it."""
    if ps.is_video:
        return []
    return [_row_warning(ps, ix, what, fix) for ix, what, fix in logged_row_doubts(ps.folder,
                                                                                  ps.manifest)]


def _row_warning(ps: PhotoSet, ix: object, what: str, fix: str) -> Problem:
    """A warning on the manifest line of row ``ix``."""
    return Problem(
        str(ps.folder / MANIFEST), int(ps.manifest.at[ix, "manifest_line"]), what, fix,
        warning=True,
    )


def pressure_order_problems(ps: PhotoSet) -> list[Problem]:
    """A warning for each manifest row whose pressure breaks its ramp's order
    (:func:`pipeline.ramp_check.pressure_order_breaks`): ``measure`` flags it and leaves it out
    of the curves (customer 30's 100 kPa typed as 1000 put a level at 1000 kPa in the curves and
    check said OK)."""
    if ps.is_video:
        return []
    return [
        _row_warning(
            ps,
            ix,
            why.replace(" a typo in the manifest?", " a typo?"),
            "correct pressure_kpa (or step) on this line; until then measure flags the photo and "
            "leaves it out of the curves",
        )
        for ix, why in pressure_order_breaks(ps.manifest).items()
    ]
