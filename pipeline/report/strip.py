"""Fig. 5-style strip: one actuator's photos across the pressure ramp, with the extracted line.

Photos come from the ``measure --overlays`` folder (``<image stem>.jpg``, line and psi drawn) when
present, else the raw photo from the photo-set folder (and the strip says so).  The text band an
overlay carries at its top (file name, psi, reason) would print at about 2 pt in a strip, so it is
cut off (:func:`crop_banner`); the strip's captions say the same in readable type.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import cv2
import numpy as np
import pandas as pd

from pipeline.measure.formats import read_image
from pipeline.measure.overlay import DIVIDER_BGR
from pipeline.photoset import overlay_name
from pipeline.report.data import Dataset, ReportData, mixed_materials
from pipeline.video.measure import frame_overlay_name
from pipeline.video.reader import probe_video, read_frames

#: photos per strip
STRIP_PHOTOS = 6
#: widest thumbnail kept (px): twice its printed width at 150 dpi; larger photos are reduced (area
#: averaging)
THUMB_MAX_WIDTH_PX = 240


@dataclass(frozen=True)
class StripPhoto:
    """One photo of the strip.

    Attributes
    ----------
    image : numpy.ndarray or None
        RGB uint8 thumbnail; ``None`` when the file is missing or unreadable.
    pressure_kpa : float
    psi_deg : float
        Measured psi (NaN when the measurement failed).
    status : str
    source : str
        ``"overlay"``, ``"raw"`` or ``"missing"``.
    """

    image: np.ndarray | None
    pressure_kpa: float
    psi_deg: float
    status: str
    source: str


@dataclass(frozen=True)
class Strip:
    """The strip of one material: which ramp and its photos."""

    material: str
    dataset: str
    actuator: str
    trial: str
    direction: str
    photos: tuple[StripPhoto, ...]
    images: tuple[str, ...] = ()
    qualified: bool = False

    @property
    def actuator_label(self) -> str:
        """The actuator as the per-actuator plot names it (``<dataset>/<actuator>`` when pooled)."""
        return f"{self.dataset}/{self.actuator}" if self.qualified else self.actuator

    @property
    def note(self) -> str:
        """What the photos are, for the caption."""
        sources = {p.source for p in self.photos}
        if sources == {"overlay"}:
            return "extracted line and psi drawn by 'measure --overlays'"
        if "overlay" in sources:
            return (
                "overlays where available, raw photos elsewhere (no overlay file for some images)"
            )
        if "raw" in sources:
            return (
                "raw photos: no overlays found "
                "(run 'measure --overlays DIR' to draw the extracted line)"
            )
        return "no photos found (pass --photosets / --overlays)"


def crop_banner(bgr: np.ndarray) -> np.ndarray:
    """Cut off the text bands above and below an overlay's photo (up to and from the lines of
    :data:`~pipeline.measure.overlay.DIVIDER_BGR` between them and the photo), or, on an overlay
    drawn before they were bands of their own, a dark text band over the top of the photo (rows
    far darker than the photo).

    A photo without such a band is returned unchanged.

    Examples
    --------
    >>> img = np.full((100, 80, 3), 200, np.uint8)
    >>> band = np.full((30, 80, 3), 40, np.uint8)  # text on dark grey
    >>> band[-2:] = DIVIDER_BGR
    >>> crop_banner(np.vstack([band, img, band[::-1]])).shape[0]
    100
    >>> img[:20] = 60
    >>> crop_banner(img).shape[0], crop_banner(np.full((100, 80, 3), 200, np.uint8)).shape[0]
    (80, 100)
    """
    h = bgr.shape[0]
    divider = np.nonzero(
        np.mean(np.all(np.abs(bgr.astype(int) - DIVIDER_BGR) <= 60, axis=2), axis=1) >= 0.9
    )[0]
    top, bottom = divider[divider < 0.4 * h], divider[divider > 0.6 * h]
    if top.size or bottom.size:
        return bgr[(top.max() + 1 if top.size else 0) : (bottom.min() if bottom.size else h)]
    rows = np.median(bgr.mean(axis=2), axis=1)
    reference = float(np.median(rows[int(0.3 * h):int(0.6 * h)]))
    dark = rows < 0.5 * reference
    n = int(np.argmin(dark)) if not dark.all() else h
    return bgr[n:] if 3 <= n <= 0.3 * h else bgr


def load_thumbnail(
    path: Path, max_width_px: int = THUMB_MAX_WIDTH_PX, *, banner: bool = False
) -> np.ndarray | None:
    """RGB thumbnail of an image file, at most ``max_width_px`` wide; ``None`` if unreadable.

    ``banner=True`` removes an overlay's text band first (:func:`crop_banner`).
    """
    if not path.is_file():
        return None
    bgr = read_image(path)
    if bgr is None:
        return None
    if banner:  # at full size: narrowed, the 2-px line between band and photo blurs away
        bgr = crop_banner(bgr)
    bgr = _narrowed(bgr, max_width_px)
    return cv2.cvtColor(bgr, cv2.COLOR_BGR2RGB)


def _narrowed(bgr: np.ndarray, max_width_px: int) -> np.ndarray:
    """``bgr`` at most ``max_width_px`` wide (its aspect kept)."""
    h, w = bgr.shape[:2]
    if w <= max_width_px:
        return bgr
    size = (max_width_px, max(1, round(h * max_width_px / w)))
    return cv2.resize(bgr, size, interpolation=cv2.INTER_AREA)


def video_frame(
    path: Path, frame: int, max_width_px: int = THUMB_MAX_WIDTH_PX
) -> np.ndarray | None:
    """RGB thumbnail of one frame of a video, at most ``max_width_px`` wide; ``None`` if it
    cannot be read."""
    if not path.is_file():
        return None
    got = next(read_frames(probe_video(path), frame, 1), None)
    if got is None or got.data is None:
        return None
    bgr = cv2.imdecode(got.data, cv2.IMREAD_COLOR) if got.data.ndim == 1 else got.data
    return None if bgr is None else cv2.cvtColor(_narrowed(bgr, max_width_px), cv2.COLOR_BGR2RGB)


def strip_image(
    photos: tuple[StripPhoto, ...], height_px: int, gap_px: int
) -> tuple[np.ndarray, list[tuple[int, int]]]:
    """The photos side by side at a common height, white between them (one image, drawn once).

    Missing photos are light grey tiles of 4:3.

    Returns
    -------
    image : numpy.ndarray
        RGB uint8.
    spans : list of (int, int)
        Left and right pixel column of each photo.

    Examples
    --------
    >>> p = StripPhoto(np.zeros((30, 40, 3), np.uint8), 0.0, 210.0, "ok", "raw")
    >>> img, spans = strip_image((p, p), 60, 10)
    >>> img.shape, spans
    ((60, 170, 3), [(0, 80), (90, 170)])
    """
    tiles: list[np.ndarray] = []
    for photo in photos:
        if photo.image is None:
            tiles.append(np.full((height_px, height_px * 4 // 3, 3), 225, np.uint8))
        else:
            h, w = photo.image.shape[:2]
            size = (max(1, round(w * height_px / h)), height_px)
            tiles.append(
                cv2.resize(
                    photo.image,
                    size,
                    interpolation=cv2.INTER_AREA if h > height_px else cv2.INTER_LINEAR,
                )
            )
    spans, x = [], 0
    parts = []
    for k, tile in enumerate(tiles):
        if k:
            parts.append(np.full((height_px, gap_px, 3), 255, np.uint8))
            x += gap_px
        parts.append(tile)
        spans.append((x, x + tile.shape[1]))
        x += tile.shape[1]
    return np.hstack(parts), spans


def pick_ramp(angles: pd.DataFrame, material: str) -> pd.DataFrame:
    """Rows of the first ramp (dataset, actuator, trial, direction) of ``material`` in sorted order.

    Increasing pressure is preferred (as Fig. 5); the rows are in ramp order.
    """
    m = angles[angles["material"].astype(str) == material].copy()
    if m.empty:
        return m
    m["actuator"] = m["actuator"].astype(str)
    m["trial"] = m["trial"].astype(str)
    direction = "up" if (m["direction"] == "up").any() else "down"
    m = m[m["direction"] == direction]
    first = m.sort_values(["dataset", "actuator", "trial"], kind="stable").iloc[0]
    ramp = m[
        (m["dataset"] == first["dataset"])
        & (m["actuator"] == first["actuator"])
        & (m["trial"] == first["trial"])
    ]
    return ramp.sort_values("pressure_kpa", ascending=(direction == "up"), kind="stable")


def build_strip(data: ReportData, material: str, n_photos: int = STRIP_PHOTOS) -> Strip | None:
    """Choose up to ``n_photos`` photos evenly spread over one ramp of ``material``.

    Returns
    -------
    Strip or None
        ``None`` when the material has no angles rows.
    """
    # real beside synthetic photo sets of the material: a real one's ramp, as its plots show
    pooled = mixed_materials(data.angles, data.datasets).get(material)
    angles = (
        data.angles
        if pooled is None
        else data.angles[data.angles["dataset"].astype(str).isin(pooled[0])]
    )
    ramp = pick_ramp(angles, material)
    if ramp.empty:
        return None
    first = ramp.iloc[0]
    dataset: Dataset = next(d for d in data.inputs.datasets if d.name == first["dataset"])
    frames = "frame" in ramp.columns and bool(ramp["frame"].notna().all())
    if frames:  # a video's frames: the overlay of each, where one was drawn (a few per video)
        names = [frame_overlay_name(str(v), int(f)) for v, f in zip(ramp["image"], ramp["frame"])]
        if dataset.overlays_dir is not None:
            drawn = [(dataset.overlays_dir / n).is_file() for n in names]
            if any(drawn):
                ramp = ramp[drawn]
                names = [n for n, d in zip(names, drawn) if d]
    else:
        names = [overlay_name(str(v)) for v in ramp["image"]]
    idx = np.unique(np.round(np.linspace(0, len(ramp) - 1, min(n_photos, len(ramp)))).astype(int))
    photos = []
    for i in idx:
        row = ramp.iloc[int(i)]
        image, source = None, "missing"
        if dataset.overlays_dir is not None:
            image = load_thumbnail(dataset.overlays_dir / names[int(i)], banner=True)
            source = "overlay" if image is not None else source
        if image is None and dataset.photoset_dir is not None:
            raw = dataset.photoset_dir / str(row["image"])
            image = video_frame(raw, int(row["frame"])) if frames else load_thumbnail(raw)
            source = "raw" if image is not None else source
        photos.append(
            StripPhoto(
                image=image, pressure_kpa=float(row["pressure_kpa"]), psi_deg=float(row["psi_deg"]),
                status=str(row["status"]), source=source,
            )
        )
    return Strip(
        material=material,
        dataset=str(first["dataset"]),
        actuator=str(first["actuator"]),
        trial=str(first["trial"]),
        direction=str(first["direction"]),
        photos=tuple(photos),
        images=tuple(str(ramp.iloc[int(i)]["image"]) for i in idx),
        qualified=data.angles["dataset"].nunique() > 1,
    )
