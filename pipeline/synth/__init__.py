"""Synthetic acquisition: a virtual rig rendering pressure-ramp photo sets with exact ground truth.

Public API
----------
SceneParams, SCENE_PRESETS, scene_from          scene knobs and presets (``clean``, ``lab``,
``hard``: a
                                                 drawn line; ``green_fibre``, ``grey_dots``,
                                                 ``grey_dots_clear``, ``dark_translucent``: bodies
                                                 without a line, ``target: body``)
centreline_mm, turning_angle_deg                 exact centrelines (total turning angle psi)
actuator_centreline_mm, curvature_weights        non-constant-curvature shapes
(``SceneParams.shape``) render_curve, render_actuator, RenderedImage     one photo with its exact
centreline in pixels (the
                                                 line's, or for ``target: body`` the body's)
render_background, render_with_background       the empty scene (a ``background`` photo)
Backdrop, make_backdrop, make_camera             static scene reused across the photos of a ramp
"""

from pipeline.synth.backdrop import Backdrop, make_backdrop
from pipeline.synth.camera import Camera, make_camera
from pipeline.synth.centreline import (
    actuator_centreline_mm,
    centreline_mm,
    curvature_per_mm,
    curvature_weights,
    turning_angle_deg,
)
from pipeline.synth.presets import SCENE_PRESETS, SceneParams, scene_from
from pipeline.synth.scene import (
    RenderedImage,
    child_seed,
    render_actuator,
    render_background,
    render_curve,
    render_with_background,
)

__all__ = [
    "SCENE_PRESETS",
    "Backdrop",
    "Camera",
    "RenderedImage",
    "SceneParams",
    "actuator_centreline_mm",
    "centreline_mm",
    "child_seed",
    "curvature_per_mm",
    "curvature_weights",
    "make_backdrop",
    "make_camera",
    "render_actuator",
    "render_background",
    "render_curve",
    "render_with_background",
    "scene_from",
    "turning_angle_deg",
]
