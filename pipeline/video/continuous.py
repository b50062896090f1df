"""Aggregation of continuous data (the frames of a video): loops, settling curves, step responses.

From the angles.csv rows of a video dataset (``frame``, ``time_s``, ``psi_deg``, ``status``,
``pressure_kpa``, optionally ``measured_pressure_kpa``, ``direction``, ``step``, ``since_step_s``
and the ramp keys), using only ``ok`` frames (``flagged`` too with ``include_flagged``):

``loops``
    Hysteresis loops binned by pressure: per ramp (material, actuator, trial), cycle (a rise
    and the fall after it) and direction, psi mean / sd / n per pressure bin of ``bin_kpa``
    (the measured pressure when logged, else the setpoint), with the leg's pressure rate; of a
    video stepped through held pressures only the ends of its holds
    (:func:`pipeline.aggregate.settled_frames`: the frames between are the step's response).
``cycles``
    Per cycle: rise and fall rates (mean rate of the setpoint over the leg, kPa/s), the loop's
    mean and largest width (psi rising minus psi falling at the same pressure, over the bins both
    legs reach, deg; positive when falling pressure bends the actuator further, as in the paper)
    and its area (width integrated over pressure, deg kPa).
``steps``
    Step-response figures of every pressure step (:func:`step_response`): psi before and after,
    rise time (10 % to 90 % of the change, from the step), overshoot (% of the change beyond its
    final value, 0 within the noise), settling time (from the step until psi stays within
    :data:`SETTLING_BAND` of the change, or 3 noise sd, of its final value); the final value is the
    mean of the last :data:`~pipeline.aggregate.SETTLED_FRACTION` of the hold, and a hold whose
    end still drifts (a straight line through that last part moves by more than the band) gives
    no figures ("did not settle within the hold": its final value, and so its 90 % level, are not
    known).  The noise sd is the ramp's frame-to-frame noise (second differences, robust).  The
    same rise and settling times for the measured pressure when logged.
``settling``
    Settling curves: psi and its normalised response ``(psi - before) / change`` against the time
    since each step (at most :data:`CURVE_POINTS` per step, medians of equal time bins).
``timeline``
    psi and pressure against time (at most :data:`TIMELINE_POINTS` per ramp, medians of equal
    time bins), for the report's overview.

Examples
--------
>>> import numpy as np
>>> t = np.arange(0, 4, 0.01)
>>> psi = 100 - 20 * (1 - np.exp(-(t - 1) / 0.2)) * (t >= 1)      # a first-order step at 1 s
>>> r = step_response(t, psi, step_time_s=1.0, before_deg=100.0)
>>> round(r["rise_time_s"], 2), round(r["settling_time_s"], 2), round(r["overshoot_pct"], 1)
(0.44, 0.79, 0.0)
"""

from __future__ import annotations

import math
import os
from pathlib import Path

import numpy as np
import pandas as pd

from pipeline.aggregate import (
    SETTLED_FRACTION,
    SETTLED_MIN_FRAMES,
    is_used,
    measured_pressure,
    settled_frames,
)
from pipeline.constants import RAMP_KEYS
from pipeline.errors import UserInputError
from pipeline.fileio import write_table

#: default pressure bin of the loops (kPa)
BIN_KPA = 5.0
#: settling band: this fraction of the step's change (or 3 noise sd if larger)
SETTLING_BAND = 0.02
#: psi's final value after a step: mean of the last this fraction of the hold (at least 3 frames)
#: psi before a step: mean of the ok frames in this window before it (s)
BEFORE_WINDOW_S = 0.5
#: a change smaller than this many noise sd (or 1 deg) has no rise/settling figures
MIN_CHANGE_SD = 10.0
CURVE_POINTS = 200
TIMELINE_POINTS = 2000
FILES: tuple[str, ...] = ("loops.csv", "cycles.csv", "steps.csv", "settling.csv", "timeline.csv")


def _frames(angles: pd.DataFrame, include_flagged: bool) -> pd.DataFrame:
    missing = [
        c
        for c in ("frame", "time_s", "psi_deg", "status", "pressure_kpa", "direction", *RAMP_KEYS)
        if c not in angles.columns
    ]
    if missing:
        raise UserInputError(
            f"angles table lacks {missing}: continuous aggregation needs the frames of a video "
            "photo set (measure a folder whose manifest lists videos)"
        )
    df = angles[angles["frame"].notna()].copy()
    for key in RAMP_KEYS:
        df[key] = df[key].astype(str)
    for column in ("time_s", "psi_deg", "pressure_kpa", "measured_pressure_kpa", "since_step_s"):
        if column in df.columns:
            df[column] = pd.to_numeric(df[column], errors="coerce")
    df["_used"] = is_used(df, include_flagged) & np.isfinite(df["psi_deg"])
    df["_settled"] = settled_frames(df)
    df["_pressure"] = measured_pressure(df)
    return df.sort_values([*RAMP_KEYS, "time_s"], kind="stable")


def _legs(ramp: pd.DataFrame) -> tuple[np.ndarray, np.ndarray]:
    """Cycle number (1-based: a rise and the fall after it) and leg number of each frame of a
    ramp."""
    leg = (ramp["direction"] != ramp["direction"].shift()).cumsum().to_numpy()
    rises = np.cumsum(
        ((ramp["direction"] == "up") & (ramp["direction"] != ramp["direction"].shift())).to_numpy()
    )
    return np.maximum(rises, 1), leg


def _rate(time_s: np.ndarray, pressure: np.ndarray) -> float:
    """Mean rate of a leg (kPa/s): its pressure range over the time the pressure moves (a rest at
    either end, the video before the ramp starts, is not counted); NaN when too short.

    Examples
    --------
    >>> t = np.arange(0.0, 22.0, 0.5)   # 1.5 s at rest, then 8 kPa/s to 160 kPa
    >>> round(_rate(t, np.clip((t - 1.5) * 8.0, 0.0, 160.0)), 2)
    8.0
    """
    ok = np.isfinite(time_s) & np.isfinite(pressure)
    t, p = time_s[ok], pressure[ok]
    if len(t) < 3 or t[-1] <= t[0]:
        return math.nan
    span = float(p.max() - p.min())
    tol = 1e-6 * span  # a setpoint rests exactly; a noisy read-back is timed end to end
    moving = np.flatnonzero(np.abs(p - p[0]) > tol)
    settled = np.flatnonzero(np.abs(p - p[-1]) > tol)
    if span == 0.0 or not len(moving):
        return 0.0 if span == 0.0 else math.nan
    i0 = max(int(moving[0]) - 1, 0)  # the last sample of the rest before the pressure moved
    i1 = min(int(settled[-1]) + 1, len(t) - 1)  # the first of the rest after it
    return float(span / (t[i1] - t[i0])) if t[i1] > t[i0] else math.nan


def loops(
    angles: pd.DataFrame, *, bin_kpa: float = BIN_KPA, include_flagged: bool = False
) -> tuple[pd.DataFrame, pd.DataFrame]:
    """Binned hysteresis loops and their per-cycle summary (see the module docstring).

    Returns
    -------
    loops : pandas.DataFrame
        ``material, actuator, trial, cycle, direction, pressure_kpa, psi_mean_deg, psi_sd_deg,
        n, n_excluded, rate_kpa_s``.
    cycles : pandas.DataFrame
        ``material, actuator, trial, cycle, rate_up_kpa_s, rate_down_kpa_s, width_mean_deg,
        width_max_deg, width_max_at_kpa, area_deg_kpa, bins_compared``.
    """
    if not (math.isfinite(bin_kpa) and bin_kpa > 0):
        raise UserInputError(f"--bin-kpa must be a positive number of kPa, got {bin_kpa}")
    df = _frames(angles, include_flagged)
    rows, summary = [], []
    for key, ramp in df.groupby(list(RAMP_KEYS), sort=False):
        cycle, leg = _legs(ramp)
        ramp = ramp.assign(
            _cycle=cycle,
            _leg=leg,
            _bin=np.floor(ramp["_pressure"].to_numpy() / bin_kpa + 0.5) * bin_kpa,
        )
        for (c, direction), g in ramp.groupby(["_cycle", "direction"], sort=False):
            rate = _rate(g["time_s"].to_numpy(), g["pressure_kpa"].to_numpy())
            # of a stepped video, the ends of its holds (the frames between are its response)
            for level, b in g[g["_settled"]].groupby("_bin", sort=True):
                psi = b.loc[b["_used"], "psi_deg"].to_numpy(float)
                rows.append(
                    dict(
                        zip(RAMP_KEYS, key),
                        cycle=int(c),
                        direction=direction,
                        pressure_kpa=float(level),
                        psi_mean_deg=float(psi.mean()) if psi.size else math.nan,
                        psi_sd_deg=float(psi.std(ddof=1)) if psi.size > 1 else math.nan,
                        n=int(psi.size),
                        n_excluded=int(len(b) - psi.size),
                        rate_kpa_s=rate,
                    )
                )
    out = pd.DataFrame(
        rows,
        columns=[
            *RAMP_KEYS,
            "cycle",
            "direction",
            "pressure_kpa",
            "psi_mean_deg",
            "psi_sd_deg",
            "n",
            "n_excluded",
            "rate_kpa_s",
        ],
    )
    for key, g in out.groupby([*RAMP_KEYS, "cycle"], sort=False):
        up = g[(g["direction"] == "up") & (g["n"] > 0)].set_index("pressure_kpa")
        down = g[(g["direction"] == "down") & (g["n"] > 0)].set_index("pressure_kpa")
        common = up.index.intersection(down.index).sort_values()
        width = (up.loc[common, "psi_mean_deg"] - down.loc[common, "psi_mean_deg"]).to_numpy(float)
        big = int(np.argmax(np.abs(width))) if width.size else -1
        summary.append(
            dict(
                zip([*RAMP_KEYS, "cycle"], key),
                rate_up_kpa_s=float(up["rate_kpa_s"].iloc[0]) if len(up) else math.nan,
                rate_down_kpa_s=float(down["rate_kpa_s"].iloc[0]) if len(down) else math.nan,
                width_mean_deg=float(width.mean()) if width.size else math.nan,
                width_max_deg=float(width[big]) if width.size else math.nan,
                width_max_at_kpa=float(common[big]) if width.size else math.nan,
                area_deg_kpa=float(np.trapezoid(width, common.to_numpy(float)))
                if width.size > 1
                else math.nan,
                bins_compared=int(width.size),
            )
        )
    cycles = pd.DataFrame(
        summary,
        columns=[
            *RAMP_KEYS,
            "cycle",
            "rate_up_kpa_s",
            "rate_down_kpa_s",
            "width_mean_deg",
            "width_max_deg",
            "width_max_at_kpa",
            "area_deg_kpa",
            "bins_compared",
        ],
    )
    return out, cycles


def noise_sd(values: np.ndarray) -> float:
    """Frame-to-frame noise sd of a smoothly changing series: robust sd of its second differences
    (which cancel a linear trend) / sqrt(6).

    Examples
    --------
    >>> y = np.linspace(0, 50, 2000) + np.random.default_rng(0).normal(0, 0.3, 2000)
    >>> round(noise_sd(y), 1)
    0.3
    """
    d = np.diff(np.asarray(values, float), n=2)
    d = d[np.isfinite(d)]
    if d.size < 3:
        return math.nan
    return float(1.4826 * np.median(np.abs(d - np.median(d))) / math.sqrt(6))


def _crossing(t: np.ndarray, y: np.ndarray, level: float, rising: bool) -> float:
    """First time (interpolated between frames) ``y`` reaches ``level`` going the way of the
    change."""
    reached = (y >= level) if rising else (y <= level)
    idx = np.flatnonzero(reached)
    if not idx.size:
        return math.nan
    i = int(idx[0])
    if i == 0:
        return float(t[0])
    y0, y1 = y[i - 1], y[i]
    return (
        float(t[i - 1] + (t[i] - t[i - 1]) * (level - y0) / (y1 - y0)) if y1 != y0 else float(t[i])
    )


#: the step table's note of a hold whose end still drifts
UNSETTLED = "did not settle within the hold"


#: the hold's last fifth scatters like noise while the lag-1 correlation of its residuals stays
#: below this (customer 35's still actuator: -0.5 to 0.2; a 2 Hz swing filmed at 30 fps: 0.9)
SMOOTH_SCATTER = 0.5


def _excursions(outside: np.ndarray) -> np.ndarray:
    """``outside`` (bool per frame) but for a lone frame outside, with no other within two
    frames: that one frame off is the measurement's (a still actuator's frame 2.1 deg off its
    hold's mean read "did not settle within the hold"); frames outside closer together are the
    actuator's (ringing at 7 Hz filmed at 30 fps is outside every other frame).

    Examples
    --------
    >>> _excursions(np.array([1, 0, 0, 0, 1, 0, 0, 1, 0, 1, 0, 0], bool)).astype(int).tolist()
    [1, 0, 0, 0, 0, 0, 0, 1, 0, 1, 0, 0]
    """
    padded = np.r_[False, False, outside, True, True]  # the last frames: nothing after says
    near = np.zeros(outside.size, bool)
    for shift in (-2, -1, 1, 2):
        near |= padded[2 + shift : 2 + shift + outside.size]
    lone = outside & ~near
    lone[:1] = False  # the first frame after the step is the way to the new value
    return outside & ~lone


def step_response(time_s: np.ndarray, values: np.ndarray, *, step_time_s: float, before_deg: float,
                  noise: float | None = None) -> dict[str, float | str]:
    """Rise time, overshoot and settling time of one step (values after the step only are used).

    Parameters
    ----------
    time_s, values : ndarray
        The series over the hold that follows the step (frames at or after ``step_time_s``); NaN
        where a frame is not used (flagged or failed): a hold whose last frames are has no final
        value.
    step_time_s : float
        When the step was applied (s).
    before_deg : float
        The value before the step.
    noise : float, optional
        Noise sd of the values (default: :func:`noise_sd` of these values).

    Returns
    -------
    dict
        ``final``, ``change``, ``rise_time_s``, ``overshoot_pct``, ``settling_time_s``, ``noise_sd``
        and ``note`` (why a figure is NaN, '' when none is).
    """
    t = np.asarray(time_s, float)
    y = np.asarray(values, float)
    after = t >= step_time_s
    t, y = t[after], y[after]
    # the end of the hold, over every frame of it: NaN where a frame is not used (flagged)
    end_ok = np.isfinite(y[-max(SETTLED_MIN_FRAMES, round(SETTLED_FRACTION * t.size)):])
    keep = np.isfinite(y)
    t, y = t[keep], y[keep]
    nan = math.nan
    out: dict[str, float | str] = {
        "final": nan,
        "change": nan,
        "rise_time_s": nan,
        "overshoot_pct": nan,
        "settling_time_s": nan,
        "noise_sd": nan,
        "note": "",
    }
    if not math.isfinite(before_deg):  # customer 27's read "too few frames around the step"
        out["note"] = "no value before it: no ok frame ends the hold before"
        return out
    if t.size < 5:
        out["note"] = f"too few ok frames after the step ({t.size})"
        return out
    tail = int(end_ok.sum())
    if tail < SETTLED_MIN_FRAMES:  # the frames before it are the way there, not its final value
        out["note"] = f"no final value: {tail} of the hold's last {end_ok.size} frames ok"
        return out
    final = float(np.mean(y[-tail:]))
    change = final - before_deg
    sd = noise_sd(y) if noise is None else noise
    out.update(final=final, change=change, noise_sd=sd)
    if abs(change) < max(1.0, MIN_CHANGE_SD * (sd if math.isfinite(sd) else 0.0)):
        out["note"] = f"change {change:+.2f} too small for step figures"
        return out
    rising = change > 0
    t10 = _crossing(t, y, before_deg + 0.1 * change, rising)
    t90 = _crossing(t, y, before_deg + 0.9 * change, rising)
    three_sd = 3.0 * (sd if math.isfinite(sd) else 0.0)
    # the final window's own scatter about its straight-line fit: a frame-to-frame noise sd
    # misses noise that holds over a few frames (customer 35's still actuator: 0.8 deg sd in the
    # last second, frames up to 2.1 deg off, read "did not settle"; the noise sd said 0.5), but
    # not a scatter that runs smoothly from frame to frame: a hold still swinging (a regulator
    # hunting) has not settled however wide it swings
    fit = np.polyfit(t[-tail:], y[-tail:], 1)
    resid = y[-tail:] - np.polyval(fit, t[-tail:])
    smooth = tail > 3 and float(np.corrcoef(resid[:-1], resid[1:])[0, 1]) >= SMOOTH_SCATTER
    scatter = 0.0 if smooth else float(np.std(resid))
    band = max(SETTLING_BAND * abs(change), three_sd, 3.0 * scatter)
    # settled: the final window itself no longer drifts (its straight-line fit moves less than the
    # band)
    slope = float(fit[0])
    drift = abs(slope) * float(t[-1] - t[-tail])
    beyond = float(np.max((y - final) * np.sign(change)))
    outside = np.flatnonzero(_excursions(np.abs(y - final) > band))
    if drift > band or (outside.size and outside[-1] >= t.size - tail):
        out["note"] = UNSETTLED
        return out
    out["rise_time_s"] = t90 - t10
    out["overshoot_pct"] = (beyond if beyond > three_sd else 0.0) / abs(change) * 100.0
    if outside.size:
        out["settling_time_s"] = float(t[outside[-1] + 1] - step_time_s)
    else:
        out["settling_time_s"] = float(t[0] - step_time_s)
    return out


def steps(
    angles: pd.DataFrame, *, include_flagged: bool = False
) -> tuple[pd.DataFrame, pd.DataFrame]:
    """Step-response figures per step and the settling curves (see the module docstring)."""
    df = _frames(angles, include_flagged)
    rows, curves = [], []
    if "step" not in df.columns or "since_step_s" not in df.columns:
        return pd.DataFrame(), pd.DataFrame()
    for key, ramp in df.groupby(list(RAMP_KEYS), sort=False):
        used = ramp[ramp["_used"]]
        sd = noise_sd(used["psi_deg"].to_numpy(float))
        for k, hold in ramp[ramp["step"] > 0].groupby("step", sort=True):
            first = hold[np.isfinite(hold["since_step_s"])]
            if first.empty:
                continue
            t_step = float((first["time_s"] - first["since_step_s"]).iloc[0])
            before_rows = used[
                (used["time_s"] < t_step) & (used["time_s"] >= t_step - BEFORE_WINDOW_S)
            ]
            before = float(before_rows["psi_deg"].mean()) if len(before_rows) else math.nan
            mine = hold[hold["_used"]]
            r = step_response(
                hold["time_s"].to_numpy(),
                hold["psi_deg"].where(hold["_used"]).to_numpy(float),
                step_time_s=t_step,
                before_deg=before,
                noise=sd,
            )
            prev = ramp[ramp["time_s"] < t_step]
            # the level held before the step, not the last frame's pressure: a frame between two
            # log lines across the jump reads a level never set (13.3 kPa between 0 and 40)
            level = ramp.loc[ramp["step"] == k - 1, "pressure_kpa"]
            from_kpa = (
                float(level.median()) if len(level)
                else float(prev["pressure_kpa"].iloc[-1]) if len(prev) else math.nan
            )
            to_kpa = float(hold["pressure_kpa"].median())
            row = dict(
                zip(RAMP_KEYS, key),
                step=int(k),
                time_s=t_step,
                from_kpa=from_kpa,
                to_kpa=to_kpa,
                # the step's own way (its hold's last frame may already count the fall after a
                # top level as down)
                direction=(
                    str(hold["direction"].iloc[-1]) if not math.isfinite(from_kpa)
                    else "up" if to_kpa > from_kpa else "down"
                ),
                hold_s=float(hold["time_s"].iloc[-1] - t_step),
                psi_before_deg=before,
                psi_final_deg=r["final"],
                change_deg=r["change"],
                rise_time_s=r["rise_time_s"],
                overshoot_pct=r["overshoot_pct"],
                settling_time_s=r["settling_time_s"],
                noise_sd_deg=r["noise_sd"],
                n_frames=len(mine),
                note=r["note"],
            )
            if (
                "measured_pressure_kpa" in hold.columns
                and hold["measured_pressure_kpa"].notna().any()
            ):
                p_before = (
                    prev["measured_pressure_kpa"].tail(max(1, int(BEFORE_WINDOW_S * 10))).mean()
                )
                rp = step_response(
                    hold["time_s"].to_numpy(),
                    hold["measured_pressure_kpa"].to_numpy(),
                    step_time_s=t_step,
                    before_deg=float(p_before),
                )
                row.update(
                    pressure_rise_time_s=rp["rise_time_s"],
                    pressure_settling_time_s=rp["settling_time_s"],
                )
            rows.append(row)
            change = r["change"]
            if len(mine) and isinstance(change, float) and math.isfinite(change) and change != 0:
                since = mine["time_s"].to_numpy() - t_step
                psi = mine["psi_deg"].to_numpy(float)
                edges = np.linspace(
                    since.min(), since.max() + 1e-9, min(CURVE_POINTS, len(since)) + 1
                )
                which = np.digitize(since, edges) - 1
                for b in np.unique(which):
                    sel = which == b
                    curves.append(
                        dict(
                            zip(RAMP_KEYS, key),
                            step=int(k),
                            since_step_s=float(np.median(since[sel])),
                            psi_deg=float(np.median(psi[sel])),
                            response=float((np.median(psi[sel]) - before) / change),
                        )
                    )
    return pd.DataFrame(rows), pd.DataFrame(curves)


def timeline(
    angles: pd.DataFrame, *, include_flagged: bool = False, points: int = TIMELINE_POINTS
) -> pd.DataFrame:
    """psi and pressure against time, medians of at most ``points`` equal time bins per ramp,
    with the failed and flagged frames each bin holds (``n_failed``, ``n_flagged``)."""
    df = _frames(angles, include_flagged)
    out = []
    for key, ramp in df.groupby(list(RAMP_KEYS), sort=False):
        t = ramp["time_s"].to_numpy(float)
        if not np.isfinite(t).any():
            continue
        edges = np.linspace(np.nanmin(t), np.nanmax(t) + 1e-9, min(points, len(t)) + 1)
        ramp = ramp.assign(_b=np.digitize(t, edges) - 1, _psi=ramp["psi_deg"].where(ramp["_used"]))
        agg = {
            "time_s": "median",
            "_psi": "median",
            "pressure_kpa": "median",
            "_pressure": "median",
        }
        g = (
            ramp.groupby("_b")
            .agg(agg)
            .rename(columns={"_psi": "psi_deg", "_pressure": "measured_pressure_kpa"})
        )
        status = ramp.groupby("_b")["status"]
        g["n_failed"] = status.apply(lambda s: int((s == "failed").sum()))
        g["n_flagged"] = status.apply(lambda s: int((s == "flagged").sum()))
        for k, v in zip(RAMP_KEYS, key):
            g.insert(0, k, v)
        out.append(g.reset_index(drop=True))
    cols = [
        *RAMP_KEYS, "time_s", "psi_deg", "pressure_kpa", "measured_pressure_kpa", "n_failed",
        "n_flagged",
    ]
    return pd.concat(out, ignore_index=True)[cols] if out else pd.DataFrame(columns=cols)


def write_continuous(
    angles: pd.DataFrame,
    out_dir: str | os.PathLike[str],
    *,
    bin_kpa: float = BIN_KPA,
    include_flagged: bool = False,
) -> dict[str, pd.DataFrame]:
    """Compute every table and write them (:data:`FILES`) into ``out_dir`` atomically."""
    loop_table, cycle_table = loops(angles, bin_kpa=bin_kpa, include_flagged=include_flagged)
    step_table, curves = steps(angles, include_flagged=include_flagged)
    tables = {
        "loops.csv": loop_table,
        "cycles.csv": cycle_table,
        "steps.csv": step_table,
        "settling.csv": curves,
        "timeline.csv": timeline(angles, include_flagged=include_flagged),
    }
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    for name, table in tables.items():
        write_table(table, out / name)
    return tables
