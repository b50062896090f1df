"""``python -m pipeline acquire``: run the pressure ramp on a rig and write a photo set.

Example (a complete virtual rig: emulator in one terminal, acquisition in another)::

    python -m pipeline rig emulate            # prints: PORT /dev/pts/5
    python -m pipeline acquire --port /dev/pts/5 --camera synthetic --material DS20 \\
        --actuator A1 --trials 6 --step-kpa 10 --max-kpa 260 --settle-s 2 --out photos/DS20_A1

Re-running the same command on the same ``--out`` resumes at the first missing step.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path
from typing import Any

from pipeline.constants import PSI0_DEG
from pipeline.errors import UserInputError
from pipeline.rig.acquire import (
    EXIT_CODES,
    SessionConfig,
    describe_plan,
    psi0_stop_criterion,
    run_session,
    trial_plans,
)


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """Options of ``acquire`` (units in every help text)."""
    parser.add_argument(
        "--port",
        help="serial port of the Pico (e.g. /dev/ttyACM0, COM3, or the pty printed by 'rig "
             "emulate'); not needed with --dry-run",
    )
    parser.add_argument(
        "--camera",
        default="synthetic",
        help="camera: device index (0), stream URL, 'cmd:COMMAND ... {path}', 'dir:FOLDER', or "
             "'synthetic[:clean|lab|hard]' (default: synthetic)",
    )
    parser.add_argument(
        "--material", required=True, help="material label written to the manifest (e.g. DS20)"
    )
    parser.add_argument(
        "--actuator", required=True, help="actuator label written to the manifest (e.g. A1)"
    )
    parser.add_argument(
        "--trials", type=int, default=6, help="number of up-and-down ramps (default 6)"
    )
    parser.add_argument(
        "--step-kpa", type=float, default=10.0, help="pressure step (kPa, default 10)"
    )
    parser.add_argument(
        "--max-kpa",
        type=float,
        default=260.0,
        help="top of the ramp and host-side limit: higher setpoints are refused before sending "
             "(kPa, default 260)",
    )
    parser.add_argument(
        "--settle-s",
        type=float,
        default=2.0,
        help="wait after each setpoint before measuring and photographing (s, default 2)",
    )
    parser.add_argument(
        "--out", required=True, type=Path, help="photo-set folder to write (resumed if it exists)"
    )
    parser.add_argument(
        "--mode",
        choices=("bending", "blocked"),
        default="bending",
        help="bending: photos; blocked: photos plus load-cell samples per step (force_n, "
             "force_sd_n, force_samples columns)",
    )
    parser.add_argument(
        "--force-samples",
        type=int,
        default=10,
        help="load-cell readings averaged per step in blocked mode (count, default 10)",
    )
    parser.add_argument(
        "--force-interval-s",
        type=float,
        default=0.0,
        help="time between load-cell readings (s, default 0: as fast as the HX711 gives them)",
    )
    parser.add_argument(
        "--no-tare",
        action="store_true",
        help="blocked mode: do not tare the load cell (vented) at the start of each trial",
    )
    parser.add_argument(
        "--dry-run",
        action="store_true",
        help="print the plan (ramp, what is recorded, where each trial resumes, duration) and exit",
    )
    parser.add_argument(
        "--calibration",
        type=Path,
        help="regulator calibration file from 'rig calibrate' (kPa <-> DAC code; YAML)",
    )
    parser.add_argument(
        "--l0-mm",
        type=float,
        help="length of the marked inextensible layer (mm; default: the material's l0 from the "
             "model data)",
    )
    parser.add_argument(
        "--mm-per-px",
        type=float,
        help="image scale (mm per pixel; default: measured from the line length)",
    )
    parser.add_argument(
        "--line-color",
        default="black",
        help="colour of the marked line: black, blue, red, green or an HSV range 'h,s,v-h,s,v' "
             "(default black)",
    )
    parser.add_argument(
        "--fixed-end", default="auto", help="pixel 'x,y' near the clamped end, or 'auto' (default)"
    )
    parser.add_argument(
        "--positive-turn",
        choices=("ccw", "cw"),
        default="ccw",
        help="turning direction on screen, from fixed to free end, counted as positive psi "
             "(default ccw)",
    )
    parser.add_argument(
        "--stop-at-psi0",
        action=argparse.BooleanOptionalAction,
        default=None,
        help="end the up leg when the live-measured psi reaches -psi0 (default: on with the "
             "synthetic camera)",
    )
    parser.add_argument(
        "--psi0-deg",
        type=float,
        help="rest bending angle psi0 for --stop-at-psi0 (deg; default: the material's, else the "
             "paper's 210)",
    )
    parser.add_argument(
        "--watchdog-s",
        type=float,
        help="the Pico vents by itself when the host sends nothing for this long, e.g. a pulled "
             "cable "
        "(s; default 3 x settle + camera timeout + 10; 0 = off)",
    )
    parser.add_argument(
        "--timeout-s",
        type=float,
        default=2.0,
        help="longest wait for one reply from the Pico before the port counts as lost (s, default "
             "2)",
    )
    parser.add_argument(
        "--camera-timeout-s",
        type=float,
        default=30.0,
        help="longest wait for a photo (s, default 30)",
    )
    parser.add_argument(
        "--seed", type=int, default=0, help="seed of the synthetic camera's noise (default 0)"
    )
    video = parser.add_argument_group("continuous recording (--record video)")
    video.add_argument(
        "--record",
        choices=("photos", "video"),
        default="photos",
        help="photos: a stepped ramp, one photo per settled step (default); video: a continuous "
             "ramp or "
        "steps filmed as a video with frame timestamps while the pressure is logged (a video photo "
        "set)",
    )
    video.add_argument(
        "--profile",
        choices=("ramp", "steps"),
        default="ramp",
        help="video: ramp 0 -> --max-kpa -> 0 at --rate-kpa-s, or steps of --step-kpa held "
             "--hold-s (default ramp)",
    )
    video.add_argument(
        "--rate-kpa-s", type=float, default=5.0, help="video: ramp rate (kPa/s, default 5)"
    )
    video.add_argument(
        "--hold-s", type=float, default=4.0, help="video: hold per step level (s, default 4)"
    )
    video.add_argument(
        "--cycles",
        type=int,
        default=1,
        help="video: repetitions of the profile per trial (default 1)",
    )
    video.add_argument(
        "--log-hz",
        type=float,
        default=20.0,
        help="video: GET (pressure log) rate (rows per second, default 20)",
    )
    video.add_argument(
        "--fps",
        type=float,
        default=30.0,
        help="video: camera frame rate (frames per second, default 30)",
    )
    video.add_argument(
        "--rest-s",
        type=float,
        default=1.0,
        help="video: recorded at 0 kPa before and after the profile (s, default 1)",
    )
    video.add_argument(
        "--video-size",
        default="480x360",
        help="video, synthetic camera: frame size WIDTHxHEIGHT (px, default 480x360)",
    )
    parser.add_argument("--progress", action=argparse.BooleanOptionalAction, default=None,
                        help="show the progress bar (default: only on a terminal)")


def _material_defaults(material: str) -> Any:
    from pipeline.model import load_materials  # ~0.5 s: only when a default is needed

    return load_materials().get(material)


def _settings(args: argparse.Namespace) -> dict[str, Any]:
    l0 = args.l0_mm
    if l0 is None:  # importing the model costs ~0.5 s: only when needed
        mat = _material_defaults(args.material)
        l0 = mat.l0_mm if mat is not None else None
    if l0 is None or l0 <= 0:
        raise UserInputError(
            f"--l0-mm is needed (material {args.material!r} has no default l0): give the marked "
            "layer's length in mm"
        )
    fixed_end: Any = args.fixed_end
    if fixed_end != "auto":
        try:
            x, y = (float(v) for v in fixed_end.split(","))
        except ValueError as exc:
            raise UserInputError(
                f"--fixed-end {fixed_end!r}: use 'auto' or 'x,y' in pixels"
            ) from exc
        fixed_end = [x, y]
    out: dict[str, Any] = {
        "l0_mm": float(l0),
        "line_color": args.line_color,
        "fixed_end": fixed_end,
        "positive_turn": args.positive_turn,
    }
    if args.mm_per_px is not None:
        out["mm_per_px"] = float(args.mm_per_px)
    return out


def _check_numbers(args: argparse.Namespace) -> None:
    for name in ("trials", "force_samples"):
        if getattr(args, name) < 1:
            raise UserInputError(f"--{name.replace('_', '-')} must be at least 1")
    for name in ("step_kpa", "max_kpa"):
        if not getattr(args, name) > 0:
            raise UserInputError(f"--{name.replace('_', '-')} must be positive (kPa)")
    if (
        args.settle_s < 0
        or args.force_interval_s < 0
        or (args.watchdog_s is not None and args.watchdog_s < 0)
    ):
        raise UserInputError("--settle-s, --force-interval-s and --watchdog-s must be >= 0 (s)")


def run(args: argparse.Namespace) -> int:
    """Run the acquisition; exit status 0 done, 2 bad input, else see
    ``pipeline.rig.acquire.EXIT_CODES``."""
    _check_numbers(args)
    settings = _settings(args)
    cfg = SessionConfig(
        out_dir=args.out,
        material=args.material,
        actuator=args.actuator,
        trials=args.trials,
        step_kpa=args.step_kpa,
        max_kpa=args.max_kpa,
        settle_s=args.settle_s,
        settings=settings,
        mode=args.mode,
        force_samples=args.force_samples,
        force_interval_s=args.force_interval_s,
        tare=not args.no_tare,
        watchdog_s=args.watchdog_s
        if args.watchdog_s is not None
        else 3 * args.settle_s + args.camera_timeout_s + 10,
    )
    if args.record == "video":
        return _acquire_video(args, settings)
    synthetic = args.camera.strip().startswith("synthetic")
    wants_stop = (
        args.stop_at_psi0
        if args.stop_at_psi0 is not None
        else (synthetic and args.mode == "bending")
    )
    stop_at_psi0 = bool(wants_stop)
    trial_plans(cfg)  # a folder begun with another ramp is refused before any port is opened
    if args.dry_run:
        print(
            describe_plan(
                cfg, stop_at_psi0=stop_at_psi0, camera_spec=args.camera, port=args.port or ""
            )
        )
        return 0
    if not args.port:
        raise UserInputError(
            "--port is required (the Pico's serial port, or the pty printed by 'python -m pipeline "
            "rig emulate')"
        )

    from pipeline.rig.calibration import read_calibration

    calibration = read_calibration(args.calibration) if args.calibration else None
    psi0 = args.psi0_deg
    if psi0 is None:
        mat = _material_defaults(args.material)
        psi0 = mat.psi0_deg if mat is not None else PSI0_DEG
    stop_up = psi0_stop_criterion(psi0) if stop_at_psi0 else None
    try:
        return _acquire(args, cfg, calibration, stop_up, settings)
    except KeyboardInterrupt:
        print(
            "acquire: interrupted before the ramp started (nothing was pressurised by this run)",
            file=sys.stderr,
        )
        return EXIT_CODES["interrupted"]


def _acquire(
    args: argparse.Namespace,
    cfg: SessionConfig,
    calibration: Any,
    stop_up: Any,
    settings: dict[str, Any],
) -> int:
    from pipeline.rig.cameras import CameraError, open_camera
    from pipeline.rig.driver import PicoDriver, RigError, UnsupportedError

    try:
        camera = open_camera(
            args.camera,
            material=args.material,
            l0_mm=settings["l0_mm"],
            seed=args.seed,
            timeout_s=args.camera_timeout_s,
            mode=args.mode,
        )
    except CameraError as exc:
        print(f"acquire: camera failed: {exc}", file=sys.stderr)
        return EXIT_CODES["camera"]
    try:
        try:
            driver = PicoDriver.open(
                args.port, max_kpa=args.max_kpa, calibration=calibration, timeout_s=args.timeout_s
            )
        except UnsupportedError:
            raise  # an option this firmware cannot honour: bad input (exit 2), not a lost port
        except RigError as exc:
            print(f"acquire: {exc}", file=sys.stderr)
            return EXIT_CODES["port_lost"]
        try:
            result = run_session(driver, camera, cfg, stop_up=stop_up, progress=args.progress)
        finally:
            driver.close()
    finally:
        camera.close()
    return result.exit_code  # the session has said what it did ("acquire: done: ...")


def _acquire_video(args: argparse.Namespace, settings: dict[str, Any]) -> int:
    """``--record video``: record each trial as a video with its pressure log
    (pipeline.rig.record_video)."""
    from pipeline.rig.record_video import VideoSessionConfig, describe_video_plan, run_video_session
    from pipeline.video.profile import PressureProfile

    for name in ("log_hz", "fps"):
        if not getattr(args, name) > 0:
            raise UserInputError(f"--{name.replace('_', '-')} must be positive")
    if args.rest_s < 0:
        raise UserInputError("--rest-s must be >= 0 (s)")
    profile = PressureProfile(
        args.profile,
        args.max_kpa,
        rate_kpa_s=args.rate_kpa_s,
        step_kpa=args.step_kpa,
        hold_s=args.hold_s,
        cycles=args.cycles,
    )
    cfg = VideoSessionConfig(
        out_dir=args.out,
        material=args.material,
        actuator=args.actuator,
        trials=args.trials,
        profile=profile,
        log_hz=args.log_hz,
        fps=args.fps,
        rest_s=args.rest_s,
        settings=settings,
        watchdog_s=args.watchdog_s if args.watchdog_s is not None else 3 * args.rest_s + 10,
    )
    if args.dry_run:
        print(describe_video_plan(cfg, camera_spec=args.camera, port=args.port or ""))
        return 0
    if not args.port:
        raise UserInputError(
            "--port is required (the Pico's serial port, or the pty printed by 'python -m pipeline "
            "rig emulate')"
        )
    from pipeline.rig.calibration import read_calibration
    from pipeline.rig.cameras import CameraError
    from pipeline.rig.driver import PicoDriver, RigError
    from pipeline.rig.video_cameras import open_recorder, parse_size

    calibration = read_calibration(args.calibration) if args.calibration else None
    try:
        recorder = open_recorder(
            args.camera,
            material=args.material,
            l0_mm=settings["l0_mm"],
            fps=args.fps,
            max_kpa=args.max_kpa,
            seed=args.seed,
            size=parse_size(args.video_size),
        )
    except CameraError as exc:
        print(f"acquire: camera failed: {exc}", file=sys.stderr)
        return EXIT_CODES["camera"]
    try:
        try:
            driver = PicoDriver.open(
                args.port, max_kpa=args.max_kpa, calibration=calibration, timeout_s=args.timeout_s
            )
        except RigError as exc:
            print(f"acquire: {exc}", file=sys.stderr)
            return EXIT_CODES["port_lost"]
        try:
            result = run_video_session(driver, recorder, cfg)
        finally:
            driver.close()
    finally:
        recorder.close()
    return result.exit_code  # the session has said what it did ("acquire: done: ...")
