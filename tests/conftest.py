"""Shared test fixtures."""

from __future__ import annotations

from pathlib import Path

import cv2
import numpy as np
import pytest

REPO = Path(__file__).resolve().parent.parent


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
