"""Ramp consistency: along one pressure ramp psi changes smoothly, so a photo that breaks the trend
of its neighbours is doubtful, and one that follows it is trustworthy.

After the photos of a set are measured, each ramp (material, actuator, trial) is split into its
legs (``up`` then ``down``, in step order).  On a leg psi is monotone in pressure, however fast it
changes (DS20 passes psi = 0 at more than 100 deg per 10 kPa step), so every measured photo
should lie between its two neighbours on the leg, and an end photo no farther beyond its
neighbour than :data:`END_STEPS` times the neighbouring step (a leg may end in its fastest part):

- a photo more than :data:`SLACK_DEG` outside that range is ``flagged``, with the reason
  ("breaks its ramp: ..."): a sign flip, a ring read the wrong way round, a piece of halo.
  The worst photo goes first (one already flagged on its own before one that is not) and the
  leg is checked again without it, so one wrong photo never drags its neighbours down;
- a photo whose measured line length is far from the ramp's median is ``flagged`` (a partial
  line); a body's centre line, half the body's width beside the layer that does not stretch, is
  first brought to that layer's length (:func:`layer_lengths`);
- a photo ``flagged`` only for a cosmetic reason (line partly hidden, touching the border) whose
  psi lies between its ``ok`` neighbours (within :data:`AGREE_DEG`) is ``ok`` again, the reason
  saying why.

Nothing is changed for a leg of fewer than 3 measured photos.

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

import numpy as np
import pandas as pd

from pipeline.measure.quality import COSMETIC_FLAGS

#: a photo this far (deg) outside the range its neighbours allow breaks its ramp
SLACK_DEG = 12.0
#: an end photo of a leg may lie this many neighbouring steps beyond its neighbour
END_STEPS = 4.0
#: a cosmetically flagged photo within this of its ramp's prediction (deg) is trusted again
AGREE_DEG = 3.0
#: measured length outside [LENGTH_LOW, LENGTH_HIGH] x the ramp's median -> partial line
LENGTH_LOW, LENGTH_HIGH = 0.85, 1.15
RAMP_KEYS: tuple[str, ...] = ("material", "actuator", "trial")


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
    status, reason = (
        out["status"].astype(str).to_numpy(copy=True),
        out["reason"].fillna("").astype(str).to_numpy(copy=True),
    )
    keys = [c for c in ("step", "time_s") if c in out.columns]  # frames of a video: over time
    order = out.sort_values(keys, kind="stable").index if keys else out.index
    position = {ix: k for k, ix in enumerate(out.index)}
    for _, ramp in out.loc[order].groupby(list(RAMP_KEYS), sort=False):
        measured = ramp[ramp["status"] != "failed"]
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
        legs = (measured["direction"] != measured["direction"].shift()).cumsum()
        for _, leg in measured.groupby(legs, sort=False):
            _check_leg(leg, position, status, reason)
    out["status"], out["reason"] = status, reason
    return out


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
    """
    lengths = measured["length_px"].to_numpy(float)
    if "width_px" not in measured.columns:
        return lengths
    shift = 0.5 * measured["width_px"].to_numpy(float) * np.deg2rad(
        measured["psi_deg"].to_numpy(float)
    )
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


def _check_leg(leg: pd.DataFrame, position: dict, status: np.ndarray, reason: np.ndarray) -> None:
    """Flag the leg's outliers one at a time (worst first, then check again without it);
    re-trust."""
    keep = list(range(len(leg)))
    psi_all = leg["psi_deg"].to_numpy(float)
    doubtful = (leg["status"] != "ok").to_numpy()  # flagged on its own, before the ramp
    while len(keep) >= 3:
        psi = psi_all[keep]
        breaking = [
            (_outside(psi[i], *_allowed(psi, i)), i, *_allowed(psi, i)) for i in range(len(keep))
        ]
        breaking = [b for b in breaking if b[0] > SLACK_DEG]
        if not breaking:
            break
        # a photo already doubtful on its own is blamed before one that is not (two photos that
        # disagree break each other's range alike); then the worst
        _, i, lo, hi = max(
            [b for b in breaking if doubtful[keep[b[1]]]] or breaking
        )
        k = position[leg.index[keep[i]]]
        status[k] = "flagged"
        reason[k] = _join(
            f"breaks its ramp: psi {psi[i]:+.0f} deg where its neighbours allow {lo:+.0f} to "
            f"{hi:+.0f}",
            reason[k],
        )
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
