"""``python -m pipeline synth OUT_DIR ...``: render a synthetic pressure-ramp photo set."""

from __future__ import annotations

import argparse
import dataclasses
import time

from pipeline.errors import UserInputError


def key_value_pairs(values: list[str] | None, what: str) -> dict[str, str]:
    """``KEY=VALUE`` command-line items as a dict (``what`` names the option in the error).

    Examples
    --------
    >>> key_value_pairs(["shadow=0.5", " width = 640"], "--set")
    {'shadow': '0.5', 'width': '640'}
    """
    out: dict[str, str] = {}
    for item in values or []:
        key, sep, value = item.partition("=")
        if not sep or not key.strip():
            raise UserInputError(f"{what} {item!r} must look like KEY=VALUE (e.g. noise_sigma=4)")
        out[key.strip()] = value.strip()
    return out


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """Define the ``synth`` options."""
    from pipeline.synth.presets import SCENE_PRESETS

    parser.add_argument(
        "out_dir",
        metavar="OUT_DIR",
        help="photo-set folder to write; it appears only when complete (a previous synthetic set "
             "there is replaced)",
    )
    parser.add_argument(
        "--material",
        required=True,
        help="material name: DS20, DS30, SS40, SS50 (model's materials)",
    )
    parser.add_argument("--actuators", type=int, default=3, help="number of actuators (default 3)")
    parser.add_argument("--trials", type=int, default=6, help="ramps per actuator (default 6)")
    parser.add_argument(
        "--seed", type=int, default=1, help="random seed; same seed, same bytes (default 1)"
    )
    parser.add_argument(
        "--scene",
        default="lab",
        choices=sorted(SCENE_PRESETS),
        help="scene preset (default lab): clean, lab, hard draw the marker line; green_fibre, "
             "grey_dots, "
        "grey_dots_clear, dark_translucent are bodies without a line (photo sets say target: body)",
    )
    parser.add_argument(
        "--step-kpa", type=float, default=10.0, help="pressure step in kPa (default 10)"
    )
    parser.add_argument(
        "--max-kpa",
        type=float,
        default=260.0,
        help="highest pressure in kPa; the ramp also turns back at psi = -psi0 (default 260)",
    )
    parser.add_argument(
        "--l0-mm",
        type=float,
        default=None,
        help="length of the marked layer in mm (default: the model's material file)",
    )
    parser.add_argument(
        "--jobs", type=int, default=1, help="worker processes, one ramp each (default 1)"
    )
    parser.add_argument(
        "--set",
        dest="scene_set",
        action="append",
        metavar="KEY=VALUE",
        help="override a scene knob, e.g. --set noise_sigma=4 --set width=640 --set height=480 "
        "(see pipeline.synth.SceneParams for keys and units); repeatable",
    )
    parser.add_argument(
        "--board",
        action="store_true",
        help="also photograph a checkerboard in the actuator's plane (board.jpg) and name it in "
        "photoset.yaml's calibration (try with --set tilt_deg=6 --set lens_k1=-0.1)",
    )
    parser.add_argument(
        "--behaviour",
        dest="behaviour_set",
        action="append",
        metavar="KEY=VALUE",
        help="override the virtual actuator's variability, e.g. --behaviour hysteresis=0.1 "
        "(fraction, 0-0.25), psi0_sd_deg=3 (deg), stiffness_sd=0.04, photo_sd_deg=1 (deg), "
        "bulge_max=0.3; repeatable",
    )


def run(args: argparse.Namespace) -> int:
    """Render the photo set and print a one-line summary."""
    from pipeline.synth.actuator import ActuatorBehaviour, behaviour_for
    from pipeline.synth.photoset_writer import render_photoset

    fields = {f.name for f in dataclasses.fields(ActuatorBehaviour)}
    beh_raw = key_value_pairs(args.behaviour_set, "--behaviour")
    unknown = sorted(set(beh_raw) - fields)
    if unknown:
        raise UserInputError(f"--behaviour key(s) {unknown} unknown; valid keys: {sorted(fields)}")
    try:
        beh = behaviour_for(args.material, **{k: float(v) for k, v in beh_raw.items()})
    except ValueError as exc:
        if isinstance(exc, UserInputError):
            raise
        raise UserInputError(f"--behaviour values must be numbers ({exc})") from exc
    t0 = time.perf_counter()
    truth = render_photoset(
        args.out_dir,
        args.material,
        actuators=args.actuators,
        trials=args.trials,
        seed=args.seed,
        scene=args.scene,
        step_kpa=args.step_kpa,
        max_kpa=args.max_kpa,
        scene_overrides=key_value_pairs(args.scene_set, "--set"),
        jobs=args.jobs,
        behaviour=beh,
        l0_mm=args.l0_mm,
        board=args.board,
    )
    dt = time.perf_counter() - t0
    outside = int((~truth["line_in_frame"].astype(bool)).sum())
    print(
        f"synth: {len(truth)} images of {args.material} ({args.actuators} actuators x "
        f"{args.trials} trials, "
        f"scene {args.scene}, psi {truth['psi_deg'].min():.0f}..{truth['psi_deg'].max():.0f} deg) "
        f"-> {args.out_dir} "
        f"in {dt:.1f} s ({len(truth) / dt:.0f} images/s)"
        + (
            f"; {outside} photo(s) with the {truth['target'].iloc[0]} partly outside the frame"
            if outside
            else ""
        )
    )
    return 0
