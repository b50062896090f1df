"""Ramp consistency: along one pressure ramp psi changes smoothly, so a photo that breaks the trend
of its neighbours is doubtful, and one that follows it is trustworthy.

After the photos of a set are measured, each ramp (material, actuator, trial) is split into its
legs (``up`` then ``down``, in step order).  On a leg psi is monotone in pressure, however fast it
changes (DS20 passes psi = 0 at more than 100 deg per 10 kPa step), so every measured photo
should lie between its two neighbours on the leg, and an end photo no farther beyond its
neighbour than :data:`END_STEPS` times the neighbouring step (a leg may end in its fastest part),
or else near an ``ok`` photo of another leg of its ramp at the same pressure (a coarse ramp's
rest photos: DS20 turns through 300 deg between 0 and 80 kPa, and 70 deg from 80 to 160):

- a photo more than :data:`SLACK_DEG` outside that range is ``flagged``, with the reason
  ("breaks its ramp: ..."): a sign flip, a ring read the wrong way round, a piece of halo.
  The worst photo goes first (one already flagged on its own before one that is not) and the
  leg is checked again without it, so one wrong photo never drags its neighbours down;
- a photo whose pressure breaks its leg's order is ``flagged`` (a typo in the manifest:
  :func:`pressure_order_breaks`), as its psi would go into the curves at the wrong pressure;
- a photo whose measured line length is far from the ramp's median is ``flagged`` (a partial
  line); a body's centre line, half the body's width beside the layer that does not stretch, is
  first brought to that layer's length (:func:`layer_lengths`);
- a photo ``flagged`` only for a cosmetic reason (line partly hidden, touching the border) whose
  psi lies between its ``ok`` neighbours (within :data:`AGREE_DEG`) is ``ok`` again, the reason
  saying why.

Nothing is changed for a leg of fewer than 3 measured photos.

First, the bodies of a ramp whose clamp holds their base in one direction are all measured from
that one direction (:func:`share_base_direction`): the start of a body's centre line, next to the
clamp, is where a shadow or a bulge tilts it most.

Examples
--------
>>> import pandas as pd
>>> df = pd.DataFrame({"image": list("abcde"), "psi_deg": [200.0, 150.0, -210.0, 50.0, 0.0],
...     "status": ["ok"] * 5, "reason": [""] * 5, "pressure_kpa": [0, 10, 20, 30, 40],
...     "direction": ["up"] * 5, "material": ["DS20"] * 5, "actuator": ["A1"] * 5,
...     "trial": ["1"] * 5})
>>> out = check_ramps(df)
>>> out["status"].tolist()
['ok', 'ok', 'flagged', 'ok', 'ok']
>>> out["reason"].iloc[2].startswith("breaks its ramp")
True
"""

from __future__ import annotations

from collections.abc import Collection, Mapping
from typing import Any

import numpy as np
import pandas as pd

from pipeline.constants import DIRECTIONS, NEAR_STEP_S, PRESSURE_OUT_OF_ORDER, RAMP_KEYS
from pipeline.measure.quality import BASE_MISMATCH_DEG, COSMETIC_FLAGS, NOTE_GIVEN_OFF
from pipeline.measure.settings import user_floats

#: a photo this far (deg) outside the range its neighbours allow breaks its ramp
SLACK_DEG = 12.0
#: a video's frame breaks its ramp when it stands off its neighbouring frames by this many times
#: the frames' own noise, and at least VIDEO_SLACK_MIN_DEG (deg): :func:`video_spikes`
VIDEO_SLACK_NOISE, VIDEO_SLACK_MIN_DEG = 6.0, 4.0
#: an end photo of a leg may lie this many neighbouring steps beyond its neighbour
END_STEPS = 4.0
#: a cosmetically flagged photo within this of its ramp's prediction (deg) is trusted again
AGREE_DEG = 3.0
#: measured length outside [LENGTH_LOW, LENGTH_HIGH] x the ramp's median -> partial line
LENGTH_LOW, LENGTH_HIGH = 0.85, 1.15
#: a ramp's bodies share one base direction when at least this many were measured ...
BASE_MIN_PHOTOS = 5
#: ... and their own base directions lie this close (deg, median absolute deviation)
BASE_SPREAD_DEG = 3.0
#: a photo whose psi moved by at least this (deg) says so in its reason
BASE_NOTE_DEG = 1.0
#: the base directions of a ramp's photos jump by more than this (deg) between two runs of at
#: least BASE_SHIFT_PHOTOS consecutive photos that each agree within BASE_SPREAD_DEG: the camera or
#: the clamp moved, and each run is measured from its own shared direction (on the rendered
#: analogues, 30 ramps over two sizes, two seeds and three camera faults, no such jump passed 3 deg)
BASE_SHIFT_DEG = 5.0
BASE_SHIFT_PHOTOS = 3
#: with ``fixed_direction_deg`` given, a ramp whose bodies leave the clamp more than this (deg)
#: off it (the median of their own directions, which agree within BASE_SPREAD_DEG) says so in
#: every row: psi is measured from the direction given, off by as much if the body sits turned in
#: its clamp (a customer's second trial: 3.2 deg).  Given their true direction, the bodies' own
#: read up to 2.7 deg off it on 26 rendered ramps (translucent ones, and at 12 MP)
GIVEN_OFF_DEG = 3.0
#: ... and more than this (deg) off it flags every row: psi may be that far off (a customer's
#: second trial, remounted turned 4 deg, the direction given once for both: every psi 5-8 deg
#: off, ``ok``).  Above the bodies' own error (2.7 deg at most, see above) with room to spare,
#: so a direction given within a degree or two of the truth is never doubted for it
GIVEN_FLAG_DEG = 5.0
#: the bodies of a ramp whose two sides diverge by more than this (deg, the median of their
#: ``base_side_split_deg`` where their own base is read) leave the clamp in a direction that
#: cannot be trusted: one side is faint or shaded there, or bulges, and the centre line turns
#: with it.  Customer 31's white body on grey, its shaded side barely brighter than the backdrop:
#: 2.7-3.5 deg, every base 8 deg off (41 rows ok and 7-10 deg off); 10 rendered ramp sets and a
#: customer's silhouettes, all right: at most 0.9
SIDE_SPLIT_DEG = 2.0
#: ... their own base may then be this far (deg) off a direction given without doubting it
#: (customer 31: 8.4); farther, the direction given is doubted as ever (a sign typo: 170 off)
SIDES_EXCUSE_DEG = 15.0


def base_runs(own_deg: np.ndarray) -> list[np.ndarray]:
    """Split a ramp's base directions (deg, in acquisition order) where the setup moved.

    The ramp is cut where the median directions of the photos before and after differ by more
    than :data:`BASE_SHIFT_DEG`, both sides hold at least :data:`BASE_SHIFT_PHOTOS` photos, each
    agrees within :data:`BASE_SPREAD_DEG` (median absolute deviation) and every photo lies nearer
    its own side's direction than the other side's; of such places, the
    one that leaves the photos closest to their side's median (least absolute deviation).  Each
    side is split again the same way.

    Returns
    -------
    list of ndarray
        Index arrays (into ``own_deg``) of the consecutive runs, in order.

    Examples
    --------
    >>> [r.tolist() for r in base_runs(np.array([0.5, -0.5, 0.0, 1.0, 9.0, 8.0, 8.5]))]
    [[0, 1, 2, 3], [4, 5, 6]]
    >>> [r.tolist() for r in base_runs(np.array([0.5, -0.5, 0.0, 6.0, 0.2, 0.0]))]  # one photo
    [[0, 1, 2, 3, 4, 5]]
    """
    d = _wrap_deg(own_deg - own_deg[0])
    best: tuple[float, int] | None = None
    for k in range(BASE_SHIFT_PHOTOS, len(d) - BASE_SHIFT_PHOTOS + 1):
        sides = (d[:k], d[k:])
        medians = [float(np.median(side)) for side in sides]
        jump = abs(medians[1] - medians[0])
        spread = [np.abs(side - m) for side, m in zip(sides, medians, strict=True)]
        # each side agrees, and each photo lies nearer its own side's direction than the other's
        nearer = all(
            (np.abs(side - m) < np.abs(side - other)).all()
            for side, m, other in zip(sides, medians, medians[::-1], strict=True)
        )
        consistent = nearer and all(float(np.median(a)) <= BASE_SPREAD_DEG for a in spread)
        cost = float(sum(a.sum() for a in spread))
        if jump > BASE_SHIFT_DEG and consistent and (best is None or cost < best[0]):
            best = (cost, k)
    if best is None:
        return [np.arange(len(d))]
    k = best[1]
    return [*base_runs(own_deg[:k]), *(run + k for run in base_runs(own_deg[k:]))]


#: a pressure out of its leg's order by more than this share of the leg's median step (and at
#: least PRESSURE_SLACK_MIN_KPA) is a typo: a gauge's own reading wobbles far less
PRESSURE_SLACK_STEPS, PRESSURE_SLACK_MIN_KPA = 0.5, 1.0
#: the leg's step is the median of its steps over this share of its span (from its tenth to its
#: ninetieth percentile: photos of one level differ by less)
LEVEL_STEP_SHARE = 0.05
#: ... and so is a leg's first or last pressure whose step is more than this many times the step
#: beside it (a typo at the top of a ramp keeps its leg in order: 90 -> 1100; a ramp that doubles
#: its steps, 40 -> 80 -> 160, is no typo)
PRESSURE_END_STEPS = 4.0


def pressure_order_breaks(rows: pd.DataFrame) -> dict[Any, str]:
    """The rows whose ``pressure_kpa`` breaks the order of its leg: a typo in the manifest.

    Along a leg (a run of one ``direction`` of a ramp, in ``step`` order) the pressure rises
    (``up``) or falls (``down``).  A pressure that does not (by more than
    :data:`PRESSURE_SLACK_STEPS` of the leg's median step) is doubtful: the fewest rows that,
    left out, put the leg in order are blamed (:func:`in_order`), so a typo never blames its
    neighbours (a customer's 100 kPa typed as 1000 went into the curves: a level at 1000 kPa;
    customer 44's retake of 30 kPa added at the end of a leg blamed the three correct rows
    before it, and they left the curves); then a leg's first or last pressure whose step is
    more than :data:`PRESSURE_END_STEPS` times the step beside it (a typo at a ramp's top).
    Nothing is said without a ``step`` column (the rows' order is then not the order taken),
    for a video's frames (their pressures come from its log, not typed) or for a leg of fewer
    than 3 pressures.

    Returns
    -------
    dict
        Row index -> the reason, naming the pressures before and after it.

    Examples
    --------
    >>> df = pd.DataFrame({"pressure_kpa": [0, 20, 40, 60, 1000, 120, 140, 120, 100],
    ...     "direction": ["up"] * 7 + ["down"] * 2, "step": range(9), "material": "M",
    ...     "actuator": "A", "trial": "1"})
    >>> for ix, why in pressure_order_breaks(df).items():  # doctest: +NORMALIZE_WHITESPACE
    ...     print(ix, why)
    4 pressure 1000 kPa is out of its ramp's order (60 -> 1000 -> 120 kPa by step): a typo in the
    manifest?
    """
    if "step" not in rows.columns or "frame" in rows.columns or not set(RAMP_KEYS) <= set(
        rows.columns
    ):
        return {}
    p_all = pd.to_numeric(rows["pressure_kpa"], errors="coerce")
    # a failed row of no known direction ('upp') would split its leg in two, each too short
    known = p_all.notna() & rows["direction"].isin(DIRECTIONS)
    ordered = rows[known].sort_values("step", kind="stable")
    out: dict[Any, str] = {}
    for _, ramp in ordered.groupby(list(RAMP_KEYS), sort=False):
        legs = (ramp["direction"] != ramp["direction"].shift()).cumsum()
        out.update(direction_breaks([leg for _, leg in ramp.groupby(legs, sort=False)], p_all))
        for _, leg in ramp.groupby(legs, sort=False):
            sign = 1.0 if leg["direction"].iloc[0] == DIRECTIONS[0] else -1.0
            p = sign * p_all[leg.index].to_numpy(float)
            keep = list(range(len(p)))
            steps = np.abs(np.diff(p))
            # the step between levels: not the wobble between photos of one level (two or three
            # photos a level read by a gauge, +-0.5 kPa, set the slack to 1 kPa and half their
            # rows were typos)
            span = float(np.percentile(p, 90) - np.percentile(p, 10)) if len(p) else 0.0
            between = steps[steps > LEVEL_STEP_SHARE * span]  # (a typo widens no such span)
            typical = float(np.median(between)) if between.size else 0.0
            slack = max(PRESSURE_SLACK_MIN_KPA, PRESSURE_SLACK_STEPS * typical)
            # ties are broken by the steps nearest the typical one where enough steps say what
            # it is, else by the smoothest (in 0 -> 100 -> 20 kPa the typo sets the median)
            keep = in_order(p, slack, typical if len(p) >= 5 else 0.0) if len(p) >= 3 else keep
            for doubt in sorted(set(range(len(p))) - set(keep)):
                # between the kept pressures before and after it (not the other doubtful ones)
                kept_before = [k for k in keep if k < doubt][-1:]
                kept_after = [k for k in keep if k > doubt][:1]
                shown = [f"{sign * p[k]:g}" for k in (*kept_before, doubt, *kept_after)]
                out[leg.index[doubt]] = (
                    f"pressure {sign * p[doubt]:g} kPa {PRESSURE_OUT_OF_ORDER} "
                    f"({' -> '.join(shown)} kPa by step): a typo in the manifest?"
                )
            if len(keep) >= 3:  # a typo that overshoots at a leg's end keeps it in order
                q = p[keep]
                for i, j, k in ((len(q) - 1, len(q) - 2, len(q) - 3), (0, 1, 2)):
                    step, before = abs(q[i] - q[j]), abs(q[j] - q[k])
                    if step > slack and step > PRESSURE_END_STEPS * max(before, slack):
                        shown = [f"{sign * q[n]:g}" for n in sorted((i, j))]
                        out[leg.index[keep[i]]] = (
                            f"pressure {sign * q[i]:g} kPa {PRESSURE_OUT_OF_ORDER} "
                            f"({' -> '.join(shown)} kPa by step, {step / max(before, slack):.0f} "
                            "times the step beside it): a typo in the manifest?"
                        )
    return out


def direction_breaks(legs: list[pd.DataFrame], pressures_kpa: pd.Series) -> dict[Any, str]:
    """The rows of one ramp (``legs``: its runs of one ``direction``, in ``step`` order) whose
    direction is a typo: a run of one or two rows between two longer runs of the other
    direction, whose pressures follow those runs' order (customer 47's 'up' typed for one row
    after the ramp's top moved the rising curve's 120 kPa level 4 deg, nothing flagged).

    Examples
    --------
    >>> def runs(df):
    ...     return [g for _, g in df.groupby((df.direction != df.direction.shift()).cumsum())]
    >>> df = pd.DataFrame({"pressure_kpa": [0, 40, 80, 120, 100, 80, 60, 40, 0],
    ...                    "direction": ["up"] * 4 + ["down"] * 2 + ["up"] + ["down"] * 2})
    >>> print(direction_breaks(runs(df), df.pressure_kpa)[6])  # doctest: +NORMALIZE_WHITESPACE
    direction up is out of its ramp's order (down rows before and after it by step: 80 -> 60 -> 40
    kPa): a typo in the manifest?
    >>> cycles = pd.DataFrame({"pressure_kpa": [0, 40, 80, 40, 0, 40, 80, 40, 0],
    ...                        "direction": ["up"] * 3 + ["down"] * 2 + ["up"] * 2 + ["down"] * 2})
    >>> direction_breaks(runs(cycles), cycles.pressure_kpa)  # a second cycle
    {}
    >>> hold = pd.DataFrame({"pressure_kpa": [0, 60, 120, 120, 120, 140, 160],
    ...                      "direction": ["up"] * 3 + ["down"] * 2 + ["up"] * 2})
    >>> direction_breaks(runs(hold), hold.pressure_kpa)  # held at the top, then on up
    {}
    """
    out: dict[Any, str] = {}
    for before, run, after in zip(legs, legs[1:], legs[2:]):
        direction, other = run["direction"].iloc[0], before["direction"].iloc[0]
        if len(run) > 2 or len(before) < 2 or len(after) < 2 or after["direction"].iloc[0] != other:
            continue
        rows = [before.index[-1], *run.index, after.index[0]]
        sign = 1.0 if other == DIRECTIONS[0] else -1.0
        if (np.diff(sign * pressures_kpa[rows].to_numpy(float)) <= PRESSURE_SLACK_MIN_KPA).any():
            # its pressures do not go on the other direction's way (a hold at one pressure, or
            # one level approached from both sides, goes both ways)
            continue
        shown = " -> ".join(f"{float(pressures_kpa[ix]):g}" for ix in rows)
        for ix in run.index:
            out[ix] = (
                f"direction {direction} {PRESSURE_OUT_OF_ORDER} ({other} rows before and after "
                f"it by step: {shown} kPa): a typo in the manifest?"
            )
    return out


def in_order(p: np.ndarray, slack: float, typical: float = 0.0) -> list[int]:
    """The indices of the longest subsequence of ``p`` (in order) in which no value falls below
    the one before it by more than ``slack``; of several as long, the one whose steps lie
    nearest the ``typical`` step (least sum of squared differences), then the one that keeps
    the earlier values.

    Examples
    --------
    >>> in_order(np.array([-60.0, -50, -40, -30, -20, -10, 0, -30, -20]), 5.0)  # a retake after
    [0, 1, 2, 3, 4, 5, 6]
    >>> in_order(np.array([0.0, 20, 40, 60, 1000, 120, 140]), 10.0)
    [0, 1, 2, 3, 5, 6]
    >>> in_order(np.array([0.0, 10, 5, 20]), 2.0, 10.0)
    [0, 1, 3]
    >>> in_order(np.array([-30.0, -20, -10, 0, -10]), 5.0, 10.0)  # a retake of the level before
    [0, 1, 2, 3]
    """
    n = len(p)
    length, cost, prev = [1] * n, [0.0] * n, [-1] * n
    for j in range(n):
        for i in range(j):
            if p[j] - p[i] >= -slack:
                c = cost[i] + (abs(float(p[j] - p[i])) - typical) ** 2
                if length[i] + 1 > length[j] or (length[i] + 1 == length[j] and c < cost[j]):
                    length[j], cost[j], prev[j] = length[i] + 1, c, i
    end = max(range(n), key=lambda j: (length[j], -cost[j]))
    chain = []
    while end >= 0:
        chain.append(end)
        end = prev[end]
    return chain[::-1]


def _allowed(psi: np.ndarray, i: int) -> tuple[float, float]:
    """The range of psi that photo ``i`` of a monotone leg may take, from its neighbours."""
    n = len(psi)
    if 0 < i < n - 1:
        return float(min(psi[i - 1], psi[i + 1])), float(max(psi[i - 1], psi[i + 1]))
    j, k = (1, 2) if i == 0 else (n - 2, n - 3)
    far = psi[j] + END_STEPS * (psi[j] - psi[k])
    return float(min(psi[j], far)), float(max(psi[j], far))


def _outside(value: float, lo: float, hi: float) -> float:
    return max(lo - value, value - hi, 0.0)


def _is_cosmetic(reason: str) -> bool:
    parts = [r.strip() for r in str(reason).split(";") if r.strip()]
    return bool(parts) and all(any(r.startswith(c) for c in COSMETIC_FLAGS) for r in parts)


def _join(*parts: str) -> str:
    return "; ".join(p for p in parts if p)


def settling(since_step_s: pd.Series) -> np.ndarray:
    """Which photos were taken while the actuator may still have been moving: a manifest's
    ``since_step_s`` from 0 up to :data:`~pipeline.constants.NEAR_STEP_S` (read as ``check``
    reads it: ``"1,2"`` is 1.2 s; text or a negative time, which check names, is no such photo).

    Examples
    --------
    >>> settling(pd.Series([0.5, 4.0, -0.3, "1,2", None, "abc"])).tolist()
    [True, False, False, True, False, False]
    """
    since = user_floats(since_step_s)
    return (since >= 0) & (since < NEAR_STEP_S)


def flag_settling(angles: pd.DataFrame) -> pd.DataFrame:
    """Flag each measured photo taken less than :data:`~pipeline.constants.NEAR_STEP_S` after
    the logged pressure reached the level it then held (:func:`settling`, by the manifest's
    ``since_step_s``, which ``photoset init --pressure-log`` writes): the actuator may still
    have been moving, so its psi is not yet its level's, and a curve averaging it in is off
    (customer 39's 30 kPa mean, 1 deg under the settled value).  A video's frames are left
    alone: the ends of their holds count (:func:`pipeline.aggregate.settled_frames`).

    Examples
    --------
    >>> df = pd.DataFrame({"status": ["ok", "ok", "failed", "ok", "ok"], "reason": "",
    ...                    "since_step_s": [0.5, 4.0, 0.2, -0.3, "1,2"]})  # typed in by hand
    >>> out = flag_settling(df)
    >>> out["status"].tolist()
    ['flagged', 'ok', 'failed', 'ok', 'flagged']
    >>> out["reason"].iloc[0].split(",")[0]
    "taken 0.5 s after a step of its pressure log's setpoint"
    """
    if "since_step_s" not in angles.columns:
        return angles
    since = user_floats(angles["since_step_s"])
    moving = settling(angles["since_step_s"]) & (angles["status"] != "failed")
    if "frame" in angles.columns:
        moving &= angles["frame"].isna()
    out = angles.copy()
    out.loc[moving, "status"] = "flagged"
    out.loc[moving, "reason"] = [
        _join(
            str(why) if isinstance(why, str) else "",
            f"taken {s:g} s after a step of its pressure log's setpoint, so the actuator may "
            "still have been moving: left out of the curves with the flagged photos (to keep "
            "it, empty since_step_s in its manifest row)",
        )
        for why, s in zip(out.loc[moving, "reason"], since[moving])
    ]
    return out


def check_ramps(
    angles: pd.DataFrame,
    clamped: Collection[tuple[Any, ...]] = (),
    doubtful: Mapping[Any, str] | None = None,
) -> pd.DataFrame:
    """Measure a ramp's bodies from its shared base direction, flag photos that break their
    ramp's trend and trust cosmetically flagged ones that follow it.

    Parameters
    ----------
    angles : pandas.DataFrame
        The angles.csv table (``psi_deg``, ``status``, ``reason``, ``pressure_kpa``,
        ``direction``, the ramp keys, optionally ``step`` and ``length_px``).
    clamped : collection of tuple
        See :func:`share_base_direction`.
    doubtful : mapping, optional
        Rows found in doubt over their ramp before (index label -> reason: a fixed end guessed
        at the free end, so psi's sign may be wrong): flagged with it and, like a row whose
        pressure is out of its ramp's order, no neighbour in the trend and length checks.

    Returns
    -------
    pandas.DataFrame
        A copy with ``status`` and ``reason`` updated (rows in the same order).
    """
    out = share_base_direction(angles, clamped=clamped)
    if out.empty or not set(RAMP_KEYS) <= set(out.columns):
        return out
    status, reason = (
        out["status"].astype(str).to_numpy(copy=True),
        out["reason"].fillna("").astype(str).to_numpy(copy=True),
    )
    position = {ix: k for k, ix in enumerate(out.index)}
    off_order = pressure_order_breaks(out)
    given = doubtful or {}
    in_doubt = {
        ix: _join(given.get(ix, ""), off_order.get(ix, "")) for ix in {*given, *off_order}
    }
    for ix, why in in_doubt.items():
        k = position[ix]
        if status[k] != "failed":  # its pressure or psi is in doubt: kept out of the curves
            status[k], reason[k] = "flagged", _join(why, reason[k])
    keys = [c for c in ("step", "time_s") if c in out.columns]  # frames of a video: over time
    order = out.sort_values(keys, kind="stable").index if keys else out.index
    for _, ramp in out.loc[order].groupby(list(RAMP_KEYS), sort=False):
        # a photo whose pressure is in doubt is no neighbour of the others (customer 44's retake
        # of 30 kPa at a leg's end flagged the three right photos before it as breaking the ramp)
        measured = ramp[(ramp["status"] != "failed") & ~ramp.index.isin(list(in_doubt))]
        if "length_px" in measured.columns and len(measured) >= 3:
            lengths = layer_lengths(measured)
            med = float(np.nanmedian(lengths)) if np.isfinite(lengths).any() else np.nan
            for ix, length in zip(measured.index, lengths):
                if (
                    np.isfinite(med)
                    and np.isfinite(length)
                    and not LENGTH_LOW <= length / med <= LENGTH_HIGH
                ):
                    k = position[ix]
                    status[k] = "flagged"
                    reason[k] = _join(
                        reason[k],
                        f"line length {100 * length / med:.0f}% of its ramp's median: part of it "
                        "may be missing or extra",
                    )
        if "frame" in measured.columns and "time_s" in measured.columns:
            for ix, expected in video_spikes(measured):
                k = position[ix]
                status[k] = "flagged"
                reason[k] = _join(
                    f"breaks its ramp: psi {float(out.at[ix, 'psi_deg']):+.0f} deg where the "
                    f"frames before and after it lead to {expected:+.0f}",
                    reason[k],
                )
        legs = (measured["direction"] != measured["direction"].shift()).cumsum()
        for number, leg in measured.groupby(legs, sort=False):
            others = measured[(legs != number) & (measured["status"] == "ok")]
            _check_leg(leg, position, status, reason, _same_pressure(leg, others))
    out["status"], out["reason"] = status, reason
    return out


def video_spikes(frames: pd.DataFrame) -> list[tuple[Any, float]]:
    """The ``ok`` frames of one video ramp that stand off their neighbours: (index, the psi the
    neighbouring frames lead to), worst first.

    A frame is a spike when it lies both outside the range of the frames just before and after
    it and off the parabola in time through the two ``ok`` frames on each side, each by more than
    :data:`VIDEO_SLACK_NOISE` times the frames' own noise (robust, from their second differences)
    and at least :data:`VIDEO_SLACK_MIN_DEG`.  A step's onset lies within its neighbours' range,
    an overshoot's peak close to their parabola, so neither is one.  The worst spike is taken
    out and the rest judged again without it.

    Examples
    --------
    >>> rng = np.random.default_rng(0)
    >>> t = np.arange(300) / 15.0                  # 20 s at 15 fps, 0.7 deg of noise: a step
    >>> psi = np.where(t < 10, 200.0, 200.0 - 150.0 * (1 - np.exp(-(t - 10) / 0.4)))
    >>> psi = psi + 8.0 * np.exp(-(t - 11) / 0.5) * np.sin(2 * np.pi * (t - 11) / 0.5) * (t > 11)
    >>> psi = psi + rng.normal(0.0, 0.7, t.size)   # ... ringing after it
    >>> psi[60] += 6.0                             # and one frame read 6 deg off
    >>> frames = pd.DataFrame({"psi_deg": psi, "status": "ok", "time_s": t})
    >>> [(int(i), round(p)) for i, p in video_spikes(frames)]
    [(60, 199)]
    """
    ok = frames[(frames["status"] == "ok") & np.isfinite(frames["psi_deg"].to_numpy(float))]
    ok = ok.sort_values("time_s")
    index = list(ok.index)
    t, psi = ok["time_s"].to_numpy(float), ok["psi_deg"].to_numpy(float)
    if len(psi) < 10:
        return []
    d2 = psi[2:] - 2.0 * psi[1:-1] + psi[:-2]
    noise = 1.4826 * float(np.median(np.abs(d2 - np.median(d2)))) / np.sqrt(6.0)
    limit = max(VIDEO_SLACK_MIN_DEG, VIDEO_SLACK_NOISE * noise)
    out: list[tuple[Any, float]] = []
    while len(psi) >= 5:
        off = np.zeros(len(psi))
        expected = np.full(len(psi), np.nan)
        for i in range(2, len(psi) - 2):
            lo, hi = sorted((psi[i - 1], psi[i + 1]))
            if max(lo - psi[i], psi[i] - hi) <= limit:
                continue
            near = [i - 2, i - 1, i + 1, i + 2]
            expected[i] = np.polyfit(t[near] - t[i], psi[near], 2)[-1]
            off[i] = abs(psi[i] - expected[i])
        worst = int(np.argmax(off))
        if off[worst] <= limit:
            break
        out.append((index[worst], float(expected[worst])))
        del index[worst]
        t, psi = np.delete(t, worst), np.delete(psi, worst)
    return out


def _unit(rows: pd.DataFrame) -> str:
    """'frames' for the rows of a video, else 'photos' (customer 27: "the median of 600
    photos" of a video's frames).

    Examples
    --------
    >>> _unit(pd.DataFrame({"frame": [0, 1]})), _unit(pd.DataFrame({"image": ["a.jpg"]}))
    ('frames', 'photos')
    """
    return "frames" if "frame" in rows.columns and rows["frame"].notna().any() else "photos"


def _screen_sign(rows: pd.DataFrame) -> float:
    """-1 where the rows count a clockwise turning positive (``positive_turn: cw``), else +1: a
    direction in psi's convention (``base_direction_deg``) times it is the one on screen, as a
    user gives ``fixed_direction_deg`` (with cw the ramp named -49 "+49.0" and its fix, the
    bodies' own, with the wrong sign).

    Examples
    --------
    >>> _screen_sign(pd.DataFrame({"positive_turn": [None, "cw"]})), _screen_sign(pd.DataFrame())
    (-1.0, 1.0)
    """
    given = rows["positive_turn"].dropna() if "positive_turn" in rows.columns else pd.Series()
    # the ramp's own (a row whose settings could not be read has none)
    return -1.0 if len(given) and given.mode().iloc[0] == "cw" else 1.0


def _wrap_deg(angle: np.ndarray) -> np.ndarray:
    """Angles (deg) brought into [-180, 180)."""
    return (np.asarray(angle, float) + 180.0) % 360.0 - 180.0


def share_base_direction(
    angles: pd.DataFrame,
    keys: tuple[str, ...] = RAMP_KEYS,
    clamped: Collection[tuple[Any, ...]] = (),
) -> pd.DataFrame:
    """Measure every body of a ramp from the ramp's one base direction, where the clamp holds it.

    A body's psi is its free end's direction minus the direction in which it leaves the fixed
    end (``base_direction_deg``).  That start is read from a short stretch next to the clamp,
    where a shadow, a bulge or the clamp's face can tilt it by several degrees in one photo,
    while the clamp holds the body's base in the same direction in every photo of the ramp.
    Where a ramp has at least :data:`BASE_MIN_PHOTOS` measured bodies whose own base
    directions agree (median absolute deviation at most :data:`BASE_SPREAD_DEG`: a clamp, not
    free strips), each photo's psi is taken against their median instead, as with a known
    ``fixed_direction_deg``; a photo whose psi moved by :data:`BASE_NOTE_DEG` or more says so,
    and one whose own base is more than ``BASE_MISMATCH_DEG`` off the ramp's is flagged.  Where
    the base direction jumps part-way through the ramp (in step order) and stays there, the
    camera or the clamp moved: each run of photos (:func:`base_runs`) is measured from its own
    direction (a run of fewer than :data:`BASE_MIN_PHOTOS`, each photo from its own) and the
    photos after the move say so.  Where the bodies of a run held by one clamp (``clamped``)
    scatter by more than :data:`BASE_SPREAD_DEG`, their base cannot be read and its rows are
    flagged (:func:`_flag_unsteady_base`); free strips scatter, and each keeps its own.

    Parameters
    ----------
    angles : pandas.DataFrame
        The angles.csv table (``psi_deg``, ``status``, ``reason``, ``base_direction_deg``, the
        ``keys``; ``kappa_per_mm`` and ``l0_mm`` are kept consistent when present).
    keys : tuple of str
        The columns naming one ramp (one clamping of one actuator).
    clamped : collection of tuple
        The ``keys`` values of the ramps whose rows name one fixed end (a clamp holds them;
        per-row fixed ends are free strips').

    Returns
    -------
    pandas.DataFrame
        A copy; rows of the ramps that share a direction have ``psi_deg``, ``kappa_per_mm``
        and ``base_direction_deg`` (now the ramp's) updated.

    Examples
    --------
    >>> df = pd.DataFrame({"psi_deg": [200.0, 100.0, 0.0, -100.0, -193.0],
    ...     "base_direction_deg": [0.5, -0.5, 0.0, 1.0, -7.0], "status": "ok", "reason": "",
    ...     "material": "DS20", "actuator": "A1", "trial": "1"})
    >>> out = share_base_direction(df)
    >>> out["psi_deg"].tolist()
    [200.5, 99.5, 0.0, -99.0, -200.0]
    >>> reason = out["reason"].iloc[4]
    >>> reason.startswith("psi -200.0 deg against its ramp's base direction (+0.0 deg")
    True
    >>> reason.endswith("the median of 5 photos; -193.0 from its own, -7.0)")
    True

    Held by one clamp (``clamped``), bodies whose own directions scatter are flagged; one read
    half a turn off is flagged alone:

    >>> df = df.assign(base_direction_deg=[90.0, -90.0, -91.0, -89.0, -92.0])
    >>> out = share_base_direction(df, clamped={("DS20", "A1", "1")})
    >>> out["status"].tolist(), out["psi_deg"].round(1).tolist()
    (['flagged', 'ok', 'ok', 'ok', 'ok'], [21.0, 101.0, 0.0, -98.0, -194.0])
    >>> out = share_base_direction(df.assign(base_direction_deg=[0.0, 6.0, -5.0, 7.0, -6.0]),
    ...                            clamped={("DS20", "A1", "1")})
    >>> out["status"].unique().tolist(), out["reason"].iloc[0][:47]
    (['flagged'], 'the bodies of this ramp leave its one fixed_end')
    """
    out = angles.copy()
    if out.empty or "base_direction_deg" not in out.columns or not set(keys) <= set(out.columns):
        return out
    order = [c for c in ("step", "time_s") if c in out.columns]  # as the photos were taken
    for key, whole in out.groupby(list(keys), sort=False):
        ramp = whole.sort_values(order, kind="stable") if order else whole
        # each body's own base as the ramp's first photo sees it: a camera held by hand turned
        # between photos (customer 34: psi off by each photo's turn, 14 rows ok 5-7 deg off)
        turn = _camera_turn(out, ramp)
        own_all = ramp["base_direction_deg"].to_numpy(float) - turn
        given = pd.to_numeric(
            ramp.get("fixed_direction_deg", pd.Series(np.nan, index=ramp.index)), errors="coerce"
        ).to_numpy(float)
        uncertain = _sides_diverge(out, ramp, own_all, flag=not np.isfinite(given).any())
        if np.isfinite(given).any():  # psi is measured from the direction given: compared only
            # with the bodies' sides diverging, their own is the doubtful one (customer 31: 8.4
            # deg off the true direction given), unless it is too far off for that
            _turn_given(out, ramp, turn, given)
            _compare_given(out, ramp, own_all, given, excused_deg=SIDES_EXCUSE_DEG * uncertain)
            continue
        used = (ramp["status"] != "failed").to_numpy() & np.isfinite(own_all)
        if used.sum() < BASE_MIN_PHOTOS:
            continue
        runs = base_runs(own_all[used])
        first = float(np.median(own_all[used][runs[0]]))
        for number, run in enumerate(runs):
            _share_run(out, ramp[used].iloc[run], first_base_deg=first if number else None,
                       clamped=key in clamped,
                       turn=turn[used][run])
    return out


def _sides_diverge(
    out: pd.DataFrame, ramp: pd.DataFrame, own: np.ndarray, *, flag: bool
) -> bool:
    """Whether the bodies of ``ramp``, held by a clamp, leave it with their two sides diverging:
    the median of their ``base_side_split_deg`` more than :data:`SIDE_SPLIT_DEG`, over at least
    :data:`BASE_MIN_PHOTOS` bodies whose own base directions (``own``) agree within
    :data:`BASE_SPREAD_DEG` (free strips scatter: a cut end's sides need not run parallel, and
    no clamp makes their start the direction of every photo).  With ``flag`` (psi is measured
    from the bodies' own base) those rows are flagged in ``out``, in place.

    Examples
    --------
    >>> df = pd.DataFrame({"status": "ok", "reason": "",
    ...     "base_side_split_deg": [-2.7, -3.5, -3.0, -2.9, -3.1, -2.2]})
    >>> _sides_diverge(df, df, np.zeros(6), flag=True), df["status"].tolist()[:2]
    (True, ['flagged', 'flagged'])
    >>> df["reason"].iloc[0][:61]
    "the body's two sides diverge by 3.0 deg where it leaves the c"
    >>> df = df.assign(status="ok", reason="", base_side_split_deg=0.4)
    >>> _sides_diverge(df, df, np.zeros(6), flag=True), df["status"].tolist()[:2]
    (False, ['ok', 'ok'])
    """
    split = pd.to_numeric(
        ramp.get("base_side_split_deg", pd.Series(np.nan, index=ramp.index)), errors="coerce"
    ).to_numpy(float)
    measured = (ramp["status"] != "failed").to_numpy()
    read = np.isfinite(split) & np.isfinite(own) & measured
    # on most of the ramp's bodies (a PneuNet's chambered ones have no split: their own base is
    # their strip's edge alone; its few straight ones, whose comb side's gaps are too narrow
    # to fill, are no reason to doubt it)
    if read.sum() < max(BASE_MIN_PHOTOS, 0.5 * (measured & np.isfinite(own)).sum()):
        return False
    spread = _wrap_deg(own[read] - own[read][0])
    if float(np.median(np.abs(spread - np.median(spread)))) > BASE_SPREAD_DEG:
        return False
    median = abs(float(np.median(split[read])))
    if median <= SIDE_SPLIT_DEG:
        return False
    if flag:
        why = (
            f"the body's two sides diverge by {median:.1f} deg where it leaves the clamp (the "
            f"median of {int(read.sum())} {_unit(ramp)} of this ramp): one side is faint or "
            "shaded there, or bulges, so the direction psi is measured from may be several deg "
            "off; give fixed_direction_deg, the clamp's direction (photoset preview draws the "
            "base)"
        )
        for ix in ramp.index[read]:
            reason = out.at[ix, "reason"]
            out.at[ix, "reason"] = _join(why, reason if isinstance(reason, str) else "")
            if out.at[ix, "status"] == "ok":
                out.at[ix, "status"] = "flagged"
    return True


def _compare_given(
    out: pd.DataFrame,
    ramp: pd.DataFrame,
    own: np.ndarray,
    given: np.ndarray,
    excused_deg: float = 0.0,
) -> None:
    """Note in every row of ``ramp`` (in place in ``out``) when its bodies' own base directions
    (``own``), agreeing among themselves, lie more than :data:`GIVEN_OFF_DEG` from the
    ``fixed_direction_deg`` given (``given``, in the same convention); flag its measured rows
    when they lie more than :data:`GIVEN_FLAG_DEG` from it.  psi stays measured from the
    direction given.  Nothing is said where the bodies' own lie within ``excused_deg`` of it
    (their sides diverge at the clamp: :func:`_sides_diverge`).

    Examples
    --------
    >>> df = pd.DataFrame({"reason": [""] * 6, "status": "ok"})
    >>> _compare_given(df, df, np.array([18.2, 18.0, 18.4, np.nan, 18.1, 18.3]), np.full(6, 15.0))
    >>> df["reason"].iloc[0][:78], df["status"].iloc[0]
    ('the bodies of this ramp leave the clamp at +18.2 deg (the median of 5 photos),', 'ok')
    >>> _compare_given(df := df.assign(reason=""), df, np.full(6, 17.5), np.full(6, 15.0))
    >>> df["reason"].iloc[0]
    ''
    >>> _compare_given(df, df, np.full(6, 21.0), np.full(6, 15.0))
    >>> df["status"].iloc[0], df["reason"].iloc[0][:22]
    ('flagged', 'psi may be 6.0 deg off')
    >>> df = df.assign(reason="", status="ok")
    >>> _compare_given(df, df, np.full(6, 19.97), np.full(6, 15.0))
    >>> df["status"].iloc[0], df["reason"].iloc[0].split(", ")[1]
    ('ok', '+4.97 deg off the fixed_direction_deg given (+15.0)')
    """
    ok = np.isfinite(own) & np.isfinite(given) & (ramp["status"] != "failed").to_numpy()
    if ok.sum() < BASE_MIN_PHOTOS:
        return
    off = _wrap_deg(own[ok] - given[ok])
    median = float(np.median(off))
    spread = float(np.median(np.abs(off - median)))
    if abs(median) <= max(GIVEN_OFF_DEG, excused_deg) or spread > BASE_SPREAD_DEG:
        return
    screen = _screen_sign(ramp)
    stated = screen * float(np.median(given[ok]))
    # on screen, within -180..180 (a direction given as 90 for one hanging down at -97 read
    # "+262.6")
    leaves = float(_wrap_deg(np.array([stated + screen * median]))[0])
    seen = f"{leaves:+.1f} deg (the median of {int(ok.sum())} {_unit(ramp)})"
    fix = (
        "if the actuator sits turned in its clamp, give this ramp's rows their own "
        f"fixed_direction_deg in manifest.csv ({leaves:+.1f}), or leave the key out "
        "where the base is seen (photoset preview draws the one given along the base)"
    )
    # up to GIVEN_FLAG_DEG off, either may be the wrong one (a translucent body's own base reads
    # up to 2.7 deg off: a customer who fitted the clamp's direction to 0.05 deg was told to
    # give the bodies' own, 3.1 deg off the truth)
    # shown to 0.01 deg by the threshold, so that a '5.0 deg off' is never left ok unexplained
    # (customer 22 read '+5.0 deg off' on ok rows under the README's 'more than 5 deg: flagged')
    d = 2 if abs(abs(median) - GIVEN_FLAG_DEG) < 0.05 else 1
    note = (
        f"psi may be {abs(median):.{d}f} deg off: it is measured from the fixed_direction_deg "
        f"given ({stated:+.1f}), but the bodies of this ramp leave the clamp at {seen}, so {fix}"
        if abs(median) > GIVEN_FLAG_DEG
        else f"{NOTE_GIVEN_OFF} {seen}, {screen * median:+.{d}f} deg off the "
        f"fixed_direction_deg given ({stated:+.1f}), which psi is measured from (the bodies' "
        "own reading may be a few deg off where the base is faint: photoset preview draws the "
        "one given along the base; if it lies off the base, give the ramp's own in "
        "manifest.csv)"
    )
    rows = ramp.index
    out.loc[rows, "reason"] = [
        _join(r, note) for r in out.loc[rows, "reason"].fillna("").astype(str)
    ]
    if abs(median) > GIVEN_FLAG_DEG:
        out.loc[rows[(ramp["status"] == "ok").to_numpy()], "status"] = "flagged"


def _camera_turn(out: pd.DataFrame, ramp: pd.DataFrame) -> np.ndarray:
    """Each row's ``camera_turn_deg`` (:mod:`pipeline.camera_turn`), 0 where unknown; where
    the camera turned between the ramp's photos, a row whose turn is unknown is flagged (in
    place in ``out``): its psi may be off by as much.

    Examples
    --------
    >>> df = pd.DataFrame({"camera_turn_deg": [0.0, 2.5, np.nan], "reason": "", "status": "ok"})
    >>> _camera_turn(df, df).tolist(), df["status"].tolist()
    ([0.0, 2.5, 0.0], ['ok', 'ok', 'flagged'])
    """
    turn = pd.to_numeric(
        ramp.get("camera_turn_deg", pd.Series(0.0, index=ramp.index)), errors="coerce"
    ).to_numpy(float)
    known = np.isfinite(turn)
    unknown = ~known & (ramp["status"] != "failed").to_numpy()
    if unknown.any() and (np.abs(turn[known]) > 0).any():
        rows = ramp.index[unknown]
        most = float(np.max(np.abs(turn[known])))
        out.loc[rows, "status"] = "flagged"
        out.loc[rows, "reason"] = [
            _join(r, f"the camera turned between this ramp's photos (up to {most:.1f} deg) and "
                     "this photo could not be lined up with its first: psi may be off by as much "
                     "(a camera on a stand keeps every photo lined up)")
            for r in out.loc[rows, "reason"].fillna("").astype(str)
        ]
    return np.where(known, turn, 0.0)


def _turn_given(out: pd.DataFrame, ramp: pd.DataFrame, turn: np.ndarray, given: np.ndarray) -> None:
    """psi of the rows of ``ramp`` (in place in ``out``) measured from the
    ``fixed_direction_deg`` given as turned with the camera since the ramp's first photo: the
    body leaves the clamp that much further round in a turned photo (``camera_turn_deg`` says
    by how much: a note in the reason kept flagged rows from being trusted again, `_check_leg`).

    Examples
    --------
    >>> df = pd.DataFrame({"psi_deg": [100.0, 120.0], "reason": ["", ""], "status": "ok"})
    >>> _turn_given(df, df, np.array([0.0, 2.5]), np.array([0.0, 0.0]))
    >>> df["psi_deg"].tolist(), df["reason"].tolist()
    ([100.0, 117.5], ['', ''])
    """
    moved = (np.abs(turn) > 0) & np.isfinite(given) & (ramp["status"] != "failed").to_numpy()
    rows = ramp.index[moved]
    if not len(rows):
        return
    psi = out.loc[rows, "psi_deg"].to_numpy(float) - turn[moved]
    out.loc[rows, "psi_deg"] = psi
    if {"kappa_per_mm", "l0_mm"} <= set(out.columns):
        out.loc[rows, "kappa_per_mm"] = np.deg2rad(psi) / out.loc[rows, "l0_mm"].to_numpy(float)


def _share_run(
    out: pd.DataFrame,
    run: pd.DataFrame,
    first_base_deg: float | None,
    turn: np.ndarray,
    clamped: bool = False,
) -> None:
    """Measure the bodies of one run of a ramp (one setting of camera and clamp) from their
    shared base direction, in place in ``out``.

    ``first_base_deg``: the base direction of the ramp's first run, when this run comes after the
    setup moved (every photo of it says so).  ``turn``: each photo's camera turn since the
    ramp's first photo (:mod:`pipeline.camera_turn`): the shared direction is that much further
    round in it.
    """
    own = run["base_direction_deg"].to_numpy(float) - turn
    rows, n = run.index, len(own)
    # measured round their circular mean (round the first photo, one read half a turn off, a
    # hook, put the rest on both sides of +-180 deg and the median between them)
    ref = float(np.rad2deg(np.angle(np.mean(np.exp(1j * np.deg2rad(own))))))
    shared = round(float(ref + np.median(_wrap_deg(own - ref))), 9) + 0.0  # no "-0.0 deg"
    moved = _wrap_deg(own - shared)
    run_base = shared  # the run's direction, for the note (one outlying photo does not set it)
    scatter = float(np.median(np.abs(moved)))
    if n < BASE_MIN_PHOTOS or scatter > BASE_SPREAD_DEG:
        # too few to share, or they scatter (free strips, a clamp that let go): each its own
        shared, moved = float("nan"), np.zeros(n)
    reasons = out.loc[rows, "reason"].fillna("").astype(str).to_numpy()
    screen = _screen_sign(run)  # the notes' directions as on screen
    setup = (
        ""
        if first_base_deg is None
        else f"the base direction is {screen * _wrap_deg(np.array(run_base - first_base_deg)):+.0f}"
        " deg off "
        "the ramp's first photos from here on (the camera or the clamp moved?): psi is measured "
        "from these photos' own"
    )
    old = out.loc[rows, "psi_deg"].to_numpy(float)
    psi = old + moved
    off = np.abs(moved) > BASE_MISMATCH_DEG
    if np.isfinite(shared):
        out.loc[rows, "psi_deg"] = psi
        out.loc[rows, "base_direction_deg"] = shared + turn
        if {"kappa_per_mm", "l0_mm"} <= set(out.columns):
            out.loc[rows, "kappa_per_mm"] = np.deg2rad(psi) / out.loc[rows, "l0_mm"].to_numpy(float)
        out.loc[rows[off], "status"] = "flagged"
    out.loc[rows, "reason"] = [
        _join(
            before,
            setup,
            # the photo's overlay shows the psi of its own base
            f"psi {p:+.1f} deg against its ramp's base direction ({screen * shared:+.1f} deg, "
            f"the median of {n} {_unit(run)}; {o:+.1f} from its own, {screen * b:+.1f})"
            if abs(m) >= BASE_NOTE_DEG
            else "",
            f"the body leaves the fixed end {screen * m:+.0f} deg off its ramp's direction: a "
            "hook at the clamp, or fixed_end is off; check with photoset preview"
            if abs(m) > BASE_MISMATCH_DEG
            else "",
        )
        for before, p, o, b, m in zip(reasons, psi, old, own, moved, strict=True)
    ]
    if clamped and n >= BASE_MIN_PHOTOS and scatter > BASE_SPREAD_DEG:
        _flag_unsteady_base(out, rows, scatter)


def _flag_unsteady_base(out: pd.DataFrame, rows: pd.Index, scatter_deg: float) -> None:
    """Flag ``rows`` (in place in ``out``), bodies held by one clamp whose own base directions
    scatter by ``scatter_deg`` (median absolute deviation, over :data:`BASE_SPREAD_DEG`): each
    psi is measured from its own base, which may be that far off.

    One clamp holds every body of the ramp in one direction, so a scatter is the base's reading,
    not the bodies: customer 42's grey-blue body lit from one side, against its empty scene, lost
    its shaded side at the clamp as shadow in some photos, and its ramps' bases scattered by
    3.1-3.6 deg, from 77 to 104 (the clamp's 88): 17 of 37 ``ok`` rows more than 3 deg off, 6
    more than 5.  Over 15 other customer sets and the rendered ramps no clamped ramp's bases
    scattered by more than 3.

    Examples
    --------
    >>> df = pd.DataFrame({"status": ["ok", "failed"], "reason": ["", "unreadable image"]})
    >>> _flag_unsteady_base(df, df.index, 3.6)
    >>> df["status"].tolist(), df["reason"].iloc[0][:59]
    (['flagged', 'failed'], 'the bodies of this ramp leave its one fixed_end in directio')
    """
    why = (
        f"the bodies of this ramp leave its one fixed_end in directions that scatter by "
        f"{scatter_deg:.1f} deg (median absolute deviation; one clamp holds them in one): psi is "
        "measured from each body's own, which may be as far off. Give fixed_direction_deg, the "
        "clamp's direction; check with photoset preview where the base is read (a pale body's "
        "shaded side at the clamp taken for shadow or backdrop? Then measure without the empty "
        "scene too and compare)"
    )
    for ix in rows:
        if out.at[ix, "status"] == "failed":
            continue
        reason = out.at[ix, "reason"]
        out.at[ix, "reason"] = _join(why, reason if isinstance(reason, str) else "")
        out.at[ix, "status"] = "flagged"


def layer_lengths(measured: pd.DataFrame) -> np.ndarray:
    """The measured lengths of a ramp's photos as lengths of the line that does not stretch.

    A drawn line lies on the inextensible layer: its length is the same in every photo.  A body's
    centre line lies half the body's width (``width_px``) beside that layer, so it is shorter by
    ``width / 2 * psi`` (psi in rad) when the body bends towards its own side and longer when it
    bends the other way: over a ramp from +210 to -225 deg a body a tenth of its length wide
    changes its centre line's length by 40 %, which is no partial line.  Which side the layer is
    on is the actuator's, the same on every photo of the ramp; it is taken as the one (or no
    correction, a line) that makes the lengths most alike.

    Examples
    --------
    >>> psi = np.array([210.0, 90.0, -60.0, -220.0])
    >>> body = pd.DataFrame({"psi_deg": psi, "width_px": 60.0,
    ...                      "length_px": 900.0 - 30.0 * np.deg2rad(psi)})
    >>> np.round(layer_lengths(body), 1).tolist()
    [900.0, 900.0, 900.0, 900.0]
    >>> np.round(layer_lengths(body.assign(length_px=900.0)), 1).tolist()  # a drawn line
    [900.0, 900.0, 900.0, 900.0]

    Where every photo has a scale (``length_mm``), in mm: a photo of the ramp taken at another
    scale (a phone turned to portrait, its row given its own ``mm_per_px``) is no partial line.

    >>> scaled = body.assign(length_mm=0.3 * body["length_px"])
    >>> scaled.loc[1, ["length_px", "width_px"]] = scaled.loc[1, ["length_px", "width_px"]] / 2
    >>> np.round(layer_lengths(scaled), 1).tolist()
    [270.0, 270.0, 270.0, 270.0]
    """
    lengths = measured["length_px"].to_numpy(float)
    widths = measured["width_px"].to_numpy(float) if "width_px" in measured.columns else None
    if "length_mm" in measured.columns:
        lengths_mm = measured["length_mm"].to_numpy(float)
        if np.isfinite(lengths_mm).all() and (lengths > 0).all():
            widths = None if widths is None else widths * lengths_mm / lengths
            lengths = lengths_mm
    if widths is None:
        return lengths
    shift = 0.5 * widths * np.deg2rad(measured["psi_deg"].to_numpy(float))
    if not np.isfinite(shift).any():
        return lengths
    best, spread = lengths, np.inf
    for side in (0.0, 1.0, -1.0):
        candidate = lengths + side * np.nan_to_num(shift)
        finite = candidate[np.isfinite(candidate)]
        if finite.size < 3:
            return lengths
        med = float(np.median(finite))
        mad = float(np.median(np.abs(finite - med))) / max(abs(med), 1e-9)
        if mad < spread - 1e-9:
            best, spread = candidate, mad
    return best


def _same_pressure(leg: pd.DataFrame, others: pd.DataFrame) -> list[np.ndarray]:
    """psi of the ``others`` (another leg's photos) at each of ``leg``'s photos' pressures.

    Pressures within a quarter of the leg's median step are the same (a rig's measured pressure
    is not exactly the set point).

    >>> leg = pd.DataFrame({"pressure_kpa": [160.0, 80.0, 0.4], "psi_deg": [-220.0, -150.0, 208.0]})
    >>> others = pd.DataFrame({"pressure_kpa": [0.0, 80.0], "psi_deg": [210.0, -95.0]})
    >>> [a.tolist() for a in _same_pressure(leg, others)]
    [[], [-95.0], [210.0]]
    """
    pressure = leg["pressure_kpa"].to_numpy(float)
    steps = np.abs(np.diff(pressure))
    steps = steps[np.isfinite(steps) & (steps > 0)]
    if not steps.size or others.empty:
        return [np.empty(0)] * len(leg)
    near = 0.25 * float(np.median(steps))
    other_p, other_psi = others["pressure_kpa"].to_numpy(float), others["psi_deg"].to_numpy(float)
    return [other_psi[np.abs(other_p - p) <= near] for p in pressure]


def _allowed_in_leg(psi: np.ndarray, i: int, same_pressure: np.ndarray) -> tuple[float, str]:
    """(how far outside, what its neighbours allow, in words): photo ``i`` against its
    neighbours' range, or for an end photo against the nearest ``ok`` photo of another leg at its
    pressure, if that is nearer.

    Examples
    --------
    >>> _allowed_in_leg(np.array([0.0, 30.0, 60.0]), 1, np.array([]))[1]
    'where its neighbours allow +0 to +60'
    >>> _allowed_in_leg(np.array([300.0, 192.0, 546.0]), 0, np.array([]))[1]
    "at its leg's start, back past its neighbour's +192 (the leg goes +192 -> +546)"
    >>> _allowed_in_leg(np.array([100.0, 100.0, 100.0, 140.0]), 3, np.array([]))[1]
    "at its leg's end, away from its neighbour's +100 (the leg goes +100 -> +100)"
    >>> _allowed_in_leg(np.array([0.0, 10.0, 20.0, 200.0]), 3, np.array([]))[1]
    "at its leg's end, more than 4 steps beyond its neighbour's +20 (the leg goes +10 -> +20)"
    """
    lo, hi = _allowed(psi, i)
    off = _outside(psi[i], lo, hi)
    if i in (0, len(psi) - 1) and same_pressure.size:
        off = min(off, float(np.min(np.abs(same_pressure - psi[i]))))
    if 0 < i < len(psi) - 1:
        return off, f"where its neighbours allow {lo:+.0f} to {hi:+.0f}"
    # an end: its range runs from its neighbour out by END_STEPS of the leg's next step, which
    # as two numbers read like nonsense (customer 40: "allow +192 to +1608")
    j, k = (1, 2) if i == 0 else (len(psi) - 2, len(psi) - 3)
    end = "start" if i == 0 else "end"
    runs = f"{psi[j]:+.0f} -> {psi[k]:+.0f}" if i == 0 else f"{psi[k]:+.0f} -> {psi[j]:+.0f}"
    back = (psi[i] - psi[j]) * (psi[j] - psi[k]) < 0  # on the wrong side of its neighbour
    flat = abs(psi[j] - psi[k]) < 1.0  # steps of nothing: "4 steps beyond" says nothing
    beyond = "away from" if flat else f"more than {END_STEPS:g} steps beyond"
    where = "back past" if back else beyond
    return off, f"at its leg's {end}, {where} its neighbour's {psi[j]:+.0f} (the leg goes {runs})"


def _check_leg(
    leg: pd.DataFrame,
    position: dict,
    status: np.ndarray,
    reason: np.ndarray,
    same_pressure: list[np.ndarray],
) -> None:
    """Flag the leg's outliers one at a time (worst first, then check again without it);
    re-trust."""
    keep = list(range(len(leg)))
    psi_all = leg["psi_deg"].to_numpy(float)
    doubtful = (leg["status"] != "ok").to_numpy()  # flagged on its own, before the ramp
    while len(keep) >= 3:
        psi = psi_all[keep]
        # a photo ok on its own is judged among the photos ok on their own (its nearest such
        # neighbours): two doubtful photos read wrong alike would otherwise outvote a right one
        trusted = [j for j in range(len(keep)) if not doubtful[keep[j]]]
        rank = {j: r for r, j in enumerate(trusted)} if len(trusted) >= 3 else {}
        psi_trusted = psi[trusted]
        breaking = []
        for i in range(len(keep)):
            if i in rank:
                off, allowed = _allowed_in_leg(psi_trusted, rank[i], same_pressure[keep[i]])
            else:
                off, allowed = _allowed_in_leg(psi, i, same_pressure[keep[i]])
            if off > SLACK_DEG:
                breaking.append((off, i, allowed))
        if not breaking:
            break
        # a photo already doubtful on its own is blamed before one that is not (two photos that
        # disagree break each other's range alike); then the worst
        _, i, allowed = max(
            [b for b in breaking if doubtful[keep[b[1]]]] or breaking
        )
        k = position[leg.index[keep[i]]]
        status[k] = "flagged"
        reason[k] = _join(f"breaks its ramp: psi {psi[i]:+.0f} deg {allowed}", reason[k])
        del keep[i]
    if len(keep) < 3:
        return
    psi = psi_all[keep]
    for i in range(1, len(keep) - 1):
        k = position[leg.index[keep[i]]]
        off = _outside(psi[i], *_allowed(psi, i))
        neighbours = (position[leg.index[keep[i - 1]]], position[leg.index[keep[i + 1]]])
        if (status[k] == "flagged" and off <= AGREE_DEG and _is_cosmetic(reason[k])
                and all(status[n] == "ok" for n in neighbours)):
            status[k] = "ok"
            reason[k] = (
                f"psi agrees with its ramp (between its neighbours) (was flagged: {reason[k]})"
            )
