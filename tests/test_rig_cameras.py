"""Camera backends on real inputs (a video file, shell commands, a folder) and camera failure
handling."""

from __future__ import annotations

import cv2
import numpy as np
import pandas as pd
import pytest

from pipeline.errors import UserInputError
from pipeline.rig.cameras import (
    CameraError,
    CommandCamera,
    FolderCamera,
    OpenCVCamera,
    Shot,
    image_suffix,
    open_camera,
)
from pipeline.rig.emulator import Emulator

SHOT = Shot(pressure_kpa=40.0, measured_kpa=39.1, direction="up", trial=1, step=2)


def test_opencv_camera_reads_frames_from_a_video(tmp_path):
    video = tmp_path / "clip.avi"
    writer = cv2.VideoWriter(str(video), cv2.VideoWriter_fourcc(*"MJPG"), 10, (64, 48))
    if not writer.isOpened():
        pytest.skip("this OpenCV build cannot write MJPG AVI")
    for i in range(8):
        writer.write(np.full((48, 64, 3), 30 * i, np.uint8))
    writer.release()
    cam = OpenCVCamera(str(video), flush_frames=2)
    data, suffix = cam.capture(SHOT)
    frame = cv2.imdecode(np.frombuffer(data, np.uint8), cv2.IMREAD_COLOR)
    assert suffix == ".jpg" and frame.shape == (48, 64, 3)
    assert abs(float(frame.mean()) - 60.0) < 8  # two frames flushed: the third frame (value 60)
    cam.close()
    with pytest.raises(CameraError):
        OpenCVCamera(str(tmp_path / "missing.avi"))


def test_command_camera(tmp_path):
    src = tmp_path / "a.png"
    cv2.imwrite(str(src), np.zeros((8, 8, 3), np.uint8))
    cam = CommandCamera(f"cp {src} {{path}}")
    data, suffix = cam.capture(SHOT)
    assert suffix == ".png" and data == src.read_bytes()
    cam.close()
    with pytest.raises(UserInputError, match="path"):
        CommandCamera("gphoto2 --capture-image")
    with pytest.raises(CameraError, match="exit 3"):
        CommandCamera("exit 3 # {path}").capture(SHOT)
    with pytest.raises(CameraError, match="wrote nothing"):
        CommandCamera("true {path}").capture(SHOT)
    with pytest.raises(CameraError, match="not a JPEG"):
        CommandCamera("echo hello > {path}").capture(SHOT)


def test_folder_camera_times_out_and_ignores_old_files(tmp_path):
    cv2.imwrite(str(tmp_path / "old.jpg"), np.zeros((8, 8, 3), np.uint8))
    cam = FolderCamera(tmp_path, timeout_s=0.2)
    with pytest.raises(CameraError, match="no new image"):
        cam.capture(SHOT)
    with pytest.raises(UserInputError):
        FolderCamera(tmp_path / "nope")


def test_image_suffix_and_specs():
    assert image_suffix(b"\xff\xd8\xff\xe0rest") == ".jpg"
    assert image_suffix(b"II*\x00rest") == ".tif"
    for bad in ("webcam", "cmd:", "http"):
        with pytest.raises(UserInputError):
            open_camera(bad, material="DS20", l0_mm=200.0)


def test_camera_failure_mid_ramp_vents_and_keeps_rows(tmp_path, capsys):
    """A camera that fails at its 3rd shot: exit 5, vented, the 2 photos before it kept."""
    from pipeline.cli import main

    src = tmp_path / "a.png"
    cv2.imwrite(str(src), np.zeros((8, 8, 3), np.uint8))
    counter = tmp_path / "n"
    command = (
        f"n=$(cat {counter} 2>/dev/null || echo 0); echo $((n+1)) > {counter}; "
        f"[ $n -lt 2 ] && cp {src} {{path}}"
    )
    out = tmp_path / "set"
    with Emulator() as emu:
        code = main(
            [
                "acquire",
                "--port",
                emu.port,
                "--camera",
                f"cmd:{command}",
                "--material",
                "DS20",
                "--actuator",
                "A1",
                "--trials",
                "1",
                "--step-kpa",
                "50",
                "--max-kpa",
                "100",
                "--settle-s",
                "0",
                "--l0-mm",
                "200",
                "--out",
                str(out),
                "--no-progress",
            ]
        )
        assert emu.setpoint_kpa == 0.0
    err = capsys.readouterr().err
    assert code == 5 and "camera failed" in err and "vented to 0 kPa" in err
    assert len(pd.read_csv(out / "manifest.csv")) == 2
