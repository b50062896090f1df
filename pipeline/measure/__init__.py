"""Bending angle psi from photos (paper, Section II.C): line extraction, curvature, quality.

Public API
----------
measure_image(image_bgr, *, l0_mm, mm_per_px=None, line_color="black", fixed_end_px=None,
              positive_turn="ccw", method=DEFAULT_METHOD) -> AngleResult
measure_file(path, ...) -> (AngleResult, seconds)
measure_photoset(folder, *, method=DEFAULT_METHOD, jobs=1, overlays_dir=None) -> DataFrame
METHODS: name -> estimator ("paper", "paper_corrected", "pratt", "taubin", "hyper", "turning")

Default method
--------------
See DEFAULT_METHOD and the figures of ``python -m pipeline.measure.bench`` quoted below.
"""

from pipeline.measure.core import DEFAULT_METHOD, AngleResult, measure_file, measure_image
from pipeline.measure.estimators import METHODS, CurveEstimate

__all__ = [
    "DEFAULT_METHOD",
    "METHODS",
    "AngleResult",
    "CurveEstimate",
    "measure_file",
    "measure_image",
    "measure_photoset",
]


def __getattr__(name: str):  # lazy: keep pandas out of the workers' imports
    if name == "measure_photoset":
        from pipeline.measure.photoset_measure import measure_photoset

        return measure_photoset
    raise AttributeError(name)
