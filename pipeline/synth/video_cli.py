"""``python -m pipeline synth-video OUT_DIR --material M ...``: render a synthetic video photo
set."""

from __future__ import annotations

import argparse
import time

from pipeline.errors import UserInputError


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """Options of ``synth-video`` (units in every help text)."""
    from pipeline.synth.presets import SCENE_PRESETS
    from pipeline.video.profile import PROFILES
    from pipeline.video.writer import CODECS

    parser.add_argument(
        "out_dir",
        metavar="OUT_DIR",
        help="video photo-set folder to write (created; its files are replaced)",
    )
    parser.add_argument(
        "--material", required=True, help="material of the virtual actuator: DS20, DS30, SS40, SS50"
    )
    parser.add_argument(
        "--profile",
        choices=PROFILES,
        default="ramp",
        help="pressure profile: ramp (0 -> max -> 0 at --rate-kpa-s) or steps (--step-kpa, "
             "--hold-s per level)",
    )
    parser.add_argument(
        "--max-kpa", type=float, default=200.0, help="top of the profile (kPa, default 200)"
    )
    parser.add_argument(
        "--rate-kpa-s", type=float, default=10.0, help="ramp rate (kPa/s, default 10)"
    )
    parser.add_argument(
        "--step-kpa", type=float, default=40.0, help="step height (kPa, default 40)"
    )
    parser.add_argument(
        "--hold-s", type=float, default=4.0, help="hold per step level (s, default 4)"
    )
    parser.add_argument(
        "--cycles", type=int, default=1, help="repetitions of the profile (default 1)"
    )
    parser.add_argument("--fps", type=float, default=30.0, help="frame rate (frames/s, default 30)")
    parser.add_argument(
        "--rest-s",
        type=float,
        default=1.0,
        help="video at rest before and after the profile (s, default 1)",
    )
    parser.add_argument(
        "--clock-offset-s",
        type=float,
        default=0.5,
        help="log time at which the video starts (s, default 0.5)",
    )
    parser.add_argument(
        "--log-hz",
        type=float,
        default=20.0,
        help="rows per second of the pressure log (default 20)",
    )
    parser.add_argument(
        "--tau-pressure-s",
        type=float,
        default=0.15,
        help="regulator lag, first order (s, default 0.15)",
    )
    parser.add_argument(
        "--tau-psi-s",
        type=float,
        default=0.4,
        help="actuator lag behind its static angle, first order (s, default 0.4)",
    )
    parser.add_argument(
        "--shutter-s",
        type=float,
        default=0.0,
        help="exposure time of a frame (s, at most 1/fps; default 0: instantaneous): a moving "
             "actuator is smeared over it, as a camera's 1/60 s smears a step response",
    )
    parser.add_argument(
        "--codec",
        choices=sorted(CODECS),
        default="mjpg",
        help="mjpg (default: what USB lab cameras record), mp4v, or h264 when this OpenCV can "
             "encode it",
    )
    parser.add_argument(
        "--scene", choices=sorted(SCENE_PRESETS), default="lab", help="scene preset (default lab)"
    )
    parser.add_argument(
        "--set",
        dest="scene_set",
        action="append",
        metavar="KEY=VALUE",
        help="scene knob, e.g. --set width=1280 --set height=720 (pipeline.synth.SceneParams); "
             "repeatable",
    )
    parser.add_argument(
        "--seed", type=int, default=1, help="random seed; same seed, same bytes (default 1)"
    )
    parser.add_argument(
        "--l0-mm",
        type=float,
        default=None,
        help="marked length (mm; default: the model's material file)",
    )
    parser.add_argument("--actuator", default="A1", help="actuator label (default A1)")
    parser.add_argument("--trial", default="1", help="trial label (default 1)")


def run(args: argparse.Namespace) -> int:
    """Render and print a one-line summary."""
    from pipeline.synth.cli import key_value_pairs
    from pipeline.synth.video import Dynamics, render_video
    from pipeline.video.profile import PressureProfile

    if args.cycles < 1:
        raise UserInputError("--cycles must be at least 1")
    profile = PressureProfile(
        args.profile,
        args.max_kpa,
        rate_kpa_s=args.rate_kpa_s,
        step_kpa=args.step_kpa,
        hold_s=args.hold_s,
        cycles=args.cycles,
    )
    t0 = time.perf_counter()
    truth = render_video(
        args.out_dir,
        args.material,
        profile=profile,
        fps=args.fps,
        rest_s=args.rest_s,
        clock_offset_s=args.clock_offset_s,
        scene=args.scene,
        scene_overrides=key_value_pairs(args.scene_set, "--set"),
        seed=args.seed,
        codec=args.codec,
        log_hz=args.log_hz,
        dynamics=Dynamics(args.tau_pressure_s, args.tau_psi_s),
        l0_mm=args.l0_mm,
        actuator=args.actuator,
        trial=args.trial,
        shutter_s=args.shutter_s,
    )
    dt = time.perf_counter() - t0
    print(
        f"synth-video: {len(truth)} frames ({len(truth) / args.fps:.1f} s at {args.fps:g} fps, "
        f"{args.codec}) of "
        f"{args.material}, {args.profile} to {args.max_kpa:g} kPa, psi "
        f"{truth['psi_deg'].min():.0f}..{truth['psi_deg'].max():.0f} "
        f"deg -> {args.out_dir} in {dt:.1f} s"
    )
    return 0
