"""Shared test fixtures."""

from __future__ import annotations

import signal
from collections.abc import Callable, Sequence
from pathlib import Path

import cv2
import numpy as np
import pandas as pd
import pytest

REPO = Path(__file__).resolve().parent.parent


#: session fixtures whose tests run on one xdist worker (pyproject: --dist loadgroup), so that each
#: is built once per run, not once on every worker
ONE_WORKER_FIXTURES = {"video_set": "video_set", "measured": "video_set"}


@pytest.hookimpl(tryfirst=True)  # before xdist reads the groups
def pytest_collection_modifyitems(items: list[pytest.Item]) -> None:
    for item in items:
        used = getattr(item, "fixturenames", ())
        for group in sorted({g for name, g in ONE_WORKER_FIXTURES.items() if name in used}):
            item.add_marker(pytest.mark.xdist_group(group))
    # the long ones first (the shared workflow run alone is over a minute on one worker): handed
    # out last, they left one worker busy while the other had nothing left to do
    items.sort(
        key=lambda it: 0 if it.get_closest_marker("slow") or it.get_closest_marker("xdist_group")
        else 1
    )


@pytest.fixture
def sigint_as_in_a_terminal():
    """Children started during the test take Ctrl-C as from a terminal, whatever the test runner
    does: a runner started in the background (``nohup ... &``) ignores SIGINT, and an ignored
    signal is passed on to every child (a handled one is reset to the default), so a Ctrl-C test
    would reach nothing."""
    before = signal.signal(signal.SIGINT, signal.default_int_handler)
    yield
    signal.signal(signal.SIGINT, before)


@pytest.fixture
def repo() -> Path:
    """The repository root (Snakefile, config.yaml, sample_images/)."""
    return REPO


@pytest.fixture
def photo_folder(tmp_path: Path) -> Path:
    """A folder of six small photos named like a lab's camera export (two ramps 0-20-0 kPa)."""
    img = np.full((24, 32, 3), 200, np.uint8)
    for trial in (1, 2):
        for step, kpa in enumerate([0, 10, 20, 10, 0][: 3 if trial == 2 else 5]):
            cv2.imwrite(str(tmp_path / f"DS30_A2_t{trial}_s{step:02d}_{kpa}kPa.jpg"), img)
    return tmp_path


@pytest.fixture(scope="session")
def video_set(tmp_path_factory) -> Path:
    """A video photo set: SS40 through pressure steps 0-40-80-40-0 kPa held 2.5 s each from 1.2 s
    (320x240, 10 fps, 135 frames, MJPEG; the video starts 0.7 s after its pressure log, at rest for
    0.5 s before and after the steps).  Read-only: copy it to change it."""
    from pipeline.synth.video import render_video
    from pipeline.video.profile import PressureProfile

    folder = tmp_path_factory.mktemp("video") / "steps"
    render_video(
        folder,
        "SS40",
        profile=PressureProfile("steps", max_kpa=80, step_kpa=40, hold_s=2.5),
        fps=10,
        rest_s=0.5,
        clock_offset_s=0.7,
        scene="lab",
        scene_overrides={"width": 320, "height": 240, "tilt_deg": 0.0},
        seed=3,
    )
    return folder


@pytest.fixture(scope="session")
def measured(video_set):
    """``measure_photoset(video_set, jobs=2)``: the angles table of every frame."""
    from pipeline.photoset_measure import measure_photoset

    return measure_photoset(video_set, jobs=2)


@pytest.fixture(scope="session")
def soft_ss50() -> str:
    """A materials file holding SS50 at half the packaged modulus (mu 0.34 MPa), l0 240 mm."""
    return (
        "geometry: {b_mm: 3.8, a0_mm: 6.4, t0_mm: 3.8, psi0_deg: 210.0, l0_mm: 240.0}\n"
        "materials:\n  SS50: {mu_mpa: [0.34], alpha: [2.0], k_p: 2.2, k_t: null}\n"
    )


def write_ramp_set(
    folder: Path, photos: Sequence[np.ndarray], settings: Sequence[str],
    empty_scene: np.ndarray | None = None,
) -> Path:
    """A photo set of one ramp, up and back down, 20 kPa a step: ``photos`` as ``p00.png`` ...,
    ``settings`` the lines of its ``photoset.yaml``, and its ``empty.png`` when given (named
    there as ``background``)."""
    folder.mkdir()
    rows = []
    top = len(photos) // 2
    for i, photo in enumerate(photos):
        name = f"p{i:02d}.png"
        cv2.imwrite(str(folder / name), photo)
        rows.append((name, 20 * min(i, 2 * top - i), "up" if i <= top else "down", "M", "A", 1, i))
    columns = ["image", "pressure_kpa", "direction", "material", "actuator", "trial", "step"]
    pd.DataFrame(rows, columns=columns).to_csv(folder / "manifest.csv", index=False)
    lines = list(settings)
    if empty_scene is not None:
        cv2.imwrite(str(folder / "empty.png"), empty_scene)
        lines.append("background: empty.png")
    (folder / "photoset.yaml").write_text("\n".join(lines) + "\n")
    return folder


@pytest.fixture(scope="session")
def ramp_set_writer() -> Callable[..., Path]:
    """:func:`write_ramp_set`, for tests that render a scene of their own."""
    return write_ramp_set
