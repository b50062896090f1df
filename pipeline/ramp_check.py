"""Ramp consistency: along one pressure ramp psi changes smoothly, so a photo that breaks the trend
of its neighbours is doubtful, and one that follows it is trustworthy.

After the photos of a set are measured, each ramp (material, actuator, trial) is split into its
legs (``up`` then ``down``, in step order) and every measured photo is compared with what its
neighbours on the same leg predict (linear in pressure between the previous and the next photo;
extrapolated from the two nearest at the ends of a leg):

- a photo farther from that prediction than :data:`JUMP_FACTOR` times the leg's own typical
  step-to-step change (and at least :data:`MIN_JUMP_DEG`) is ``flagged``, with the reason
  ("breaks its ramp: ..."): a sign flip, a ring read the wrong way round, a piece of halo;
- a photo whose measured line length is far from the ramp's median is ``flagged`` (a partial
  line);
- a photo ``flagged`` only for a cosmetic reason (line partly hidden, touching the border) whose
  psi agrees with its ramp within :data:`AGREE_DEG` and whose neighbours are ``ok`` is ``ok`` again,
  the reason saying why.

Nothing is changed for a leg of fewer than 3 measured photos.

Examples
--------
>>> import pandas as pd
>>> df = pd.DataFrame({"image": list("abcde"), "psi_deg": [200.0, 150.0, -210.0, 50.0, 0.0],
...     "status": ["ok"] * 5, "reason": [""] * 5, "pressure_kpa": [0, 10, 20, 30, 40],
...     "direction": ["up"] * 5, "material": ["DS20"] * 5, "actuator": ["A1"] * 5, "trial": ["1"] * 5})
>>> out = check_ramps(df)
>>> out["status"].tolist()
['ok', 'ok', 'flagged', 'ok', 'ok']
>>> out["reason"].iloc[2].startswith("breaks its ramp")
True
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from pipeline.measure.quality import COSMETIC_FLAGS

#: a photo is off its ramp beyond this many typical steps of its leg (the median step-to-step
#: change, leaving out the photo's own two steps) ...
JUMP_FACTOR = 4.0
#: ... and beyond this many degrees in any case
MIN_JUMP_DEG = 12.0
#: a cosmetically flagged photo within this of its ramp's prediction (deg) is trusted again
AGREE_DEG = 3.0
#: measured length outside [LENGTH_LOW, LENGTH_HIGH] x the ramp's median -> partial line
LENGTH_LOW, LENGTH_HIGH = 0.85, 1.15
RAMP_KEYS: tuple[str, ...] = ("material", "actuator", "trial")


def _predict(p: np.ndarray, psi: np.ndarray, i: int) -> tuple[float, bool]:
    """psi at photo ``i`` from its neighbours on the leg (interpolated inside, extrapolated at the ends)."""
    n = len(p)
    if 0 < i < n - 1:
        j, k, inner = i - 1, i + 1, True
    elif i == 0:
        j, k, inner = 1, 2, False
    else:
        j, k, inner = n - 2, n - 3, False
    if p[k] == p[j]:
        return float(0.5 * (psi[j] + psi[k])), inner
    return float(psi[j] + (psi[k] - psi[j]) * (p[i] - p[j]) / (p[k] - p[j])), inner


def _is_cosmetic(reason: str) -> bool:
    parts = [r.strip() for r in str(reason).split(";") if r.strip()]
    return bool(parts) and all(any(r.startswith(c) for c in COSMETIC_FLAGS) for r in parts)


def _join(*parts: str) -> str:
    return "; ".join(p for p in parts if p)


def check_ramps(angles: pd.DataFrame) -> pd.DataFrame:
    """Flag photos that break their ramp's trend and trust cosmetically flagged ones that follow it.

    Parameters
    ----------
    angles : pandas.DataFrame
        The angles.csv table (``psi_deg``, ``status``, ``reason``, ``pressure_kpa``,
        ``direction``, the ramp keys, optionally ``step`` and ``length_px``).

    Returns
    -------
    pandas.DataFrame
        A copy with ``status`` and ``reason`` updated (rows in the same order).
    """
    out = angles.copy()
    if out.empty or not set(RAMP_KEYS) <= set(out.columns):
        return out
    status, reason = out["status"].astype(str).to_numpy(copy=True), out["reason"].fillna("").astype(str).to_numpy(copy=True)
    order = out.sort_values("step", kind="stable").index if "step" in out.columns else out.index
    position = {ix: k for k, ix in enumerate(out.index)}
    for _, ramp in out.loc[order].groupby(list(RAMP_KEYS), sort=False):
        measured = ramp[ramp["status"] != "failed"]
        if "length_px" in measured.columns and len(measured) >= 3:
            lengths = measured["length_px"].to_numpy(float)
            med = float(np.nanmedian(lengths)) if np.isfinite(lengths).any() else np.nan
            for ix, length in zip(measured.index, lengths):
                if np.isfinite(med) and np.isfinite(length) and not LENGTH_LOW <= length / med <= LENGTH_HIGH:
                    k = position[ix]
                    status[k] = "flagged"
                    reason[k] = _join(reason[k], f"line length {100 * length / med:.0f}% of its ramp's median: part of it may be missing or extra")
        legs = (measured["direction"] != measured["direction"].shift()).cumsum()
        for _, leg in measured.groupby(legs, sort=False):
            _check_leg(leg, position, status, reason)
    out["status"], out["reason"] = status, reason
    return out


def _check_leg(leg: pd.DataFrame, position: dict, status: np.ndarray, reason: np.ndarray) -> None:
    """Flag the leg's outliers one at a time (worst first, then re-predict without it); re-trust."""
    keep = list(range(len(leg)))
    p_all = leg["pressure_kpa"].to_numpy(float)
    psi_all = leg["psi_deg"].to_numpy(float)
    while len(keep) >= 3:
        p, psi = p_all[keep], psi_all[keep]
        steps = np.abs(np.diff(psi))
        scores = []
        for i in range(len(keep)):
            # the leg's typical step, without the two steps that touch this photo
            others = np.delete(steps, [j for j in (i - 1, i) if 0 <= j < len(steps)])
            typical = float(np.median(others)) if others.size else float(np.median(steps))
            pred, inner = _predict(p, psi, i)
            limit = max(JUMP_FACTOR * typical, MIN_JUMP_DEG) * (1.0 if inner else 1.5)
            scores.append((abs(psi[i] - pred) / limit, i, pred))
        worst, i, pred = max(scores)
        if worst <= 1.0:
            break
        k = position[leg.index[keep[i]]]
        status[k] = "flagged"
        reason[k] = _join(f"breaks its ramp: psi {psi[i]:+.0f} deg where its neighbours give {pred:+.0f}", reason[k])
        del keep[i]
    if len(keep) < 3:
        return
    p, psi = p_all[keep], psi_all[keep]
    for i in range(1, len(keep) - 1):
        k = position[leg.index[keep[i]]]
        pred, _ = _predict(p, psi, i)
        neighbours = (position[leg.index[keep[i - 1]]], position[leg.index[keep[i + 1]]])
        if (status[k] == "flagged" and abs(psi[i] - pred) <= AGREE_DEG and _is_cosmetic(reason[k])
                and all(status[n] == "ok" for n in neighbours)):
            status[k] = "ok"
            reason[k] = f"psi agrees with its ramp within {abs(psi[i] - pred):.1f} deg (was flagged: {reason[k]})"
