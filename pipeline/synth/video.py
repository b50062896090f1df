"""A synthetic video photo set: the virtual rig filmed through a pressure profile, with exact truth.

Physics (seeded, deterministic):

1. the setpoint follows a :class:`~pipeline.video.profile.PressureProfile` (ramp or steps);
2. the regulator's pressure follows the setpoint with a first-order lag
   (``Dynamics.tau_pressure_s``), as the rig emulator's plant does;
3. the static angle is the virtual actuator of :mod:`pipeline.synth.actuator` (the model's
   loading branch scaled per actuator, and its hysteresis: falling pressure reads the loading
   curve at ``P + 4 h P (P_peak - P) / P_peak``, the peak being the highest pressure since the
   rig was last vented);
4. the actuator lags its static angle with a first-order lag (``Dynamics.tau_psi_s``): creep
   after a step, rate-dependent loops on a ramp.

Frames are rendered by :func:`pipeline.synth.render_actuator` over one static scene and written
with OpenCV's ``VideoWriter`` as MJPEG (what USB lab cameras record; FFmpeg's encoder, default
quality, about 30 kB a 1280x720 frame) or MPEG-4 Part 2; H.264 when this OpenCV build can encode
it (most pip wheels cannot: the request is then refused, naming the codecs that work).  The folder
is a video photo set (:mod:`pipeline.video`): ``manifest.csv`` (one row), ``photoset.yaml``
(``target: body`` for a scene of a body without a line, as a still photo set of that scene says),
the video, ``background.jpg`` (the empty scene) for a scene that has one, the pressure log
(``time_s, pressure_kpa`` = setpoint, ``measured_kpa`` = the regulator's pressure plus monitor
noise) and ``truth.csv`` (per frame: its time on the log clock, psi, psi as seen in the image, the
true pressure).  The video starts ``clock_offset_s`` after the log.

Examples
--------
>>> import numpy as np
>>> from pipeline.video.profile import PressureProfile
>>> sim = simulate(PressureProfile("steps", max_kpa=40, step_kpa=20, hold_s=2), toy_actuator(),
...                Dynamics(tau_pressure_s=0.1, tau_psi_s=0.3), start_s=0.5, end_s=11.0)
>>> round(float(np.interp(4.4, sim["time_s"], sim["psi_deg"])))   # settled on the 20 kPa step
170
"""

from __future__ import annotations

import dataclasses
import math
import os
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd
from scipy.signal import lfilter

from pipeline.errors import UserInputError
from pipeline.fileio import atomic_write_bytes, write_table
from pipeline.photoset import TRUTH, write_manifest, write_settings
from pipeline.synth.actuator import (
    ActuatorBehaviour,
    PsiFunction,
    TrialActuator,
    behaviour_for,
    draw_actuator,
    draw_trial,
    loading_curve,
)
from pipeline.synth.backdrop import make_backdrop
from pipeline.synth.camera import make_camera
from pipeline.synth.centreline import centreline_mm
from pipeline.synth.photoset_writer import (
    BACKGROUND_IMAGE,
    choose_layout,
    default_l0_mm,
    material_key,
    target_settings,
)
from pipeline.synth.presets import SceneParams, scene_from
from pipeline.synth.scene import (
    child_seed,
    encode_jpeg,
    render_actuator,
    render_background,
    world_extent_mm,
)
from pipeline.video.profile import PressureProfile
from pipeline.video.writer import CODECS, open_writer

#: seed streams (after the material key)
_ACTUATOR, _TRIAL, _TABLE, _FRAME, _LOG, _BACKGROUND = 11, 12, 13, 14, 15, 16
#: the rig counts as vented (the hysteresis peak restarts) below this pressure (kPa)
VENTED_KPA = 1.0
#: time step of the simulation (s)
SIM_DT_S = 1e-3


@dataclass(frozen=True)
class Dynamics:
    """Time constants of the virtual rig (s) and the noise of its pressure monitor (kPa)."""

    tau_pressure_s: float = 0.15
    tau_psi_s: float = 0.4
    monitor_noise_kpa: float = 0.2

    def __post_init__(self) -> None:
        for f in dataclasses.fields(self):
            value = getattr(self, f.name)
            if not (math.isfinite(value) and value >= 0):
                raise UserInputError(f"{f.name} = {value!r} must be a number >= 0")


def toy_actuator(psi0_deg: float = 210.0, kpa_per_deg: float = 1 / 2.0) -> TrialActuator:
    """A linear actuator (psi = psi0 - P / kpa_per_deg) with 10 % hysteresis, for examples and
    tests."""

    def fn(material: str, p: Any, branch: str = "loading") -> np.ndarray:
        return psi0_deg - np.asarray(p, float) / kpa_per_deg

    curve = loading_curve("toy", max_kpa=600.0, psi_fn=fn)
    return TrialActuator(
        "toy", curve, psi0_deg, 1.0, ActuatorBehaviour(hysteresis=0.1, photo_sd_deg=0.0)
    )


def _lag(x: np.ndarray, tau_s: float, dt_s: float) -> np.ndarray:
    """First-order lag of a sampled signal, starting at rest on its first value."""
    if tau_s <= 0:
        return x.copy()
    a = math.exp(-dt_s / tau_s)
    y, _ = lfilter([1.0 - a], [1.0, -a], x, zi=[a * x[0]])
    return np.asarray(y)


def static_psi_deg(trial: TrialActuator, pressure_kpa: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Static angle along a pressure history and whether each sample is on the loading branch.

    The peak is the highest pressure since the rig was last below :data:`VENTED_KPA`.
    """
    p = np.asarray(pressure_kpa, float)
    segment = np.cumsum(p < VENTED_KPA)
    peak = pd.Series(p).groupby(segment).cummax().to_numpy()
    loading = p >= peak - 1e-9
    h = trial.behaviour.hysteresis
    equivalent = np.where(peak > 0, p + 4.0 * h * p * (peak - p) / np.where(peak > 0, peak, 1.0), p)
    return trial.psi_loading_deg(equivalent), loading


def simulate(
    profile: PressureProfile,
    trial: TrialActuator,
    dynamics: Dynamics,
    *,
    start_s: float,
    end_s: float,
    dt_s: float = SIM_DT_S,
) -> pd.DataFrame:
    """The virtual rig on a fine time grid (log clock): setpoint, pressure, static and lagged psi.

    Parameters
    ----------
    profile : PressureProfile
        Starts at ``start_s`` on the log clock.
    trial : TrialActuator
    dynamics : Dynamics
    start_s, end_s : float
        Profile start and end of the simulation (s, log clock; the rig is at rest at 0).

    Returns
    -------
    pandas.DataFrame
        ``time_s, setpoint_kpa, pressure_kpa, psi_static_deg, psi_deg, loading``.

    Raises
    ------
    UserInputError
        When the profile goes beyond the pressures the actuator's model describes.
    """
    t = np.arange(0.0, end_s + dt_s / 2, dt_s)
    setpoint = profile.setpoint_kpa(t - start_s)
    pressure = _lag(setpoint, dynamics.tau_pressure_s, dt_s)
    psi_static, loading = static_psi_deg(trial, pressure)
    if not np.isfinite(psi_static).all():
        raise UserInputError(
            f"max_kpa {profile.max_kpa:g} is beyond what the model describes for {trial.material} "
            f"(up to {trial.curve.limit_kpa * trial.stiffness:.0f} kPa for this actuator); lower it"
        )
    return pd.DataFrame(
        {
            "time_s": t,
            "setpoint_kpa": setpoint,
            "pressure_kpa": pressure,
            "psi_static_deg": psi_static,
            "psi_deg": _lag(psi_static, dynamics.tau_psi_s, dt_s),
            "loading": loading,
        }
    )


def fit_scene(
    scene: SceneParams, l0_mm: float, psi_range: tuple[float, float]
) -> tuple[SceneParams, float]:
    """Zoom out (as the experimenter would) until every shape of the recording fits; the clamp
    direction."""
    curves = [world_extent_mm(centreline_mm(float(p), l0_mm, n=241), scene.body_width_mm)
              for p in np.linspace(psi_range[0], psi_range[1], 17)]
    rotation, _, need = choose_layout(curves, scene)
    if need > 1.0:
        scene = dataclasses.replace(
            scene, mm_per_px=float(np.ceil(scene.mm_per_px * need * 1000) / 1000)
        )
        rotation, _, need = choose_layout(curves, scene)
    return scene, rotation


#: a frame exposed over ``shutter_s`` is the mean of this many renders (odd: the middle one is
#: the frame's own time)
SHUTTER_SUBFRAMES = 5


def _exposed(
    middle: np.ndarray,
    t_s: float,
    shutter_s: float,
    sim: pd.DataFrame,
    render: Callable[[float], np.ndarray],
) -> np.ndarray:
    """The frame at ``t_s`` exposed over ``shutter_s``: the mean of ``middle`` (rendered at
    ``t_s``) and the renders (``render(psi_deg)``, same seed: same noise) at the other
    :data:`SHUTTER_SUBFRAMES` - 1 instants spread evenly over the exposure."""
    offsets = shutter_s * ((np.arange(SHUTTER_SUBFRAMES) + 0.5) / SHUTTER_SUBFRAMES - 0.5)
    psi = np.interp(t_s + offsets, sim["time_s"], sim["psi_deg"])
    if np.ptp(psi) == 0:  # at rest over the exposure: the frame itself, not five equal renders
        return middle
    total = np.zeros(middle.shape, np.float32)
    for dt, p in zip(offsets, psi):
        total += middle if dt == 0 else render(float(p))
    return np.clip(total / SHUTTER_SUBFRAMES + 0.5, 0, 255).astype(np.uint8)


def render_video(
    out_dir: str | os.PathLike[str],
    material: str,
    *,
    profile: PressureProfile,
    fps: float = 30.0,
    rest_s: float = 1.0,
    clock_offset_s: float = 0.5,
    scene: str | SceneParams = "lab",
    scene_overrides: Mapping[str, Any] | None = None,
    seed: int = 1,
    codec: str = "mjpg",
    log_hz: float = 20.0,
    dynamics: Dynamics | None = None,
    l0_mm: float | None = None,
    actuator: str = "A1",
    trial: str = "1",
    behaviour: ActuatorBehaviour | None = None,
    psi_fn: PsiFunction | None = None,
    trial_actuator: TrialActuator | None = None,
    progress: bool | None = None,
    shutter_s: float = 0.0,
) -> pd.DataFrame:
    """Render a video photo set of one actuator going through ``profile`` (see the module
    docstring).

    Parameters
    ----------
    out_dir : path
        Folder to write (created; the files it writes are replaced).
    material : str
        Material of the virtual actuator (DS20, DS30, SS40, SS50 or one ``psi_fn`` knows).
    profile : PressureProfile
        The setpoint; the video shows ``rest_s`` at rest before and after it.
    fps : float
        Frame rate (frames per second).
    clock_offset_s : float
        Log time at which the video starts (s); the log runs from 0 to 0.5 s after the video.
    scene, scene_overrides
        Scene preset and knobs (``width``, ``height``, ``noise_sigma``, ...).
    seed : int
        Seeds everything (same seed, same bytes).
    codec : str
        A key of :data:`pipeline.video.writer.CODECS`.
    log_hz : float
        Rate of the pressure log (rows per second).
    dynamics : Dynamics, optional
        Time constants (default :class:`Dynamics`).
    l0_mm : float, optional
        Marked length (default: the model's material file).
    actuator, trial : str
        Labels in the manifest.
    behaviour, psi_fn
        Actuator variability and loading branch (defaults of :mod:`pipeline.synth.actuator`).
    trial_actuator : TrialActuator, optional
        Use this actuator instead of drawing one (tests).
    progress : bool or None
        Progress bar (None: on a terminal only).
    shutter_s : float
        Exposure time of each frame (s; 0: instantaneous).  A moving actuator is smeared over
        it: the frame is the mean of :data:`SHUTTER_SUBFRAMES` renders spread evenly over the
        exposure, centred on the frame's time (its truth).

    Returns
    -------
    pandas.DataFrame
        ``truth.csv``: one row per frame.
    """
    from tqdm import tqdm

    if not (
        fps > 0
        and log_hz > 0
        and rest_s >= 0
        and math.isfinite(clock_offset_s)
        and clock_offset_s >= 0
    ):
        raise UserInputError("fps and log_hz must be positive, rest_s and clock_offset_s >= 0")
    if not (math.isfinite(shutter_s) and 0 <= shutter_s <= 1 / fps):
        raise UserInputError(
            f"shutter_s = {shutter_s!r} must lie between 0 and one frame (1 / fps = {1 / fps:g} s)"
        )
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    dyn = dynamics or Dynamics()
    l0 = float(l0_mm) if l0_mm is not None else default_l0_mm(material)
    mk = material_key(material)
    if trial_actuator is None:
        beh = behaviour or behaviour_for(material)
        curve = loading_curve(material, max_kpa=profile.max_kpa * 1.6, psi_fn=psi_fn)
        act = draw_actuator(
            material, curve, beh, np.random.default_rng(child_seed(seed, mk, _ACTUATOR))
        )
        trial_actuator = draw_trial(
            material, curve, beh, act, np.random.default_rng(child_seed(seed, mk, _TRIAL))
        )
    n_frames = round((profile.duration_s + 2 * rest_s) * fps)
    video_end_s = clock_offset_s + (n_frames - 1) / fps
    log_end_s = video_end_s + 0.5
    sim = simulate(profile, trial_actuator, dyn, start_s=clock_offset_s + rest_s, end_s=log_end_s)
    frame_t = clock_offset_s + np.arange(n_frames) / fps
    psi = np.interp(frame_t, sim["time_s"], sim["psi_deg"])
    sc = scene_from(scene, **dict(scene_overrides or {}))
    sc, rotation = fit_scene(sc, l0, (float(psi.min()), float(psi.max())))
    extent = np.vstack(
        [centreline_mm(float(p), l0, n=241) for p in np.linspace(psi.min(), psi.max(), 9)]
    )
    camera = make_camera(sc, rotation_deg=rotation, extent_mm=extent)
    backdrop = make_backdrop(sc, camera, seed=child_seed(seed, mk, _TABLE), keepout_mm=[extent])
    name = f"{material}_{actuator}_t{trial}_{profile.kind}{CODECS.get(codec, ('', ''))[1]}"
    tmp = out / f".{name}.tmp{CODECS.get(codec, ('', '.avi'))[1]}"
    writer = open_writer(tmp, codec, fps, (sc.width, sc.height))
    seen, fixed_end = np.empty(n_frames), (math.nan, math.nan)
    try:
        for k in tqdm(
            range(n_frames),
            desc=f"render {name}",
            unit="frame",
            disable=None if progress is None else not progress,
            leave=False,
        ):
            r = render_actuator(float(psi[k]), l0, sc, seed=child_seed(seed, mk, _FRAME, k),
                                bulge=float(trial_actuator.bulge(psi[k])), backdrop=backdrop)
            seen[k] = r.psi_image_deg
            fixed_end = r.fixed_end_px
            if shutter_s > 0:  # smeared over the exposure: the same seed, the same noise

                def at(p: float, k: int = k) -> np.ndarray:
                    return render_actuator(p, l0, sc, seed=child_seed(seed, mk, _FRAME, k),
                                           bulge=float(trial_actuator.bulge(p)),
                                           backdrop=backdrop).image

                writer.write(_exposed(r.image, frame_t[k], shutter_s, sim, at))
            else:
                writer.write(r.image)
    finally:
        writer.release()
    os.replace(tmp, out / name)
    log_t = np.round(np.arange(0.0, log_end_s + 1e-9, 1.0 / log_hz), 6)
    noise = np.random.default_rng(child_seed(seed, mk, _LOG)).normal(
        0.0, dyn.monitor_noise_kpa, len(log_t)
    )
    log = pd.DataFrame(
        {
            "time_s": log_t,
            "pressure_kpa": np.interp(log_t, sim["time_s"], sim["setpoint_kpa"]),
            "measured_kpa": np.interp(log_t, sim["time_s"], sim["pressure_kpa"]) + noise,
        }
    )
    log_name = f"{Path(name).stem}_pressure.csv"
    write_table(log, out / log_name)
    write_manifest(
        out,
        pd.DataFrame(
            [
                {
                    "video": name,
                    "pressure_log": log_name,
                    "clock_offset_s": f"{clock_offset_s:g}",
                    "material": material,
                    "actuator": actuator,
                    "trial": trial,
                }
            ]
        ),
    )
    settings: dict[str, Any] = {
        "l0_mm": l0,
        "mm_per_px": float(sc.mm_per_px),
        **target_settings(sc),
        "fixed_end": [round(fixed_end[0], 2), round(fixed_end[1], 2)],
        "positive_turn": "ccw",
    }
    if sc.background_photo:  # the empty scene, filmed with the same camera and light
        empty = render_background(backdrop, sc, seed=child_seed(seed, mk, _BACKGROUND))
        atomic_write_bytes(out / BACKGROUND_IMAGE, encode_jpeg(empty, sc.jpeg_quality))
        settings["background"] = BACKGROUND_IMAGE
    write_settings(out, settings)
    truth = pd.DataFrame(
        {
            "image": name,
            "frame": np.arange(n_frames),
            "time_s": frame_t,
            "psi_deg": psi,
            "psi_image_deg": seen,
            "psi_static_deg": np.interp(frame_t, sim["time_s"], sim["psi_static_deg"]),
            "pressure_true_kpa": np.interp(frame_t, sim["time_s"], sim["pressure_kpa"]),
            "setpoint_kpa": np.interp(frame_t, sim["time_s"], sim["setpoint_kpa"]),
            "loading": np.interp(frame_t, sim["time_s"], sim["loading"].astype(float)) > 0.5,
        }
    ).assign(
        material=material,
        actuator=actuator,
        trial=trial,
        fps=fps,
        codec=codec,
        profile=profile.kind,
        tau_pressure_s=dyn.tau_pressure_s,
        tau_psi_s=dyn.tau_psi_s,
        psi0_deg=trial_actuator.psi0_deg,
        stiffness=trial_actuator.stiffness,
        hysteresis=trial_actuator.behaviour.hysteresis,
        l0_mm=l0,
        mm_per_px=sc.mm_per_px,
        width=sc.width,
        height=sc.height,
        seed=seed,
    )
    write_table(truth, out / TRUTH)
    return truth


class LiveActuator:
    """The same physics as :func:`simulate`, advanced in real time from observed pressures.

    Used by the synthetic video camera of the rig (``acquire --record video --camera synthetic``):
    each :meth:`psi_deg` call takes the time and the pressure the rig reports and returns the
    lagged angle with the hysteresis of :func:`static_psi_deg` (the peak restarts when vented).

    Examples
    --------
    >>> live = LiveActuator(toy_actuator(), tau_psi_s=0.0)
    >>> live.psi_deg(0.0, 0.0), live.psi_deg(1.0, 50.0), live.psi_deg(2.0, 25.0) < 210 - 2 * 25
    (210.0, 110.0, True)
    """

    def __init__(self, trial: TrialActuator, *, tau_psi_s: float = Dynamics().tau_psi_s) -> None:
        self.trial, self.tau_psi_s = trial, tau_psi_s
        self._peak = 0.0
        self._t: float | None = None
        self._psi = float(trial.psi_loading_deg(0.0))

    def psi_deg(self, t_s: float, pressure_kpa: float) -> float:
        """The angle (deg) at time ``t_s`` (s) when the actuator sees ``pressure_kpa``."""
        p = max(float(pressure_kpa), 0.0)
        self._peak = p if p < VENTED_KPA else max(self._peak, p)
        h = self.trial.behaviour.hysteresis
        equivalent = p + 4.0 * h * p * (self._peak - p) / self._peak if self._peak > 0 else p
        static = float(self.trial.psi_loading_deg(equivalent))
        if not math.isfinite(static):
            static = self._psi
        if self._t is None or self.tau_psi_s <= 0:
            self._psi = static
        else:
            self._psi = static + (self._psi - static) * math.exp(
                -max(t_s - self._t, 0.0) / self.tau_psi_s
            )
        self._t = t_s
        return self._psi
