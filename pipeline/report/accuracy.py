"""How well one dataset's angles were measured, as the report's first page says it.

A photo set rendered by ``synth`` holds the renderer's ``truth.csv``: its ``ok`` photos are
compared with it.  A real set has no truth; what its data can tell is how far two trials of one
actuator at the same pressure and direction differ.  That scatter is the rig's and the
measurement's together, and it is blind to an error every photo shares (a base direction read a
few degrees off), so the words say so.  Customer 24's advisor found only how many photos were
flagged, nothing on how good the others were.
"""

from __future__ import annotations

from dataclasses import dataclass
from itertools import combinations

import numpy as np
import pandas as pd

from pipeline.aggregate import actuator_keys, is_used, pressure_levels, settled_frames

#: an ``ok`` photo further than this from the truth (deg) is counted: the bench's "wrong ok"
OFF_DEG = 5.0


@dataclass(frozen=True)
class AngleAccuracy:
    """The size of one dataset's angle errors, or of their scatter between trials.

    Attributes
    ----------
    basis : str
        ``"truth"`` (against ``truth.csv``), ``"trials"`` (two trials' difference) or ``"none"``.
    n : int
        Photos compared with the truth, or pairs of trials.
    median_deg, p95_deg : float
        Median and 95th percentile of the absolute error or difference (deg); NaN for ``none``.
    off : int
        ``ok`` photos more than :data:`OFF_DEG` from the truth (0 unless ``truth``).
    """

    basis: str
    n: int
    median_deg: float = float("nan")
    p95_deg: float = float("nan")
    off: int = 0

    def cell(self) -> str:
        """The figure in a table cell: median / 95th percentile and what they are against.

        Examples
        --------
        >>> AngleAccuracy("truth", 40, 0.31, 1.24, 1).cell()
        '0.31 / 1.2 truth, 1 ok > 5°'
        >>> AngleAccuracy("truth", 40, 0.31, 1.24, 0).cell()
        '0.31 / 1.2 truth'
        >>> AngleAccuracy("trials", 12, 0.8, 2.14).cell()
        '0.80 / 2.1 trials'

        The 95th percentile to a second place where one place would show it below the median
        (customer 48 read "0.14 / 0.1 trials"):

        >>> AngleAccuracy("trials", 12, 0.14, 0.14).cell()
        '0.14 / 0.14 trials'
        >>> AngleAccuracy("none", 0).cell()
        'n/a (one trial)'
        >>> AngleAccuracy("no ok photo", 0).cell()
        'n/a (no ok photo)'
        """
        if self.basis == "none":
            return "n/a (one trial)"
        if self.basis == NO_OK:
            return f"n/a ({NO_OK})"
        places = 1 if round(self.p95_deg, 1) >= round(self.median_deg, 2) else 2
        figure = f"{self.median_deg:.2f} / {self.p95_deg:.{places}f} {self.basis}"
        return f"{figure}, {self.off} ok > {OFF_DEG:g}°" if self.off else figure


#: no figure: no truth and one trial per actuator
NO_ACCURACY = AngleAccuracy("none", 0)
#: ... or no photo measured ok (customer 33 read "n/a (one trial)" for two trials of 68 photos)
NO_OK = "no ok photo"


def truth_errors(angles: pd.DataFrame, truth: pd.DataFrame) -> np.ndarray:
    """``psi_deg - psi_image_deg`` of each ``ok`` photo that ``truth`` names (deg).

    Rows are matched by ``image``, or by its file name when the two name the photo with different
    folders; video frames (no truth per frame) and photos the truth does not name are left out.

    Examples
    --------
    >>> a = pd.DataFrame({"image": ["images/a.jpg", "b.jpg", "c.jpg"], "psi_deg": [10.0, 20.0, 5.0],
    ...                   "status": ["ok", "ok", "flagged"]})
    >>> t = pd.DataFrame({"image": ["a.jpg", "b.jpg", "c.jpg"], "psi_image_deg": [9.0, 23.0, 5.0]})
    >>> truth_errors(a, t).tolist()
    [1.0, -3.0]
    """
    if not {"image", "psi_image_deg"} <= set(truth.columns):
        return np.array([])
    rows = angles[is_used(angles)]
    if "frame" in rows.columns:
        rows = rows[rows["frame"].isna()]
    true = pd.to_numeric(truth["psi_image_deg"], errors="coerce").to_numpy(float)
    by_name = dict(zip(truth["image"].astype(str).map(_file_name), true, strict=True))
    by_image = dict(zip(truth["image"].astype(str), true, strict=True))
    images = rows["image"].astype(str)
    expected = np.array(
        [by_image.get(i, by_name.get(_file_name(i), np.nan)) for i in images], dtype=float
    )
    err = pd.to_numeric(rows["psi_deg"], errors="coerce").to_numpy(float) - expected
    return err[np.isfinite(err)]


def _file_name(image: str) -> str:
    return image.replace("\\", "/").rsplit("/", 1)[-1]


def trial_differences(angles: pd.DataFrame) -> np.ndarray:
    """|psi| difference of every pair of trials of one actuator at one pressure and direction (deg).

    Each trial counts once per level: the mean of its ``ok`` photos there (of a video stepped
    through held pressures, its settled frames; a continuous one's frames binned by pressure,
    :func:`pipeline.aggregate.pressure_levels`).

    Examples
    --------
    >>> a = pd.DataFrame({"material": "M", "actuator": "A1", "trial": [1, 2, 3, 1, 2],
    ...                   "direction": "up", "pressure_kpa": [0, 0, 0, 20, 20],
    ...                   "psi_deg": [200.0, 201.0, 199.5, 150.0, 152.0], "status": "ok"})
    >>> trial_differences(a).tolist()
    [1.0, 0.5, 1.5, 2.0]
    """
    rows = angles[settled_frames(angles) & is_used(angles)].copy()
    if rows.empty:
        return np.array([])
    rows["_actuator"] = actuator_keys(rows)
    rows["_level"] = pressure_levels(rows)
    rows["_psi"] = pd.to_numeric(rows["psi_deg"], errors="coerce")
    rows["_trial"] = rows["trial"].astype(str)
    keys = ["material", "_actuator", "direction", "_level"]
    means = rows.groupby([*keys, "_trial"], sort=True)["_psi"].mean().dropna()
    diffs = [
        abs(a - b)
        for _, level in means.groupby(level=keys, sort=True)
        for a, b in combinations(level.to_numpy(float), 2)
    ]
    return np.asarray(diffs, dtype=float)


def angle_accuracy(angles: pd.DataFrame, truth: pd.DataFrame | None) -> AngleAccuracy:
    """How well a dataset's angles were measured: against its truth where it has one, else the
    scatter between its trials, else ``none``.

    Examples
    --------
    >>> a = pd.DataFrame({"material": "M", "actuator": "A1", "trial": [1, 2],
    ...                   "direction": "up", "pressure_kpa": 0, "image": ["a.jpg", "b.jpg"],
    ...                   "psi_deg": [200.0, 207.0], "status": "ok"})
    >>> truth = pd.DataFrame({"image": ["a.jpg", "b.jpg"], "psi_image_deg": [200.5, 200.0]})
    >>> angle_accuracy(a, truth)
    AngleAccuracy(basis='truth', n=2, median_deg=3.75, p95_deg=6.675, off=1)
    >>> angle_accuracy(a, None)
    AngleAccuracy(basis='trials', n=1, median_deg=7.0, p95_deg=7.0, off=0)
    """
    if not is_used(angles).any():
        return AngleAccuracy(NO_OK, 0)
    if truth is not None:
        err = np.abs(truth_errors(angles, truth))
        if len(err):
            return AngleAccuracy(
                "truth",
                len(err),
                float(np.median(err)),
                float(np.percentile(err, 95)),
                int((err > OFF_DEG).sum()),
            )
    diffs = trial_differences(angles)
    if len(diffs):
        return AngleAccuracy(
            "trials", len(diffs), float(np.median(diffs)), float(np.percentile(diffs, 95))
        )
    return NO_ACCURACY


#: the quality table's note on its error column
ACCURACY_NOTE = (
    "ψ check (deg, median / 95th percentile of the ok photos): truth = error against the "
    f"renderer's truth.csv (ok photos over {OFF_DEG:g}° off counted); trials = how far two "
    "trials of one actuator differ at one pressure and direction: repeatability and measurement "
    "together, not the angles' error, and blind to an error all photos share, such as a base "
    "direction read off (give fixed_direction_deg, the clamp's, to rule that out)."
)
