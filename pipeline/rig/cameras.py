"""Camera backends for acquisition, chosen by a ``--camera`` spec string.

=============================  =================================================================
spec                           camera
=============================  =================================================================
``0``, ``1``, ...              OpenCV ``VideoCapture`` device index (webcam, capture card)
``rtsp://...``, ``http://...``  OpenCV ``VideoCapture`` URL (IP camera stream)
``cmd:TEMPLATE``               a shell command that writes the photo to ``{path}``, e.g.
                               ``cmd:gphoto2 --capture-image-and-download --force-overwrite
                               --filename {path}`` for a tethered camera
``dir:PATH``                   a watched folder: each capture waits for the next image file that
                               appears in PATH after the request (a camera's auto-save folder)
``synthetic[:PRESET]``         renders the actuator at the measured pressure with
                               :mod:`pipeline.synth` and :func:`pipeline.model.psi_deg`
                               (PRESET: ``clean``, ``lab`` (default) or ``hard``)
=============================  =================================================================

Every camera returns encoded image bytes (JPEG, PNG or TIFF) and the file suffix to store them
under; the session writes them atomically.
"""

from __future__ import annotations

import dataclasses
import hashlib
import os
import shlex
import subprocess
import tempfile
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Protocol

import numpy as np

from pipeline.errors import UserInputError
from pipeline.photoset import IMAGE_SUFFIXES


class CameraError(RuntimeError):
    """A capture failed (device gone, command failed, no file arrived in time)."""


@dataclass(frozen=True)
class Shot:
    """What a capture is of: the rig state when the photo is taken.

    Attributes
    ----------
    pressure_kpa : float
        Setpoint (kPa).
    measured_kpa : float
        Pressure the rig reports (kPa).
    direction : str
        ``up`` or ``down``.
    trial : int
        Trial number (1-based).
    step : int
        Step within the trial (0-based).
    """

    pressure_kpa: float
    measured_kpa: float
    direction: str
    trial: int
    step: int


class Camera(Protocol):
    """What the acquisition needs from a camera."""

    def capture(self, shot: Shot) -> tuple[bytes, str]:
        """Take one photo; return the encoded bytes and the file suffix (``.jpg``, ``.png``,
        ...)."""

    def photoset_settings(self) -> dict[str, Any]:
        """``photoset.yaml`` values the camera knows better than the user (empty for real
        cameras)."""

    def close(self) -> None:
        """Release the device."""


def image_suffix(data: bytes) -> str:
    """File suffix from the magic bytes of an encoded image.

    Raises
    ------
    CameraError
        If the bytes are not a JPEG, PNG, TIFF or BMP image.
    """
    if data[:3] == b"\xff\xd8\xff":
        return ".jpg"
    if data[:8] == b"\x89PNG\r\n\x1a\n":
        return ".png"
    if data[:4] in (b"II*\x00", b"MM\x00*"):
        return ".tif"
    if data[:2] == b"BM":
        return ".bmp"
    raise CameraError(f"captured file is not a JPEG/PNG/TIFF/BMP image (starts with {data[:8]!r})")


class OpenCVCamera:
    """OpenCV ``VideoCapture`` on a device index or stream URL; frames saved as JPEG (quality
    95)."""

    def __init__(self, source: int | str, *, flush_frames: int = 2, jpeg_quality: int = 95) -> None:
        import cv2

        self._cv2 = cv2
        self.source = source
        self.cap = cv2.VideoCapture(source)
        if not self.cap.isOpened():
            raise CameraError(
                f"OpenCV cannot open camera {source!r}; check the index/URL (try --camera 0, 1, "
                "...)"
            )
        self.flush_frames = flush_frames
        self.jpeg_quality = jpeg_quality

    def capture(self, shot: Shot) -> tuple[bytes, str]:
        for _ in range(self.flush_frames):  # frames buffered before the pressure settled
            self.cap.grab()
        ok, frame = self.cap.read()
        if not ok or frame is None:
            raise CameraError(f"camera {self.source!r} returned no frame")
        ok, buf = self._cv2.imencode(
            ".jpg", frame, [self._cv2.IMWRITE_JPEG_QUALITY, self.jpeg_quality]
        )
        if not ok:
            raise CameraError("JPEG encoding failed")
        return buf.tobytes(), ".jpg"

    def photoset_settings(self) -> dict[str, Any]:
        return {}

    def close(self) -> None:
        self.cap.release()


class CommandCamera:
    """A shell command that writes one photo to ``{path}`` (quoted for the shell)."""

    def __init__(self, template: str, *, timeout_s: float = 60.0) -> None:
        if "{path}" not in template:
            raise UserInputError(
                f"--camera 'cmd:{template}' has no {{path}}; the command must write the photo to "
                f"{{path}}"
            )
        self.template = template
        self.timeout_s = timeout_s
        self._tmp = tempfile.TemporaryDirectory(prefix="acquire-cmd-")

    def capture(self, shot: Shot) -> tuple[bytes, str]:
        path = Path(self._tmp.name) / f"shot_t{shot.trial}_s{shot.step}.jpg"
        path.unlink(missing_ok=True)
        command = self.template.replace("{path}", shlex.quote(str(path)))
        try:
            done = subprocess.run(
                command, shell=True, capture_output=True, timeout=self.timeout_s, check=False
            )
        except subprocess.TimeoutExpired as exc:
            raise CameraError(
                f"camera command timed out after {self.timeout_s:g} s: {command}"
            ) from exc
        if done.returncode != 0:
            raise CameraError(
                f"camera command failed (exit {done.returncode}): "
                f"{command}\n{done.stderr.decode(errors='replace')[-500:]}"
            )
        if not path.is_file() or path.stat().st_size == 0:
            raise CameraError(f"camera command wrote nothing to {path}: {command}")
        data = path.read_bytes()
        path.unlink(missing_ok=True)
        return data, image_suffix(data)

    def photoset_settings(self) -> dict[str, Any]:
        return {}

    def close(self) -> None:
        self._tmp.cleanup()


class FolderCamera:
    """A watched folder: the first image file to appear after the capture request is the photo.

    Files already there when the camera opens, and files that arrive between requests, are
    never used (so a late or stray shot is not attributed to the wrong pressure).  A file
    counts as complete when its size has stayed the same for ``stable_s``.
    """

    def __init__(
        self,
        folder: str | os.PathLike[str],
        *,
        timeout_s: float = 30.0,
        poll_s: float = 0.02,
        stable_s: float = 0.05,
    ) -> None:
        self.folder = Path(folder)
        if not self.folder.is_dir():
            raise UserInputError(
                f"--camera dir:{folder}: not a folder; create it or point to the camera's save "
                "folder"
            )
        self.timeout_s, self.poll_s, self.stable_s = timeout_s, poll_s, stable_s
        self._seen = set(self._images())

    def _images(self) -> list[str]:
        return sorted(p.name for p in self.folder.iterdir()
                      if p.suffix.lower() in IMAGE_SUFFIXES and not p.name.startswith("."))

    def capture(self, shot: Shot) -> tuple[bytes, str]:
        self._seen.update(self._images())  # whatever arrived before this request is not this photo
        deadline = time.monotonic() + self.timeout_s
        while time.monotonic() < deadline:
            new = [n for n in self._images() if n not in self._seen]
            if new:
                path = self.folder / new[0]
                size = -1
                while size != path.stat().st_size:
                    size = path.stat().st_size
                    time.sleep(self.stable_s)
                self._seen.add(new[0])
                data = path.read_bytes()
                return data, image_suffix(data)
            time.sleep(self.poll_s)
        raise CameraError(f"no new image arrived in {self.folder} within {self.timeout_s:g} s")

    def photoset_settings(self) -> dict[str, Any]:
        return {}

    def close(self) -> None:
        pass


class SyntheticCamera:
    """Renders the actuator at the pressure the rig reports (a complete virtual rig with the
    emulator).

    psi comes from :func:`pipeline.model.psi_deg` at the *measured* pressure (``loading`` branch
    going up, ``unloading`` going down); the image from :func:`pipeline.synth.render_actuator`.
    In ``blocked`` mode the line is the ellipse arc of
    :func:`pipeline.force.synth_blocked.blocked_arc_mm` at the eccentricity
    :func:`~pipeline.force.synth_blocked.blocked_eccentricity` gives for the measured pressure.
    The static scene (camera placement, table, clamp, light) is built once per session from
    ``seed``, so the fixed end stays at one pixel position (written to ``photoset.yaml``); each
    photo's noise seed is derived from (seed, material, trial, step), so a re-run renders the
    same image.
    """

    def __init__(self, material: str, l0_mm: float, *, preset: str = "lab", seed: int = 0,
                 psi_fn: Any = None, scene_overrides: dict[str, Any] | None = None,
                 psi_frame_deg: float = 240.0, mode: str = "bending") -> None:
        from pipeline import synth

        if psi_fn is None:
            from pipeline.model import psi_deg as psi_fn
        self._synth = synth
        self.psi_fn = psi_fn
        self.material, self.l0_mm, self.seed = material, float(l0_mm), seed
        try:
            self.scene = synth.scene_from(preset, **(scene_overrides or {}))
        except KeyError as exc:
            raise UserInputError(
                f"--camera synthetic:{preset}: unknown scene preset; use one of "
                f"{sorted(synth.SCENE_PRESETS)}"
            ) from exc
        # one static scene (camera placement, table, clamp, lighting) for the whole session, framed
        # to hold every shape from -psi_frame to +psi_frame, so the fixed end stays put on screen
        self.mode = mode
        self._blocked: Any = None
        if mode == "blocked":
            from pipeline.force import synth_blocked

            self._blocked = synth_blocked
            curves = [
                synth_blocked.blocked_arc_mm(float(e), self.l0_mm).points_mm
                for e in (0.0, 0.45, 0.9)
            ]
        else:
            curves = [
                synth.centreline_mm(float(p), self.l0_mm, n=400)
                for p in np.linspace(-psi_frame_deg, psi_frame_deg, 17)
            ]
        # zoom out just enough (as render_photoset does) and turn the clamp so every shape fits
        from pipeline.synth.photoset_writer import choose_layout

        rotation_deg, _, need = choose_layout(curves, self.scene)
        if need > 1.0:
            mm_per_px = float(np.ceil(self.scene.mm_per_px * need * 1000) / 1000)
            self.scene = dataclasses.replace(self.scene, mm_per_px=mm_per_px)
        camera = synth.make_camera(
            self.scene, rotation_deg=rotation_deg, extent_mm=np.vstack(curves)
        )
        self.backdrop = synth.make_backdrop(
            self.scene, camera, seed=synth.child_seed(seed, 0), keepout_mm=curves
        )
        probe = synth.render_actuator(
            0.0, self.l0_mm, self.scene, seed=0, backdrop=self.backdrop, n=400
        )
        self._fixed_end = (float(probe.fixed_end_px[0]), float(probe.fixed_end_px[1]))

    def psi_deg(self, pressure_kpa: float, direction: str) -> float:
        """Model bending angle (deg) at ``pressure_kpa`` on the branch of ``direction``."""
        branch = "loading" if direction == "up" else "unloading"
        return float(
            np.asarray(
                self.psi_fn(self.material, np.array([max(pressure_kpa, 0.0)]), branch=branch)
            ).ravel()[0]
        )

    def _seed(self, trial: int, step: int) -> int:
        digest = hashlib.sha256(f"{self.seed}/{self.material}/{trial}/{step}".encode()).digest()
        return int.from_bytes(digest[:4], "little")

    def capture(self, shot: Shot) -> tuple[bytes, str]:
        if self._blocked is not None:
            e = float(
                self._blocked.blocked_eccentricity(self.material, max(shot.measured_kpa, 0.0))
            )
            shape = self._blocked.blocked_arc_mm(min(e, 0.95), self.l0_mm)
            rendered = self._synth.render_curve(
                shape.points_mm,
                self.scene,
                seed=self._seed(shot.trial, shot.step),
                backdrop=self.backdrop,
            )
            return bytes(rendered.jpeg_bytes), ".jpg"
        rendered = self._synth.render_actuator(
            self.psi_deg(shot.measured_kpa, shot.direction),
            self.l0_mm,
            self.scene,
            seed=self._seed(shot.trial, shot.step),
            backdrop=self.backdrop,
        )
        return bytes(rendered.jpeg_bytes), ".jpg"

    def photoset_settings(self) -> dict[str, Any]:
        out: dict[str, Any] = {
            "positive_turn": "ccw",
            "fixed_end": [round(v, 1) for v in self._fixed_end],
        }
        for key, attr in (("mm_per_px", "mm_per_px"), ("line_color", "line_color")):
            value = getattr(self.scene, attr, None)
            if value is not None:
                out[key] = value
        return out

    def close(self) -> None:
        pass


def open_camera(spec: str, *, material: str, l0_mm: float, seed: int = 0, timeout_s: float = 30.0,
                mode: str = "bending") -> Camera:
    """Open the camera named by ``spec`` (table in the module docstring).

    Raises
    ------
    UserInputError
        On a spec that names no backend.
    """
    spec = spec.strip()
    if spec.startswith("cmd:"):
        return CommandCamera(spec[4:], timeout_s=timeout_s)
    if spec.startswith("dir:"):
        return FolderCamera(spec[4:], timeout_s=timeout_s)
    if spec == "synthetic" or spec.startswith("synthetic:"):
        preset = spec.partition(":")[2] or "lab"
        return SyntheticCamera(material, l0_mm, preset=preset, seed=seed, mode=mode)
    if spec.isdigit():
        return OpenCVCamera(int(spec))
    if "://" in spec:
        return OpenCVCamera(spec)
    raise UserInputError(
        f"--camera {spec!r} is not understood; use a device index (0), a stream URL (rtsp://...), "
        "'cmd:COMMAND {path}', 'dir:FOLDER' or 'synthetic[:clean|lab|hard]'"
    )
