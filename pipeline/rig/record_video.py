"""Record a continuous ramp on the rig: the pressure profile, a pressure log and a timed video.

For every trial (``acquire --record video``): vent and rest, start the camera's recorder, then
drive the :class:`~pipeline.video.profile.PressureProfile` (a continuous ramp, or steps) in a
control loop at ``log_hz``: each tick sends ``SET`` when the setpoint changes and logs a ``GET``
(``time_s, pressure_kpa`` = the setpoint asked for, ``measured_kpa`` = the regulator's monitor),
stamped with the same monotonic clock as the frames; after the profile and a rest, stop the
recorder and write the trial as one row of a video manifest (``clock_offset_s`` 0, the frame
times in their own file), so the folder is a video photo set (:mod:`pipeline.video`).

Files of a trial: ``<material>_<actuator>_t<trial>_<profile>.avi``, ``..._pressure.csv`` and
``..._frames.csv``; while recording they carry a ``.partial`` suffix and only a finished trial
is renamed and listed.  Whatever stops a trial (e-stop, lost port, camera failure, Ctrl-C) vents
the rig (as the photo acquisition does, same exit codes), keeps what was recorded as
``*.interrupted.*`` files for inspection, and a re-run records that trial again; finished trials
are skipped.
"""

from __future__ import annotations

import os
import sys
import time
import traceback
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, TextIO

import pandas as pd

from pipeline.errors import UserInputError
from pipeline.fileio import write_table
from pipeline.photoset import MANIFEST, append_manifest_rows, is_video_manifest, write_settings
from pipeline.rig import session
from pipeline.rig.acquire import SessionResult, _Interrupts, failure_status
from pipeline.rig.cameras import CameraError
from pipeline.rig.driver import PicoDriver
from pipeline.rig.video_cameras import VideoRecorder
from pipeline.video.profile import PressureProfile


@dataclass(frozen=True)
class VideoSessionConfig:
    """A video acquisition (the CLI options).

    Attributes
    ----------
    out_dir : Path
        Video photo-set folder (created, or resumed).
    material, actuator : str
        Manifest labels.
    trials : int
        Recordings (trials 1..trials).
    profile : PressureProfile
        The pressure against time of each recording.
    log_hz : float
        Control and logging rate (ticks per second).
    fps : float
        Camera frame rate asked for (frames per second).
    rest_s : float
        Recorded at 0 kPa before and after the profile (s).
    settings : dict
        ``photoset.yaml`` values.
    watchdog_s : float
        Device watchdog (s; 0 = off).
    """

    out_dir: Path
    material: str
    actuator: str
    trials: int
    profile: PressureProfile
    log_hz: float = 20.0
    fps: float = 30.0
    rest_s: float = 1.0
    settings: dict[str, Any] = field(default_factory=dict)
    watchdog_s: float = 0.0

    def names(self, trial: int) -> tuple[str, str, str]:
        """Video, pressure-log and frame-times file names of one trial."""
        stem = f"{self.material}_{self.actuator}_t{trial}_{self.profile.kind}"
        return f"{stem}.avi", f"{stem}_pressure.csv", f"{stem}_frames.csv"


def recorded_trials(cfg: VideoSessionConfig) -> set[int]:
    """Trials of this material/actuator already in the folder's video manifest (video present).

    Raises
    ------
    UserInputError
        If the folder holds a photo manifest (not written by a video acquisition).
    """
    path = cfg.out_dir / MANIFEST
    if not path.is_file():
        return set()
    df = pd.read_csv(path, dtype=str)
    if not is_video_manifest(df):
        raise UserInputError(
            f"{path}: lists photos, not videos; record videos into a new --out folder"
        )
    mine = df[(df["material"] == cfg.material) & (df["actuator"] == cfg.actuator)]
    return {
        int(t)
        for t, v in zip(mine["trial"], mine["video"])
        if str(t).isdigit() and (cfg.out_dir / str(v)).is_file()
    }


def describe_video_plan(cfg: VideoSessionConfig, *, camera_spec: str = "", port: str = "") -> str:
    """The ``--dry-run`` text of a video acquisition."""
    p = cfg.profile
    shape = (f"ramp 0 -> {p.max_kpa:g} -> 0 kPa at {p.rate_kpa_s:g} kPa/s" if p.kind == "ramp" else
             f"steps of {p.step_kpa:g} kPa to {p.max_kpa:g} kPa and back, {p.hold_s:g} s each")
    done = recorded_trials(cfg)
    todo = [t for t in range(1, cfg.trials + 1) if t not in done]
    seconds = len(todo) * (p.duration_s + 2 * cfg.rest_s)
    return "\n".join(
        [
            (f"acquire plan (video): {cfg.material} actuator {cfg.actuator}, {cfg.trials} "
             f"trial(s), port {port or '-'}, "
            f"camera {camera_spec or '-'} at {cfg.fps:g} fps"),
            f"  out: {cfg.out_dir}",
            (f"  profile: {shape}, x{p.cycles} ({p.duration_s:g} s), {cfg.rest_s:g} s at rest "
             "before and after; "
            f"pressure logged at {cfg.log_hz:g} Hz"),
            "  photoset.yaml: " + ", ".join(f"{k}={v}" for k, v in cfg.settings.items()),
            (
                f"  recorded: {sorted(done) or 'none'}; to do: trials {todo or 'none'}, about "
                f"{seconds / 60:.1f} min"
            ),
        ]
    )


def _record_trial(driver: PicoDriver, recorder: VideoRecorder, cfg: VideoSessionConfig, trial: int,
                  interrupts: _Interrupts, result: SessionResult) -> None:
    video, log_name, frames_name = cfg.names(trial)
    partial = [cfg.out_dir / f"{n}.partial{Path(n).suffix}" for n in (video, log_name, frames_name)]
    log_rows: list[tuple[float, float, float]] = []
    period = 1.0 / cfg.log_hz
    end_s = cfg.rest_s + cfg.profile.duration_s + cfg.rest_s
    driver.vent()
    driver.sleep(cfg.rest_s)
    t0 = time.monotonic()

    def log_get(setpoint: float) -> None:
        before = time.monotonic()
        reading = driver.get()
        recorder.observe(reading.measured_kpa)
        log_rows.append(((before + time.monotonic()) / 2 - t0, setpoint, reading.measured_kpa))

    log_get(0.0)  # the log starts before the first frame and ends after the last
    recorder.start(partial[0], t0)
    try:
        last = None
        tick = 0
        while True:
            t = tick * period
            if t > end_s + 1e-9:
                break
            driver.sleep(max(0.0, t0 + t - time.monotonic()))
            setpoint = float(cfg.profile.setpoint_kpa(t - cfg.rest_s))
            if last is None or abs(setpoint - last) > 1e-9:
                driver.set_kpa(setpoint)
                last = setpoint
            log_get(setpoint)
            check = getattr(recorder, "check", None)
            if check is not None:
                check()
            tick += 1
        times = recorder.stop()
        log_get(float(cfg.profile.setpoint_kpa(time.monotonic() - t0 - cfg.rest_s)))
    except BaseException:
        _keep_interrupted(recorder, partial, log_rows, cfg)
        raise
    driver.vent()
    with interrupts.held():
        write_table(
            pd.DataFrame(log_rows, columns=["time_s", "pressure_kpa", "measured_kpa"]),
            partial[1],
            float_format="%.4f",
        )
        write_table(
            pd.DataFrame({"frame": range(len(times)), "time_s": times}),
            partial[2],
            float_format="%.4f",
        )
        for src, name in zip(partial, (video, log_name, frames_name)):
            os.replace(src, cfg.out_dir / name)
        append_manifest_rows(
            cfg.out_dir,
            [
                {
                    "video": video,
                    "pressure_log": log_name,
                    "frame_times": frames_name,
                    "clock_offset_s": "0",
                    "material": cfg.material,
                    "actuator": cfg.actuator,
                    "trial": str(trial),
                }
            ],
        )
    result.photos_taken += len(times)


def _keep_interrupted(
    recorder: VideoRecorder,
    partial: list[Path],
    log_rows: list[tuple[float, float, float]],
    cfg: VideoSessionConfig,
) -> None:
    """After a stop: close the recording, keep what was recorded as ``*.interrupted.*`` files."""
    try:
        times = recorder.stop()
    except CameraError:
        times = []
    if log_rows:
        write_table(
            pd.DataFrame(log_rows, columns=["time_s", "pressure_kpa", "measured_kpa"]),
            partial[1],
            float_format="%.4f",
        )
    write_table(
        pd.DataFrame({"frame": range(len(times)), "time_s": times}), partial[2], float_format="%.4f"
    )
    for p in partial:
        if p.is_file():
            os.replace(p, p.with_name(p.name.replace(".partial", ".interrupted")))


def run_video_session(driver: PicoDriver, recorder: VideoRecorder, cfg: VideoSessionConfig, *,
                      stream: TextIO | None = None) -> SessionResult:
    """Record (or resume) every trial; never raises for rig, camera or interrupt failures.

    Returns
    -------
    SessionResult
        ``photos_taken`` counts the frames recorded in this run, ``steps_skipped`` the trials
        already recorded; ``status`` is one of :data:`pipeline.rig.acquire.EXIT_CODES`.
    """
    stream = stream or sys.stderr
    result = SessionResult()
    cfg.out_dir.mkdir(parents=True, exist_ok=True)
    raw_settings = {**cfg.settings, **recorder.photoset_settings()}
    done = recorded_trials(cfg)
    if session.check_settings(cfg.out_dir, raw_settings):
        write_settings(cfg.out_dir, raw_settings)
    if cfg.profile.max_kpa > driver.max_kpa + 1e-9:
        result.status, result.message = (
            "limit",
            (
                f"--max-kpa {cfg.profile.max_kpa:g} is above the driver limit "
                f"{driver.max_kpa:g} kPa (calibration max_kpa); nothing was done"
            ),
        )
        print(f"acquire: {result.message}", file=stream)
        return result
    result.steps_skipped = len(done)
    interrupts = _Interrupts()
    current = 0
    try:
        with interrupts:
            if cfg.watchdog_s > 0:
                driver.set_watchdog(cfg.watchdog_s)
            for trial in range(1, cfg.trials + 1):
                if trial in done:
                    continue
                current = trial
                _record_trial(driver, recorder, cfg, trial, interrupts, result)
            driver.vent()
            if cfg.watchdog_s > 0:
                driver.set_watchdog(0.0)
    except (KeyboardInterrupt, Exception) as exc:  # noqa: BLE001 - any failure must still vent and report
        result.status, result.message = failure_status(exc)
        if result.status == "error":
            traceback.print_exc(file=stream)
    finally:
        if result.status != "done":
            result.vented = driver.safe_vent()
        result.garbage_lines = driver.garbage_lines
    if result.status == "done":
        print(
            f"acquire: done: {result.photos_taken} frame(s) recorded, {result.steps_skipped} "
            "trial(s) already recorded; "
            f"manifest {cfg.out_dir / MANIFEST}",
            file=stream,
        )
    else:
        vent = (
            "vented to 0 kPa"
            if result.vented
            else "COULD NOT VENT: the port is not answering -- press the emergency stop / open the "
                 "relief valve"
        )
        print(
            f"acquire: STOPPED during trial {current}: {result.message}\n"
            f"acquire: {vent}; finished trials are kept in {cfg.out_dir / MANIFEST}; what trial "
            f"{current} recorded is "
            f"kept as {cfg.names(current)[0].replace('.avi', '')}*.interrupted.* (not listed)\n"
            f"acquire: re-run the same command to record trial {current} again",
            file=stream,
        )
    return result
