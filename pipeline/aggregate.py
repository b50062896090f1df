"""Hysteresis aggregation: angles.csv rows -> mean/sd bending angle per pressure level.

One output row per material x direction (``up`` = increasing, ``down`` = decreasing pressure)
x pressure level, as in the paper's Fig. 6.  A pressure level is the nominal setpoint
(``pressure_kpa``) by default, or, when measured pressures scatter around the setpoints, a bin of
configurable width of the measured pressure (``measured_pressure_kpa`` when present).

Frames of a video (rows with a ``frame``) have no setpoint levels: without a bin width they are
binned by :data:`CONTINUOUS_BIN_KPA` of their measured pressure, and the frames of one trial in one
bin and direction are first averaged, so a video trial counts once per level as a photo ramp does
(``n`` counts trials there, not frames; :mod:`pipeline.video.continuous` has the per-cycle loops,
settling curves and step responses).  Of a video stepped through held pressures only the frames at
the end of each hold count (:func:`settled_frames`): those between are the step's response.
Likewise a trial photographed more than once at one level and direction counts once there, with
the mean of its photos (:func:`_collapse_repeats`).

Rows whose ``status`` is not ``ok`` (``flagged`` or ``failed``) or whose psi is not finite are
excluded by default and counted in ``n_excluded``; a level whose rows are all excluded is still
written (with ``n = 0`` and a NaN mean) so nothing disappears silently.

Identity conventions: an actuator is identified by its ``actuator`` value (as text) within a
material; a trial by the pair (actuator, trial).  When rows come from several datasets (a
``dataset`` column with more than one value, as :func:`read_angles` writes), actuators are
``"<dataset>/<actuator>"``: different photo sets hold different actuators.

Examples
--------
>>> import pandas as pd
>>> rows = pd.DataFrame({
...     "image": ["a", "b", "c"], "psi_deg": [200.0, 190.0, 0.0], "status": ["ok", "ok", "failed"],
...     "pressure_kpa": [0.0, 0.0, 0.0], "direction": ["up"] * 3, "material": ["DS20"] * 3,
...     "actuator": [1, 2, 2], "trial": [1, 1, 2]})
>>> h = aggregate_hysteresis(rows)
>>> h[["psi_mean_deg", "n", "n_actuators", "n_excluded"]].to_numpy().tolist()
[[195.0, 2.0, 2.0, 1.0]]
"""

from __future__ import annotations

import math
import os
from collections.abc import Sequence
from pathlib import Path

import numpy as np
import pandas as pd

from pipeline.constants import DIRECTIONS, PRESSURE_OUT_OF_ORDER, STATUSES
from pipeline.errors import UserInputError
from pipeline.fileio import read_table

#: columns angles.csv must have for aggregation
REQUIRED_ANGLE_COLUMNS: tuple[str, ...] = (
    "image", "psi_deg", "status", "pressure_kpa", "direction", "material", "actuator", "trial",
)
#: hysteresis.csv columns, in order (contract); ``pressure_mean_kpa`` is an extra trailing column
HYSTERESIS_COLUMNS: tuple[str, ...] = (
    "material", "direction", "pressure_kpa", "psi_mean_deg", "psi_sd_deg",
    "n", "n_actuators", "n_trials", "n_excluded", "pressure_mean_kpa",
)
#: per-actuator curve columns, in order
PER_ACTUATOR_COLUMNS: tuple[str, ...] = (
    "material", "actuator", "direction", "pressure_kpa", "psi_mean_deg", "psi_sd_deg",
    "n", "n_trials", "n_excluded", "pressure_mean_kpa",
)
#: bin width (kPa) of the frames of a video when no bin width is asked for
CONTINUOUS_BIN_KPA = 5.0
#: of a video stepped through held pressures, the frames that settled: each hold's last this
#: fraction of frames (at least SETTLED_MIN_FRAMES), as the step responses' final value
SETTLED_FRACTION, SETTLED_MIN_FRAMES = 0.2, 3


def read_angles(paths: Sequence[str | os.PathLike[str]]) -> pd.DataFrame:
    """Read and concatenate angles.csv files, checking the columns aggregation needs.

    Parameters
    ----------
    paths : sequence of path-like
        angles.csv files written by ``python -m pipeline measure``.

    Returns
    -------
    pandas.DataFrame
        All rows, in file order, with an added ``dataset`` column (the path as given) and
        ``actuator``/``trial`` read as text.

    Raises
    ------
    UserInputError
        If a file is missing, unreadable, lacks a required column, or has a bad direction,
        status or pressure value (the message names the file and the 1-based CSV line).
    """
    if not paths:
        raise UserInputError("no angles.csv given; pass at least one file")
    frames = []
    for path in paths:
        p = Path(path)
        df = read_table(p, "an angles.csv written by 'measure'",
                        dtype={"actuator": str, "trial": str, "image": str, "reason": str})
        check_angles(df, str(p))
        df.insert(0, "dataset", str(path))
        frames.append(df)
    return pd.concat(frames, ignore_index=True)


def check_angles(angles: pd.DataFrame, where: str = "angles.csv") -> None:
    """Validate an angles frame for aggregation.

    Parameters
    ----------
    angles : pandas.DataFrame
        Rows shaped like angles.csv.
    where : str
        File name used in error messages.

    Raises
    ------
    UserInputError
        Missing columns, unknown direction or status, non-numeric pressure or psi.
    """
    missing = [c for c in REQUIRED_ANGLE_COLUMNS if c not in angles.columns]
    if missing:
        raise UserInputError(
            f"{where}: missing column(s) {missing}; an angles.csv needs "
            f"{list(REQUIRED_ANGLE_COLUMNS)}"
        )
    for column in ("pressure_kpa", "psi_deg") + (
        ("measured_pressure_kpa",) if "measured_pressure_kpa" in angles.columns else ()
    ):
        values = pd.to_numeric(angles[column], errors="coerce")
        bad = values.isna() & angles[column].notna()
        if bad.any():
            i = int(np.flatnonzero(bad.to_numpy())[0])
            raise UserInputError(
                f"{where} line {i + 2}: column '{column}' must be a number, got "
                f"{angles[column].iloc[i]!r}"
            )
    # a failed row may have no pressure (a bad manifest pressure, a frame outside its pressure log)
    bad_p = (
        pd.to_numeric(angles["pressure_kpa"], errors="coerce").isna()
        & (angles["status"] != "failed")
    ).to_numpy()
    if bad_p.any():
        i = int(np.flatnonzero(bad_p)[0])
        raise UserInputError(
            f"{where} line {i + 2}: 'pressure_kpa' is empty; every measured row needs its setpoint "
            "(kPa)"
        )
    for column, allowed in (("direction", DIRECTIONS), ("status", STATUSES)):
        bad = ~angles[column].isin(allowed).to_numpy()
        if column == "direction":
            # a failed row may have any: measure made a manifest's 'upp' one failed row with its
            # reason (customer 44's run stopped here, and its report was the run before's)
            bad &= (angles["status"] != "failed").to_numpy()
        if bad.any():
            i = int(np.flatnonzero(bad)[0])
            raise UserInputError(
                f"{where} line {i + 2}: '{column}' is {angles[column].iloc[i]!r}; use one of "
                f"{list(allowed)}"
            )


def measured_pressure(angles: pd.DataFrame) -> pd.Series:
    """The pressure each row was measured at (kPa): ``measured_pressure_kpa`` where present and
    finite, else the setpoint ``pressure_kpa``.

    Examples
    --------
    >>> df = pd.DataFrame({"pressure_kpa": [10.0, 20.0], "measured_pressure_kpa": [9.5, None]})
    >>> measured_pressure(df).tolist()
    [9.5, 20.0]
    """
    nominal = pd.to_numeric(angles["pressure_kpa"], errors="coerce").astype(float)
    if "measured_pressure_kpa" not in angles.columns:
        return nominal
    measured = pd.to_numeric(angles["measured_pressure_kpa"], errors="coerce").astype(float)
    return measured.where(np.isfinite(measured), nominal)


def is_used(angles: pd.DataFrame, include_flagged: bool = False) -> pd.Series:
    """Whether each row's psi may enter a curve by its status: ``ok``, and ``flagged`` if asked
    (``failed`` never, nor a row whose pressure breaks its ramp's order: a manifest typo's
    psi would enter at a pressure never set).

    Examples
    --------
    >>> status = pd.DataFrame({"status": ["ok", "flagged", "failed", "flagged"], "reason": [
    ...     "", "", "", "pressure 400 kPa is out of its ramp's order (30 -> 400 -> 50 kPa)"]})
    >>> is_used(status, include_flagged=True).tolist()
    [True, True, False, False]
    """
    used = angles["status"].isin(("ok", "flagged") if include_flagged else ("ok",))
    if "reason" in angles.columns:
        used &= ~angles["reason"].fillna("").astype(str).str.contains(
            PRESSURE_OUT_OF_ORDER, regex=False
        )
    return used


def settled_frames(angles: pd.DataFrame) -> pd.Series:
    """Which rows are points of a hysteresis curve: every photo, and every frame of a video
    ramped continuously; of a video stepped through held pressures (frames with a finite
    ``since_step_s``: its pressure log steps), only the frames at the end of each hold (its last
    :data:`SETTLED_FRACTION`, at least :data:`SETTLED_MIN_FRAMES`).

    The frames between holds are the step's response: binned by pressure they drew a loop of
    how fast the actuator follows, not of hysteresis (a customer's 720p step video: 234 deg
    "wide" at 55 kPa, a pressure it never held); they stay in the step responses
    (:mod:`pipeline.video.continuous`).

    Examples
    --------
    >>> import pandas as pd
    >>> rows = pd.DataFrame({"image": ["v.avi"] * 8, "frame": range(8), "step": [0] * 4 + [1] * 4,
    ...                      "since_step_s": [float("nan")] * 4 + [0.1, 0.2, 0.3, 0.4]})
    >>> settled_frames(rows).tolist()
    [False, True, True, True, False, True, True, True]
    >>> settled_frames(rows.assign(since_step_s=float("nan"))).all()  # a continuous ramp
    np.True_
    """
    keep = pd.Series(True, index=angles.index)
    if not {"frame", "step", "since_step_s"} <= set(angles.columns):
        return keep
    frames = angles[angles["frame"].notna()]
    video = [c for c in ("dataset", "image") if c in frames.columns]
    since = pd.to_numeric(frames["since_step_s"], errors="coerce")
    stepped = np.isfinite(since).groupby([frames[c] for c in video]).transform("any")
    frames = frames[stepped.to_numpy(bool)]
    if frames.empty:
        return keep
    hold = frames.groupby([*(frames[c] for c in video), frames["step"]], sort=False)["frame"]
    from_end = hold.rank(method="first", ascending=False)
    size = hold.transform("size")
    tail = np.maximum(SETTLED_MIN_FRAMES, np.round(SETTLED_FRACTION * size))
    keep.loc[frames.index] = (from_end <= tail).to_numpy(bool)
    return keep


def pressure_levels(angles: pd.DataFrame, bin_kpa: float | None = None) -> pd.Series:
    """Pressure level (kPa) of each row.

    Parameters
    ----------
    angles : pandas.DataFrame
        Rows with ``pressure_kpa`` and optionally ``measured_pressure_kpa``.
    bin_kpa : float, optional
        Bin width (kPa).  ``None``: the nominal setpoint ``pressure_kpa`` (for the frames of a
        video, which have no setpoint levels: bins of :data:`CONTINUOUS_BIN_KPA`).  Otherwise the
        measured pressure (``measured_pressure_kpa`` where present and finite, else the
        setpoint) rounded to the nearest multiple of ``bin_kpa`` (bin centres 0, W, 2W, ...).

    Returns
    -------
    pandas.Series of float

    Examples
    --------
    >>> import pandas as pd
    >>> df = pd.DataFrame({"pressure_kpa": [10.0, 10.0], "measured_pressure_kpa": [8.1, 12.6]})
    >>> pressure_levels(df, 5.0).tolist()
    [10.0, 15.0]
    """
    nominal = pd.to_numeric(angles["pressure_kpa"], errors="coerce").astype(float)
    if bin_kpa is None:
        if "frame" not in angles.columns or angles["frame"].isna().all():
            return nominal
        frames = angles["frame"].notna()
        return nominal.where(~frames, pressure_levels(angles, CONTINUOUS_BIN_KPA))
    if not (math.isfinite(bin_kpa) and bin_kpa > 0):
        raise UserInputError(f"--bin-kpa must be a positive number of kPa, got {bin_kpa}")
    measured = measured_pressure(angles)
    # floor(x / w + 0.5) rounds half up, unlike numpy's round-half-to-even
    return pd.Series(np.floor(measured.to_numpy() / bin_kpa + 0.5) * bin_kpa, index=angles.index)


def _prepare(angles: pd.DataFrame, bin_kpa: float | None, include_flagged: bool) -> pd.DataFrame:
    check_angles(angles)
    # a failed row of no known direction (a manifest's 'upp') belongs to no curve
    df = angles[settled_frames(angles) & angles["direction"].isin(DIRECTIONS)].copy()
    df["actuator"] = actuator_keys(df)
    df["trial"] = df["trial"].astype(str)
    df["psi_deg"] = pd.to_numeric(df["psi_deg"], errors="coerce").astype(float)
    df["_level"] = pressure_levels(df, bin_kpa)
    binned = pd.Series(bin_kpa is not None, index=df.index)
    if "frame" in df.columns:
        binned |= df["frame"].notna()
    # binned rows average the measured pressure, setpoint levels the setpoint
    setpoint = pd.to_numeric(df["pressure_kpa"], errors="coerce").astype(float)
    df["_pressure"] = measured_pressure(df).where(binned, setpoint)
    df["_included"] = is_used(df, include_flagged) & np.isfinite(df["psi_deg"])
    df["_ramp"] = df["actuator"] + "\x1f" + df["trial"]
    if "frame" in df.columns and df["frame"].notna().any():
        df = _collapse_frames(df)
    return _collapse_repeats(df)


def _collapse_repeats(df: pd.DataFrame) -> pd.DataFrame:
    """One row for the included photos of a trial photographed more than once in a row at one
    level and direction: their mean, so the trial counts once there, as every other trial does
    (customer 39's repeated 60 kPa photo weighed its trial double in the mean and the sd).
    Photos at one level that are not next to each other in the trial (by ``step``, else in row
    order: several ramps labelled one trial) stay apart.  Rows not included are kept as they
    are, counted in ``n_excluded``.

    Examples
    --------
    >>> df = pd.DataFrame({"material": "m", "actuator": "a", "trial": ["1", "1", "2"],
    ...                    "direction": "up", "_level": 60.0, "psi_deg": [100.0, 102.0, 90.0],
    ...                    "_pressure": 60.0, "_included": True, "status": "ok"})
    >>> df["_ramp"] = df["actuator"] + "/" + df["trial"]
    >>> _collapse_repeats(df).sort_values("trial")[["trial", "psi_deg"]].to_numpy().tolist()
    [['1', 101.0], ['2', 90.0]]
    >>> _collapse_repeats(df.assign(_level=[60.0, 40.0, 60.0], trial="1", _ramp="a/1")).shape[0]
    3
    """
    keys = ["material", "actuator", "trial", "_ramp", "direction", "_level"]
    order = df.sort_values(["_ramp", "step"], kind="stable") if "step" in df else df
    ordered = order.sort_values("_ramp", kind="stable")  # each trial's photos in their order
    # a run: photos next to each other in their trial, at one level and direction
    changed = (ordered[keys] != ordered[keys].shift()).any(axis=1)
    run = changed.cumsum().rename("_run")
    df = df.join(run)
    inc = df[df["_included"]]
    repeated = inc.duplicated("_run", keep=False)
    if not repeated.any():
        return df.drop(columns="_run")
    means = (
        inc[repeated]
        .groupby([*keys, "_run"], sort=False)
        .agg(psi_deg=("psi_deg", "mean"), _pressure=("_pressure", "mean"))
        .reset_index()
        .assign(_included=True, status="ok")
    )
    rest = df.drop(index=inc.index[repeated])
    return pd.concat([rest, means], ignore_index=True).drop(columns="_run")


def _collapse_frames(df: pd.DataFrame) -> pd.DataFrame:
    """One row per video trial, direction and pressure bin: the mean of its included frames.

    A video trial then counts once per level, as a photo ramp does (its frames are not
    independent trials); the bin counts as excluded when none of its frames is included.
    """
    frames = df[df["frame"].notna()]
    keys = ["material", "actuator", "trial", "_ramp", "direction", "_level"]
    inc = frames[frames["_included"]]
    mean = inc.groupby(keys, sort=False)[["psi_deg", "_pressure"]].mean()
    rows = (
        frames.groupby(keys, sort=False)
        .size()
        .rename("_frames")
        .to_frame()
        .join(mean)
        .reset_index()
    )
    rows["_included"] = rows["psi_deg"].notna()
    rows["status"] = np.where(rows["_included"], "ok", "failed")
    rows["_pressure"] = rows["_pressure"].where(rows["_included"], np.nan)
    rows = rows.drop(columns="_frames")
    return pd.concat([df[df["frame"].isna()], rows], ignore_index=True)


def _summarise(df: pd.DataFrame, keys: list[str]) -> pd.DataFrame:
    """Group ``df`` by ``keys`` (+ level) and compute the statistics of included rows."""
    rows = []
    for key, group in df.groupby(keys + ["_level"], sort=False):
        inc = group[group["_included"]]
        psi = inc["psi_deg"].to_numpy(dtype=float)
        n = psi.size
        rows.append(
            dict(
                zip(keys + ["pressure_kpa"], key, strict=True),
                psi_mean_deg=float(np.mean(psi)) if n else math.nan,
                psi_sd_deg=float(np.std(psi, ddof=1)) if n > 1 else math.nan,
                n=n,
                n_actuators=int(inc["actuator"].nunique()),
                n_trials=int(inc["_ramp"].nunique()),
                n_excluded=int(len(group) - n),
                pressure_mean_kpa=float(np.mean(inc["_pressure"])) if n else math.nan,
            )
        )
    out = pd.DataFrame(rows)
    if out.empty:
        return out
    out["_dir"] = out["direction"].map({d: i for i, d in enumerate(DIRECTIONS)})
    sort_keys = [k if k != "direction" else "_dir" for k in keys] + ["pressure_kpa"]
    out = out.sort_values(sort_keys, kind="stable").drop(columns="_dir").reset_index(drop=True)
    for c in ("n", "n_actuators", "n_trials", "n_excluded"):
        out[c] = out[c].astype(int)
    return out


def aggregate_hysteresis(
    angles: pd.DataFrame, *, bin_kpa: float | None = None, include_flagged: bool = False
) -> pd.DataFrame:
    """Mean and sample standard deviation of psi per material x direction x pressure level.

    Parameters
    ----------
    angles : pandas.DataFrame
        Rows shaped like angles.csv (see :data:`REQUIRED_ANGLE_COLUMNS`).
    bin_kpa : float, optional
        Pressure bin width (kPa); ``None`` groups by the nominal setpoint (see
        :func:`pressure_levels`).
    include_flagged : bool
        Also average rows with status ``flagged`` (``failed`` rows are always excluded).

    Returns
    -------
    pandas.DataFrame
        Columns :data:`HYSTERESIS_COLUMNS`, sorted by material, direction (up, down) and
        pressure.  ``psi_sd_deg`` uses ddof=1 (NaN when n < 2); ``n`` counts averaged rows,
        ``n_actuators`` distinct actuators, ``n_trials`` distinct (actuator, trial) ramps,
        ``n_excluded`` rows left out (status or non-finite psi), ``pressure_mean_kpa`` the mean
        pressure of the averaged rows (measured when binning).
    """
    df = _prepare(angles, bin_kpa, include_flagged)
    out = _summarise(df, ["material", "direction"])
    if out.empty:
        return pd.DataFrame(columns=list(HYSTERESIS_COLUMNS))
    return out[list(HYSTERESIS_COLUMNS)]


def aggregate_per_actuator(
    angles: pd.DataFrame, *, bin_kpa: float | None = None, include_flagged: bool = False
) -> pd.DataFrame:
    """Per-actuator hysteresis curves: mean/sd of psi over that actuator's trials.

    Parameters
    ----------
    angles, bin_kpa, include_flagged
        As in :func:`aggregate_hysteresis`.

    Returns
    -------
    pandas.DataFrame
        Columns :data:`PER_ACTUATOR_COLUMNS`, sorted by material, actuator, direction, pressure.
    """
    df = _prepare(angles, bin_kpa, include_flagged)
    out = _summarise(df, ["material", "actuator", "direction"])
    if out.empty:
        return pd.DataFrame(columns=list(PER_ACTUATOR_COLUMNS))
    return out[list(PER_ACTUATOR_COLUMNS)]


#: an actuator's rising curve "bends one way" when its psi changes by at least this much (deg)
#: from its lowest to its highest pressure
OPPOSITE_BEND_DEG = 30.0


def opposite_bending(curves: pd.DataFrame) -> pd.DataFrame:
    """Materials whose actuators bend opposite ways as the pressure rises.

    An actuator's rise is the change of its mean psi from its lowest to its highest pressure on
    the rising branch.  Actuators of one material are averaged into one curve; where one rises
    by :data:`OPPOSITE_BEND_DEG` or more and another falls as far, that mean is neither's curve
    (customer 38's three chambers of one actuator, each photographed as an actuator of one
    material: a curve with a spike of +106 deg and an sd of 229 deg).  Actuators that bend the
    same way but from different rest angles, or by different amounts, are not listed.

    Parameters
    ----------
    curves : pandas.DataFrame
        Per-actuator curves (:func:`aggregate_per_actuator`; the report's are of the rows it
        plots).

    Returns
    -------
    pandas.DataFrame
        One row per actuator of such a material: ``material``, ``actuator``, ``rise_deg``, and
        the pressures it runs between, ``from_kpa`` and ``to_kpa``; sorted by material and rise.

    Examples
    --------
    >>> rows = [(a, p, s * p) for a, s in (("1", 2.0), ("2", -1.0), ("3", 0.1)) for p in (0, 50)]
    >>> angles = pd.DataFrame([{"image": f"{a}_{p}.jpg", "material": "SIL", "actuator": a,
    ...     "trial": 1, "direction": "up", "pressure_kpa": p, "psi_deg": psi, "status": "ok"}
    ...     for a, p, psi in rows])
    >>> found = opposite_bending(aggregate_per_actuator(angles))
    >>> found[["actuator", "rise_deg"]].to_numpy().tolist()
    [['2', -50.0], ['3', 5.0], ['1', 100.0]]
    >>> same_way = aggregate_per_actuator(angles[angles["actuator"] != "2"])
    >>> none = aggregate_per_actuator(angles[:0])
    >>> opposite_bending(same_way).empty, opposite_bending(none).empty
    (True, True)
    """
    mean = pd.to_numeric(curves["psi_mean_deg"], errors="coerce")  # an empty table's: object
    rising = curves[(curves["direction"] == "up") & mean.notna()]
    rows = []
    for (material, actuator), g in rising.groupby(["material", "actuator"], sort=True):
        if len(g) >= 2:
            g = g.sort_values("pressure_kpa")
            rise = float(g["psi_mean_deg"].iloc[-1] - g["psi_mean_deg"].iloc[0])
            rows.append((material, actuator, rise, *g["pressure_kpa"].iloc[[0, -1]].tolist()))
    out = pd.DataFrame(rows, columns=["material", "actuator", "rise_deg", "from_kpa", "to_kpa"])
    both = out.groupby("material")["rise_deg"].transform(
        lambda r: bool((r >= OPPOSITE_BEND_DEG).any() and (r <= -OPPOSITE_BEND_DEG).any())
    )
    return out[both.astype(bool)].sort_values(["material", "rise_deg"]).reset_index(drop=True)


def actuator_keys(angles: pd.DataFrame) -> pd.Series:
    """Actuator identity of each row (text): the ``actuator`` value, qualified by ``dataset``
    (``"<dataset>/<actuator>"``) when the rows come from more than one dataset."""
    actuator = angles["actuator"].astype(str)
    if "dataset" in angles.columns and angles["dataset"].nunique() > 1:
        return angles["dataset"].astype(str) + "/" + actuator
    return actuator


def pool_hysteresis(hyst: pd.DataFrame) -> pd.DataFrame:
    """Merge hysteresis rows of the same material x direction x level (e.g. two datasets of DS20).

    The pooled mean and sample sd are exactly those of the union of the underlying rows:
    mean = sum(n_i m_i) / N and sd^2 = (sum((n_i - 1) s_i^2) + sum(n_i (m_i - mean)^2)) / (N - 1).
    Counts are summed (actuators and trials of different datasets are distinct).

    Parameters
    ----------
    hyst : pandas.DataFrame
        Rows with at least :data:`HYSTERESIS_COLUMNS` minus ``pressure_mean_kpa``.

    Returns
    -------
    pandas.DataFrame
        Same columns, one row per material x direction x pressure level, sorted as
        :func:`aggregate_hysteresis` sorts.

    Examples
    --------
    >>> import pandas as pd
    >>> a = dict(material="DS20", direction="up", pressure_kpa=0.0, n_actuators=1, n_trials=2,
    ...          n_excluded=0)
    >>> h = pd.DataFrame([dict(a, psi_mean_deg=1.0, psi_sd_deg=2 ** 0.5, n=2),
    ...                   dict(a, psi_mean_deg=4.0, psi_sd_deg=float("nan"), n=1)])
    >>> pool_hysteresis(h)[["psi_mean_deg", "psi_sd_deg", "n"]].to_numpy().tolist()  # of 0, 2, 4
    [[2.0, 2.0, 3.0]]
    """
    keys = ["material", "direction", "pressure_kpa"]
    if not hyst.duplicated(keys).any():
        return hyst.reset_index(drop=True)
    rows = []
    for key, g in hyst.groupby(keys, sort=False):
        n = g["n"].to_numpy(float)
        m = g["psi_mean_deg"].to_numpy(float)
        sd = np.nan_to_num(g["psi_sd_deg"].to_numpy(float))
        used = n > 0
        total = float(n[used].sum())
        mean = float(np.sum(n[used] * m[used]) / total) if total else math.nan
        ss = (
            float(np.sum((n[used] - 1) * sd[used] ** 2) + np.sum(n[used] * (m[used] - mean) ** 2))
            if total
            else 0.0
        )
        row = dict(zip(keys, key, strict=True))
        row.update(
            psi_mean_deg=mean,
            psi_sd_deg=math.sqrt(ss / (total - 1)) if total > 1 else math.nan,
            n=int(total),
            n_actuators=int(g["n_actuators"].sum()) if "n_actuators" in g else 0,
            n_trials=int(g["n_trials"].sum()) if "n_trials" in g else 0,
            n_excluded=int(g["n_excluded"].sum()) if "n_excluded" in g else 0,
        )
        if "pressure_mean_kpa" in g:
            pm = g["pressure_mean_kpa"].to_numpy(float)
            row["pressure_mean_kpa"] = (
                float(np.sum(n[used] * pm[used]) / total) if total else math.nan
            )
        rows.append(row)
    out = pd.DataFrame(rows)
    out["_dir"] = out["direction"].map({d: i for i, d in enumerate(DIRECTIONS)})
    out = out.sort_values(["material", "_dir", "pressure_kpa"], kind="stable").drop(columns="_dir")
    return out.reset_index(drop=True)
