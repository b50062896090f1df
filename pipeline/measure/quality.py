"""Quality status of one measurement: ``ok``, ``flagged`` (with reasons) or ``failed``.

Never a silent wrong number: whatever the estimator returns, a row is ``flagged`` when

- the line touches the image border (it may continue outside the photo);
- the line is partly hidden (measured length < 93 % of ``l0`` when ``mm_per_px`` is known) or
  longer than ``l0`` by more than 7 % (wrong scale or extra marks joined to the line);
- several candidate lines were found;
- the contrast between line and surroundings is low;
- the curvature is not constant beyond what the arc model explains (the BIC-chosen tangent-angle
  fit needs degree >= 2 *and* its psi differs from the Hyper circle fit's by more than
  ``NONCONSTANT_DEG``); the ``turning`` and ``auto`` methods measure such lines correctly, so for it
  this is only noted in ``reason`` and the row stays ``ok``;
- the estimator disagrees with both the arc and the turning fits by more than
  ``DISAGREE_DEG`` (e.g. the faithful ``paper`` average, biased by pixel noise); when the full
  ``turning`` fit gave psi (``turning``, or ``auto`` on non-constant curvature) its "turning
  fit" for this check is the same model with one term more: an unstable fit is flagged;
- the two ends almost touch, or the line closes on itself / branches;
- the fixed end had to be guessed (``fixed_end: auto``) and no clamp was seen at either end
  -- the sign may be wrong.

``failed`` rows (no psi) come from :class:`pipeline.measure.extract.NoLineFound` or an image
that cannot be decoded; their reason is set by the caller.

A body (``target: body``) is judged by :func:`assess_body` instead: see its docstring.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from pipeline.measure.extract import LineExtraction

#: below this colour distance (BGR units) the contrast is low
LOW_CONTRAST = 45.0
#: turning-vs-arc difference (deg) beyond which the curvature is called non-constant
NONCONSTANT_DEG = 1.5
#: an estimator farther than this from both the arc and the turning fit is flagged (deg)
DISAGREE_DEG = 3.0
#: measured / expected length outside [LENGTH_LOW, LENGTH_HIGH] -> flagged
LENGTH_LOW, LENGTH_HIGH = 0.93, 1.07
#: flags that doubt only how much of the line was seen, not the angle read from it: a photo
#: flagged for these alone is trusted again when its psi agrees with its ramp (pipeline.ramp_check)
COSMETIC_FLAGS: tuple[str, ...] = (
    "line partly hidden",
    "line touches the image border",
    "body partly hidden",
)


@dataclass(frozen=True)
class Quality:
    """Status and reasons of one measurement."""

    status: str
    reason: str



def line_flags(
    line: LineExtraction, length_px: float, expected_length_px: float | None
) -> list[str]:
    """Reasons to distrust an extracted line, whatever is computed from it (angle or ellipse).

    Parameters
    ----------
    line : LineExtraction
        The extracted line.
    length_px : float
        Measured centre-line length (original px).
    expected_length_px : float or None
        ``l0_mm / mm_per_px`` when the scale is known.

    Returns
    -------
    list of str
        Border touch, partly hidden or too long for l0, several candidate lines, low contrast.
    """
    flags: list[str] = []
    if line.touches_border:
        flags.append("line touches the image border")
    if expected_length_px:
        ratio = length_px / expected_length_px
        if ratio < LENGTH_LOW:
            flags.append(
                f"line partly hidden: {100 * ratio:.0f}% of l0 visible (or the scale is off: "
                "mm_per_px, a calibration's square_mm, or a camera not square to the "
                "actuator's plane, which a calibration corrects)"
            )
        elif ratio > LENGTH_HIGH:
            flags.append(
                f"line {100 * ratio:.0f}% of l0: check mm_per_px or marks joined to the line"
            )
    if line.n_candidates > 1:
        flags.append(f"{line.n_candidates} candidate lines")
    if line.contrast < LOW_CONTRAST:
        flags.append(f"low contrast ({line.contrast:.0f})")
    return flags


def assess(
    line: LineExtraction,
    *,
    method: str,
    psi_deg: float,
    length_px: float,
    expected_length_px: float | None,
    psi_turning_deg: float,
    psi_arc_deg: float,
    turning_degree: int,
) -> Quality:
    """Decide ``ok`` / ``flagged`` and list every reason.

    Parameters
    ----------
    line : LineExtraction
        The extracted line.
    method : str
        Estimator used for psi.
    psi_deg : float
        psi from that estimator.
    length_px : float
        Measured line length (original px).
    expected_length_px : float or None
        ``l0_mm / mm_per_px`` when the scale is known.
    psi_turning_deg, psi_arc_deg : float
        psi from the turning-angle fit and from the Hyper circle fit.
    turning_degree : int
        Polynomial degree the BIC chose for theta(s).

    Returns
    -------
    Quality
    """
    flags = line_flags(line, length_px, expected_length_px)
    notes: list[str] = []
    ratio = length_px / expected_length_px if expected_length_px else 1.0
    if LENGTH_LOW <= ratio <= LENGTH_HIGH and abs(psi_deg * (1.0 - ratio)) > DISAGREE_DEG:
        # psi is the curvature times l0_mm: a scale a few % off this photo's moves it as much
        # (customer 46, a camera held by hand, its scale +-3 %: 8 of 26 rows ok 3-8 deg off); the
        # line's own turning, its curvature times its length as seen, does not depend on it
        flags.append(
            f"the line as seen is {100 * ratio:.1f}% of l0_mm at mm_per_px, so its own turning "
            f"reads {psi_deg * ratio:+.1f} deg where its curvature times l0_mm reads "
            f"{psi_deg:+.1f}: this photo's scale is not mm_per_px (a camera held by hand, moved "
            "or zoomed? Then leave mm_per_px out: psi is the line's own turning), or part of the "
            "line is missing or extra (photoset preview shows it)"
        )
    if line.gap_bridged:
        flags.append("line partly hidden: gap bridged")
    if not line.fixed_end_found:
        flags.append("no line reaches fixed_end; used the longest")
    diff = psi_turning_deg - psi_arc_deg
    if turning_degree >= 2 and abs(diff) > NONCONSTANT_DEG:
        text = f"non-constant curvature (turning - arc = {diff:+.1f} deg)"
        (notes if method in ("turning", "auto") else flags).append(text)
    off = min(abs(psi_deg - psi_arc_deg), abs(psi_deg - psi_turning_deg))
    if off > DISAGREE_DEG:
        flags.append(f"{method} differs from the arc and turning fits by {off:.0f} deg")
    if line.branched_fraction > 0.05:
        flags.append("line closes on itself or branches")
    elif line.ends_gap_px < 3.0 * line.width_px + 4.0:
        flags.append(f"ends almost touching ({line.ends_gap_px:.0f} px apart)")
    if line.fixed_end_auto and not line.clamp_removed:
        flags.append("fixed end guessed (no clamp seen at either end); set fixed_end")
    status = "flagged" if flags else "ok"
    return Quality(status, "; ".join(flags + notes))


#: body: the free end's tangent may move this much (deg) when its fit window doubles
TIP_UNSTABLE_DEG = 8.0
#: body: either end's tangent may move this much (deg) when its fit window halves.  On 480
#: rendered analogue photos (5 scenes; clean at 1280x960 with two seeds and at 1280x720; with
#: JPEG quality 40, noise, uneven light, blur or underexposure) 10 deg flagged 3 ``ok`` rows off
#: by more than 5 deg (2 of the 3 off by more than 10) and 1 right one; 8 deg flagged 6 right ones
END_HOOK_DEG = 10.0
#: body: psi from the end tangents and from a smooth fit of the whole centre line's tangent angle
#: (:func:`~pipeline.measure.estimators.turning`) may differ this much (deg); more: a wobbly
#: centre line (on rendered translucent bodies it caught the ok rows 8-10 deg off)
SMOOTH_DISAGREE_DEG = 8.0
#: body: width along the centre line (90th / 10th percentile) above this -> uneven outline
WIDTH_RATIO = 2.2
#: body: a body this share of which differs from the background by less than the clear
#: threshold is faint, and a flag on its selection's shape (these words) says so first:
#: customer 55's translucent body one grey level fainter was flagged as a PneuNet, a ring,
#: rival bodies or an uneven outline, its mask speckled on its shaded half
FAINT_BODY_SHARE = 0.5
SELECTION_SHAPE_FLAGS = (
    "a row of chambers", "candidate bodies", "uneven outline", "body closes on itself",
    "the end tangents and a smooth fit", "end direction unstable",
)
#: body: the free end's direction may change this much (deg) when the centre line is carried on
#: along the selection's ridge over the part of the tip it did not reach; more is flagged, and
#: psi is then the carried-on line's (:func:`pipeline.measure.core.carried_on_psi_deg`)
RIDGE_TIP_DEG = 4.0
#: body: a free end narrower than this fraction of the body's width has lost a side
NARROW_FREE_END = 0.6
#: body, a frame of a video: a free end wider than this times the body is smeared, the tip a fan
#: of its places over the exposure.  Rendered step responses (DS20 on green, SS40 on grey, 850
#: sharp frames) reach at most 1.08; with a shutter open a whole frame at 30 fps the frames more
#: than 10 deg off reach 1.12 and more (one `ok` at 1.12, 23.5 deg off)
SMEARED_FREE_END = 1.1
#: body: where the free end is narrower than this fraction of the body's width (a faint side),
#: its curvature says less of how far the uncovered tip turns, and a centre line stopping short
#: of a tip that turns more than FAINT_TIP_TURN_DEG (deg) at that curvature is flagged (not
#: carried on)
FAINT_TIP_WIDTH, FAINT_TIP_TURN_DEG = 0.9, 5.0
#: body: so is one stopping more than this many of the body's widths short of a tip that turns
#: more than FAINT_TIP_TURN_DEG: past the half width of a cap, a faint stretch of the tip is lost
#: (the rendered bodies' lines stop 0.6-0.9 widths short of a tip seen whole)
FAINT_TIP_SHORT_WIDTHS = 0.9


def tip_out_of_reach(end_short_px: float, width_px: float) -> bool:
    """Whether the centre line stops so far short of the body's free end (more than one and a
    half widths) that the outline there is uneven, rather than a tip the selection fades at.

    Examples
    --------
    >>> tip_out_of_reach(59.0, 40.0), tip_out_of_reach(134.0, 40.0)
    (False, True)
    """
    return end_short_px > 1.5 * width_px + 4.0


#: a fixed end inside an excluded part: flagged where the base's curvature carried over that
#: stretch turns psi this much (deg) or more
EXCLUDED_START_DEG = 2.0
#: a body read wider or narrower than ``body_width_mm`` by more than this share of it, and by
#: more than BODY_WIDTH_MIN_MM, is flagged (:func:`width_off`)
BODY_WIDTH_SHARE, BODY_WIDTH_MIN_MM = 0.2, 1.0


def width_off(read_mm: float, given_mm: float) -> str:
    """The flag of a body read far wider or narrower (``read_mm``) than ``body_width_mm``
    (``given_mm``), or "" (:data:`BODY_WIDTH_SHARE`, :data:`BODY_WIDTH_MIN_MM`; NaN: no check).

    The body's own width is a witness like its length: customer 55's 13 mm translucent body with
    a strong shadow was read 17.5 mm wide (its shadow taken in), `ok` and 6-10 deg off; customer
    52's off-white body on pale paper about 6.5 of its 14 mm (its lit side lost to the backdrop).

    Examples
    --------
    >>> width_off(17.5, 13.0)[:58]
    'body read 17.5 mm wide where body_width_mm is 13: its shad'
    >>> width_off(6.4, 14.0)[:60]
    'body read 6.4 mm wide where body_width_mm is 14: a side of i'
    >>> width_off(14.2, 13.0), width_off(float("nan"), 13.0)
    ('', '')
    """
    if not (np.isfinite(read_mm) and np.isfinite(given_mm)):
        return ""
    if abs(read_mm - given_mm) <= max(BODY_WIDTH_SHARE * given_mm, BODY_WIDTH_MIN_MM):
        return ""
    why = (
        "its shadow, or something beside it, is taken in"
        if read_mm > given_mm
        else "a side of it is not selected (faint, or lit like the backdrop)"
    )
    return (
        f"body read {read_mm:.1f} mm wide where body_width_mm is {given_mm:g}: {why}; check "
        "with photoset preview (a body that swells under pressure: leave body_width_mm out)"
    )


def tip_seen_whole(
    end_short_px: float, width_px: float, free_end_width_ratio: float, ridge_tip_deg: float
) -> bool:
    """Whether the selection holds the body's free end whole: the centre line stops at most
    :data:`FAINT_TIP_SHORT_WIDTHS` widths short of it, the free end is as wide as the body
    (:data:`FAINT_TIP_WIDTH`) and the selection's ridge does not turn on past the centre line
    (:data:`RIDGE_TIP_DEG`).  Where it does not, what ends the selection is not the body's own
    end (a faint tip or side the selection fades at).

    Examples
    --------
    >>> tip_seen_whole(28.0, 68.0, 1.0, 0.0), tip_seen_whole(70.0, 60.0, 1.0, 0.0)
    (True, False)
    >>> tip_seen_whole(20.0, 60.0, 0.8, 0.0), tip_seen_whole(20.0, 60.0, 1.0, 6.0)
    (False, False)
    """
    return (
        end_short_px <= FAINT_TIP_SHORT_WIDTHS * width_px
        and free_end_width_ratio >= FAINT_TIP_WIDTH
        and abs(ridge_tip_deg) <= RIDGE_TIP_DEG
    )


def tip_turn_deg(
    ridge_tip_deg: float, missed_tip_deg: float, *, out_of_reach: bool = False
) -> float:
    """The turn (deg, image axes) psi is carried on by past the centre line's free end: see
    :func:`pipeline.measure.core.carried_on_psi_deg`.

    Examples
    --------
    >>> tip_turn_deg(13.0, 32.0), tip_turn_deg(13.0, -32.0), tip_turn_deg(3.0, 6.0)
    (32.0, 13.0, 0.0)
    """
    if abs(ridge_tip_deg) > RIDGE_TIP_DEG:
        further = missed_tip_deg * ridge_tip_deg > 0 and abs(missed_tip_deg) > abs(ridge_tip_deg)
        return missed_tip_deg if further else ridge_tip_deg
    if not out_of_reach and abs(missed_tip_deg) > TIP_UNSTABLE_DEG:
        return missed_tip_deg
    return 0.0


#: a measured base direction this far (deg) from ``fixed_direction_deg`` is doubtful
BASE_MISMATCH_DEG = 20.0
#: a body's line touching the image border and this many times the body long (l0 and the sealed
#: end) may have something joined at its free end, its tip in view
JOINED_AT_TIP = 1.3
#: the notes a body's ``reason`` may hold beside its flags, saying how psi was taken (an ``ok``
#: row's reason holds only these): how each begins
NOTE_FIXED_DIRECTION = "psi from the free end's tangent against fixed_direction_deg"
NOTE_SIDE_ON_BORDER = "a side runs along the image border"
NOTE_SELECTION_COVERS = "selection covers"
#: the ramp check's note where a ramp's bodies leave the clamp a little off fixed_direction_deg
NOTE_GIVEN_OFF = "the bodies of this ramp leave the clamp at"
#: a doubtful body measured again against its ramp's estimate of the empty scene, and kept
NOTE_RAMP_BACKGROUND = "measured against the empty scene estimated from its ramp's photos"
#: a line walked from its tip by ``fixed_end: auto``, measured again from its ramp's start
NOTE_FROM_RAMP_START = "measured again from where its ramp's photos' lines start"
#: a capped body measured without ``sealed_end_mm``, bent this much (deg) or more
NOTE_NO_SEALED_END = "no sealed_end_mm"
NO_SEALED_END_PSI_DEG = 100.0
#: a body whose tip direction was read on the flat face ending it, where that turned psi by at
#: least TIP_FACE_NOTE_DEG from where its centre line stops
NOTE_TIP_FACE = "tip direction read on the flat face that ends the body"
TIP_FACE_NOTE_DEG = 1.0
#: the sealed-end check's note where an actuator's photos show a straight end a little longer
#: than the sealed_end_mm given (pipeline.sealed_end_check)
NOTE_SEALED_END_LONGER = "the photos show a longer straight end"
NOTES: tuple[str, ...] = (
    NOTE_NO_SEALED_END,
    NOTE_TIP_FACE,
    NOTE_SEALED_END_LONGER,
    NOTE_FIXED_DIRECTION,
    NOTE_SIDE_ON_BORDER,
    NOTE_SELECTION_COVERS,
    NOTE_GIVEN_OFF,
    NOTE_RAMP_BACKGROUND,
    NOTE_FROM_RAMP_START,
)


def start_seen(start_gap_px: float, width_px: float) -> bool:
    """Whether the body's centre line starts at ``fixed_end``: within two of its widths (and 4
    px) of it, so that the direction in which the body leaves the clamp is read there.

    Examples
    --------
    >>> start_seen(30.0, 20.0), start_seen(150.0, 20.0)
    (True, False)
    """
    return start_gap_px <= 2.0 * width_px + 4.0


#: a body this far (deg) off the ``fixed_direction_deg`` given is told the direction it leaves at
MISREAD_DIRECTION_DEG = 45.0


def _direction_hint(given_deg: float | None, mismatch_deg: float) -> str:
    """What a body far off the ``fixed_direction_deg`` given says of its own direction: a
    direction read with y down (90 for a body hanging down) is a sign off (customer 31 was told
    only "-171 deg off").

    Examples
    --------
    >>> _direction_hint(90.0, -171.0)
    ' (it leaves at -99 deg, counter-clockwise from +x: 90 is up, -90 down)'
    >>> _direction_hint(90.0, -25.0), _direction_hint(None, -171.0)
    ('', '')
    """
    if given_deg is None or abs(mismatch_deg) <= MISREAD_DIRECTION_DEG:
        return ""
    own = (given_deg - mismatch_deg + 180.0) % 360.0 - 180.0
    return f" (it leaves at {own:+.0f} deg, counter-clockwise from +x: 90 is up, -90 down)"


def assess_body(
    line: LineExtraction,
    *,
    psi_deg: float,
    psi_check_deg: float,
    widths_px: np.ndarray,
    expected_length_px: float | None,
    length_px: float,
    base_mismatch_deg: float | None,
    selected_fraction: float,
    continues: bool = False,
    start_gap_px: float = 0.0,
    end_short_px: float = 0.0,
    ridge_tip_deg: float = 0.0,
    free_end_width_ratio: float = 1.0,
    side_on_border: bool = False,
    tip_at_region_edge: bool = False,
    background_estimated: bool = False,
    background_given: bool = False,
    video_frame: bool = False,
    missed_tip_deg: float = 0.0,
    smooth_mismatch_deg: float = 0.0,
    short_end_shift_deg: tuple[float, float] = (0.0, 0.0),
    excluded: bool = False,
    fixed_direction_deg: float | None = None,
    hollow_outline: bool = False,
    sealed_end_unknown: bool = False,
    tip_face_turn_deg: float | None = None,
    chambered: bool = False,
    sealed_end_px: float = 0.0,
    method: str = "tangents",
    psi_tip_deg: float | None = None,
    width_mm: tuple[float, float] | None = None,
    excluded_start_deg: float = 0.0,
    excluded_start_px: float = 0.0,
    faint_share: float = 0.0,
) -> Quality:
    """``ok`` / ``flagged`` for a body's centre line (``target: body``), every reason listed.

    Flagged when the free end reaches the image border (a side along it is a note; a selection
    reaching it more than :data:`JOINED_AT_TIP` times the body's length, ``expected_length_px``
    plus ``sealed_end_px``, may have something joined at its tip); several
    bodies compete; the fixed end is not reached or guessed; the outline is uneven (the
    segmentation leaked into the backdrop, or lost part of the body); the free end's direction
    depends on how much of the end is fitted (a hooked or ragged tip), or either end's direction
    on fitting half as much of it (``short_end_shift_deg``: a hook in the last few pixels, where
    the body meets the clamp or the tip, that a longer fit smooths over); the centre line stops
    short of a tip that still turns (``missed_tip_deg``: the free end's curvature times the part
    of the body beyond the centre line's end, less half a width for a cap, signed as the turn;
    over :data:`TIP_UNSTABLE_DEG`, or over :data:`FAINT_TIP_TURN_DEG` where the free end is
    narrower than :data:`FAINT_TIP_WIDTH` of the body, a faint side, or the line stops more than
    :data:`FAINT_TIP_SHORT_WIDTHS` widths short, a faint stretch of the tip); the body starts far
    from ``fixed_end`` (not when ``fixed_direction_deg`` is given, ``base_mismatch_deg`` not
    None: psi does not depend on it); the body closes on itself (``excluded``: the row already
    excludes a region, which may miss the gap); the selection is the outline of a long region
    whose inside does not differ from the background (``hollow_outline``: a clear body seen by
    its rims, which may be measured instead of its middle); or it is much shorter
    than ``l0`` (partly hidden); or, in a video frame (``video_frame``), its free end is wider than
    :data:`SMEARED_FREE_END` times the body (smeared by motion).  Notes (status stays ``ok``) say
    how psi was taken, and that a capped body bent :data:`NO_SEALED_END_PSI_DEG` or more was
    read without its sealed end's length (``sealed_end_unknown``): its |psi| reads high, and that
    its tip's direction was read on the flat face ending it (``tip_face_turn_deg``: how far that
    turned psi on from the centre line's end, noted from :data:`TIP_FACE_NOTE_DEG`).  A
    ``chambered`` body (a PneuNet's row of chambers, filled) without the base's direction given
    is flagged (its own is its first chamber's), and so is one whose tip was not read on its
    flat end face.  With
    another ``method`` than the tip angle, psi further than :data:`DISAGREE_DEG` from the tip
    angle (``psi_tip_deg``) is flagged: a body is rarely an arc.
    """
    import numpy as np

    flags: list[str] = []
    notes: list[str] = []
    of_body = length_px / (expected_length_px + sealed_end_px) if expected_length_px else 0.0
    if line.touches_border and of_body > JOINED_AT_TIP:
        # a hand near the tip joined the selection and ran it to the border (customer 42's
        # finger photo read "the tip may be outside", with the tip well in view; customer 43's
        # feed tube swung past the tip)
        flags.append(
            "the selection runs on from the body's free end to the image border, "
            f"{100 * of_body:.0f}% as long as the body (l0_mm, sealed_end_mm and mm_per_px say): "
            "something there may join it (a hand, a tube, a cable?), or those settings are off, "
            "or the tip is outside the photo; exclude what joins it (a box over it) or retake "
            "the photo; check with photoset preview"
        )
    elif line.touches_border:
        flags.append("body touches the image border at its free end: the tip may be outside")
    elif side_on_border:
        notes.append(
            f"{NOTE_SIDE_ON_BORDER}: the centre line there is half the body's width from the "
            "other edge"
        )
    if sealed_end_unknown and abs(psi_deg) >= NO_SEALED_END_PSI_DEG:
        # every row says it, not only check and the report's first page (customer 37: 36 of 116
        # rows ok 5-7 deg off, their reasons empty)
        notes.append(
            f"{NOTE_NO_SEALED_END}: psi read where the centre line stops, as if the body bent to "
            "its end, and a straight sealed end and cap there read |psi| high (2-7 deg at |psi| "
            "100-220 for an 8 mm one): give sealed_end_mm"
        )
    if width_mm is not None and (off := width_off(*width_mm)):
        flags.append(off)
    if excluded_start_deg >= EXCLUDED_START_DEG:
        # the review of stop 60: carried over, a click inside an excluded clamp read psi 240 as
        # 245-249; stopped at the box, a box drawn onto the body read it as 232-220
        flags.append(
            f"fixed_end lies {excluded_start_px:.0f} px inside what exclude / roi leave out, "
            "and psi takes the body to bend on over that stretch, which is not seen (about "
            f"{excluded_start_deg:.0f} deg of turn): click fixed_end where the body leaves the "
            "clamp, draw the box up to there, or give fixed_direction_deg"
        )
    if chambered and base_mismatch_deg is None:
        flags.append(
            "a row of chambers (a PneuNet?): its centre line runs through them as a polygon, so "
            "the direction it leaves the clamp in is its first chamber's: give "
            "fixed_direction_deg, the direction of the strip under the chambers at the clamp"
        )
    if chambered and tip_face_turn_deg is None:
        # its centre line's end is a chamber's side: a rounded or slanted last chamber read
        # 3-16 deg off, ok (the review's rendered PneuNets)
        flags.append(
            "a row of chambers (a PneuNet?) whose tip is not read on a flat end face square to "
            "the strip under the chambers (rounded, cut aslant, faint, or a sealed_end_mm given): "
            "its centre line's end is a chamber's side; check with photoset preview"
        )
    if tip_face_turn_deg is not None and abs(tip_face_turn_deg) >= TIP_FACE_NOTE_DEG:
        notes.append(
            f"{NOTE_TIP_FACE} ({tip_face_turn_deg:+.1f} deg on from where its centre line stops, "
            "about half a width short of it)"
        )
    if tip_at_region_edge:
        flags.append(
            "the body's free end reaches the edge of roi / exclude: the tip may be cut off there "
            "(photoset preview shows the outlines)"
        )
    if hollow_outline:
        flags.append(
            "the selection is the outline of a long region whose inside does not differ from the "
            + ("empty scene" if background_given else "backdrop")
            + ": a clear body seen only by its rims? Photograph it on a backdrop it shows "
            "against (darker, or patterned: its refraction bends the pattern), or tint it"
            + ("" if background_given else ", or give the empty scene (background)")
            + "; check with photoset preview"
        )
    elif line.n_candidates > 1:
        flags.append(
            f"{line.n_candidates} candidate bodies: another selection as large as this body lies "
            "elsewhere (another object in view, such as a ruler or another actuator, or part of "
            "this one beyond a gap?); for an object, give exclude (a box over it) or a roi "
            "around this actuator (a photo of several actuators: one photo set per actuator, "
            "each with its roi); check with photoset preview"
        )
    if not line.fixed_end_found:
        flags.append("no body reaches fixed_end; used the largest")
    elif line.fixed_end_auto:
        flags.append("fixed end guessed; set fixed_end")
    w = widths_px[np.isfinite(widths_px) & (widths_px > 0)]
    if w.size >= 8:
        core = w[int(0.1 * len(w)) : max(int(0.9 * len(w)), int(0.1 * len(w)) + 1)]
        lo, hi = np.percentile(core, [10, 90])
        if lo > 0 and hi / lo > WIDTH_RATIO:
            flags.append(
                f"uneven outline (width {lo:.0f}-{hi:.0f} px): check line_color / roi / exclude in "
                "photoset preview"
            )
    if psi_tip_deg is not None and abs(psi_deg - psi_tip_deg) > DISAGREE_DEG:
        # a circle fit on a body that is not an arc (rendered analogues, method hyper: 61 of 109
        # rows ok more than 5 deg off, none flagged for it)
        flags.append(
            f"{method} reads psi {abs(psi_deg - psi_tip_deg):.0f} deg from the tip angle (the end "
            f"tangents, {psi_tip_deg:+.1f} deg): the body is not an arc, and its psi is the tip "
            "angle (leave method out: the tip angle is a body's default)"
        )
    if abs(psi_check_deg - psi_deg) > TIP_UNSTABLE_DEG:
        flags.append(
            f"end direction unstable ({psi_deg:+.0f} vs {psi_check_deg:+.0f} deg over a longer end)"
        )
    for end, shift in zip(("fixed", "free"), short_end_shift_deg, strict=True):
        if abs(shift) > END_HOOK_DEG:
            flags.append(
                f"the {end} end's direction turns {abs(shift):.0f} deg when fitted over half as "
                "much of it: a hook where the body meets the "
                + (
                    # customer 43's clamp and feed tube, selected with the body without an
                    # empty scene, were named nowhere: an exclude box over them took 73 to 77 ok
                    "clamp, or the clamp or its tube selected with the body (an exclude box over "
                    "them)"
                    if end == "fixed"
                    else "tip"
                )
                + "?; check with photoset preview"
            )
    if abs(smooth_mismatch_deg) > SMOOTH_DISAGREE_DEG:
        flags.append(
            "the end tangents and a smooth fit of the whole centre line disagree by "
            + (
                f"{abs(smooth_mismatch_deg):.0f} deg"
                if abs(smooth_mismatch_deg) <= 360.0
                else "more than a full turn"  # the fit ran away: its figure would mean nothing
            )
            + ": the centre line wobbles (a faint or translucent side?); check with photoset "
            "preview"
        )
    if line.branched_fraction > 0.05:
        flags.append(
            "body closes on itself: where its two ends touch, an exclude box over the gap "
            "between them opens the ring ("
            + (
                "one given may miss the gap, or two other parts of the body touch: "
                if excluded
                else ""
            )
            + "photoset preview shows the outlines)"
        )
    elif line.ends_gap_px < 1.5 * line.width_px + 4.0:
        flags.append(f"ends almost touching ({line.ends_gap_px:.0f} px apart)")
    if line.gap_bridged:
        flags.append(
            "body partly hidden: the selection has a gap along the body's course, bridged "
            "(photoset preview shows it)"
        )
    if continues:
        flags.append(
            "the selection goes on past a gap beyond the free end: part of the body may be missed "
            "(photoset preview shows it)"
        )
    if free_end_width_ratio < NARROW_FREE_END:
        flags.append(
            f"the free end is {100 * free_end_width_ratio:.0f}% as wide as the body: one side of "
            "it may not be selected "
            "(faint), which turns its direction; check with photoset preview"
        )
    if video_frame and free_end_width_ratio > SMEARED_FREE_END:
        flags.append(
            f"the free end is {100 * free_end_width_ratio:.0f}% as wide as the body: smeared, "
            "the body moving while the frame was exposed (a shorter shutter keeps it sharp), or "
            "wider at its tip than along it (a dot or a highlight there, in a slow frame)"
        )
    if abs(ridge_tip_deg) > RIDGE_TIP_DEG:
        further = tip_turn_deg(ridge_tip_deg, missed_tip_deg) != ridge_tip_deg
        flags.append(
            f"the free end's direction is uncertain: the centre line stops {end_short_px:.0f} px "
            "short of the body's end; psi is carried on along the selection there, which turns "
            f"the end by {abs(ridge_tip_deg):.0f} deg"
            + (
                f", and on at the free end's curvature to its end, {abs(missed_tip_deg):.0f} deg"
                if further
                else ""
            )
            + " (photoset preview shows it)"
        )
    elif tip_out_of_reach(end_short_px, line.width_px):
        flags.append(
            f"the centre line stops {end_short_px:.0f} px short of the body's free end (uneven "
            "outline there): check with photoset preview"
        )
    elif abs(missed_tip_deg) > TIP_UNSTABLE_DEG:
        flags.append(
            f"the centre line stops {end_short_px:.0f} px short of the body's free end where the "
            f"body still turns: psi is carried on over that part at the free end's curvature, "
            f"about {abs(missed_tip_deg):.0f} deg (photoset preview shows it)"
        )
    elif abs(missed_tip_deg) > FAINT_TIP_TURN_DEG and (
        free_end_width_ratio < FAINT_TIP_WIDTH
        or end_short_px > FAINT_TIP_SHORT_WIDTHS * line.width_px
    ):
        flags.append(
            f"the centre line stops {end_short_px:.0f} px "
            f"({end_short_px / line.width_px:.1f} widths) short of the body's free end, which "
            f"still turns (about {abs(missed_tip_deg):.0f} deg at its curvature, not carried on) "
            f"and is {100 * free_end_width_ratio:.0f}% as wide as the body there (a faint tip?): "
            "psi may miss part of the tip's turn; check with photoset preview"
            + ("" if background_given else ", or give the empty scene (background)")
        )
    if not start_seen(start_gap_px, line.width_px) and base_mismatch_deg is None:
        # with the base known psi is the free end's tangent against it: the gap cannot change it
        # (nor is it noted: the overlay shows the fixed end given and where the line starts)
        flags.append(
            f"the body starts {start_gap_px:.0f} px from fixed_end: part of it may be missed, or "
            "fixed_end is off (give fixed_direction_deg, the clamp's direction, and psi will not "
            "depend on it)"
        )
    if expected_length_px and length_px < 0.8 * expected_length_px:
        seen = f"{100 * length_px / expected_length_px:.0f}% of l0"
        # a tip in view says nothing is cut off: a body bending out of the photo's plane looks
        # short (customer 38's chambers bending 120 deg round from it: "69% of l0 visible"), and
        # its psi changes smoothly along the ramp, so this is no cosmetic flag the ramp check
        # may lift
        flags.append(
            f"body partly hidden: {seen} visible"
            if line.touches_border or tip_at_region_edge
            else f"body short of l0 with its tip in view ({seen}): it may bend out of the "
            "photo's plane (towards or away from the camera: psi is then the angle as seen, "
            "less than its bending angle), or mm_per_px is off"
        )
    # psi taken against the direction given is angles.csv's fixed_direction_deg column; a note
    # saying so on every row hid the rows that matter (customer 29)
    if base_mismatch_deg is not None and abs(base_mismatch_deg) > BASE_MISMATCH_DEG:
        flags.append(
            f"the body leaves the clamp {-base_mismatch_deg:+.0f} deg off fixed_direction_deg"
            + _direction_hint(fixed_direction_deg, base_mismatch_deg)
        )
    if selected_fraction > 0.35:
        notes.append(f"{NOTE_SELECTION_COVERS} {100 * selected_fraction:.0f}% of the photo")
    if background_estimated:
        notes.append(NOTE_RAMP_BACKGROUND)
    if faint_share >= FAINT_BODY_SHARE and any(
        word in flag for flag in flags for word in SELECTION_SHAPE_FLAGS
    ):
        flags.insert(0, faint_body(faint_share, background_given))
    return Quality("flagged" if flags else "ok", "; ".join(flags + notes))


def faint_body(share: float, background_given: bool) -> str:
    """Why a faint body's selection is flagged, said first (:data:`FAINT_BODY_SHARE`).

    Examples
    --------
    >>> faint_body(0.83, True)[:67]
    'the body differs only faintly from the empty scene over 83% of it: '
    """
    return (
        "the body differs only faintly from the "
        + ("empty scene" if background_given else "backdrop")
        + f" over {100 * share:.0f}% of it: its selection may be speckled or in pieces "
        "(photoset preview shows it), which the reasons after this one may stem from; light "
        "its shaded side too (a second lamp, a reflector) or use a backdrop it stands out against"
    )
