"""A sealed end left out, or given shorter than the photos show: rows whose |psi| reads high.

psi is read where the bending stops, ``sealed_end_mm`` before the tip (cap included).  Left
out, or given short, the free end's tangent is read on the straight sealed end, fitted over a
window that reaches back into the bending part, and |psi| reads high: customer 37's actuator
(8 mm sealed end and cap) read 36 rows ``ok`` 5-7 deg off without it and 26 with ``4``.  A
capped body's centre line shows its straight end where it is well bent
(:func:`pipeline.measure.estimators.straight_end`; ``straight_end_mm`` in angles.csv, the tip's
face included): over an actuator's photos its median is the sealed end the photos show (7.9 mm
for customer 37's 8, 7.7 for customer 33's 7, 6.8 for customer 34's 6, 12.2 for customer 36's
12.4, 10.4 for customer 38's 10).  Where that is longer than the one given by more than
:data:`SEALED_END_MARGIN_MM` (and :data:`SEALED_END_MARGIN_SHARE` of itself), over enough of
the actuator's photos (:data:`SEALED_END_MIN_PHOTOS`, :data:`SEALED_END_MIN_SHARE`), every row
it reads |psi| high by :data:`SEALED_END_FLAG_DEG` or more is flagged, naming the length the
photos show.  Where it is longer by less, but by more than :data:`SEALED_END_NOTE_MM` and
:data:`SEALED_END_NOTE_SHARE` of itself, a row that may
read |psi| :data:`SEALED_END_NOTE_DEG` high or more keeps its status with a note
(:data:`~pipeline.measure.quality.NOTE_SEALED_END_LONGER`) naming both lengths.
"""

from __future__ import annotations

import numpy as np
import pandas as pd
from scipy.stats import theilslopes

from pipeline.measure.quality import NOTE_NO_SEALED_END, NOTE_SEALED_END_LONGER

#: photos of one actuator whose straight end shows, at least, for a verdict ...
SEALED_END_MIN_PHOTOS = 3
#: ... and more than this share of its photos bent 90 deg or more (a few stray ones are no
#: verdict: customer 33's clear body with its empty scene read 10 mm for its 7 in 2 photos of
#: 14 per actuator; customer 35's video shows it in 18 % of such frames, customer 37 in 95 %)
SEALED_END_MIN_SHARE = 0.15
#: ... counting only photos bent at least this much (deg): a straight end on a body hardly bent
#: is its centre line's wander (customer 55's straight photos of a body with one faint side
#: read 26 mm for a 4 mm sealed end, and the advice "about 26 mm" left 20 of 20 rows flagged)
SEALED_END_MIN_PSI_DEG = 45.0
#: ... and agreeing among themselves: their median absolute deviation at most the larger of
#: SEALED_END_MARGIN_MM and this share of their median (customer 49's clear body without its
#: empty scene showed 5.9, 13.5 and 22.7 mm for its 6, two of them tips not seen whole, and the
#: advice to give 13 put 10 of 15 frames ok 13-20 deg low)
SEALED_END_SPREAD_SHARE = 0.25
#: where they scatter so, a photo whose own straight end is this many times the one given, and
#: SEALED_END_STRAY_MM longer, is flagged alone: its tip is likely not seen whole (customer 49's
#: 13.5 mm for 6 read psi 7 deg low, ok; a 2 mm end given without its dome shows 4.3)
SEALED_END_STRAY_FACTOR, SEALED_END_STRAY_MM = 2.0, 4.0
#: the straight end the photos show must exceed the one given by more than this (mm), and by
#: more than SEALED_END_MARGIN_SHARE of itself (without mm_per_px the scale is the bent body's
#: length against l0_mm, a few % off: a 25 mm end read 27.9) ...
SEALED_END_MARGIN_MM = 2.0
SEALED_END_MARGIN_SHARE = 0.15
#: ... and a row is flagged where that reads |psi| this much high or more (deg): about half the
#: turning over the stretch missed, ``0.5 * |psi| / l0_mm * (shown - given)`` (customer 37, 4 mm
#: short at psi near 220: 3-7 deg)
SEALED_END_FLAG_DEG = 2.5
#: a straight end shown longer than the one given by more than this (mm), though not by the
#: margins above, is noted on each row where it may read |psi| SEALED_END_NOTE_DEG high or more,
#: the turning over the whole stretch missed (``|psi| / l0_mm * (shown - given)``): customer 45
#: gave its caps without their 2 mm domes, the photos showed 1.6-2.7 mm more, and 7 rows read
#: 3.1-4.4 deg high, ok, their reasons empty
SEALED_END_NOTE_MM = 1.0
SEALED_END_NOTE_DEG = 2.0
#: ... and by more than this share of itself: a right 25 mm end read 27.9 without mm_per_px, a
#: right 10 mm one 11.2 (customer 45's read 1.6-2.7 mm, 14-21 %, over its 10 and 11)
SEALED_END_NOTE_SHARE = 0.12


def check_sealed_ends(angles: pd.DataFrame) -> pd.DataFrame:
    """Flag the rows of each actuator whose sealed end is left out or given shorter than its
    photos show (see the module docstring).

    Parameters
    ----------
    angles : pandas.DataFrame
        angles.csv rows of one photo set (or video set): ``material``, ``actuator``,
        ``psi_deg``, ``l0_mm``, ``status``, ``reason``, ``sealed_end_mm`` (the one given, NaN
        when none) and ``straight_end_mm``; a table without the last two is returned as it is.

    Returns
    -------
    pandas.DataFrame
        A copy, the rows reading high ``flagged`` with the cause first in ``reason``.

    Examples
    --------
    >>> rows = pd.DataFrame({"material": "M", "actuator": "A", "psi_deg": [30.0, 150, 200, 210],
    ...     "l0_mm": 90.0, "status": "ok", "reason": "", "sealed_end_mm": 4.0,
    ...     "straight_end_mm": [np.nan, 7.8, 8.0, 7.9]})
    >>> out = check_sealed_ends(rows)
    >>> out["status"].tolist()
    ['ok', 'flagged', 'flagged', 'flagged']
    >>> print(out["reason"][2])  # doctest: +NORMALIZE_WHITESPACE
    sealed end shorter than the photos show: sealed_end_mm is 4 but this actuator's last 8 mm stay
    straight in 3 of its photos, so |psi| reads high (about 4 deg here): measure it again from
    where the chamber ends to the tip, cap included (about 8 mm)
    >>> check_sealed_ends(rows.assign(sealed_end_mm=7.5))["status"].tolist()
    ['ok', 'ok', 'ok', 'ok']
    >>> noted = check_sealed_ends(rows.assign(sealed_end_mm=6.5))
    >>> noted["status"].tolist()
    ['ok', 'ok', 'ok', 'ok']
    >>> print(noted["reason"][3])  # doctest: +NORMALIZE_WHITESPACE
    the photos show a longer straight end: this actuator's last 7.9 mm stay straight in 3 of its
    photos, 1.4 mm more than sealed_end_mm (6.5): if its sealed end is that long (from where the
    chamber ends to the very tip, cap and any rounded dome included), |psi| reads up to about 3
    deg high here
    """
    if not {"straight_end_mm", "sealed_end_mm"} <= set(angles.columns):
        return angles
    out = angles.copy()
    seen = pd.to_numeric(out["straight_end_mm"], errors="coerce")
    given = pd.to_numeric(out["sealed_end_mm"], errors="coerce")
    psi_abs = pd.to_numeric(out["psi_deg"], errors="coerce").abs()
    high = 0.5 * psi_abs / out["l0_mm"]  # deg read high per mm of the end missed
    past = pd.to_numeric(out.get("past_l0_mm", pd.Series(np.nan, out.index)), errors="coerce")
    unit = "frames" if "frame" in out.columns and out["frame"].notna().any() else "photos"
    bent_seen = seen.where(psi_abs >= SEALED_END_MIN_PSI_DEG)
    for _, g in out[out["status"] != "failed"].groupby(["material", "actuator"], sort=False):
        shown = bent_seen[g.index].dropna()
        bent = int((psi_abs[g.index] >= 90.0).sum())
        own, witness, scale_mm = bent_seen, "stay straight", 0.0
        if len(shown) < SEALED_END_MIN_PHOTOS or len(shown) <= SEALED_END_MIN_SHARE * bent:
            # no straight end shows (one shorter than about 3/64 of the body, or a cap wider
            # than the body, whose step hides it): with the scale given, the body's length does
            # (customer 50's 5 mm cap on a 90 mm body, left out: 8 rows ok 5-8 deg off, no
            # straight end seen), of the rows measured ok (a flagged one's may be part of it: a
            # clear body's first look, its tips lost, read "-33 mm past l0_mm"), to within the
            # scale's own error times the body's length
            ok = g[g["status"] == "ok"]
            own = end_past_l0_mm(past[ok.index], ok["psi_deg"]).reindex(g.index)
            shown = own.dropna()
            if len(shown) < SEALED_END_MIN_PHOTOS or shown.median() <= 0.0:
                continue  # too few, or short of l0_mm: not seen whole, or the scale is off
            witness = (
                "run past l0_mm (its length at mm_per_px, less its centre line's stretch as it "
                "bends)"
            )
            scale_mm = PAST_L0_SCALE_SHARE * float(g["l0_mm"].median() + shown.median())
        spread = float((shown - shown.median()).abs().median())
        if spread > max(SEALED_END_MARGIN_MM, SEALED_END_SPREAD_SHARE * float(shown.median())):
            if own is bent_seen:
                _flag_strays(out, g.index, own, given)
            continue
        shown_mm = float(shown.median())
        short_mm = shown_mm - given[g.index].fillna(0.0)
        margin_mm = max(SEALED_END_MARGIN_MM, SEALED_END_MARGIN_SHARE * shown_mm, scale_mm)
        reads_high = (short_mm > margin_mm) & (
            high[g.index] * short_mm >= SEALED_END_FLAG_DEG
        )
        noted = (
            ~reads_high
            & (short_mm > max(SEALED_END_NOTE_MM, SEALED_END_NOTE_SHARE * shown_mm, scale_mm))
            & given[g.index].notna()
            & (2.0 * high[g.index] * short_mm >= SEALED_END_NOTE_DEG)
        )
        for i in g.index[noted]:
            note = (
                f"{NOTE_SEALED_END_LONGER}: this actuator's last {shown_mm:.1f} mm {witness} "
                f"in {len(shown)} of its {unit}, {short_mm[i]:.1f} mm more than sealed_end_mm "
                f"({given[i]:g}): if its sealed end is that long (from where the chamber ends to "
                "the very tip, cap and any rounded dome included), |psi| reads up to about "
                f"{2.0 * high[i] * short_mm[i]:.0f} deg high here"
            )
            reason = out.at[i, "reason"]
            out.at[i, "reason"] = "; ".join(
                c for c in (str(reason) if pd.notna(reason) else "", note) if c
            )
        for i in g.index[reads_high]:
            read_deg = float(high[i] * short_mm[i])
            cause = (
                f"sealed end not given, and this actuator's last {shown_mm:.0f} mm {witness} "
                f"in {len(shown)} of its {unit}: |psi| reads high (about {read_deg:.0f} deg "
                "here): give sealed_end_mm, from where the chamber ends to the tip, cap included "
                f"(about {shown_mm:.0f} mm)"
                if np.isnan(given[i])
                else f"sealed end shorter than the photos show: sealed_end_mm is {given[i]:g} but "
                f"this actuator's last {shown_mm:.0f} mm {witness} in {len(shown)} of its "
                f"{unit}, so |psi| reads high (about {read_deg:.0f} deg here): measure it again "
                "from where the chamber ends to the tip, cap included "
                f"(about {shown_mm:.0f} mm)"
            ) + ("" if own is bent_seen else ", or check l0_mm and mm_per_px")
            # the note that a sealed end left out may read |psi| high says it less exactly
            reason = out.at[i, "reason"]
            before = [
                c
                for c in (str(reason) if pd.notna(reason) else "").split("; ")
                if c and not c.startswith(NOTE_NO_SEALED_END)
            ]
            out.at[i, "status"] = "flagged"
            out.at[i, "reason"] = "; ".join([cause, *before])
    return out


#: an actuator's photos span at least this range of psi (deg) for its centre line's stretch as it
#: bends to be told from the end that does not bend (:func:`end_past_l0_mm`), and one of them is
#: bent this little or less (the end is read at psi 0: from a ramp over 120-210 deg alone, 13 mm
#: for 10)
PAST_L0_SPAN_DEG, PAST_L0_NEAR_DEG = 60.0, 60.0
#: the body's length, and so the end read from it, is only as good as mm_per_px and l0_mm: the
#: end shown must exceed the one given by this share of the body's length too (the review's
#: right 10 mm end on a 255 mm body read 16 at a scale 2 % off, and 19 at 3 %)
PAST_L0_SCALE_SHARE = 0.025


def end_past_l0_mm(past_l0_mm: pd.Series, psi_deg: pd.Series) -> pd.Series:
    """Each photo's end that does not bend (mm), from how far its body runs past ``l0_mm``.

    A body's centre line lies beside the layer that does not stretch, so it is ``l0_mm`` plus its
    distance from that layer times psi (rad) long, plus the end that does not bend: over an
    actuator's photos ``past_l0_mm`` is a straight line in psi, and where psi is 0 it is that
    end.  The slope is fitted over the photos (Theil-Sen: robust to a few); each photo's own
    reading is its ``past_l0_mm`` less the slope times its psi.  All NaN where fewer than
    :data:`SEALED_END_MIN_PHOTOS` photos have one, their psi spans less than
    :data:`PAST_L0_SPAN_DEG` or none is bent :data:`PAST_L0_NEAR_DEG` or less.

    Examples
    --------
    >>> psi = pd.Series([0.0, 60.0, 120.0, 180.0])  # a 5 mm end, its centre line 6 mm off
    >>> past = 5.0 + 6.0 * np.deg2rad(psi)
    >>> end_past_l0_mm(past, psi).round(2).tolist()
    [5.0, 5.0, 5.0, 5.0]
    >>> end_past_l0_mm(past[:2], psi[:2]).isna().all()
    np.True_
    """
    psi = pd.to_numeric(psi_deg, errors="coerce")
    have = past_l0_mm.notna() & psi.notna()
    if (
        have.sum() < SEALED_END_MIN_PHOTOS
        or np.ptp(psi[have]) < PAST_L0_SPAN_DEG
        or psi[have].abs().min() > PAST_L0_NEAR_DEG
    ):
        return pd.Series(np.nan, index=past_l0_mm.index)
    # a robust slope: one photo whose tip is hidden does not tilt it
    slope = float(theilslopes(past_l0_mm[have], np.deg2rad(psi[have]))[0])
    return past_l0_mm - slope * np.deg2rad(psi)


def _flag_strays(out: pd.DataFrame, rows: pd.Index, seen: pd.Series, given: pd.Series) -> None:
    """Flag (in place in ``out``) each of ``rows`` whose own straight end (``seen``, mm) is
    :data:`SEALED_END_STRAY_FACTOR` times the sealed end given (``given``) or more, and
    :data:`SEALED_END_STRAY_MM` longer: where the straight ends of its actuator's photos
    scatter, such a photo's tip is likely not seen whole.

    Examples
    --------
    >>> out = pd.DataFrame({"status": "ok", "reason": ""}, index=range(3))
    >>> _flag_strays(out, out.index, pd.Series([5.9, 13.5, np.nan]), pd.Series(6.0, index=range(3)))
    >>> out["status"].tolist()
    ['ok', 'flagged', 'ok']
    """
    stray = (seen[rows] >= SEALED_END_STRAY_FACTOR * given[rows]) & (
        seen[rows] - given[rows] >= SEALED_END_STRAY_MM
    )
    shown = seen[rows].dropna()
    for i in rows[stray.to_numpy()]:
        cause = (
            f"this photo's last {seen[i]:.1f} mm stay straight, twice sealed_end_mm "
            f"({given[i]:g}) or more, where its actuator's photos show straight ends that "
            f"scatter ({shown.min():.1f} to {shown.max():.1f} mm): its tip may not be seen whole "
            "(a clear or faint tip: an empty scene, background, helps), so psi may be off; "
            "check with photoset preview"
        )
        reason = out.at[i, "reason"]
        out.at[i, "status"] = "flagged"
        out.at[i, "reason"] = "; ".join(
            c for c in (cause, str(reason) if pd.notna(reason) else "") if c
        )
