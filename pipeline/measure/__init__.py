"""Bending angle psi from photos (paper, Section II.C): line extraction, curvature, quality.

Public API
----------
``measure_image(image_bgr, settings, *, method=DEFAULT_METHOD) -> AngleResult``
    One decoded photo; ``settings`` is a :class:`~pipeline.measure.settings.MeasureSettings`
    (``resolve_settings(l0_mm=..., line_color=..., ...)`` builds one).
``measure_file(path, settings, *, method) -> (AngleResult, seconds)``
    One image file, decoded once at reduced size (grey for a black line).
``METHODS``
    name -> estimator: ``paper``, ``paper_corrected``, ``pratt``, ``taubin``, ``hyper``,
    ``turning``, ``auto`` (see :mod:`pipeline.measure.estimators`).

Pipeline: :mod:`~pipeline.measure.settings` (the typed per-photo settings, parsed once;
colours in :mod:`~pipeline.measure.colors`) -> :mod:`~pipeline.measure.extract` (a drawn line:
mask, components, clamp cut, geodesic ordering, sub-pixel centre line) or
:mod:`~pipeline.measure.body` (``target: body``: the actuator's own outline against the backdrop,
a background photo or a colour, its centre line between the two long edges) ->
:mod:`~pipeline.measure.estimators` -> :mod:`~pipeline.measure.quality` (``ok`` / ``flagged`` /
``failed`` with reasons) -> :mod:`~pipeline.measure.overlay`.  After a whole set,
:mod:`pipeline.ramp_check` compares each photo with its ramp.

Body mode (``target: body``) reads psi as the tip angle
(:func:`~pipeline.measure.estimators.tangents`): on synthetic analogues of real scenes (``python -m
pipeline bench realscenes``) the median error is 1.3-1.8 deg and p95 3-6 deg; on the committed real
strips 5 of 10 photos are within their label's tolerance and none is ``ok`` outside it.
``AngleResult.degree`` (angles.csv column ``degree``, after ``seconds``) is the complexity of the
curve model used: 1 = circular arc, more = the turning-angle series ``turning`` / ``auto`` chose.

Files (``measure_file``, :func:`pipeline.photoset_measure.measure_photoset`) with a black line are
decoded in grey at reduced size; the extraction runs on a further halved copy and the centre line is
refined on the decoded image (:mod:`~pipeline.measure.refine`: darkness-profile centroids across the
line), which costs a third of the work and is as precise; a result that is not ``ok`` there is
measured again at the decoded size.  ``measure_image`` on a colour array uses the decoded-size path
only.

Default method: ``auto``
------------------------
``auto`` is the Hyper circle fit, switching to ``turning`` only when a BIC-chosen tangent-angle
fit says the curvature is not constant and the two disagree by more than 1.5 deg.  Measured
with ``python -m pipeline bench measure`` (lab scenes: noise, blur, JPEG 90, textured table,
uneven light, distractor marks, clamp, tube, tilt 0-3 deg; |error| in deg):

==================  ===========================  ===========================
case                hyper (median / p95 / max)   turning (median / p95 / max)
==================  ===========================  ===========================
nominal, n=60       0.086 / 0.36 / 0.65          0.100 / 0.44 / 0.54
near straight, 30   0.021 / 0.070 / 0.091        0.035 / 0.42 / 0.56
bulged, 30          18.6 / 53 / 71               0.13 / 0.48 / 0.78
other profiles, 30  11.4 / 35 / 44               0.35 / 0.95 / 0.98
==================  ===========================  ===========================

``auto`` equals Hyper on constant curvature (it is the most precise there, notably near
straight) and equals ``turning`` on non-constant curvature (where every arc fit is tens of
degrees off), so it is best or tied-best in every case; it costs one extra linear fit per photo.
The paper's own estimator (``paper``) reads 36-96 deg off on nominal / near-straight photos (a
straight line never reads 0); ``paper_corrected`` removes that bias.

Speed (same benchmark, 40 lab photos per size, 1 OpenCV thread, medians; against
``cv2.imread`` alone and against a skeletonize (scikit-image) + Hyper-fit baseline, scored
pairwise on |psi| of the same photos):

==========  ======  =====  ==========  =========  ===========  ==============================
size        imread  ours   ours/imread  skeleton   skel/ours    accuracy, camera tilt 0
==========  ======  =====  ==========  =========  ===========  ==============================
1280x960    2.4 ms  3.4    1.42x        13.5 ms    4.1x         ours 0.032, skeleton 0.101 deg
4000x3000   38.9    13.7   0.35x        267        19.4x        0.027 vs 0.033; paired CI of
                                                                the difference -0.017..0.006
==========  ======  =====  ==========  =========  ===========  ==============================

At 4000x3000 we are 19x faster at equal accuracy. At 1280x960 the 10x target is out of reach of
any method that decodes the file: decoding alone, at 1/8 size in grey, takes 1.16 ms, so even
with no other work the ceiling is 11.7x. 10x would leave 0.2 ms for extraction, quality checks
and the fit. The bench's ``bare`` column is decoding at 1/4, an Otsu threshold, the largest
component and a Hyper fit, with no checks and often the wrong blob. It alone takes 2.7 ms, so it
is 5x at best.
"""

from pipeline.measure.core import DEFAULT_METHOD, AngleResult, measure_file, measure_image
from pipeline.measure.estimators import METHODS, CurveEstimate
from pipeline.measure.settings import MeasureSettings, resolve_settings

__all__ = [
    "DEFAULT_METHOD",
    "METHODS",
    "AngleResult",
    "CurveEstimate",
    "MeasureSettings",
    "measure_file",
    "measure_image",
    "resolve_settings",
]
