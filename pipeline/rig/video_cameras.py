"""Camera back-ends that record a video with a timestamp per frame (``acquire --record video``).

Each recorder runs in its own thread between :meth:`start` and :meth:`stop`, writes MJPEG AVI
(:mod:`pipeline.video.writer`) and stamps every frame with the host's monotonic clock, relative
to the ``t0`` the session gives it -- the same clock the pressure log uses, so the frame-times
file needs no clock offset.

=============================  =================================================================
spec                           recorder
=============================  =================================================================
``0``, ``1``, ... / URL        OpenCV ``VideoCapture``: every frame the camera delivers, stamped
                               when the host receives it (a camera's own latency, typically tens
                               of ms, then shows as a constant offset: measure it once and set
                               ``clock_offset_s`` in the manifest)
``synthetic[:PRESET]``         renders the virtual actuator
(:class:`pipeline.synth.video.LiveActuator`:
                               the model with hysteresis and a first-order lag) at the pressure the
                               rig last reported, at ``fps`` as far as the machine keeps up: the
                               frame-times file records when each frame really was taken
=============================  =================================================================
"""

from __future__ import annotations

import math
import threading
import time
from pathlib import Path
from typing import Any, Protocol

import numpy as np

from pipeline.errors import UserInputError
from pipeline.rig.cameras import CameraError


class VideoRecorder(Protocol):
    """What a video acquisition needs from a camera."""

    def start(self, path: Path, t0: float) -> None:
        """Start recording into ``path``; frame times are ``time.monotonic() - t0``."""

    def observe(self, pressure_kpa: float) -> None:
        """The pressure the rig reports now (used by the synthetic camera)."""

    def stop(self) -> list[float]:
        """Stop, close the file; return the frame times (s). Raises CameraError if recording
        failed."""

    def photoset_settings(self) -> dict[str, Any]:
        """``photoset.yaml`` values the camera knows (empty for real cameras)."""

    def close(self) -> None:
        """Release the device."""


class _Threaded:
    """The recording thread, the frame times and the error a back-end may hit."""

    def __init__(self) -> None:
        self._thread: threading.Thread | None = None
        self._stop = threading.Event()
        self._times: list[float] = []
        self._error: BaseException | None = None
        self._t0 = 0.0

    def start(self, path: Path, t0: float) -> None:
        self._stop.clear()
        self._times, self._error, self._t0 = [], None, t0
        self._thread = threading.Thread(
            target=self._guarded, args=(Path(path),), name="video-recorder", daemon=True
        )
        self._thread.start()

    def _guarded(self, path: Path) -> None:
        try:
            self._record(path)
        except BaseException as exc:  # noqa: BLE001 - reported by stop() in the session's thread
            self._error = exc

    def _record(self, path: Path) -> None:  # pragma: no cover - implemented by the back-ends
        raise NotImplementedError

    def stop(self) -> list[float]:
        self._stop.set()
        if self._thread is not None:
            self._thread.join(timeout=30)
        if self._error is not None:
            raise CameraError(
                f"video recording failed: {type(self._error).__name__}: {self._error}"
            )
        return list(self._times)

    def check(self) -> None:
        """Raise :class:`CameraError` now if the recording thread has failed."""
        if self._error is not None:
            raise CameraError(
                f"video recording failed: {type(self._error).__name__}: {self._error}"
            )


class OpenCVRecorder(_Threaded):
    """Every frame of an OpenCV ``VideoCapture`` device or stream, written as MJPEG."""

    def __init__(self, source: int | str, *, fps: float) -> None:
        import cv2

        super().__init__()
        self.source, self.fps = source, fps
        self.cap = cv2.VideoCapture(source)
        if not self.cap.isOpened():
            raise CameraError(
                f"OpenCV cannot open camera {source!r}; check the index/URL (try --camera 0, 1, "
                "...)"
            )
        self.cap.set(cv2.CAP_PROP_FPS, float(fps))

    def observe(self, pressure_kpa: float) -> None:
        pass

    def _record(self, path: Path) -> None:
        from pipeline.video.writer import open_writer

        writer = None
        try:
            while not self._stop.is_set():
                ok, frame = self.cap.read()
                t = time.monotonic() - self._t0
                if not ok or frame is None:
                    raise CameraError(f"camera {self.source!r} returned no frame")
                if writer is None:
                    writer = open_writer(path, "mjpg", self.fps, (frame.shape[1], frame.shape[0]))
                writer.write(frame)
                self._times.append(t)
        finally:
            if writer is not None:
                writer.release()

    def photoset_settings(self) -> dict[str, Any]:
        return {}

    def close(self) -> None:
        self.cap.release()


class SyntheticRecorder(_Threaded):
    """The virtual actuator filmed at the pressure the rig reports (see the module docstring)."""

    def __init__(
        self,
        material: str,
        l0_mm: float,
        *,
        fps: float,
        max_kpa: float,
        preset: str = "lab",
        size: tuple[int, int] = (480, 360),
        seed: int = 0,
    ) -> None:
        from pipeline import synth
        from pipeline.synth.actuator import TrialActuator, behaviour_for, loading_curve
        from pipeline.synth.video import LiveActuator, fit_scene

        super().__init__()
        self.fps, self.seed, self.l0_mm = fps, seed, float(l0_mm)
        curve = loading_curve(material, max_kpa=max_kpa * 1.6)
        self.trial = TrialActuator(material, curve, curve.psi0_deg, 1.0, behaviour_for(material))
        self._live_factory = lambda: LiveActuator(self.trial)
        try:
            scene = synth.scene_from(preset, width=size[0], height=size[1])
        except KeyError as exc:
            raise UserInputError(
                f"--camera synthetic:{preset}: unknown scene preset; use one of "
                f"{sorted(synth.SCENE_PRESETS)}"
            ) from exc
        psi = self.trial.psi_loading_deg(np.linspace(0.0, max_kpa, 50))
        psi = psi[np.isfinite(psi)]
        self.scene, rotation = fit_scene(
            scene, self.l0_mm, (float(psi.min()) - 10.0, float(psi.max()) + 5.0)
        )
        extent = np.vstack([synth.centreline_mm(float(p), self.l0_mm, n=241)
                            for p in np.linspace(psi.min() - 10.0, psi.max() + 5.0, 9)])
        camera = synth.make_camera(self.scene, rotation_deg=rotation, extent_mm=extent)
        self.backdrop = synth.make_backdrop(
            self.scene, camera, seed=synth.child_seed(seed, 0), keepout_mm=[extent]
        )
        probe = synth.render_actuator(
            float(psi.max()), self.l0_mm, self.scene, seed=0, backdrop=self.backdrop
        )
        self._fixed_end = probe.fixed_end_px
        self._lock = threading.Lock()
        self._pressure = 0.0

    def observe(self, pressure_kpa: float) -> None:
        with self._lock:
            self._pressure = float(pressure_kpa)

    def _record(self, path: Path) -> None:
        from pipeline import synth
        from pipeline.video.writer import open_writer

        live = self._live_factory()
        writer = open_writer(path, "mjpg", self.fps, (self.scene.width, self.scene.height))
        period = 1.0 / self.fps
        next_t = 0.0
        try:
            while not self._stop.is_set():
                now = time.monotonic() - self._t0
                if now < next_t:
                    time.sleep(min(next_t - now, 0.01))
                    continue
                with self._lock:
                    pressure = self._pressure
                psi = live.psi_deg(now, pressure)
                frame = synth.render_actuator(
                    psi,
                    self.l0_mm,
                    self.scene,
                    seed=synth.child_seed(self.seed, 1, len(self._times)),
                    backdrop=self.backdrop,
                )
                writer.write(frame.image)
                self._times.append(now)
                next_t = max(next_t + period, now - period / 2)  # a late frame is not made up for
        finally:
            writer.release()

    def photoset_settings(self) -> dict[str, Any]:
        return {"positive_turn": "ccw", "fixed_end": [round(float(v), 1) for v in self._fixed_end],
                "mm_per_px": self.scene.mm_per_px, "line_color": self.scene.line_color}

    def close(self) -> None:
        pass


def parse_size(text: str) -> tuple[int, int]:
    """``'640x480'`` -> (640, 480).

    Raises
    ------
    UserInputError
        When the text is not WIDTHxHEIGHT with both at least 16.
    """
    try:
        w, h = (int(v) for v in text.lower().split("x"))
    except ValueError:
        raise UserInputError(
            f"--video-size {text!r}: write WIDTHxHEIGHT in pixels, e.g. 640x480"
        ) from None
    if w < 16 or h < 16:
        raise UserInputError(f"--video-size {text!r}: at least 16x16 pixels")
    return w, h


def open_recorder(
    spec: str,
    *,
    material: str,
    l0_mm: float,
    fps: float,
    max_kpa: float,
    seed: int = 0,
    size: tuple[int, int] = (480, 360),
) -> VideoRecorder:
    """The video recorder named by ``spec`` (table in the module docstring).

    Raises
    ------
    UserInputError
        A spec that names no video back-end (``cmd:`` and ``dir:`` take photos, not videos).
    """
    spec = spec.strip()
    if not (math.isfinite(fps) and fps > 0):
        raise UserInputError(f"--fps {fps!r} must be a positive number of frames per second")
    if spec == "synthetic" or spec.startswith("synthetic:"):
        return SyntheticRecorder(
            material,
            l0_mm,
            fps=fps,
            max_kpa=max_kpa,
            preset=spec.partition(":")[2] or "lab",
            size=size,
            seed=seed,
        )
    if spec.isdigit():
        return OpenCVRecorder(int(spec), fps=fps)
    if "://" in spec:
        return OpenCVRecorder(spec, fps=fps)
    raise UserInputError(
        f"--camera {spec!r} cannot record video; with --record video use a device index (0), a "
        "stream "
        "URL (rtsp://...) or 'synthetic[:clean|lab|hard]'"
    )


__all__ = ["OpenCVRecorder", "SyntheticRecorder", "VideoRecorder", "open_recorder", "parse_size"]
