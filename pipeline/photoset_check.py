"""``photoset check`` of any photo set: the format's problems and, for a video set, its videos'.

:mod:`pipeline.photoset` checks the format (``photoset.yaml``, the manifest rows, the settings,
the images and calibrations); :mod:`pipeline.video.clips` checks the videos and pressure logs of a
video set.  :func:`check_photoset` loads the set once and asks both.
"""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np

from pipeline.constants import RAMP_KEYS
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
        if decode_images:
            problems += background_exposure_problems(ps)
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


#: an empty scene whose brightness differs from its ramp's first photo by more than this share
#: (the three channels' median ratio) ...
BACKGROUND_EXPOSURE_OFF = 0.2
#: ... or whose three channels' ratios to it spread by more than this share (white balance)
BACKGROUND_BALANCE_OFF = 0.1


def exposure_offset(photo_bgr: np.ndarray, background_bgr: np.ndarray) -> tuple[float, float]:
    """How the photo's light differs from the empty scene's: the mean of the three channels'
    ratios of their medians (1 for the same exposure) and their spread (max - min over the
    mean: 0 for the same white balance).  The body, a small part of the photo, barely moves
    the medians.

    Examples
    --------
    >>> bg = np.full((4, 4, 3), 200, np.uint8)
    >>> [round(v, 2) for v in exposure_offset((bg * 0.7).astype(np.uint8), bg)]
    [0.71, 0.0]
    >>> [round(v, 2) for v in exposure_offset((bg * [1.0, 1.0, 0.8]).astype(np.uint8), bg)]
    [0.93, 0.21]
    """
    ratio = (np.median(photo_bgr.reshape(-1, 3), axis=0) + 4.0) / (
        np.median(background_bgr.reshape(-1, 3), axis=0) + 4.0
    )
    mean = float(ratio.mean())
    return mean, float((ratio.max() - ratio.min()) / mean)


def background_exposure_problems(ps: PhotoSet) -> list[Problem]:
    """A warning on the first row of each ramp whose empty scene (``background``) was taken at
    another exposure or white balance than the ramp's first photo (:func:`exposure_offset`,
    beyond :data:`BACKGROUND_EXPOSURE_OFF` or :data:`BACKGROUND_BALANCE_OFF`).

    ``measure`` matches the empty scene's light to each photo, but not perfectly: customer 42's
    empty scene taken at 0.72 of the photos' exposure and another white balance read 5 rows of
    its grey-blue body ``ok`` and 7-10 deg off (1 with the empty scene taken with the photos),
    and ``check`` said nothing.
    """
    import cv2

    from pipeline.measure.core import decode_for_work

    if ps.is_video or not set(RAMP_KEYS) <= set(ps.manifest.columns):
        return []
    out: list[Problem] = []
    for _, ramp in ps.manifest.groupby(list(RAMP_KEYS), sort=False):
        first = next((i for i in ramp.index if ps.rows[i] is not None), None)
        settings = None if first is None else ps.rows[first]
        if settings is None or settings.background_path is None:
            continue
        images = []
        for path in (ps.image_path(str(ps.manifest.at[first, "image"])),
                     Path(settings.background_path)):
            try:
                data = np.fromfile(str(path), np.uint8)
            except OSError:  # the format's problems say so
                data = np.zeros(0, np.uint8)
            images.append(decode_for_work(data)[0] if data.size else None)
        photo, empty = images
        if photo is None or empty is None or photo.ndim != 3 or empty.ndim != 3:
            continue
        empty = cv2.resize(empty, (photo.shape[1], photo.shape[0]), interpolation=cv2.INTER_AREA)
        brightness, balance = exposure_offset(photo, empty)
        if abs(brightness - 1.0) <= BACKGROUND_EXPOSURE_OFF and balance <= BACKGROUND_BALANCE_OFF:
            continue
        name = Path(settings.background_path).name
        out.append(_row_warning(
            ps,
            first,
            f"background photo {name} was taken at another exposure or white balance than this "
            f"ramp's first photo: {abs(1.0 / brightness - 1.0) * 100:.0f}% "
            + ("brighter" if brightness < 1.0 else "darker")
            + f", its colour channels {100 * balance:.0f}% apart; measure matches its light to "
            "each photo, but a faint or shaded part of the body may then pass for backdrop or "
            "shadow",
            "take the empty scene with the camera's exposure and white balance locked as for the "
            "photos (a phone: lock AE/AWB, or its manual mode), just before or after the ramp",
        ))
    return out
