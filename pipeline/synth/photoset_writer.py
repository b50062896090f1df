"""Render a whole synthetic campaign of one material as a photo set (DESIGN.md format + truth.csv).

Work is split per ramp (one actuator, one trial): the static backdrop (table, light, clamp, tube:
the same for every ramp, only the actuator's mounting angle varies) is built once per ramp and
ramps run in parallel processes.  Everything random is derived from ``seed`` and fixed keys
(material, actuator, trial, step), so the bytes written do not depend on ``jobs``.

Scenes with ``target: body`` write ``target: body`` and no line colour, the fixed end at the
body's centre line, optionally ``background.jpg`` (the empty scene, ``background_photo``) and a
per-photo ``fixed_direction_deg`` column (``known_fixed_direction``); their truth is the body's
centre line (``psi_image_deg``: its total turning as seen through the camera).

Examples
--------
>>> import tempfile, numpy as np
>>> toy = lambda material, p, branch="loading": 210.0 - 3.0 * np.asarray(p, float)
>>> truth = render_photoset(tempfile.mkdtemp(), "DS20", actuators=1, trials=1, step_kpa=70,
...                         scene="clean", scene_overrides={"width": 320, "height": 240},
...                         psi_fn=toy)
>>> truth[["pressure_kpa", "direction"]].values.tolist()[:3]
[[0.0, 'up'], [70.0, 'up'], [140.0, 'up']]
"""

from __future__ import annotations

import concurrent.futures
import dataclasses
import multiprocessing
import os
import signal
import zlib
from collections.abc import Mapping
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd
from numpy.typing import NDArray

from pipeline.errors import UserInputError
from pipeline.fileio import atomic_write_bytes, write_table
from pipeline.folders import staged_folder
from pipeline.photoset import MANIFEST, TRUTH, write_manifest, write_settings
from pipeline.synth.actuator import (
    ActuatorBehaviour,
    PsiFunction,
    behaviour_for,
    draw_actuator,
    draw_trial,
    loading_curve,
    plan_ramp,
)
from pipeline.synth.backdrop import make_backdrop
from pipeline.synth.camera import Camera, camera_for, make_camera
from pipeline.synth.centreline import actuator_centreline_mm
from pipeline.synth.presets import SceneParams, scene_from
from pipeline.synth.scene import (
    check_body_fits,
    child_seed,
    compose_photo,
    encode_jpeg,
    render_background,
    world_extent_mm,
)

#: seed streams (second key after the material)
_TABLE, _ACTUATOR, _TRIAL, _RAMP, _IMAGE, _LAYOUT, _BACKGROUND, _BOARD = range(8)
#: file name of the empty-scene photo of ``background_photo`` scenes
BACKGROUND_IMAGE = "background.jpg"
#: the checkerboard photo of a set rendered with ``board=True``
BOARD_PHOTO = "board.jpg"
DEFAULT_L0_MM = 195.0
LAYOUT_MARGIN_PX = 16


def material_key(material: str) -> int:
    """Stable integer key of a material name for seeding (CRC-32, not Python's salted hash)."""
    return zlib.crc32(material.encode()) & 0x7FFFFFFF


def target_settings(sc: SceneParams) -> dict[str, Any]:
    """What a photo set of scene ``sc`` measures: ``target: body`` for a body without a line,
    else the drawn line's ``line_color``.

    Examples
    --------
    >>> from pipeline.synth.presets import scene_from
    >>> target_settings(scene_from("green_fibre")), target_settings(scene_from("lab"))
    ({'target': 'body'}, {'line_color': 'black'})
    """
    return {"target": "body"} if sc.target == "body" else {"line_color": sc.line_color}


def image_name(
    material: str, actuator: str, trial: str, step: int, direction: str, pressure_kpa: float
) -> str:
    """File name of one photo, e.g. ``DS20_A1_t1_s003_up_30kPa.jpg``."""
    p = f"{pressure_kpa:g}".replace(".", "p")
    return f"{material}_{actuator}_t{trial}_s{step:03d}_{direction}_{p}kPa.jpg"


def default_l0_mm(material: str) -> float:
    """l0 of the material from ``pipeline.model.load_materials`` (195 mm if unknown)."""
    from pipeline.model import load_materials

    mats = load_materials()
    return float(mats[material].l0_mm) if material in mats else DEFAULT_L0_MM


def plan_photoset(
    material: str,
    *,
    actuators: int = 3,
    trials: int = 6,
    seed: int = 1,
    step_kpa: float = 10.0,
    max_kpa: float = 260.0,
    psi_fn: PsiFunction | None = None,
    behaviour: ActuatorBehaviour | None = None,
) -> pd.DataFrame:
    """Every photo of the campaign of one material with its true angle (no rendering).

    Returns
    -------
    pandas.DataFrame
        One row per photo: ``image, material, actuator, trial`` and the columns of
        :func:`pipeline.synth.actuator.plan_ramp`.
    """
    if actuators < 1 or trials < 1:
        raise UserInputError(f"actuators = {actuators} and trials = {trials} must be at least 1")
    beh = behaviour or behaviour_for(material)
    # headroom: the stiffest plausible actuator needs more pressure than the model for max_kpa
    curve = loading_curve(material, max_kpa=max_kpa * 1.6, psi_fn=psi_fn)
    mk = material_key(material)
    ramps = []
    for a in range(1, actuators + 1):
        act = draw_actuator(
            material, curve, beh, np.random.default_rng(child_seed(seed, mk, _ACTUATOR, a))
        )
        for t in range(1, trials + 1):
            rng = np.random.default_rng(child_seed(seed, mk, _TRIAL, a, t))
            trial = draw_trial(material, curve, beh, act, rng)
            ramp = plan_ramp(trial, step_kpa=step_kpa, max_kpa=max_kpa, rng=rng)
            ramp.insert(0, "trial", str(t))
            ramp.insert(0, "actuator", f"A{a}")
            ramp.insert(0, "material", material)
            ramps.append(ramp)
    df = pd.concat(ramps, ignore_index=True)
    df.insert(
        0,
        "image",
        [
            image_name(
                r.material, r.actuator, r.trial, int(r.step), r.direction, float(r.pressure_kpa)
            )
            for r in df.itertuples()
        ],
    )
    return df


def _sample_extents(
    plan: pd.DataFrame, l0_mm: float, scene: SceneParams, n_curves: int = 48
) -> list[np.ndarray]:
    order = plan.sort_values("psi_deg")
    pick = np.unique(
        np.round(np.linspace(0, len(order) - 1, min(n_curves, len(order)))).astype(int)
    )
    rows = order.iloc[pick]
    return [
        world_extent_mm(
            actuator_centreline_mm(float(r.psi_deg), l0_mm, scene, bulge=float(r.bulge), n=241),
            scene.body_width_mm,
            scene.tip_cap_mm,
            scene.sealed_end_mm,
        )
        for r in rows.itertuples()
    ]


def _rotate(points: np.ndarray, deg: float) -> np.ndarray:
    c, s = np.cos(np.radians(deg)), np.sin(np.radians(deg))
    return points @ np.array([[c, s], [-s, c]])


def choose_layout(
    extents_mm: list[np.ndarray], scene: SceneParams
) -> tuple[float, tuple[float, float], float]:
    """Clamp direction and fixed-end position that frame every shape of the campaign best.

    Tries clamp directions every 15 deg, keeps the one needing the least field of view (shapes
    widened by +-2.5 sd of the mounting jitter), then centres the union of the shapes.

    Returns
    -------
    rotation_deg : float
    fixed_end_px : (x, y)
        Fixed end before tilt (tilt is applied by the camera).
    need : float
        Field of view needed relative to the frame (<= 1: everything fits).
    """
    jit = 2.5 * scene.rotation_jitter_deg
    pts = np.vstack([_rotate(e, d) for e in extents_mm for d in ({-jit, 0.0, jit})])
    best: tuple[float, float, NDArray[np.float64]] | None = None
    for rot in np.arange(0.0, 360.0, 15.0):
        cam = Camera(scene.width, scene.height, scene.mm_per_px, float(rot), (0.0, 0.0), np.eye(3))
        px = cam.flat_px(pts)
        size = px.max(axis=0) - px.min(axis=0)
        need = max(
            size[0] / (scene.width - 2 * LAYOUT_MARGIN_PX),
            size[1] / (scene.height - 2 * LAYOUT_MARGIN_PX),
        )
        if best is None or need < best[0] - 1e-9:
            best = (need, float(rot), (px.max(axis=0) + px.min(axis=0)) / 2)
    assert best is not None  # the loop tries 24 directions
    _, rot, centre = best
    origin = np.array([scene.width / 2, scene.height / 2]) - centre
    for _ in range(3):  # centre the shapes as seen through the tilted camera
        px = camera_for(scene, rotation_deg=rot, origin_px=tuple(origin)).to_px(pts)
        lo, hi = px.min(axis=0), px.max(axis=0)
        origin = origin + np.array([scene.width / 2, scene.height / 2]) - (lo + hi) / 2
    size = hi - lo
    need = max(
        size[0] / (scene.width - 2 * LAYOUT_MARGIN_PX),
        size[1] / (scene.height - 2 * LAYOUT_MARGIN_PX),
    )
    return rot, (float(origin[0]), float(origin[1])), float(need)


def _worker_init() -> None:
    """Ctrl-C reaches the whole process group: a worker just stops, the main process cleans up."""
    signal.signal(signal.SIGINT, lambda signum, frame: os._exit(128 + signum))


def _render_ramp(task: dict[str, Any]) -> list[dict[str, Any]]:
    """Render and write the photos of one ramp (runs in a worker process)."""
    import cv2

    cv2.setNumThreads(1)
    scene: SceneParams = task["scene"]
    camera = make_camera(
        scene, rotation_deg=task["rotation_deg"], fixed_end_px=task["fixed_end_px"]
    )
    backdrop = _static_scene(
        scene,
        task["base_rotation_deg"],
        task["fixed_end_px"],
        task["table_seed"],
        task["keepout_mm"],
    )
    out_dir = Path(task["out_dir"])
    results = []
    for row in task["rows"]:
        pts = actuator_centreline_mm(row["psi_deg"], task["l0_mm"], scene, bulge=row["bulge"])
        rng = np.random.default_rng(child_seed(*task["image_seed"], row["step"]))
        r = compose_photo(pts, scene, camera, backdrop, scene.body_width_mm, rng)
        tmp = out_dir / f".{row['image']}.tmp"
        tmp.write_bytes(r.jpeg_bytes)
        os.replace(tmp, out_dir / row["image"])
        results.append(
            {
                "image": row["image"],
                "psi_image_deg": r.psi_image_deg,
                "line_in_frame": r.line_in_frame,
                "fixed_end_x": r.fixed_end_px[0],
                "fixed_end_y": r.fixed_end_px[1],
                "fixed_direction_deg": r.fixed_direction_deg,
            }
        )
    return results


def _static_scene(
    scene: SceneParams,
    rotation_deg: float,
    fixed_end_px: tuple[float, float],
    seed: Any,
    keepout_mm: list[np.ndarray],
) -> Any:
    """The backdrop every ramp shares (clamp at the base mounting angle), as a background photo
    shows it."""
    camera = make_camera(scene, rotation_deg=rotation_deg, fixed_end_px=fixed_end_px)
    return make_backdrop(scene, camera, seed=seed, keepout_mm=keepout_mm)


def render_photoset(
    out_dir: str | os.PathLike[str],
    material: str,
    *,
    actuators: int = 3,
    trials: int = 6,
    seed: int = 1,
    scene: str | SceneParams = "lab",
    step_kpa: float = 10.0,
    max_kpa: float = 260.0,
    scene_overrides: Mapping[str, Any] | None = None,
    jobs: int = 1,
    psi_fn: PsiFunction | None = None,
    behaviour: ActuatorBehaviour | None = None,
    l0_mm: float | None = None,
    overwrite: bool = True,
    fit_view: bool = True,
    board: bool = False,
) -> pd.DataFrame:
    """Render the pressure-ramp photos of ``actuators`` x ``trials`` of one material.

    Writes ``out_dir`` as a photo set (images, ``manifest.csv``, ``photoset.yaml`` with
    ``positive_turn: ccw`` -- psi > 0 turns counter-clockwise as seen on screen -- and the
    clamp's ``fixed_end``) plus ``truth.csv``.

    Parameters
    ----------
    out_dir : path
        Folder to write.  It is written under a temporary name beside it and renamed when
        complete (:func:`pipeline.folders.staged_folder`): an interrupted render leaves no partial
        set, and an existing synthetic set (one with ``truth.csv``) is replaced as a whole.
    material : str
        Material name (``DS20``, ``DS30``, ``SS40``, ``SS50`` or any name ``psi_fn`` knows).
    actuators, trials : int
        Campaign size (the paper: 3 x 6).
    seed : int
        Seeds everything; same seed, same bytes.
    scene : str or SceneParams
        Preset name or scene; ``scene_overrides`` are applied on top (see ``scene_from``).
    step_kpa, max_kpa : float
        Ramp protocol (kPa): steps up to ``max_kpa`` or psi <= -psi0, then back down.
    jobs : int
        Worker processes (one ramp per task).
    psi_fn : callable, optional
        Loading branch ``psi_fn(material, pressure_kpa, branch="loading")`` (deg); default
        ``pipeline.model.psi_deg``.
    behaviour : ActuatorBehaviour, optional
        Hysteresis and variability (default per material, ``actuator.BEHAVIOURS``).
    l0_mm : float, optional
        Marked length (default: the model's material file, else 195 mm).
    overwrite : bool
        Allow replacing a folder that already holds a synthetic photo set (a folder holding other
        files, such as a real photo set without ``truth.csv``, is never replaced).
    fit_view : bool
        When the campaign's shapes do not fit the frame at ``scene.mm_per_px``, increase
        ``mm_per_px`` just enough (the value used is written to ``photoset.yaml``).
    board : bool
        Also photograph a checkerboard lying in the actuator's plane with the same camera
        (``board.jpg``, :mod:`pipeline.synth.board`) and name it in ``photoset.yaml``'s
        ``calibration``.

    Returns
    -------
    pandas.DataFrame
        The contents of ``truth.csv``: ``image, psi_deg, psi_image_deg`` then the conditions.
    """
    out = Path(out_dir)
    if (out / MANIFEST).exists() and not overwrite:
        raise UserInputError(
            f"{out / MANIFEST} exists; choose an empty OUT_DIR or pass --overwrite"
        )
    if jobs < 1:
        raise UserInputError(f"jobs = {jobs} must be at least 1")
    sc = scene_from(scene, **dict(scene_overrides or {}))
    scene_name = scene if isinstance(scene, str) else "custom"
    l0 = float(l0_mm) if l0_mm is not None else default_l0_mm(material)
    plan = plan_photoset(material, actuators=actuators, trials=trials, seed=seed, step_kpa=step_kpa,
                         max_kpa=max_kpa, psi_fn=psi_fn, behaviour=behaviour)
    if sc.target == "body":  # refuse before writing anything: a folded body has no centre line
        for r in plan.loc[[plan["psi_deg"].idxmax(), plan["psi_deg"].idxmin()]].itertuples():
            check_body_fits(
                actuator_centreline_mm(float(r.psi_deg), l0, sc, bulge=float(r.bulge), n=4001), sc
            )
    extents = _sample_extents(plan, l0, sc)
    base_rot, fixed_flat, need = choose_layout(extents, sc)
    if need > 1.0 and fit_view:
        # zoom the camera out (as the experimenter would) until every shape is in the frame
        sc = dataclasses.replace(sc, mm_per_px=float(np.ceil(sc.mm_per_px * need * 1000) / 1000))
        base_rot, fixed_flat, need = choose_layout(extents, sc)
    # the fixed end as seen (after the tilt) of the chosen placement; the same for every ramp
    fixed_end_px = camera_for(sc, rotation_deg=base_rot, origin_px=fixed_flat).fixed_end_px
    jit = 2.5 * sc.rotation_jitter_deg
    keepout = [_rotate(e, d) for e in extents for d in ({-jit, 0.0, jit})]
    mk = material_key(material)
    with staged_folder(out, marker=TRUTH) as tmp:  # the set appears complete or not at all
        tasks = []
        for (act, trial), g in plan.groupby(["actuator", "trial"], sort=False):
            a, t = int(act[1:]), int(trial)
            rot = base_rot + float(
                np.random.default_rng(child_seed(seed, mk, _RAMP, a, t)).normal(
                    0, sc.rotation_jitter_deg
                )
            )
            tasks.append(
                {
                    "scene": sc,
                    "rotation_deg": rot,
                    "base_rotation_deg": base_rot,
                    "fixed_end_px": fixed_end_px,
                    "keepout_mm": keepout,
                    "table_seed": child_seed(seed, mk, _TABLE),
                    "out_dir": str(tmp),
                    "l0_mm": l0,
                    "image_seed": (child_seed(seed, mk, _IMAGE, a, t),),
                    "rows": g[["image", "psi_deg", "bulge", "step"]].to_dict("records"),
                }
            )
        if jobs == 1 or len(tasks) == 1:
            results = [_render_ramp(task) for task in tasks]
        else:
            ctx = multiprocessing.get_context("spawn")
            pool = concurrent.futures.ProcessPoolExecutor(
                max_workers=jobs, mp_context=ctx, initializer=_worker_init
            )
            try:
                results = list(pool.map(_render_ramp, tasks))
            finally:  # on Ctrl-C/SIGTERM: drop the ramps not started, wait for the (dead) workers
                pool.shutdown(wait=True, cancel_futures=True)
        rendered = pd.DataFrame([r for res in results for r in res])
        truth = plan.merge(rendered, on="image", how="left", validate="one_to_one")
        truth = truth.assign(
            scene=scene_name,
            l0_mm=l0,
            mm_per_px=sc.mm_per_px,
            line_color=sc.line_color,
            noise_sigma=sc.noise_sigma,
            blur_sigma_px=sc.blur_sigma_px,
            tilt_deg=sc.tilt_deg,
            jpeg_quality=sc.jpeg_quality,
            occluded_fraction=sc.occluded_fraction,
            seed=seed,
            target=sc.target,
            shape=sc.shape,
            marker_line=sc.marker_line,
            body_width_mm=sc.body_width_mm,
            body_translucency=sc.body_translucency,
            texture=sc.texture,
            dots=sc.dots,
            clamp_style=sc.clamp_style,
            lens_k1=sc.lens_k1,
        )
        first = [
            "image",
            "psi_deg",
            "psi_image_deg",
            "material",
            "actuator",
            "trial",
            "step",
            "pressure_kpa",
            "direction",
            "bulge",
        ]
        truth = truth[first + [c for c in truth.columns if c not in first]]
        columns = ["image", "pressure_kpa", "direction", "material", "actuator", "trial", "step"]
        manifest = truth[
            columns + (["fixed_direction_deg"] if sc.known_fixed_direction else [])
        ].round({"fixed_direction_deg": 3})
        write_manifest(tmp, manifest)
        settings: dict[str, Any] = {"l0_mm": l0, "mm_per_px": float(sc.mm_per_px)}
        if sc.target == "body":
            # the fixed end of the body's centre line, at the clamp face (base mounting angle)
            base = camera_for(sc, rotation_deg=base_rot, origin_px=fixed_flat)
            end_x, end_y = base.to_px([[0.0, sc.body_width_mm / 2]])[0]
            fixed_end_px = (float(end_x), float(end_y))
        settings.update(target_settings(sc))
        settings.update(
            {
                "fixed_end": [round(fixed_end_px[0], 2), round(fixed_end_px[1], 2)],
                "positive_turn": "ccw",
            }
        )
        if sc.background_photo:
            backdrop = _static_scene(
                sc, base_rot, tasks[0]["fixed_end_px"], child_seed(seed, mk, _TABLE), keepout
            )
            image = render_background(backdrop, sc, seed=child_seed(seed, mk, _BACKGROUND))
            atomic_write_bytes(tmp / BACKGROUND_IMAGE, encode_jpeg(image, sc.jpeg_quality))
            settings["background"] = BACKGROUND_IMAGE
        if board:
            from pipeline.synth.board import write_board_photo

            del settings["mm_per_px"]  # the board gives the scale (truth.csv keeps the scene's)
            settings["calibration"] = write_board_photo(
                tmp / BOARD_PHOTO,
                sc,
                make_camera(sc, rotation_deg=base_rot, fixed_end_px=tasks[0]["fixed_end_px"]),
                seed=child_seed(seed, mk, _BOARD),
            )
        write_settings(tmp, settings)
        write_table(truth, tmp / TRUTH)
    return truth
