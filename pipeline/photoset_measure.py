"""Measure every photo of a photo set into the angles.csv table (one row per manifest row).

Photos are measured in a process pool (``jobs``); workers import only OpenCV/numpy/scipy
(:mod:`pipeline.measure.worker`) and each photo is decoded once, at reduced size for large JPEGs.
One bad photo never stops the set: it becomes a ``failed`` row with the reason.
"""

from __future__ import annotations

import os
import shutil
import tempfile
from collections.abc import Sequence
from dataclasses import replace
from pathlib import Path
from typing import Any

import cv2
import numpy as np
import pandas as pd
from numpy.typing import NDArray

from pipeline.camera_turn import RampPhotos, ramp_turns
from pipeline.constants import RAMP_KEYS
from pipeline.errors import UserInputError
from pipeline.fileio import atomic_write_bytes, write_table
from pipeline.measure.core import DEFAULT_METHOD, decode_for_work
from pipeline.measure.estimators import METHODS
from pipeline.measure.quality import NOTE_FROM_RAMP_START, NOTES
from pipeline.measure.ramp_background import (
    RAMP_BACKGROUND_MIN_PHOTOS,
    covered,
    estimate_background,
    estimates_background,
)
from pipeline.measure.settings import OVERRIDE_COLUMNS, MeasureSettings
from pipeline.measure.worker import Task
from pipeline.photoset import (
    PhotoSet,
    load_photoset,
    missing_image_problem,
    overlay_name,
    photo_names,
)
from pipeline.pool import map_photos
from pipeline.ramp_check import check_ramps, flag_settling
from pipeline.result_cache import cached_tasks, check_cache_dir, prune, run_cached
from pipeline.sealed_end_check import check_sealed_ends

#: angles.csv: the measurement columns, in this order, then the manifest's own columns
#: (``degree``: curve-model complexity the estimator used, see
#: :class:`~pipeline.measure.AngleResult`;
#: empty on failed rows; ``width_px``: the line's or body's width, edge to edge;
#: ``base_direction_deg``: the direction a body's psi is measured from, see
#: :func:`pipeline.ramp_check.share_base_direction`; ``base_side_split_deg``: how far a body's
#: two sides diverge there (:func:`pipeline.measure.body.base_side_split_deg`);
#: ``camera_turn_deg``: how far the camera turned since the ramp's first photo
#: (:mod:`pipeline.camera_turn`, in the convention of ``base_direction_deg``);
#: ``fixed_direction_deg``: the one given,
#: which psi is then measured from (in the same convention); ``positive_turn``: that convention,
#: psi's (``cw``: the three directions clockwise from +x); ``l0_mm``: the
#: length psi was computed with; ``calibration_px`` /
#: ``calibration_mm``: reprojection error of the row's camera calibration, empty when uncalibrated;
#: ``sealed_end_mm``: the one given; ``straight_end_mm``: the straight end seen on a capped
#: body's centre line; ``past_l0_mm``: how far it runs past l0_mm at the scale given, see
#: :mod:`pipeline.sealed_end_check`)
RESULT_COLUMNS: tuple[str, ...] = (
    "image",
    "psi_deg",
    "kappa_per_mm",
    "length_mm",
    "length_px",
    "width_px",
    "base_direction_deg",
    "base_side_split_deg",
    "camera_turn_deg",
    "fixed_direction_deg",
    "positive_turn",
    "method",
    "residual_px",
    "status",
    "reason",
    "seconds",
    "degree",
    "l0_mm",
    "calibration_px",
    "calibration_mm",
    "sealed_end_mm",
    "straight_end_mm",
    "past_l0_mm",
)
#: an ``ok`` first look and an ``ok`` second look further apart than this (deg): the second is
#: taken.  A first look told from a model of the backdrop misses a faint side of a translucent
#: body and reads the tip's direction off (customer 23: three curled photos 6-7 deg off, ok).
#: Only in a ramp that has a doubtful row, whose empty scene is estimated anyway: ``bench
#: ramps`` (with the second look) went from 3 ``ok`` rows 5-10 deg off to 0, 400 -> 403 within
#: 5 deg, in 47 s beside 38; ``--held-out``, six sets not used to choose it, 6 and 1 over 10 deg
#: to 0, 291 -> 298 of 298 within 5 deg (docs/body.md, "Two looks that disagree")
SECOND_LOOK_APART_DEG = 4.0
#: manifest columns carried over first (when present), then any others
CARRIED_FIRST: tuple[str, ...] = (
    "pressure_kpa",
    "direction",
    "material",
    "actuator",
    "trial",
    "step",
)


def _tasks(ps: PhotoSet, method: str, overlays_dir: Path | None) -> list[Task]:
    tasks = []
    in_folder: list[str] | None = None  # the folder's photos, listed once if a row's is missing
    for i, m in enumerate(ps.manifest.itertuples(index=False)):
        image = str(m.image)
        overlay = None if overlays_dir is None else str(overlays_dir / overlay_name(image))
        # which actuator, as preview's tiles say: the sets of several actuators in one view show
        # the same photos (customer 45)
        title = (
            f"{image}  {m.material} {m.actuator} t{m.trial}  {m.pressure_kpa:g} kPa {m.direction}"
        )
        row = ps.rows[i]
        if row is not None and not ps.image_path(image).is_file():
            if in_folder is None:
                in_folder = photo_names(ps.folder, subfolders=True) if ps.folder.is_dir() else []
            line = int(ps.manifest["manifest_line"].iloc[i])
            p = missing_image_problem(ps, line, image, in_folder)
            reason = f"manifest line {line}: {p.message} (fix: {p.fix})"
            tasks.append(Task(str(ps.image_path(image)), None, method, overlay, title, reason))
            continue
        cal = None if row is None else row.calibration
        if cal is not None and cal.plane is not None:
            title += f"  calibrated ({cal.plane.rms_px:.2f} px)"
        tasks.append(
            Task(str(ps.image_path(image)), row, method, overlay, title, ps.row_reason(i))
        )
    return tasks


def measure_photoset(
    folder: str | os.PathLike[str] | PhotoSet,
    *,
    method: str = DEFAULT_METHOD,
    jobs: int = 1,
    overlays_dir: str | os.PathLike[str] | None = None,
    ramp_check: bool = True,
    second_look: bool = True,
    cache_dir: str | os.PathLike[str] | None = None,
) -> pd.DataFrame:
    """Measure psi on every photo of a photo set; a bad photo or manifest row is a ``failed`` row.

    Parameters
    ----------
    folder : path or PhotoSet
        Photo-set folder (manifest.csv + photoset.yaml + images), or one already loaded
        (:func:`pipeline.photoset.load_photoset`).
    method : str
        Estimator, a key of :data:`pipeline.measure.METHODS`.
    jobs : int
        Worker processes (1 = measure in this process).
    overlays_dir : path, optional
        Write ``<image stem>.jpg`` overlays and ``contact_<material>_<actuator>_<trial>.jpg``.
    ramp_check : bool
        Check every photo against its ramp (:mod:`pipeline.ramp_check`): flag the ones that
        break its trend, trust again the cosmetically flagged ones that follow it.
    second_look : bool
        Measure a doubtful body again against its ramp's estimate of the empty scene
        (:func:`estimates_background`); off only to compare (``python -m pipeline bench ramps``).
    cache_dir : path, optional
        Keep each photo's measurement there (:mod:`pipeline.result_cache`): a run cut off
        resumes, and a photo, setting or program unchanged since the last run is not measured
        again (the table's ``attrs["from_cache"]`` counts them, ``attrs["cached_seconds"]`` their
        seconds); the folder keeps other entries up to twice as many as the set's
        (:func:`pipeline.result_cache.prune`).  Photos of a video set are always measured.

    Returns
    -------
    pandas.DataFrame
        The angles.csv table: :data:`RESULT_COLUMNS`, then the manifest's columns
        (pressure_kpa, direction, material, actuator, trial, step, and any others such as
        measured_pressure_kpa, timestamp or force columns) and ``l0_mm``, the marked length
        each photo was measured with (the row's or the folder's setting).  One row per manifest
        row, same order; for a video photo set one row per frame, with ``frame`` and ``time_s``
        after :data:`RESULT_COLUMNS` (see :func:`pipeline.video.measure.measure_video_set`).

    Raises
    ------
    UserInputError
        If the photo set cannot be read at all (see :func:`pipeline.photoset.load_photoset`) or
        the method is unknown.
    """
    if method not in METHODS:
        raise UserInputError(f"--method {method!r} is unknown; use one of {sorted(METHODS)}")
    if jobs < 1:
        raise UserInputError(f"--jobs {jobs} must be at least 1")
    ps = folder if isinstance(folder, PhotoSet) else load_photoset(folder)
    odir = None if overlays_dir is None else Path(overlays_dir)
    if odir is not None:
        odir.mkdir(parents=True, exist_ok=True)
    if ps.is_video:  # one row per frame (pipeline.video.measure)
        from pipeline.video.measure import measure_video_set

        out = measure_video_set(ps, method=method, jobs=jobs, overlays_dir=odir)
    else:
        cache = None if cache_dir is None else Path(cache_dir)
        if cache is not None:
            check_cache_dir(cache, ps.folder)
        out = _measure_photos(ps, method, jobs, odir, second_look, cache, ramp_check)
    from_cache = int(out.attrs.get("from_cache", 0))
    cached_seconds = float(out.attrs.get("cached_seconds", 0.0))
    drawn = out[["status", "reason", "psi_deg"]].copy()
    if ramp_check:
        out = check_ramps(
            out,
            clamped=() if ps.is_video else clamped_ramps(ps, out),
            doubtful=guessed_at_the_free_end(ps, out, out.attrs.get("line_ends")),
        )
    if not ps.is_video:
        out = flag_settling(note_uneven_light(ps, out))
    out = check_sealed_ends(out)
    if "calibration_px" in out.columns:
        out = flag_doubtful_calibration(out)
    if odir is not None:
        if not ps.is_video:
            note_changed_statuses(out, drawn, odir)
        write_contact_sheets(out, odir)
    out.attrs["from_cache"] = from_cache
    out.attrs["cached_seconds"] = cached_seconds
    return out


#: the rows of a ramp whose fixed ends lie this close (px, or half its bodies' median width where
#: that is more) name one clamp (:func:`clamped_ramps`)
SAME_CLAMP_PX = 5.0
#: ... for at least this share of its rows (one fixed end mistyped is no free strip)
SAME_CLAMP_SHARE = 0.8


def clamped_ramps(ps: PhotoSet, angles: pd.DataFrame) -> set[tuple[Any, ...]]:
    """The ramps (their :data:`~pipeline.constants.RAMP_KEYS` values in ``angles``, one row per
    manifest row of ``ps``) whose rows name one fixed end: a clamp holds their bodies in one
    direction.  Fixed ends given per row count as one when :data:`SAME_CLAMP_SHARE` of them lie
    within :data:`SAME_CLAMP_PX` (or half the ramp's median ``width_px``) of their median; rows
    that could not be read (a typo: ``ps.rows`` None) are passed over.  Free strips name one per
    row, farther apart; a guessed fixed end (``auto``) names none.

    Examples
    --------
    >>> from types import SimpleNamespace as S
    >>> ps = S(rows=[S(fixed_end_px=(10.0, 5.0)), None, S(fixed_end_px=(10.3, 5.0)),
    ...              S(fixed_end_px=(10.0, 5.0)), S(fixed_end_px=(40.0, 5.0))])
    >>> df = pd.DataFrame({"material": "M", "actuator": "A1", "trial": [1, 1, 1, 2, 2]})
    >>> clamped_ramps(ps, df)
    {('M', 'A1', 1)}
    >>> sorted(clamped_ramps(ps, df.assign(width_px=70.0)))  # 30 px apart: in half a width
    [('M', 'A1', 1), ('M', 'A1', 2)]
    >>> ps = S(rows=[S(fixed_end_px=(10.0, 5.0))] * 5 + [S(fixed_end_px=(1000.0, 5.0))])
    >>> clamped_ramps(ps, pd.DataFrame({"material": "M", "actuator": "A1", "trial": [1] * 6}))
    {('M', 'A1', 1)}
    """
    if not set(RAMP_KEYS) <= set(angles.columns):
        return set()
    widths = pd.to_numeric(
        angles.get("width_px", pd.Series(np.nan, index=angles.index)), errors="coerce"
    )
    out = set()
    for key, ramp in angles.groupby(list(RAMP_KEYS), sort=False):
        read = [r for r in (ps.rows[i] for i in ramp.index) if r is not None]
        if not read or any(r.fixed_end_px is None for r in read):
            continue
        ends = np.array([r.fixed_end_px for r in read], float)
        off = np.hypot(*(ends - np.median(ends, axis=0)).T)
        width = float(widths[ramp.index].median()) if widths[ramp.index].notna().any() else 0.0
        if np.mean(off <= max(SAME_CLAMP_PX, 0.5 * width)) >= SAME_CLAMP_SHARE:
            out.add(key)
    return out


#: a guessed fixed end (``auto``) lies at a photo's free end where the other end of its line
#: lies within this share of the ramp's median line length of where most of its photos' lines
#: start (the clamp, which stays put, or moves with a camera held by hand)
SAME_START_SHARE = 0.1


def ramp_start(ends: NDArray[np.float64], radius_px: float) -> NDArray[np.float64] | None:
    """Where the lines of one ramp start: the line end (``ends`` rows are ``x0, y0, x1, y1``,
    start then end) with the most photos' lines ending within ``radius_px`` of it at either end,
    a start before an end; None where fewer than 60 % of the photos (and 3) share one.

    Examples
    --------
    >>> ends = np.array([[0, 0, 90, 50], [2, 1, 80, 70], [60, 95, 1, 2], [1, 0, 40, 95.0]])
    >>> ramp_start(ends, 10.0).tolist()
    [0.0, 0.0]
    >>> ramp_start(ends[:2], 10.0) is None
    True
    """
    points = np.r_[ends[:, :2], ends[:, 2:]]
    near = [
        int(np.sum(np.minimum(np.hypot(*(ends[:, :2] - p).T), np.hypot(*(ends[:, 2:] - p).T))
                   <= radius_px))
        for p in points
    ]
    best = int(np.argmax(near))  # the first of the most: a start before an end
    if near[best] < max(3, 0.6 * len(ends)):
        return None
    return points[best]


def guessed_at_the_free_end(
    ps: PhotoSet, angles: pd.DataFrame, line_ends: Sequence[Any] | None
) -> dict[Any, str]:
    """The rows whose fixed end was guessed (``fixed_end: auto``) at the line's free end, each
    with its reason: their line's other end lies where the lines of most of the ramp's photos
    start (:func:`walked_from_the_tip`), so psi, walked from the tip, may have the wrong sign;
    after :func:`measure_photoset` measured them again from there, those it could not (customer
    46's clamp beside a grey backdrop: two rows ok with psi +61 and +64 for -58 and -60, and
    the ramp check flagged the right rows beside them as breaking it).

    ``line_ends`` holds each row's line start and end (``x0, y0, x1, y1``, image px; None where
    not measured), in the order of ``angles``' rows.
    """
    if line_ends is None or not set(RAMP_KEYS) <= set(angles.columns):
        return {}
    guessed = np.array([r is not None and r.fixed_end_px is None for r in ps.rows])
    found = np.array([e is not None for e in line_ends]) & (angles["status"] != "failed")
    ramps = [
        list(ramp.index)
        for _, ramp in angles[guessed & found.to_numpy()].groupby(list(RAMP_KEYS), sort=False)
    ]
    return {
        i: (
            "fixed end guessed at the free end (fixed_end auto): the line's other end "
            f"lies where most of its ramp's photos start, near ({start[0]:.0f}, "
            f"{start[1]:.0f}), so psi may have the wrong sign (set fixed_end, the pixel "
            "where the actuator leaves the clamp)"
        )
        for i, start in walked_from_the_tip(ramps, line_ends, angles["length_px"]).items()
    }


def walked_from_the_tip(
    ramps: Sequence[Sequence[int]],
    line_ends: Sequence[Any],
    lengths_px: Sequence[float] | pd.Series,
) -> dict[int, NDArray[np.float64]]:
    """The rows, of ``ramps`` (lists of row positions, each row's fixed end guessed), whose line
    was walked from its tip, each with where its ramp's lines start (:func:`ramp_start`): its
    line ends within :data:`SAME_START_SHARE` of the ramp's median line length of that point, and
    starts farther from it.  ``line_ends`` holds each row's ``x0, y0, x1, y1`` (image px; None
    where not measured) and ``lengths_px`` its line length, both by row position.

    Examples
    --------
    >>> ends = [(0, 0, 90, 50), (1, 0, 80, 70), (2, 1, 60, 95), (40, 95, 1, 1), None]
    >>> {i: p.tolist() for i, p in walked_from_the_tip([[0, 1, 2, 3]], ends, [100] * 5).items()}
    {3: [0.0, 0.0]}
    """
    out: dict[int, NDArray[np.float64]] = {}
    for idx in ramps:
        if len(idx) < 3:
            continue
        ends = np.array([line_ends[i] for i in idx], float)
        radius = SAME_START_SHARE * float(np.nanmedian([lengths_px[i] for i in idx]))
        start = ramp_start(ends, radius)
        if start is None:
            continue
        for i, e in zip(idx, ends, strict=True):
            if np.hypot(*(e[2:] - start)) <= radius < np.hypot(*(e[:2] - start)):
                out[i] = start
    return out


#: a body told from the backdrop whose light falls off by more than this across its photo
#: (:func:`pipeline.measure.body.light_falloff`; rendered lamp-lit scenes 0.2-0.45) ...
UNEVEN_LIGHT_FALLOFF = 0.5
#: ... is told so when it is flagged or failed, with the fix
NOTE_UNEVEN_LIGHT = "the backdrop's light falls off by"


def note_uneven_light(ps: PhotoSet, angles: pd.DataFrame) -> pd.DataFrame:
    """Say in the reason of each flagged or failed body told from the backdrop (no empty scene,
    no colour) whose ramp's first such photo shows light that falls off by more than
    :data:`UNEVEN_LIGHT_FALLOFF` that it does, and the fix: a photo of the empty scene.

    Without one the body's faint parts are lost where the photo is darker, and the other reasons
    (a rival selection by the clamp, a gap) point at ``roi`` or ``exclude`` instead (a rendered
    12 MP translucent ramp darkened to 0.6 at a corner: all 44 flagged, 3 within 10 deg; with
    its empty scene all within 5).
    """
    out = angles.copy()
    bad = (out["status"] != "ok").to_numpy()
    told_by_backdrop = np.array(
        [r is not None and r.target == "body" and r.color is None and r.background_path is None
         for r in ps.rows]
    )
    if not (bad & told_by_backdrop).any() or not set(RAMP_KEYS) <= set(out.columns):
        return out
    from pipeline.measure.body import light_falloff
    from pipeline.measure.extract import region_mask

    for _, ramp in out.groupby(list(RAMP_KEYS), sort=False):
        rows = [i for i in ramp.index if told_by_backdrop[i]]
        if not rows or not bad[rows].any():
            continue
        first = ps.rows[rows[0]]
        assert first is not None
        try:
            data = np.fromfile(ps.image_path(str(out.at[rows[0], "image"])), np.uint8)
        except OSError:  # its row says so already
            continue
        img, scale = decode_for_work(data, grey=False) if data.size else (None, 1)
        if img is None:
            continue
        region = region_mask(img.shape, first.roi, first.exclude, scale)
        falloff = light_falloff(img, np.ones(img.shape[:2], np.uint8) if region is None else region)
        if falloff <= UNEVEN_LIGHT_FALLOFF:
            continue
        note = (
            f"{NOTE_UNEVEN_LIGHT} {100 * falloff:.0f} % across the photo (one lamp to a side?): "
            "without the empty scene the body's faint parts are lost where it is darker; take a "
            "photo of the empty scene and name it as background in photoset.yaml"
        )
        for i in rows:
            if bad[i]:
                reason = str(out.at[i, "reason"]) if isinstance(out.at[i, "reason"], str) else ""
                out.at[i, "reason"] = f"{reason}; {note}" if reason else note
    return out


def note_changed_statuses(angles: pd.DataFrame, drawn: pd.DataFrame, overlays_dir: Path) -> None:
    """Write the final status on the overlay of each photo whose status, reason or psi (as
    drawn, to 0.1 deg) the set's checks changed after it was drawn (``drawn``: the per-photo
    ``status``, ``reason`` and ``psi_deg``)."""
    from pipeline.measure.overlay import note_final_status

    moved = (angles["psi_deg"] - drawn["psi_deg"]).abs() >= 0.05
    changed = (angles["status"] != drawn["status"]) | (angles["reason"] != drawn["reason"]) | moved
    for image, status, reason, drawn_reason, psi, psi_moved in zip(
        angles.loc[changed, "image"],
        angles.loc[changed, "status"],
        angles.loc[changed, "reason"],
        drawn.loc[changed, "reason"],
        angles.loc[changed, "psi_deg"],
        moved[changed],
        strict=True,
    ):
        path = overlays_dir / overlay_name(str(image))
        img = cv2.imread(str(path))
        if img is None:
            continue
        ok, buf = cv2.imencode(
            ".jpg",
            note_final_status(
                img, str(status), str(reason), str(drawn_reason), psi if psi_moved else None
            ),
            [cv2.IMWRITE_JPEG_QUALITY, 85],
        )
        if ok:
            atomic_write_bytes(path, buf.tobytes())


def _measured(
    tasks: list[Task], jobs: int, cache_dir: Path | None, used: set[str]
) -> list[dict[str, Any]]:
    """Each task's angles.csv fields (:func:`pipeline.measure.worker.run_task`), taken from
    ``cache_dir`` where an earlier run measured the same (:mod:`pipeline.result_cache`); the
    entries are added to ``used``."""
    rows = map_photos(
        run_cached,
        cached_tasks(tasks, cache_dir),
        jobs=jobs,
        preload=["pipeline.measure.worker", "pipeline.result_cache"],
    )
    used.update(name for r in rows if (name := r.pop("cache_entry")) is not None)
    return rows


def _measure_photos(
    ps: PhotoSet,
    method: str,
    jobs: int,
    odir: Path | None,
    second_look: bool = True,
    cache_dir: Path | None = None,
    from_ramp_starts: bool = True,
) -> pd.DataFrame:
    """The angles.csv table of a photo set of images (one row per manifest row); its ``attrs``
    hold ``from_cache``, how many photos an earlier run had measured (with ``cache_dir``).
    ``from_ramp_starts``: measure a line walked from its tip again (:func:`_from_ramp_starts`;
    not with ``--no-ramp-check``, which measures each photo on its own)."""
    manifest = ps.manifest
    tasks = _tasks(ps, method, odir)
    used: set[str] = set()
    rows = _measured(tasks, jobs, cache_dir, used)
    cached = [bool(r.pop("from_cache")) for r in rows]
    cached_s = float(np.nansum([r["seconds"] for r, c in zip(rows, cached, strict=True) if c]))
    if second_look:
        rows = _on_ramp_backgrounds(ps, tasks, rows, jobs, cache_dir, used)
    if from_ramp_starts:
        rows = _from_ramp_starts(ps, tasks, rows, jobs, cache_dir, used)
    if cache_dir is not None:
        prune(cache_dir, used)
    turns = _camera_turns(ps, tasks, rows, jobs)
    result = pd.DataFrame(rows, index=manifest.index).drop(columns="centreline_px")
    result["camera_turn_deg"] = turns
    result["degree"] = result["degree"].astype("Int64")
    result.insert(0, "image", manifest["image"].astype(str))
    result["l0_mm"] = [np.nan if r is None else r.l0_mm for r in ps.rows]
    result["fixed_direction_deg"] = [np.nan if r is None else r.base_given_deg for r in ps.rows]
    result["positive_turn"] = [None if r is None else r.positive_turn for r in ps.rows]
    result["sealed_end_mm"] = [np.nan if r is None else r.sealed_end_mm for r in ps.rows]
    rms = [(np.nan, np.nan) if r is None else r.calibration_rms for r in ps.rows]
    result["calibration_px"] = [px for px, _ in rms]
    result["calibration_mm"] = [mm for _, mm in rms]
    carried = [c for c in CARRIED_FIRST if c in manifest.columns]
    # every other column of the manifest, its setting columns as given (customer 47 could not
    # trace a row's fixed_end_x), but the settings angles.csv writes as used (l0_mm,
    # positive_turn, ...); a column of the user's own named as one angles.csv writes ('reason',
    # 'seconds') as manifest_<name> (angles.csv would hold two columns of that name)
    as_used = {"image", "manifest_line", *(set(OVERRIDE_COLUMNS) & set(RESULT_COLUMNS))}
    carried += [c for c in manifest.columns if c not in as_used and c not in carried]
    own = manifest[carried].rename(
        columns={c: f"manifest_{c}" for c in carried if c in RESULT_COLUMNS}
    )
    out = pd.concat([result[list(RESULT_COLUMNS)], own], axis=1).reset_index(drop=True)
    out.attrs["from_cache"] = sum(cached)
    out.attrs["cached_seconds"] = cached_s
    out.attrs["line_ends"] = [_line_ends(r) for r in rows]
    return out


def _camera_turns(
    ps: PhotoSet, tasks: list[Task], rows: list[dict[str, Any]], jobs: int
) -> np.ndarray:
    """Each body row's camera turn since its ramp's first photo (:func:`ramp_turns`, in the
    convention of ``base_direction_deg``: clockwise with ``positive_turn: cw``); NaN for a drawn
    line (its psi does not depend on the camera's turn) and where unknown."""
    turns = np.full(len(rows), np.nan)
    if not set(RAMP_KEYS) <= set(ps.manifest.columns):
        return turns
    order = ps.manifest["step"] if "step" in ps.manifest.columns else pd.Series(range(len(rows)))
    ramps: dict[tuple[str, ...], list[int]] = {}
    for i, settings in enumerate(ps.rows):
        if settings is not None and settings.target == "body" and Path(tasks[i].path).is_file():
            key = tuple(str(ps.manifest[k].iloc[i]) for k in RAMP_KEYS)
            ramps.setdefault(key, []).append(i)
    groups = [
        sorted(m, key=lambda i: (pd.to_numeric(order.iloc[i], errors="coerce"), i))
        for m in ramps.values()
        if len(m) >= 2
    ]
    photos = []
    for members in groups:
        found = [rows[i]["status"] != "failed" for i in members]
        photos.append(RampPhotos(
            tuple(tasks[i].path for i in members),
            tuple(rows[i]["centreline_px"] if f else None
                  for i, f in zip(members, found, strict=True)),
            tuple(float(rows[i]["width_px"]) if f else float("nan")
                  for i, f in zip(members, found, strict=True)),
            first.exclude if (first := ps.rows[members[0]]) is not None else (),
            first.fixed_end_px if first is not None else None,
        ))
    for members, got in zip(
        groups, map_photos(ramp_turns, photos, jobs=jobs, preload=["pipeline.camera_turn"],
                           desc="ramps"), strict=True
    ):
        for i, turn in zip(members, got, strict=True):
            settings = ps.rows[i]
            assert settings is not None
            turns[i] = settings.sign * turn
    return turns


def second_look_ramps(ps: PhotoSet) -> list[list[int]]:
    """The rows of each ramp whose body ``measure`` may look at again against the empty scene
    estimated from the ramp's photos: rows that :func:`estimates_background` and whose photo is
    there, in ramps of at least :data:`RAMP_BACKGROUND_MIN_PHOTOS` such rows (the estimate also
    needs that many photos that decode, of one size; a video set has none)."""
    if ps.is_video or not set(RAMP_KEYS) <= set(ps.manifest.columns):
        return []
    ramps: dict[tuple[str, ...], list[int]] = {}
    for i, (image, row) in enumerate(zip(ps.manifest["image"], ps.rows, strict=True)):
        if estimates_background(row) and ps.image_path(str(image)).is_file():
            key = tuple(str(ps.manifest[k].iloc[i]) for k in RAMP_KEYS)
            ramps.setdefault(key, []).append(i)
    return [m for m in ramps.values() if len(m) >= RAMP_BACKGROUND_MIN_PHOTOS]


def _ramp_estimates(
    ps: PhotoSet, tasks: list[Task], rows: list[dict[str, Any]], folder: Path
) -> dict[int, Path]:
    """For each ramp of at least :data:`RAMP_BACKGROUND_MIN_PHOTOS` photos of one size whose rows
    :func:`estimates_background`, its empty scene estimated from its photos and their first
    measurement (:mod:`pipeline.measure.ramp_background`), written into ``folder``: row -> file.
    """
    out: dict[int, Path] = {}
    for number, members in enumerate(second_look_ramps(ps)):
        if all(rows[i]["status"] == "ok" for i in members):
            continue
        used: list[int] = []
        images: list[np.ndarray] = []
        covers: list[np.ndarray] = []
        for i in members:
            img, f = decode_for_work(np.fromfile(tasks[i].path, np.uint8))
            if img is None or (images and img.shape != images[0].shape):
                continue  # a photo that cannot be read, or of another size: not in the estimate
            line = np.asarray(rows[i]["centreline_px"], float).reshape(-1, 2)
            used.append(i)
            images.append(img)
            covers.append(
                covered(img.shape[:2], (line - (f - 1) / 2) / f, float(rows[i]["width_px"]) / f)
                if rows[i]["status"] != "failed"
                else np.ones(img.shape[:2], bool)
            )
        if len(used) >= RAMP_BACKGROUND_MIN_PHOTOS:
            path = folder / f"ramp{number}.png"
            cv2.imwrite(str(path), estimate_background(images, covers))
            out.update({i: path for i in used})
    return out


def _on_ramp_backgrounds(
    ps: PhotoSet,
    tasks: list[Task],
    rows: list[dict[str, Any]],
    jobs: int,
    cache_dir: Path | None = None,
    used: set[str] | None = None,
) -> list[dict[str, Any]]:
    """``rows``, where a body's first measurement is doubtful (flagged or failed), with its
    measurement against the empty scene estimated from its ramp's photos when that one is
    ``ok`` (its reason then says so); and where the first is ``ok`` too, with the second when
    both are ``ok`` and more than :data:`SECOND_LOOK_APART_DEG` apart.

    Without a photo of the empty scene a translucent body on a backdrop of its own grey is told
    from the backdrop by a model of it, which misses its faint parts (a tip that the light
    leaves); the other photos of the ramp show the backdrop there.  The estimate is made for a
    ramp that has a doubtful row, and only an ``ok`` second look replaces a row (a flagged first
    look keeps its psi and reasons); an ``ok`` first look only where the two disagree: on 47
    rendered ramp sets (1962 photos) taking the second look for every photo put 17 more ``ok``
    rows 5-10 deg off and 2 over 10, where the first looks were right (``docs/body.md``, "The
    empty scene from the ramp's own photos" and "Two looks that disagree").
    """
    out = list(rows)
    with tempfile.TemporaryDirectory(prefix="ramp-backgrounds-") as tmp:
        estimates = _ramp_estimates(ps, tasks, rows, Path(tmp))
        changed = {
            i: replace(settings, background_path=str(path), background_estimated=True)
            for i, path in estimates.items()
            if (settings := tasks[i].settings) is not None
        }
        for i, (task, row) in _measured_again(tasks, changed, jobs, cache_dir, used, tmp).items():
            first = rows[i]
            apart = abs(float(row["psi_deg"]) - float(first["psi_deg"]))
            if row["status"] != "ok" or (
                first["status"] == "ok" and not apart > SECOND_LOOK_APART_DEG
            ):
                continue
            # its reason says how it was measured (NOTE_RAMP_BACKGROUND, last); and what the
            # first look read, so that a user sees how much the second one changed
            read = (
                f"{first['psi_deg']:+.1f} deg, {first['status']}"
                if np.isfinite(first["psi_deg"])
                else str(first["status"])
            )
            if first["status"] == "ok":
                read += f", {apart:.1f} deg apart: the second look is taken"
            elif cause := first_cause(str(first["reason"] or "")):
                read += f": {cause}"  # customer 29 had to run preview to learn why
            out[i] = {**row, "reason": f"{row['reason']} (the first look read {read})"}
            _keep_overlay(task, tasks[i])
    return out


def _measured_again(
    tasks: list[Task],
    settings: dict[int, MeasureSettings],
    jobs: int,
    cache_dir: Path | None,
    used: set[str] | None,
    tmp: str,
) -> dict[int, tuple[Task, dict[str, Any]]]:
    """Measure photos ``tasks[i]`` again with ``settings[i]``, each drawing its overlay into
    ``tmp`` (kept only by :func:`_keep_overlay`): row ``i`` -> (its task, its row)."""
    again = [
        (i, replace(
            tasks[i],
            settings=s,
            overlay_path=None if tasks[i].overlay_path is None else str(Path(tmp) / f"{i}.jpg"),
        ))
        for i, s in settings.items()
    ]
    measured = (
        _measured([t for _, t in again], jobs, cache_dir, set() if used is None else used)
        if again
        else []
    )
    out = {}
    for (i, task), row in zip(again, measured, strict=True):
        row.pop("from_cache")
        out[i] = (task, row)
    return out


def _keep_overlay(task: Task, first: Task) -> None:
    """Put the overlay a photo measured again drew (``task``) where its first one was."""
    drawn, final = task.overlay_path, first.overlay_path
    if drawn is not None and final is not None:
        shutil.move(drawn, final)  # the temporary folder may be on another disk


def _from_ramp_starts(
    ps: PhotoSet,
    tasks: list[Task],
    rows: list[dict[str, Any]],
    jobs: int,
    cache_dir: Path | None = None,
    used: set[str] | None = None,
) -> list[dict[str, Any]]:
    """``rows``, where a drawn line's fixed end guessed (``fixed_end: auto``) took its free end
    (:func:`walked_from_the_tip`), with the photo measured again from where its ramp's photos'
    lines start (the clamp stays put, the tip moves), when that measurement is not ``failed``;
    its reason says so (:data:`~pipeline.measure.quality.NOTE_FROM_RAMP_START`), and its
    overlay is the second measurement's only then.

    A black line on a body held by a white clamp gave ``auto`` no dark clamp to start from: it
    walked every photo of a rendered ramp from the tip, and psi had the wrong sign in each.  A
    body (whose doubtful rows may have had a second look against the ramp's empty scene) is
    left to :func:`guessed_at_the_free_end`'s flag.
    """
    ends = [_line_ends(r) for r in rows]
    manifest = ps.manifest
    if not set(RAMP_KEYS) <= set(manifest.columns):
        return rows
    guessed = [
        i for i, t in enumerate(tasks)
        if t.settings is not None and t.settings.fixed_end_px is None
        and t.settings.target == "line" and ends[i] is not None
    ]
    ramps: dict[tuple[str, ...], list[int]] = {}
    for i in guessed:
        ramps.setdefault(tuple(str(manifest[k].iloc[i]) for k in RAMP_KEYS), []).append(i)
    starts = walked_from_the_tip(list(ramps.values()), ends, [r["length_px"] for r in rows])
    if not starts:
        return rows
    out = list(rows)
    changed = {}
    for i, start in starts.items():
        settings = tasks[i].settings
        assert settings is not None
        changed[i] = replace(settings, fixed_end_px=(float(start[0]), float(start[1])))
    with tempfile.TemporaryDirectory(prefix="ramp-starts-") as tmp:
        for i, (task, row) in _measured_again(tasks, changed, jobs, cache_dir, used, tmp).items():
            if row["status"] == "failed":
                continue
            note = (
                f"{NOTE_FROM_RAMP_START}, near "
                f"({starts[i][0]:.0f}, {starts[i][1]:.0f}): fixed_end auto had taken the free "
                f"end (psi {rows[i]['psi_deg']:+.1f} deg from there), so set fixed_end, the "
                "pixel where the actuator leaves the clamp"
            )
            out[i] = {**row, "reason": f"{row['reason']}; {note}" if row["reason"] else note}
            _keep_overlay(task, tasks[i])
    return out


def _line_ends(row: dict[str, Any]) -> tuple[float, float, float, float] | None:
    """A measured row's line start and end (``x0, y0, x1, y1``, image px); None where failed."""
    line = row.get("centreline_px")
    if row["status"] == "failed" or line is None or len(line) < 2:
        return None
    a = np.asarray(line, float)
    return (float(a[0, 0]), float(a[0, 1]), float(a[-1, 0]), float(a[-1, 1]))


def first_cause(reason: str) -> str:
    """The first cause of a row's reason, without the notes on how psi was taken and without
    its fix (what follows its first colon).

    Examples
    --------
    >>> first_cause("psi from the free end's tangent against fixed_direction_deg; the centre "
    ...             "line stops 24 px short of the body's free end (uneven outline there): check "
    ...             "with photoset preview")
    "the centre line stops 24 px short of the body's free end (uneven outline there)"
    >>> first_cause("end direction unstable (-13 vs +11 deg over a longer end)")
    'end direction unstable (-13 vs +11 deg over a longer end)'
    """
    for part in reason.split(";"):
        text = part.strip()
        if text and not text.startswith(NOTES):
            return text.split(": ", 1)[0]
    return ""


def flag_doubtful_calibration(angles: pd.DataFrame) -> pd.DataFrame:
    """Flag the measured rows whose calibration's reprojection error is above ``MAX_RMS_PX``."""
    from pipeline.measure.calibration import MAX_RMS_PX

    bad = (angles["calibration_px"] > MAX_RMS_PX) & (angles["status"] != "failed")
    if not bad.any():
        return angles
    out = angles.copy()
    note = out.loc[bad, "calibration_px"].map(
        lambda e: f"calibration reprojection error {e:.2f} px > {MAX_RMS_PX:g} px"
    )
    old = out.loc[bad, "reason"].fillna("").astype(str)
    out.loc[bad, "reason"] = [f"{r}; {n}" if r else n for r, n in zip(old, note)]
    out.loc[bad, "status"] = "flagged"
    return out


def write_contact_sheets(angles: pd.DataFrame, overlays_dir: Path) -> list[Path]:
    """One ``contact_<material>_<actuator>_<trial>.jpg`` per ramp, photos in manifest order
    (for a video: the frames that have an overlay, in time order)."""
    from pipeline.measure.overlay import (
        contact_sheet,  # cv2 drawing only when overlays are asked for
    )

    written = []
    for (material, actuator, trial), g in angles.groupby(
        list(RAMP_KEYS), sort=False
    ):
        if "frame" in g.columns:
            from pipeline.video.measure import frame_overlay_name

            paths = [
                overlays_dir / frame_overlay_name(str(i), int(k))
                for i, k in zip(g["image"], g["frame"])
                if pd.notna(k)
            ]
            paths = [p for p in paths if p.is_file()]
            if not paths:
                continue
        else:
            paths = [overlays_dir / overlay_name(str(i)) for i in g["image"]]
        sheet = contact_sheet(paths)
        ok, buf = cv2.imencode(".jpg", sheet, [cv2.IMWRITE_JPEG_QUALITY, 85])
        if ok:
            path = overlays_dir / f"contact_{material}_{actuator}_{trial}.jpg"
            atomic_write_bytes(path, buf.tobytes())
            written.append(path)
    return written


def write_angles(angles: pd.DataFrame, out: str | os.PathLike[str]) -> None:
    """Write angles.csv atomically (failed rows have an empty psi_deg)."""
    write_table(angles, out)


def summary(angles: pd.DataFrame, seconds: bool = True) -> str:
    """One-line summary of a measured set: its counts and (``seconds``) the seconds the photos
    took to measure in this run (not those read back from a cache: customer 33 read "17.4 s of
    work" for a run that measured nothing).

    Examples
    --------
    >>> t = pd.DataFrame({"status": ["ok", "ok", "failed"], "seconds": [2.0, 3.0, 0.5]})
    >>> summary(t)
    'measured 3 photos: 2 ok, 0 flagged, 1 failed (5.5 s of work)'
    >>> t.attrs["cached_seconds"] = 5.0
    >>> summary(t)
    'measured 3 photos: 2 ok, 0 flagged, 1 failed (0.5 s of work)'
    """
    counts = angles["status"].value_counts()
    sec = float(np.nansum(angles["seconds"])) - float(angles.attrs.get("cached_seconds", 0.0))
    unit = "frames" if "frame" in angles.columns else "photos"
    return (
        f"measured {len(angles)} {unit}: {counts.get('ok', 0)} ok, {counts.get('flagged', 0)} "
        f"flagged, {counts.get('failed', 0)} failed"
        + (f" ({max(sec, 0.0):.1f} s of work)" if seconds else "")
    )


def run_summaries(
    angles_paths: dict[str, Path], logs: dict[str, Path] | None = None, most: int = 5
) -> list[str]:
    """What the console says at the end of a workflow run: one line per dataset measured
    (:func:`summary`), and where a set's flagged and failed rows say why; then, indented, the
    warnings its measure job's log holds (``logs``: dataset -> log; at most ``most``).

    Snakemake writes each job's output to its log, so a run ended with exit status 0 and nothing
    on the console about a failed row (customer 30), nor of a key ignored that moved psi on every
    ``ok`` row, or of a photo of the folder left out (customer 47).  A job not run again keeps
    its log, whose warnings still hold for its set.  ``angles_paths`` maps a dataset's name to
    its angles.csv; a missing file is skipped.  The seconds of work are not said: angles.csv
    holds those of photos measured in earlier runs too (customer 44 read "12.3 s of work" for
    a run that measured one photo in 0.9 s); each measure job's log says its own.
    """
    lines = []
    for name, path in angles_paths.items():
        if not Path(path).is_file():
            continue
        angles = pd.read_csv(path, usecols=lambda c: c in {"status", "seconds", "frame"})
        line = f"{name}: {summary(angles, seconds=False)}"
        if (angles["status"] != "ok").any():
            line += f"; why: the 'reason' column of {path}"
        lines.append(line)
        log = None if logs is None else Path(logs[name])
        if log is None or not log.is_file():
            continue
        said = log.read_text(errors="replace").splitlines()
        warnings = list(dict.fromkeys(w.strip() for w in said if ": warning: " in w))
        lines += [f"  {w}" for w in warnings[:most]]
        if len(warnings) > most:
            lines.append(f"  ... and {len(warnings) - most} more warnings in {log}")
    return lines


#: what an earlier run's report is renamed to when a run fails before making it again
STALE_REPORT_SUFFIX = ".STALE.pdf"


def set_aside_stale_report(report: Path, angles_paths: Sequence[Path]) -> Path | None:
    """Rename ``report`` to ``<name>.STALE.pdf`` (replacing an older one) when it is stale: an
    earlier run's, older than one of the sets' ``angles_paths`` or with one of them missing (a
    failed or interrupted measure job's is removed); return the new path, or None where the
    report is not there or not stale (a failed benchmark or rig job leaves it as it is).

    Customer 47's run stopped on a set's photoset.yaml, and the report of the run before, whose
    numbers no longer matched the photos, stayed as ``results/report.pdf`` for anyone to open
    on Monday.  A run that makes the report again removes the stale one
    (:func:`remove_stale_report`).

    Examples
    --------
    >>> import tempfile, os
    >>> root = Path(tempfile.mkdtemp())
    >>> report, angles = root / "report.pdf", root / "angles.csv"
    >>> _ = angles.write_text("x"); _ = report.write_bytes(b"%PDF")
    >>> os.utime(angles, (1, 1))
    >>> set_aside_stale_report(report, [angles]) is None  # newer than its table
    True
    >>> angles.unlink()
    >>> set_aside_stale_report(report, [angles]).name, report.exists()
    ('report.STALE.pdf', False)
    >>> _ = report.write_bytes(b"%PDF"); remove_stale_report(report); report.exists()
    True
    >>> (report.parent / "report.STALE.pdf").exists()
    False
    """
    if not report.is_file():
        return None
    made = report.stat().st_mtime
    if all(p.is_file() and p.stat().st_mtime <= made for p in map(Path, angles_paths)):
        return None
    stale = report.with_name(report.stem + STALE_REPORT_SUFFIX)
    os.replace(report, stale)
    return stale


def remove_stale_report(report: Path) -> None:
    """Remove the report :func:`set_aside_stale_report` set aside, once ``report`` is made."""
    if report.is_file():
        report.with_name(report.stem + STALE_REPORT_SUFFIX).unlink(missing_ok=True)
