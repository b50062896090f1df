"""End to end: the real `snakemake` on a tiny config in a temporary folder."""

from __future__ import annotations

import os
import re
import shutil
import subprocess
import sys
from pathlib import Path

import pandas as pd
import pytest
import yaml

from pipeline.bench.campaign import run_accuracy

pytestmark = pytest.mark.slow

SNAKEMAKE = [sys.executable, "-m", "snakemake"]


def _tiny_config(repo: Path) -> dict:
    return {
        "datasets": [
            {"name": "sample", "source": "folder", "path": str(repo / "sample_images")},
            {
                "name": "tiny",
                "source": "synthetic",
                "material": "SS50",
                "actuators": 1,
                "trials": 1,
                "step_kpa": 60,
                "max_kpa": 240,
                "scene": "clean",
                "scene_set": {"width": 480, "height": 360},
            },
        ],
        "compare": {"bootstrap": 20},
        "bench": {"in_report": False},
    }


def _snakemake(workdir: Path, repo: Path, *args: str) -> subprocess.CompletedProcess:
    return subprocess.run(
        [*SNAKEMAKE, "-s", str(repo / "Snakefile"), "--directory", str(workdir), *args],
        capture_output=True,
        text=True,
    )


def _planned_jobs(stdout: str) -> dict[str, int]:
    table = stdout.split("Job stats:")[-1]
    return {m[1]: int(m[2]) for m in re.finditer(r"^(\w+)\s+(\d+)$", table, re.MULTILINE) if m[1] != "total"}


@pytest.fixture(scope="module")
def finished_run(tmp_path_factory, request):
    repo = Path(request.config.rootpath)
    workdir = tmp_path_factory.mktemp("wf")
    (workdir / "config.yaml").write_text(yaml.safe_dump(_tiny_config(repo)))
    out = _snakemake(workdir, repo, "--cores", "2")
    assert out.returncode == 0, out.stdout[-3000:] + out.stderr[-5000:]
    return repo, workdir


def test_outputs_exist_and_hold_real_numbers(finished_run):
    repo, workdir = finished_run
    res = workdir / "results"
    for name in ("sample", "tiny"):
        angles = pd.read_csv(res / "datasets" / name / "angles.csv")
        assert {"image", "psi_deg", "status", "pressure_kpa", "direction"} <= set(angles.columns)
        assert (angles["status"] != "failed").mean() > 0.9
        hyst = pd.read_csv(res / "datasets" / name / "hysteresis.csv")
        assert {"material", "direction", "pressure_kpa", "psi_mean_deg", "psi_sd_deg", "n"} <= set(hyst.columns)
    # both sets carry ground truth: the run is measured against it
    accuracy = run_accuracy(res).set_index("dataset")
    assert set(accuracy.index) == {"sample", "tiny"}
    assert (accuracy["n_ok"] >= accuracy["n"] - 1).all()
    assert (accuracy["median_deg"] < 1.0).all() and (accuracy["n_ok_over_5deg"] == 0).all()
    rms = pd.read_csv(res / "rms.csv")
    assert {"DS20", "SS50"} <= set(rms["material"])
    pdf = (res / "report.pdf").read_bytes()
    assert pdf.startswith(b"%PDF") and len(pdf) > 20_000
    for sub in ("logs", "benchmarks"):
        assert any((res / sub).rglob("*")), f"no {sub} written"


def test_rerun_does_nothing(finished_run):
    repo, workdir = finished_run
    out = _snakemake(workdir, repo, "-n", "--cores", "2")
    assert out.returncode == 0
    assert "Nothing to be done" in out.stdout + out.stderr


def test_adding_a_dataset_reruns_only_its_jobs_and_the_summary(finished_run):
    repo, workdir = finished_run
    cfg = _tiny_config(repo)
    cfg["datasets"].append({"name": "new", "source": "synthetic", "material": "SS50", "actuators": 1, "trials": 1, "step_kpa": 120, "max_kpa": 240})
    (workdir / "config2.yaml").write_text(yaml.safe_dump(cfg))
    out = _snakemake(workdir, repo, "-n", "--cores", "2", "--configfile", str(workdir / "config2.yaml"))
    assert out.returncode == 0, out.stderr[-3000:]
    jobs = _planned_jobs(out.stdout)
    assert jobs.get("synth_photoset") == 1 and jobs.get("measure") == 1 and jobs.get("aggregate") == 1
    assert jobs.get("compare") == 1 and jobs.get("report") == 1
    assert "model_curve" not in jobs  # SS50's curve is already there
    assert "results/datasets/new/angles.csv" in out.stdout
    assert "results/datasets/tiny/angles.csv" not in re.findall(r"output: (\S+)", out.stdout)


def test_model_readings_in_the_config_reach_model_and_compare(finished_run):
    repo, workdir = finished_run
    cfg = _tiny_config(repo)
    cfg["model"] = {"readings": {"l0_factor": "metres", "jacobian": "deformed"}}
    (workdir / "config3.yaml").write_text(yaml.safe_dump(cfg))
    out = _snakemake(workdir, repo, "-n", "-p", "--cores", "2", "--configfile", str(workdir / "config3.yaml"))
    assert out.returncode == 0, out.stderr[-3000:]
    jobs = _planned_jobs(out.stdout)
    assert jobs.get("model_curve") == 2 and jobs.get("compare") == 1  # DS20 (sample) and SS50
    assert "measure" not in jobs and "synth_photoset" not in jobs  # photos and angles stay
    commands = [line for line in out.stdout.splitlines() if "python -m pipeline model curve" in line
                or "python -m pipeline compare" in line]
    assert len(commands) == 3
    assert all("--jacobian deformed --l0-factor metres" in c for c in commands)


def test_broken_config_is_refused_before_any_job(tmp_path, repo):
    cfg = _tiny_config(repo)
    cfg["datasets"][1]["material"] = "DS25"
    (tmp_path / "config.yaml").write_text(yaml.safe_dump(cfg))
    out = _snakemake(tmp_path, repo, "--cores", "1")
    assert out.returncode != 0
    text = out.stdout + out.stderr
    assert "datasets[1].material: unknown material 'DS25'" in text
    assert not (tmp_path / "results").exists()


def test_lint_and_dry_run_on_the_default_config(repo, tmp_path):
    work = tmp_path / "clone"
    shutil.copytree(repo, work, ignore=shutil.ignore_patterns("results", ".snakemake", ".git", "__pycache__"))
    out = subprocess.run([*SNAKEMAKE, "--lint"], cwd=work, capture_output=True, text=True)
    assert out.returncode == 0, out.stdout[-3000:] + out.stderr[-3000:]
    out = subprocess.run([*SNAKEMAKE, "-n", "--cores", "2"], cwd=work, capture_output=True, text=True)
    assert out.returncode == 0, out.stderr[-3000:]
    jobs = _planned_jobs(out.stdout)
    assert jobs["synth_photoset"] == 4 and jobs["measure"] == 5 and jobs["report"] == 1


def test_slurm_profile_plans_the_workflow(repo, tmp_path):
    work = tmp_path / "clone"
    shutil.copytree(repo, work, ignore=shutil.ignore_patterns("results", ".snakemake", ".git", "__pycache__"))
    out = subprocess.run(
        [*SNAKEMAKE, "--executor", "slurm", "--profile", "rules/profiles/slurm", "-n"],
        cwd=work, capture_output=True, text=True,
        env={**os.environ, "SBATCH_ACCOUNT": "lab", "SBATCH_PARTITION": "debug"},
    )
    assert out.returncode == 0, out.stdout[-3000:] + out.stderr[-3000:]
    assert _planned_jobs(out.stdout)["measure"] == 5


def test_rig_dataset_is_acquired_through_the_emulator_and_measured(tmp_path, repo):
    """A `rig` dataset: Snakemake runs `acquire` against the pty emulator, photos land outside results/."""
    from pipeline.rig.emulator import Emulator

    with Emulator(seed=4) as emu:
        cfg = {
            "datasets": [
                {"name": "rigA1", "source": "rig", "path": "data/rigA1", "port": emu.port, "camera": "synthetic",
                 "material": "SS50", "actuator": "A1", "trials": 1, "step_kpa": 100, "max_kpa": 200,
                 "settle_s": 0, "l0_mm": 270},
            ],
            "bench": {"in_report": False},
        }
        (tmp_path / "config.yaml").write_text(yaml.safe_dump(cfg))
        out = _snakemake(tmp_path, repo, "--cores", "1", "results/datasets/rigA1/hysteresis.csv")
    assert out.returncode == 0, out.stdout[-3000:] + out.stderr[-3000:]
    photos = sorted((tmp_path / "data" / "rigA1").glob("*.jpg"))
    assert len(photos) == 5  # 0, 100, 200 kPa up; 100, 0 down
    angles = pd.read_csv(tmp_path / "results" / "datasets" / "rigA1" / "angles.csv")
    assert (angles["status"] == "ok").all()
    assert angles["psi_deg"].iloc[0] > angles["psi_deg"].iloc[2]  # pressure uncurls it
