"""Run the ramp on a rig and write the photo set as it goes (resumable, vented on any stop).

For every step: set the pressure, wait ``settle_s`` watching for ``EVT ESTOP``, read the
measured pressure, take the photo (and, in ``blocked`` mode, several load-cell samples), check
the stop once more, then write the photo and its manifest row atomically (Ctrl-C is held off
during those two writes so a photo never lacks its row).  Steps already recorded are skipped;
the first missing step is reached along the same pressure history (see
:func:`pipeline.rig.session.approach_path`).

Whatever ends the run early -- Ctrl-C/SIGTERM, ``EVT ESTOP``, a lost port, a camera failure, any
exception -- the host vents to 0 kPa if the port still answers, keeps every row written, prints
what happened and how to resume, and returns a non-zero :data:`EXIT_CODES` value.

Firmware that speaks only the base protocol (no ``CFG``, ``WDOG`` or load cell) runs a bending
ramp too: the session says at the start and in its final message what it could not use
(:func:`unused_features`); blocked mode, which needs the load cell, stops before pressurising.
"""

from __future__ import annotations

import contextlib
import logging
import signal
import sys
import traceback
from collections.abc import Callable, Iterator
from dataclasses import dataclass, field
from datetime import datetime, timezone
from pathlib import Path
from typing import TYPE_CHECKING, Any, TextIO

import numpy as np
from tqdm import tqdm

from pipeline.errors import UserInputError
from pipeline.fileio import atomic_write_bytes
from pipeline.measure.settings import MeasureSettings, SettingsError, resolve_settings
from pipeline.photoset import MANIFEST, append_manifest_rows, write_manifest, write_settings
from pipeline.rig import session
from pipeline.rig.cameras import Camera, CameraError, Shot
from pipeline.rig.driver import EStopError, LimitError, PicoDriver, PortLostError

if TYPE_CHECKING:
    from typing_extensions import Self

log = logging.getLogger(__name__)

#: exit status per way a run ends
EXIT_CODES: dict[str, int] = {
    "done": 0, "error": 1, "estop": 3, "port_lost": 4, "camera": 5, "limit": 6, "interrupted": 130,
}

StopCriterion = Callable[[bytes, MeasureSettings], bool]


@dataclass(frozen=True)
class SessionConfig:
    """Everything that defines a run (the CLI options).

    Attributes
    ----------
    out_dir : Path
        Photo-set folder (created, or resumed when it exists).
    material, actuator : str
        Manifest labels.
    trials : int
        Number of ramps (trials 1..trials).
    step_kpa, max_kpa : float
        Ramp step and top (kPa).
    settle_s : float
        Wait after each setpoint before measuring and photographing (s).
    settings : dict
        ``photoset.yaml`` values (l0_mm, mm_per_px, line_color, fixed_end, positive_turn).
    mode : str
        ``bending`` (photos) or ``blocked`` (photos plus load-cell samples).
    force_samples : int
        Load-cell readings per step in blocked mode.
    force_interval_s : float
        Time between load-cell readings (s).
    tare : bool
        Tare the load cell (vented) at the start of each trial in blocked mode.
    watchdog_s : float
        Device watchdog (s): the Pico vents by itself if the host sends nothing for this long
        (lost cable, crashed host); 0 leaves it off.
    """

    out_dir: Path
    material: str
    actuator: str
    trials: int
    step_kpa: float
    max_kpa: float
    settle_s: float
    settings: dict[str, Any] = field(default_factory=dict)
    mode: str = "bending"
    force_samples: int = 10
    force_interval_s: float = 0.0
    tare: bool = True
    watchdog_s: float = 0.0


@dataclass
class SessionResult:
    """How a run ended."""

    status: str = "done"
    message: str = ""
    photos_taken: int = 0
    steps_skipped: int = 0
    vented: bool | None = None
    last_step: session.StepPlan | None = None
    garbage_lines: int = 0
    unused: list[str] = field(default_factory=list)

    @property
    def exit_code(self) -> int:
        return EXIT_CODES[self.status]


def failure_status(exc: BaseException) -> tuple[str, str]:
    """How a run that raised ``exc`` ended: its :class:`SessionResult` status and message.

    Examples
    --------
    >>> failure_status(KeyboardInterrupt())
    ('interrupted', 'interrupted (Ctrl-C / SIGTERM)')
    >>> failure_status(ValueError("bad"))
    ('error', 'ValueError: bad')
    """
    if isinstance(exc, KeyboardInterrupt):
        return "interrupted", "interrupted (Ctrl-C / SIGTERM)"
    if isinstance(exc, EStopError):
        return "estop", str(exc)
    if isinstance(exc, PortLostError):
        return "port_lost", str(exc)
    if isinstance(exc, CameraError):
        return "camera", f"camera failed: {exc}"
    if isinstance(exc, LimitError):
        return "limit", str(exc)
    return "error", f"{type(exc).__name__}: {exc}"


class _Interrupts:
    """SIGINT/SIGTERM raise KeyboardInterrupt, except inside :meth:`held` (raised right after)."""

    def __init__(self) -> None:
        self._holding = False
        self._pending = False
        self._old: dict[int, Any] = {}

    def _handler(self, signum: int, frame: Any) -> None:
        if self._holding:
            self._pending = True
            return
        raise KeyboardInterrupt(signal.Signals(signum).name)

    def __enter__(self) -> Self:
        for sig in (signal.SIGINT, signal.SIGTERM):
            try:
                self._old[sig] = signal.signal(sig, self._handler)
            except ValueError:  # not the main thread: leave default handling
                pass
        return self

    def __exit__(self, *exc: object) -> None:
        for sig, old in self._old.items():
            signal.signal(sig, old)

    @contextlib.contextmanager
    def held(self) -> Iterator[None]:
        self._holding = True
        try:
            yield
        finally:
            self._holding = False
            if self._pending:
                self._pending = False
                raise KeyboardInterrupt("SIGINT")


def trial_plans(cfg: SessionConfig) -> list[tuple[int, list[session.StepPlan], set[int]]]:
    """Per trial: the full sequence (peak as far as known from the folder) and the steps
    recorded."""
    up = session.ramp_pressures(cfg.step_kpa, cfg.max_kpa)
    rec = session.recorded_steps(cfg.out_dir, cfg.material, cfg.actuator)
    out = []
    for trial in range(1, cfg.trials + 1):
        rows = rec[rec["trial_n"] == trial]
        peak = session.known_peak(rows, len(up))
        seq = session.trial_sequence(trial, up, peak)
        mismatch = session.recorded_mismatch(rows, seq)
        if mismatch:
            raise UserInputError(
                f"{cfg.out_dir / MANIFEST}: trial {trial}'s {mismatch} (--step-kpa "
                f"{cfg.step_kpa:g}, --max-kpa {cfg.max_kpa:g}); resume with the ramp the set was "
                "started with, or give a new --out folder for this one"
            )
        out.append((trial, seq, set(rows["step_n"].tolist())))
    return out


def describe_plan(
    cfg: SessionConfig, *, stop_at_psi0: bool, camera_spec: str = "", port: str = ""
) -> str:
    """The ``--dry-run`` text: ramp, what is recorded, where each trial resumes, time estimate."""
    up = session.ramp_pressures(cfg.step_kpa, cfg.max_kpa)
    lines = [
        (
            f"acquire plan: {cfg.material} actuator {cfg.actuator}, {cfg.trials} trial(s), mode "
            f"{cfg.mode}, "
            f"port {port or '-'}, camera {camera_spec or '-'}"
        ),
        f"  out: {cfg.out_dir}",
        f"  ramp (kPa): up {' '.join(f'{p:g}' for p in up)}; then down the same steps to 0",
        f"  settle {cfg.settle_s:g} s per step"
        + (f"; {cfg.force_samples} load-cell samples per step" if cfg.mode == "blocked" else "")
        + ("; up leg stops early when measured psi <= -psi0" if stop_at_psi0 else ""),
        "  photoset.yaml: " + ", ".join(f"{k}={v}" for k, v in cfg.settings.items())
        + (
            "; the synthetic camera writes its own scene's fixed_end, mm_per_px and line_color "
            "over these"
            if camera_spec.strip().startswith("synthetic")
            else ""
        ),
    ]
    todo = 0
    for trial, seq, recorded in trial_plans(cfg):
        k = session.first_missing(seq, recorded)
        if k is None:
            lines.append(f"  trial {trial}: complete ({len(seq)} photos recorded)")
            continue
        todo += len(seq) - k
        where = (
            f"resume at step {seq[k].step} ({seq[k].pressure_kpa:g} kPa {seq[k].direction})"
            if k
            else "start at step 0"
        )
        approach = session.approach_path(seq, k)
        lines.append(
            f"  trial {trial}: {len(seq)} steps, {k} recorded, {where}"
            + (
                f" after passing {' '.join(f'{p:g}' for p in approach)} kPa without photos"
                if approach
                else ""
            )
        )
    minutes = todo * (cfg.settle_s + 0.5) / 60.0
    lines.append(
        f"  to do: {todo} photo(s), about {minutes:.1f} min (at most; settle + ~0.5 s per photo)"
    )
    return "\n".join(lines)


def unused_features(driver: PicoDriver, cfg: SessionConfig) -> list[str]:
    """What this run would use but the firmware does not speak (one sentence each; empty for ours).

    Parameters
    ----------
    driver : PicoDriver
        Connected driver (its extensions were probed at connect).
    cfg : SessionConfig
        The run.

    Returns
    -------
    list of str
    """
    name = f"{driver.info.name} {driver.info.version}" if driver.info else "the device"
    out = []
    if not driver.supports("CFG"):
        out.append(
            f"firmware {name} has no CFG: its own pressure limit is unknown, so only the host "
            "limit "
            f"--max-kpa {driver.max_kpa:g} kPa guards the setpoints"
        )
    if cfg.watchdog_s > 0 and not driver.supports("WDOG"):
        out.append(
            f"firmware {name} has no WDOG: the device cannot vent by itself if the host stops "
            "talking "
            "(pulled cable, crashed host); keep the emergency stop at hand"
        )
    if cfg.mode == "blocked" and not driver.supports("LOAD"):
        out.append(
            f"firmware {name} has no load-cell commands (LOAD/TARE/SCALE), which --mode blocked "
            "needs"
        )
    return out


def run_session(
    driver: PicoDriver,
    camera: Camera,
    cfg: SessionConfig,
    *,
    stop_up: StopCriterion | None = None,
    progress: bool | None = None,
    stream: TextIO | None = None,
) -> SessionResult:
    """Run (or resume) every trial; never raises for rig/camera/interrupt failures.

    Parameters
    ----------
    driver : PicoDriver
        Connected driver (its ``max_kpa`` is the host limit).
    camera : Camera
        Opened camera.
    cfg : SessionConfig
        The run.
    stop_up : callable, optional
        ``stop_up(image_bytes, settings) -> bool``: end the up leg at this photo (psi reached
        -psi0); ``settings`` are the photo set's, resolved once.
    progress : bool or None
        Show the tqdm bar (``None``: only on a terminal).
    stream : text stream, optional
        Where the final message goes (default stderr).

    Returns
    -------
    SessionResult
        ``status`` is one of :data:`EXIT_CODES`; every row written stays written.
    """
    stream = stream or sys.stderr
    result = SessionResult(unused=unused_features(driver, cfg))
    for note in result.unused:
        print(f"acquire: not used: {note}", file=stream)
    if cfg.mode == "blocked" and not driver.supports("LOAD"):
        result.status, result.message = (
            "error",
            (
                "blocked mode needs the load cell, which this firmware does not speak; nothing was "
                "done "
                "(flash the firmware of pipeline/rig/firmware or use --mode bending)"
            ),
        )
        print(f"acquire: {result.message}", file=stream)
        return result
    cfg.out_dir.mkdir(parents=True, exist_ok=True)
    raw_settings = {**cfg.settings, **camera.photoset_settings()}
    if session.check_settings(cfg.out_dir, raw_settings):
        write_settings(cfg.out_dir, raw_settings)
    settings: MeasureSettings | None = None
    if stop_up is not None:
        try:
            settings = resolve_settings(
                {k: v for k, v in raw_settings.items() if v is not None}, folder=cfg.out_dir
            )
        except SettingsError as exc:
            result.status, result.message = (
                "error",
                f"the psi0 stop needs valid photo-set settings: {exc}; nothing was done",
            )
            print(f"acquire: {result.message}", file=stream)
            return result
    up = session.ramp_pressures(cfg.step_kpa, cfg.max_kpa)
    if up[-1] > driver.max_kpa + 1e-9:
        result.status, result.message = (
            "limit",
            (
                f"--max-kpa {cfg.max_kpa:g} is above the driver limit {driver.max_kpa:g} kPa "
                "(calibration max_kpa); nothing was done"
            ),
        )
        print(f"acquire: {result.message}", file=stream)
        return result
    plans = trial_plans(cfg)
    total = 0  # steps still to record
    for _, seq, rec in plans:
        first = session.first_missing(seq, rec)
        total += 0 if first is None else len(seq) - first
    result.steps_skipped = sum(len(rec) for _, _, rec in plans)
    bar = tqdm(
        total=total,
        unit="photo",
        desc=f"{cfg.material} {cfg.actuator}",
        disable=(not progress) if progress is not None else None,
        file=sys.stderr,
        dynamic_ncols=True,
    )
    interrupts = _Interrupts()
    try:
        with interrupts:
            watchdog = cfg.watchdog_s > 0 and driver.supports("WDOG")
            driver.vent()
            if watchdog:
                driver.set_watchdog(cfg.watchdog_s)
            driver.sleep(cfg.settle_s)
            for trial, seq, recorded in plans:
                _run_trial(
                    driver,
                    camera,
                    cfg,
                    trial,
                    seq,
                    recorded,
                    up,
                    stop_up,
                    settings,
                    bar,
                    interrupts,
                    result,
                )
            driver.vent()
            if watchdog:
                driver.set_watchdog(0.0)
    except (KeyboardInterrupt, Exception) as exc:  # noqa: BLE001 - any failure must still vent and report
        result.status, result.message = failure_status(exc)
        if result.status == "error":
            traceback.print_exc(file=stream)
    finally:
        bar.close()
        if result.status != "done":
            result.vented = driver.safe_vent()
        result.garbage_lines = driver.garbage_lines
    print(_final_message(cfg, result), file=stream)
    return result


def _fewer_steps(bar: tqdm, n: int) -> None:
    """Take ``n`` steps off the progress bar's total (an up leg cut short at -psi0)."""
    assert bar.total is not None  # the bar is made with the steps still to record
    bar.total -= n


def _run_trial(
    driver: PicoDriver,
    camera: Camera,
    cfg: SessionConfig,
    trial: int,
    seq: list[session.StepPlan],
    recorded: set[int],
    up: list[float],
    stop_up: StopCriterion | None,
    settings: MeasureSettings | None,
    bar: tqdm,
    interrupts: _Interrupts,
    result: SessionResult,
) -> None:
    """Run one trial from its first missing step."""
    start = session.first_missing(seq, recorded)
    if start is None:
        return
    peak_known = any(p.direction == "down" for p in seq if p.step in recorded)
    if stop_up is not None and not peak_known and start > 0:
        # the up leg may already have ended early: re-check the recorded up photos
        for plan in seq[:start]:
            if (
                plan.direction == "up"
                and 0 < plan.step
                and settings is not None
                and _recorded_image_stops(cfg, plan, stop_up, settings)
            ):
                seq = session.trial_sequence(trial, up, plan.step)
                _fewer_steps(bar, len(session.trial_sequence(trial, up)) - len(seq))
                start = session.first_missing(seq, recorded)
                if start is None:
                    return
                break
    driver.vent()
    driver.sleep(cfg.settle_s)
    if cfg.mode == "blocked" and cfg.tare:
        driver.tare()
    for p in session.approach_path(seq, start):
        bar.set_postfix_str(f"trial {trial}/{cfg.trials} approach {p:g} kPa", refresh=False)
        driver.set_kpa(p)
        driver.sleep(cfg.settle_s)
    i = start
    while i < len(seq):
        plan = seq[i]
        result.last_step = plan
        bar.set_postfix_str(
            f"trial {trial}/{cfg.trials} step {plan.step} {plan.direction} {plan.pressure_kpa:g} "
            "kPa",
            refresh=False,
        )
        image_bytes = _record_step(driver, camera, cfg, plan, interrupts)
        result.photos_taken += 1
        bar.update(1)
        if (
            stop_up is not None
            and settings is not None
            and plan.direction == "up"
            and 0 < plan.step < len(up) - 1
            and stop_up(image_bytes, settings)
        ):
            new_seq = session.trial_sequence(trial, up, plan.step)
            _fewer_steps(bar, len(seq) - len(new_seq))
            bar.refresh()
            seq = new_seq
        i += 1


def _record_step(driver: PicoDriver, camera: Camera, cfg: SessionConfig, plan: session.StepPlan,
                 interrupts: _Interrupts) -> bytes:
    """Set, settle, measure, photograph (and sample the load cell), then write photo and row
    atomically."""
    driver.set_kpa(plan.pressure_kpa)
    driver.sleep(cfg.settle_s)
    reading = driver.get()
    data, suffix = camera.capture(
        Shot(plan.pressure_kpa, reading.measured_kpa, plan.direction, plan.trial, plan.step)
    )
    row: dict[str, Any] = {
        "image": session.image_name(
            cfg.material,
            cfg.actuator,
            plan.trial,
            plan.step,
            plan.pressure_kpa,
            plan.direction,
            suffix,
        ),
        "pressure_kpa": f"{plan.pressure_kpa:g}",
        "direction": plan.direction,
        "material": cfg.material,
        "actuator": cfg.actuator,
        "trial": str(plan.trial),
        "step": str(plan.step),
        "timestamp": datetime.now(timezone.utc).isoformat(timespec="milliseconds"),
        "measured_pressure_kpa": f"{reading.measured_kpa:.3f}",
    }
    if cfg.mode == "blocked":
        forces = driver.load_samples(cfg.force_samples, cfg.force_interval_s)
        row["force_n"] = f"{float(np.mean(forces)):.5f}"
        row["force_sd_n"] = f"{float(np.std(forces, ddof=1)) if forces.size > 1 else 0.0:.5f}"
        row["force_samples"] = str(int(forces.size))
    driver.check_events()  # a stop during the photo voids it: the rig vented meanwhile
    with interrupts.held():
        atomic_write_bytes(cfg.out_dir / row["image"], data)
        _append_row(cfg, row)
    return data


def _append_row(cfg: SessionConfig, row: dict[str, Any]) -> None:
    """Append ``row``, first dropping any row of the same material/actuator/trial/step (a
    re-take)."""
    path = cfg.out_dir / MANIFEST
    if path.is_file():
        import pandas as pd

        old = pd.read_csv(path, dtype=str)
        same = (
            (old["material"] == row["material"])
            & (old["actuator"] == row["actuator"])
            & (old["trial"] == row["trial"])
            & (old.get("step") == row["step"])
            & (old["image"] != row["image"])
        )
        if same.any():
            for stale in old.loc[same, "image"]:
                (cfg.out_dir / stale).unlink(missing_ok=True)
            write_manifest(cfg.out_dir, old[~same])
    append_manifest_rows(cfg.out_dir, [row])


def _recorded_image_stops(cfg: SessionConfig, plan: session.StepPlan, stop_up: StopCriterion,
                          settings: MeasureSettings) -> bool:
    rows = session.recorded_steps(cfg.out_dir, cfg.material, cfg.actuator)
    hit = rows[(rows["trial_n"] == plan.trial) & (rows["step_n"] == plan.step)]
    if hit.empty:
        return False
    return bool(stop_up((cfg.out_dir / hit["image"].iloc[0]).read_bytes(), settings))


def _final_message(cfg: SessionConfig, result: SessionResult) -> str:
    n_rows = 0
    if (cfg.out_dir / MANIFEST).is_file():
        with open(cfg.out_dir / MANIFEST) as fh:
            n_rows = max(sum(1 for _ in fh) - 1, 0)
    garbage = (
        f"; ignored {result.garbage_lines} garbage line(s) from the device"
        if result.garbage_lines
        else ""
    )
    garbage += "".join(f"\nacquire: not used: {note}" for note in result.unused)
    if result.status == "done":
        return (
            f"acquire: done: {result.photos_taken} photo(s) taken, {result.steps_skipped} already "
            "recorded; "
            f"{n_rows} row(s) in {cfg.out_dir / MANIFEST}{garbage}"
        )
    where = ""
    if result.last_step is not None:
        s = result.last_step
        where = f" at trial {s.trial} step {s.step} ({s.pressure_kpa:g} kPa {s.direction})"
    vent = (
        "vented to 0 kPa"
        if result.vented
        else "COULD NOT VENT: the port is not answering -- press the emergency stop / open the "
             "relief valve"
    )
    return (f"acquire: STOPPED{where}: {result.message}\n"
            f"acquire: {vent}; kept {n_rows} recorded row(s) in {cfg.out_dir / MANIFEST} "
            f"({result.photos_taken} taken in this run){garbage}\n"
            f"acquire: re-run the same command to resume at the first missing step")


def psi0_stop_criterion(
    psi0_deg: float, measure_image: Callable[..., Any] | None = None
) -> StopCriterion:
    """A ``stop_up`` callable: True when the photo's measured psi is at or below ``-psi0_deg``.

    Uses :func:`pipeline.measure.measure_image` unless another function is given; failed
    measurements never stop the ramp.
    """
    if measure_image is None:
        from pipeline.measure import measure_image as default_measure

        measure_image = default_measure
    measure = measure_image  # never None: the name the closure below calls

    def stop(image_bytes: bytes, settings: MeasureSettings) -> bool:
        import cv2

        image = cv2.imdecode(np.frombuffer(image_bytes, np.uint8), cv2.IMREAD_COLOR)
        if image is None:
            return False
        try:
            r = measure(image, settings)
        except Exception as exc:  # noqa: BLE001 - a failed live measurement must never stop the rig
            log.warning(
                "live psi measurement failed (%s: %s); the ramp continues to --max-kpa",
                type(exc).__name__,
                exc,
            )
            return False
        return getattr(r, "status", "failed") != "failed" and float(r.psi_deg) <= -abs(psi0_deg)

    return stop


def summarise(result: SessionResult) -> dict[str, Any]:
    """Small dict of the result (for logs and tests)."""
    return {
        "status": result.status,
        "photos_taken": result.photos_taken,
        "steps_skipped": result.steps_skipped,
        "vented": result.vented,
        "exit_code": result.exit_code,
    }


__all__ = [
    "EXIT_CODES",
    "SessionConfig",
    "SessionResult",
    "describe_plan",
    "psi0_stop_criterion",
    "run_session",
    "summarise",
    "trial_plans",
    "unused_features",
]

