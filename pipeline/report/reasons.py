"""Why photos were flagged or failed, in words a reader understands, counted per dataset.

A flagged row's ``reason`` (angles.csv) lists its causes separated by ``;`` (a failed row's
reason is one message, whose fix may follow a ``;``); each cause is
matched against :data:`WORDS` (first match wins) and otherwise shortened to its text before
the first ``:``, ``(`` or ``=`` with numbers and brackets removed, so a cause that quotes a
setting (e.g. an HSV range) still reads as words.

Examples
--------
>>> words("line partly hidden: 65% of l0 visible")
'line partly hidden'
>>> words("no line found: no long thin component of line_color=(((0, 0, 0), (180, 255, 80)),)")
'no marker line found'
>>> words("manifest line 7: pressure_kpa '8O' is not a number (fix: write the gauge pressure")
'manifest row: pressure_kpa is not a number'
>>> words("manifest line 12: image 'IMG_4310.JPG' does not exist in /lab/C (fix: copy it in")
'manifest row: photo missing from the folder'
>>> words("background photo IMG_5000.JPG is 4032x3024 px, another shape than the photo: take")
'empty-scene photo of another shape'
>>> words("the selection runs on from the body's free end to the image border, 199% as long")
'something joins the body at its free end (a hand?)'
>>> words("the bodies of this ramp leave its one fixed_end in directions that scatter by 3.6")
'bodies leave one clamp in scattered directions (base unreadable)'
>>> words("hyper reads psi 41 deg from the tip angle (the end tangents, +175.2 deg): the body")
'method reads a body as an arc, which it is not'
>>> words("the line as seen is 95.8% of l0_mm at mm_per_px, so its own turning reads +206.1")
"line's length off l0_mm at mm_per_px (scale differs?)"
>>> words("tilted board 12.5 (((1, 2), (3, 4)),)")
'tilted board'
>>> words("psi may be 5.1 deg off: it is measured from the fixed_direction_deg given (+49.0)")
'bodies leave the clamp off fixed_direction_deg'
>>> top_reasons(pd.DataFrame({"dataset": "v", "status": "flagged", "reason": [
...     "the end tangents and a smooth fit of the whole centre line disagree by 12 deg: the "
...     "centre line wobbles (a faint or translucent side?); check with photoset preview",
...     "the free end's direction is uncertain: the centre line stops 86 px short of the body's "
...     "end; psi is carried on along the selection there, which turns the end by 17 deg"]}))
{'v': [('centre line wobbles', 1), ("free end's direction uncertain", 1)]}
>>> top_reasons(pd.DataFrame({"dataset": ["v"], "status": ["flagged"], "reason": [
...     "body touches the image border at its free end: the tip may be outside; psi from the "
...     "free end's tangent against fixed_direction_deg"]}))
{'v': [("body's tip at the image border", 1)]}
"""

from __future__ import annotations

import re
from collections import Counter

import pandas as pd

from pipeline.measure.quality import NOTES

#: (pattern, words): the causes the measure stage writes, in words
WORDS: tuple[tuple[str, str], ...] = (
    (r"^no line found", "no marker line found"),
    (r"^unreadable image", "photo cannot be read"),
    (r"^a grey image", "grey photo, colour line expected"),
    (r"^curvature fit failed", "curvature fit failed"),
    (r"^internal error", "internal error (please report)"),
    (r"^body touches the image border", "body's tip at the image border"),
    (r"^the selection runs on from the body's free end to the image border",
     "something joins the body at its free end (a hand?)"),
    (r"^body short of l0 with its tip in view", "body short of l0, tip in view (out of plane?)"),
    (r"^sealed end shorter than the photos show", "sealed_end_mm shorter than the photos show"),
    (r"^sealed end not given, and", "no sealed_end_mm, and the photos show one"),
    (r"touches the image border", "line touches the image border"),
    (r"^line partly hidden", "line partly hidden"),
    (r"^line \d+% of l0", "line longer than l0 (scale or extra marks)"),
    (r"candidate lines", "several candidate lines"),
    (r"^low contrast", "low contrast"),
    (r"^no line reaches fixed_end", "no line reaches the fixed end"),
    (r"^non-constant curvature", "curvature not constant"),
    (r"differs from the arc and turning fits", "angle methods disagree"),
    (r"^the line as seen is [\d.]+% of l0_mm at mm_per_px",
     "line's length off l0_mm at mm_per_px (scale differs?)"),
    (r"^\w+ reads psi [\d.]+ deg from the tip angle",
     "method reads a body as an arc, which it is not"),
    (r"closes on itself or branches", "line closes on itself or branches"),
    (r"^ends almost touching", "ends almost touching"),
    (r"^fixed end guessed at the free end", "fixed end guessed at the tip (fixed_end auto)"),
    (r"^fixed end guessed", "fixed end guessed (no clamp seen)"),
    (r"^psi may be [\d.]+ deg off: it is measured from the fixed_direction_deg",
     "bodies leave the clamp off fixed_direction_deg"),
    (r"^pressure [-+\d.e]+ kPa is out of its ramp's order",
     "pressure out of its ramp's order (a manifest typo?)"),
    (r"^direction \w+ is out of its ramp's order",
     "direction out of its ramp's order (a manifest typo?)"),
    (r"^image .*does not exist", "photo missing from the folder"),
    (r"^background photo .* another shape than the photo \(turned",
     "empty-scene photo turned against the photos"),
    (r"^background photo .* another shape than the photo", "empty-scene photo of another shape"),
    (r"^background photo .* cannot be decoded", "empty-scene photo cannot be read"),
    (r"^taken [\d.e+-]+ s after a step of its pressure log", "taken while settling after a step"),
    (r"^the body's two sides diverge", "body's sides diverge at the clamp (a faint side?)"),
    (r"^the bodies of this ramp leave its one fixed_end in directions that scatter",
     "bodies leave one clamp in scattered directions (base unreadable)"),
    # a body's causes
    (r"^the free end's direction is uncertain", "free end's direction uncertain"),
    (r"^the centre line stops \d+ px short of the body's free end where the body still turns",
     "centre line stops short of a tip that still turns"),
    (r"^the centre line stops \d+ px short of the body's free end \(uneven outline",
     "centre line stops short of an uneven tip"),
    (r"^the centre line stops \d+ px \([\d.]+ widths\) short",
     "centre line stops short of a faint tip"),
    (r"^the end tangents and a smooth fit", "centre line wobbles"),
    (r"^the selection is the outline of a long region", "a clear body seen only by its rims"),
    (r"direction turns \d+ deg when fitted over half", "hook at an end of the centre line"),
    (r"^line length \d+% of its ramp's median", "length far from its ramp's median"),
    (r"^the body starts \d+ px from fixed_end", "body starts away from fixed_end"),
    (r"^the body leaves the clamp [-+\d]+ deg off fixed_direction_deg",
     "body leaves the clamp far off fixed_direction_deg"),
    (r"^the body leaves the fixed end [-+\d]+ deg off its ramp's direction",
     "body leaves the clamp off its ramp's direction"),
    (r"^the free end is \d+% as wide as the body: smeared",
     "free end wider than the body (motion smear?)"),
)
#: how the parts of a cause that follow a ``;`` inside it begin (a fix, a carried-on figure, a
#: bracket's second half), and the ramp check's note of the base psi is taken from: not causes
CONTINUATION = re.compile(
    r"^(check with photoset preview|psi is carried on|[-+\d.]+ from its own"
    r"|psi [-+\d.]+ deg against its ramp's base direction)"
)


def words(cause: str) -> str:
    """One cause in words (see module docstring)."""
    text = cause.strip()
    if not text:
        return "no reason given"
    row = re.match(r"manifest line \d+: (.*)", text)
    if row:  # a row measure could not take: what is wrong with it, not its line (all differ)
        return "manifest row: " + words(re.sub(r"'[^']*'", "", row.group(1)))
    for pattern, phrase in WORDS:
        if re.search(pattern, text):
            return phrase
    head = re.split(r"[:(=]", text, maxsplit=1)[0]
    head = re.sub(r"[-+]?\d+(?:\.\d+)?%?|[\[\]{}(),]", " ", head)
    return " ".join(head.split()) or "other"


def top_reasons(angles: pd.DataFrame, limit: int = 3) -> dict[str, list[tuple[str, int]]]:
    """The most frequent causes among the non-ok rows of each dataset.

    Parameters
    ----------
    angles : pandas.DataFrame
        angles rows with ``dataset``, ``status`` and ``reason``.
    limit : int
        Causes kept per dataset; the photos with any other cause are counted, once each, as
    ``"other causes"``.

    Returns
    -------
    dict
        dataset -> [(words, count)], most frequent first (ties by name); datasets without
        non-ok rows are absent.
    """
    out: dict[str, list[tuple[str, int]]] = {}
    bad = angles[angles["status"].astype(str) != "ok"]
    for dataset, g in bad.groupby("dataset", sort=True):
        counts: Counter[str] = Counter()
        per_photo = []
        for status, reason in zip(
            g["status"].astype(str), g["reason"].fillna("").astype(str), strict=True
        ):
            causes = [reason] if status == "failed" else reason.split(";")
            # a note says how psi was taken, not why the row is doubted
            said = {
                words(p)
                for p in causes
                if not (p.strip().startswith(NOTES) or CONTINUATION.match(p.strip()))
            }
            per_photo.append(said)
            counts.update(said)
        ordered = sorted(counts.items(), key=lambda kv: (-kv[1], kv[0]))
        if len(ordered) > limit:
            # photos with another cause, each once (a sum over the causes counted 260 for 68)
            shown = {phrase for phrase, _ in ordered[:limit]}
            others = sum(bool(said - shown) for said in per_photo)
            ordered = ordered[:limit] + [("other causes", others)]
        out[str(dataset)] = ordered
    return out
