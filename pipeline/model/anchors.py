"""What Section III of the paper reports, as data: the figures the model is judged on.

Two are results of the paper's own model (SS50 straight at 674 kPa, SS40 at -psi0 at 378 kPa):
the selection protocol lets them fix one physical parameter (l0).  The others are measurements
(Section III.A): they are scored out of sample and choose nothing.
"""

from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True)
class Anchor:
    """One figure the paper reports, to compare the model against.

    Attributes
    ----------
    group : str
        ``"model"`` (a result of the paper's model) or ``"measured"`` (Section III.A data).
    material : str
    kind : str
        ``"pressure"``: the paper gives the pressure (kPa) at angle ``at`` (deg); ``"psi"``: the
        angle (deg) at pressure ``at`` (kPa) on the loading branch.
    at : float
    paper : float
        The paper's value (kPa or deg).
    text : str
        What the paper says, in a few words.
    range_deg : float or None
        For ``"psi"`` anchors, the range of motion psi0 - psi the paper states for that pressure.
    """

    group: str
    material: str
    kind: str
    at: float
    paper: float
    text: str
    range_deg: float | None = None


#: Section III, model results first (the +-5 % bar and the l0 fit use only these two)
ANCHORS: tuple[Anchor, ...] = (
    Anchor("model", "SS50", "pressure", 0.0, 674.0, "SS50 reaches psi = 0 (model)"),
    Anchor("model", "SS40", "pressure", -210.0, 378.0, "SS40 reaches psi = -psi0 (model)"),
    Anchor("measured", "DS20", "pressure", 0.0, 65.0, "DS20 reaches psi = 0"),
    Anchor("measured", "DS30", "pressure", 0.0, 105.0, "DS30 reaches psi = 0"),
    Anchor("measured", "SS40", "pressure", 0.0, 215.0, "SS40 reaches psi = 0"),
    # angles: psi0 - the range of motion the paper states (436 deg in 112 kPa -> -226 deg)
    Anchor("measured", "DS20", "psi", 112.0, -226.0, "DS20 at 112 kPa", 436.0),
    Anchor("measured", "DS30", "psi", 175.0, -214.0, "DS30 at 175 kPa", 424.0),
    Anchor("measured", "SS40", "psi", 255.0, -55.0, "SS40 at 255 kPa", 265.0),
    Anchor("measured", "SS50", "psi", 255.0, 146.0, "SS50 at 255 kPa", 64.0),
)

MODEL_ANCHORS: tuple[Anchor, ...] = tuple(a for a in ANCHORS if a.group == "model")

#: RMS (deg) between the paper's model and its mean measured curves; needs measured data
PAPER_RMS_DEG: dict[str, float] = {"DS20": 74.0, "DS30": 68.0, "SS40": 32.0, "SS50": 4.5}

#: l0 range implied by the grasping section (9 cm object smaller than the rest circle, 15 cm
#: object reached by uncurling): pi*d/l0 = psi0 for d = 9..15 cm
L0_PLAUSIBLE_MM: tuple[float, float] = (170.0, 270.0)

#: the bar on the two model results (percent)
MODEL_BAR_PCT = 5.0
