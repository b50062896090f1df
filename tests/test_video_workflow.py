"""End to end: the real `snakemake` on a config holding one small synthetic video dataset."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pandas as pd
import pypdfium2 as pdfium
import pytest
import yaml

from pipeline.bench.campaign import run_accuracy

pytestmark = pytest.mark.slow

CONFIG = {
    "datasets": [
        {
            "name": "vid",
            "source": "synthetic_video",
            "material": "SS40",
            "profile": "steps",
            "max_kpa": 80,
            "step_kpa": 40,
            "hold_s": 2.5,
            "fps": 10,
            "rest_s": 0.5,
            "scene": "lab",
            "scene_set": {"width": 320, "height": 240, "tilt_deg": 0},
        }
    ],
    "compare": {"bootstrap": 20},
    "bench": {"in_report": False},
    "force": {"grasp_log": None},
}


def _snakemake(workdir: Path, repo: Path, *args: str) -> subprocess.CompletedProcess:
    return subprocess.run(
        [
            sys.executable,
            "-m",
            "snakemake",
            "-s",
            str(repo / "Snakefile"),
            "--directory",
            str(workdir),
            *args,
        ],
        capture_output=True,
        text=True, check=False,
    )


def test_a_video_dataset_runs_from_render_to_its_report_page(tmp_path, repo):
    (tmp_path / "config.yaml").write_text(yaml.safe_dump(CONFIG))
    out = _snakemake(tmp_path, repo, "--cores", "2")
    assert out.returncode == 0, out.stdout[-3000:] + out.stderr[-5000:]
    res = tmp_path / "results"
    angles = pd.read_csv(res / "datasets" / "vid" / "angles.csv")
    assert len(angles) == 135 and {"frame", "time_s"} <= set(angles.columns)
    accuracy = run_accuracy(res).set_index("dataset")
    assert accuracy.loc["vid", "n_ok"] >= 130 and accuracy.loc["vid", "median_deg"] < 0.1
    steps = pd.read_csv(res / "continuous" / "vid" / "steps.csv")
    assert list(steps["to_kpa"]) == [40, 80, 40, 0] and steps["rise_time_s"].notna().all()
    assert (res / "continuous" / "vid" / "strip.jpg").is_file()
    doc = pdfium.PdfDocument(str(res / "report.pdf"))
    text = [doc[i].get_textpage().get_text_range() for i in range(len(doc))]
    assert sum("Video dataset vid" in t for t in text) == 1
    again = _snakemake(tmp_path, repo, "-n", "--cores", "2")
    assert again.returncode == 0 and "Nothing to be done" in again.stdout + again.stderr
