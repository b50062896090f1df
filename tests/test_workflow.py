"""End to end: the real `snakemake` on tiny configs of the tests' own in temporary folders.

No test reads the user's `config.yaml`: adding a dataset to it (the README's step) changes no
test result (``test_lint_and_dry_run_plan_every_stage`` runs against such a checkout too).
"""

from __future__ import annotations

import os
import re
import shlex
import shutil
import signal
import subprocess
import sys
import time
from pathlib import Path

import cv2
import numpy as np
import pandas as pd
import pypdfium2 as pdfium
import pytest
import yaml

from pipeline.bench.campaign import run_accuracy
from pipeline.compare import rms_deg

pytestmark = pytest.mark.slow

SNAKEMAKE = [sys.executable, "-m", "snakemake"]
PHOTOS = "photos/sample"  # the folder dataset: the first ramp of sample_images/, copied per test


def _tiny_config() -> dict:
    return {
        "datasets": [
            {"name": "sample", "source": "folder", "path": PHOTOS},
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


#: a small synthetic video dataset, run with the two photo sets: SS40 through pressure steps
#: 0-40-80-40-0 kPa held 2.5 s each (320x240, 10 fps, 135 frames)
VIDEO_DATASET = {
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


#: the photo set of a shorter SS50 actuator (l0 220 mm), rendered by synth into the work folder
SHORT = "short"
#: the materials file of 'soft' (the photos of 'short' against SS50 at half the modulus)
SOFT_YAML = "soft.yaml"
OURS = "ours"  # a lab's own material: see _lab_material_set


def _finished_config() -> dict:
    """The config of the finished run: the two photo sets, the video dataset, and the photos of a
    shorter actuator twice, against the packaged model ('short') and against its own materials
    file ('soft')."""
    cfg = _tiny_config()
    cfg["datasets"] += [
        dict(VIDEO_DATASET),
        {"name": "short", "source": "folder", "path": SHORT},
        {"name": "soft", "source": "folder", "path": SHORT, "materials_file": SOFT_YAML},
        {"name": "ours", "source": "folder", "path": OURS},
    ]
    return cfg


def _lab_material_set(short: Path, folder: Path) -> None:
    """The short actuator's photos as a lab's own material (the model has no 'OurGel'; two rows
    say 'DS-20', a typo), with no renderer's truth: a real set."""
    shutil.copytree(short, folder, ignore=shutil.ignore_patterns("truth.csv"))
    rows = pd.read_csv(folder / "manifest.csv", dtype=str)
    rows["material"] = "OurGel"
    rows.loc[rows.index[:2], "material"] = "DS-20"
    rows.to_csv(folder / "manifest.csv", index=False)


def _render_short(folder: Path) -> None:
    """A folder photo set of an SS50 actuator of l0 = 220 mm (the packaged SS50 has 255 mm)."""
    from pipeline.cli import main

    args = ["--material", "SS50", "--actuators", "1", "--trials", "1", "--step-kpa", "80"]
    args += ["--max-kpa", "240", "--scene", "clean", "--set", "width=400", "--set", "height=300"]
    assert main(["synth", str(folder), *args, "--l0-mm", "220", "--seed", "3"]) == 0


def _snakemake(workdir: Path, repo: Path, *args: str) -> subprocess.CompletedProcess:
    return subprocess.run(
        [*SNAKEMAKE, "-s", str(repo / "Snakefile"), "--directory", str(workdir), *args],
        capture_output=True,
        text=True, check=False,
    )


def _workdir(path: Path, repo: Path, config: dict) -> Path:
    """A work folder holding the tests' own config and the first ramp of the sample photo set."""
    photos = path / PHOTOS
    photos.mkdir(parents=True)
    shutil.copy(repo / "sample_images" / "photoset.yaml", photos)
    for table in ("manifest.csv", "truth.csv"):
        rows = pd.read_csv(repo / "sample_images" / table, dtype=str)
        rows = rows[rows["trial"] == "1"]
        rows.to_csv(photos / table, index=False)
    for image in rows["image"]:
        shutil.copy2(repo / "sample_images" / image, photos)
    (path / "config.yaml").write_text(yaml.safe_dump(config))
    return path


def _planned_jobs(stdout: str) -> dict[str, int]:
    table = stdout.split("Job stats:")[-1]
    return {
        m[1]: int(m[2])
        for m in re.finditer(r"^(\w+)\s+(\d+)$", table, re.MULTILINE)
        if m[1] != "total"
    }


#: tests using the finished run go to one xdist worker (pyproject: --dist loadgroup), which builds
#: it once
ON_THE_FINISHED_RUN = pytest.mark.xdist_group("finished_run")


@pytest.fixture(scope="module")
def finished_run(tmp_path_factory, request, soft_ss50):
    repo = Path(request.config.rootpath)
    workdir = _workdir(tmp_path_factory.mktemp("wf"), repo, _finished_config())
    _render_short(workdir / SHORT)
    _lab_material_set(workdir / SHORT, workdir / OURS)
    (workdir / SOFT_YAML).write_text(soft_ss50)  # SS50 at mu 0.34 MPa; l0 240 mm, photos say 220
    out = _snakemake(workdir, repo, "--cores", "2")
    assert out.returncode == 0, out.stdout[-3000:] + out.stderr[-5000:]
    (workdir / "console.txt").write_text(out.stderr)  # what the user saw
    return repo, workdir


@ON_THE_FINISHED_RUN
def test_outputs_exist_and_hold_real_numbers(finished_run):
    _repo, workdir = finished_run
    res = workdir / "results"
    for name in ("sample", "tiny"):
        angles = pd.read_csv(res / "datasets" / name / "angles.csv")
        assert {"image", "psi_deg", "status", "pressure_kpa", "direction"} <= set(angles.columns)
        assert (angles["status"] != "failed").mean() > 0.9
        hyst = pd.read_csv(res / "datasets" / name / "hysteresis.csv")
        assert {"material", "direction", "pressure_kpa", "psi_mean_deg", "psi_sd_deg", "n"} <= set(
            hyst.columns
        )
    # every set carries ground truth: the run is measured against it (the video's in its own test)
    accuracy = run_accuracy(res).set_index("dataset")
    assert set(accuracy.index) == {"sample", "tiny", "vid", "short", "soft"}
    accuracy = accuracy.drop(index="vid")
    assert (accuracy["n_ok"] >= accuracy["n"] - 1).all()
    assert (accuracy["median_deg"] < 1.0).all() and (accuracy["n_ok_over_5deg"] == 0).all()
    rms = pd.read_csv(res / "rms.csv")
    assert {"DS20", "SS50"} <= set(rms["material"])
    pdf = (res / "report.pdf").read_bytes()
    assert pdf.startswith(b"%PDF") and len(pdf) > 20_000
    # the console ends with each set's counts (the jobs' own output is in their logs)
    console = (workdir / "console.txt").read_text()
    n = len(pd.read_csv(res / "datasets" / "sample" / "angles.csv"))
    assert f"sample: measured {n} photos: " in console, console[-2000:]
    for sub in ("logs", "benchmarks"):
        assert any((res / sub).rglob("*")), f"no {sub} written"


@ON_THE_FINISHED_RUN
def test_rerun_does_nothing(finished_run):
    repo, workdir = finished_run
    out = _snakemake(workdir, repo, "-n", "--cores", "2")
    assert out.returncode == 0
    assert "Nothing to be done" in out.stdout + out.stderr


@ON_THE_FINISHED_RUN
def test_adding_a_dataset_reruns_only_its_jobs_and_the_summary(finished_run):
    repo, workdir = finished_run
    cfg = _finished_config()
    cfg["datasets"].append(
        {
            "name": "new",
            "source": "synthetic",
            "material": "SS50",
            "actuators": 1,
            "trials": 1,
            "step_kpa": 120,
            "max_kpa": 240,
        }
    )
    (workdir / "config2.yaml").write_text(yaml.safe_dump(cfg))
    out = _snakemake(
        workdir, repo, "-n", "--cores", "2", "--configfile", str(workdir / "config2.yaml")
    )
    assert out.returncode == 0, out.stderr[-3000:]
    jobs = _planned_jobs(out.stdout)
    assert (
        jobs.get("synth_photoset") == 1 and jobs.get("measure") == 1 and jobs.get("aggregate") == 1
    )
    assert jobs.get("compare") == 1 and jobs.get("report") == 1
    assert "model_curve" not in jobs  # SS50's curve is already there
    assert "results/datasets/new/angles.csv" in out.stdout
    assert "results/datasets/tiny/angles.csv" not in re.findall(r"output: (\S+)", out.stdout)


@ON_THE_FINISHED_RUN
def test_model_readings_in_the_config_reach_model_and_compare(finished_run):
    repo, workdir = finished_run
    cfg = _finished_config()
    cfg["model"] = {"readings": {"l0_factor": "metres", "jacobian": "deformed"}}
    (workdir / "config3.yaml").write_text(yaml.safe_dump(cfg))
    out = _snakemake(
        workdir, repo, "-n", "-p", "--cores", "2", "--configfile", str(workdir / "config3.yaml")
    )
    assert out.returncode == 0, out.stderr[-3000:]
    jobs = _planned_jobs(out.stdout)
    # DS20 (sample), SS50 (tiny and short), SS40 (vid), and soft's SS50 of its own file
    assert jobs.get("model_curve") == 3 and jobs.get("model_curve_dataset") == 1
    assert jobs.get("compare") == 1
    # photos, videos and angles stay
    assert not {"measure", "synth_photoset", "synth_video", "continuous"} & set(jobs)
    commands = [line for line in out.stdout.splitlines() if "python -m pipeline model curve" in line
                or "python -m pipeline compare" in line]
    assert len(commands) == 5
    assert all("--jacobian deformed --l0-factor metres" in c for c in commands)


def test_a_manifest_saved_only_in_a_spreadsheets_format_is_said_on_the_console(tmp_path, repo):
    """Edits saved in manifest.xlsx are not read: the warning was only in measure's job log."""
    cfg = _tiny_config()
    cfg["datasets"] = cfg["datasets"][:1]
    _workdir(tmp_path, repo, cfg)
    workbook = tmp_path / PHOTOS / "manifest.xlsx"
    workbook.write_bytes(b"PK\x03\x04")
    later = (tmp_path / PHOTOS / "manifest.csv").stat().st_mtime + 60
    os.utime(workbook, (later, later))
    out = _snakemake(tmp_path, repo, "-n", "--cores", "1")
    assert out.returncode == 0, out.stderr[-3000:]
    assert "dataset 'sample': " in out.stderr
    assert "manifest.xlsx is newer than manifest.csv: edits saved only there are not read" in (
        out.stderr
    )


def test_broken_config_is_refused_before_any_job(tmp_path, repo):
    cfg = _tiny_config()
    cfg["datasets"][1]["material"] = "DS25"
    _workdir(tmp_path, repo, cfg)
    out = _snakemake(tmp_path, repo, "--cores", "1")
    assert out.returncode != 0
    text = out.stdout + out.stderr
    assert "datasets[1].material: unknown material 'DS25'" in text
    assert not (tmp_path / "results").exists()


def _users_checkout(repo: Path, path: Path) -> Path:
    """A checkout after the README's "add a dataset" step: a config.yaml with the user's own set.

    Written here, not derived from this checkout's config.yaml, which the tests never read.
    """
    ignore = shutil.ignore_patterns("results", ".snakemake", ".git", "__pycache__", "tests")
    shutil.copytree(repo, path, ignore=ignore)
    shutil.copytree(repo / "sample_images", path / "my_photos")
    (path / "config.yaml").write_text(
        "datasets:\n"
        "  - {name: sample, source: folder, path: sample_images}\n"
        "  - {name: my_photos, source: folder, path: my_photos}  # the README's step\n"
    )
    return path


def _every_stage_config(checkout: Path) -> dict:
    """One of each input: a folder set, synthetic sets, folder and synthetic force sets, a grasp
    log, the bench.

    The folder's name has a space and a scene override shell syntax: both must reach the commands
    intact.
    """
    photos = "lab photos"  # copied into the work folder
    return {
        "datasets": [
            {"name": "lab", "source": "folder", "path": photos},
            {
                "name": "DS20",
                "source": "synthetic",
                "material": "DS20",
                "scene_set": {"noise_sigma": "1 $(touch x)"},
            },
            {"name": "SS50", "source": "synthetic", "material": "SS50"},
        ],
        "force": {
            "datasets": [
                {"name": "force_lab", "source": "folder", "path": photos},
                {"name": "force_SS40", "source": "synthetic", "material": "SS40"},
            ],
            "grasp_log": str(checkout / "pipeline" / "force" / "data" / "grasp_example.csv"),
        },
    }


def test_the_readmes_report_of_your_photos_alone_plans_nothing_synthetic(repo, tmp_path):
    # customer 19 added a set beside the shipped entries and got a 16-page PDF of which most was
    # the sample, synthetic materials, synthetic force sets, the paper's grasp example and the
    # bench; the README's config for a report of your photos alone (tested as written there)
    # plans the user's set and the report only
    readme = (repo / "README.md").read_text(encoding="utf-8")
    block = re.search(r"report of your photos alone.*?```yaml\n(.*?)```", readme, re.DOTALL)
    assert block is not None
    (tmp_path / "config.yaml").write_text(block[1])
    shutil.copytree(repo / "sample_images", tmp_path / "my_photos")
    out = _snakemake(tmp_path, repo, "-n", "--cores", "2")
    assert out.returncode == 0, out.stderr[-3000:]
    planned = _planned_jobs(out.stdout)
    assert planned["measure"] == 1 and planned["report"] == 1, planned
    assert not [j for j in planned if "synth" in j or "bench" in j or "force" in j], planned


@pytest.mark.parametrize("checkout", ["as shipped", "after the README's add-a-dataset step"])
def test_lint_and_dry_run_plan_every_stage(checkout, repo, tmp_path):
    src = repo if checkout == "as shipped" else _users_checkout(repo, tmp_path / "user")
    work = tmp_path / "work"
    shutil.copytree(repo / "sample_images", work / "lab photos")
    (work / "config.yaml").write_text(yaml.safe_dump(_every_stage_config(src)))
    out = _snakemake(work, src, "--lint")
    assert out.returncode == 0, out.stdout[-3000:] + out.stderr[-3000:]
    out = _snakemake(work, src, "-n", "-p", "--cores", "2")
    assert out.returncode == 0, out.stderr[-3000:]
    commands = [
        shlex.split(line) for line in re.findall(r"^Shell command: (.*)$", out.stdout, re.MULTILINE)
    ]
    # one argument, not two
    measure = next(c for c in commands if "measure" in c and "lab photos" in c)
    assert measure[measure.index("measure") + 1] == "lab photos"
    synth = next(c for c in commands if "synth" in c and "results/photosets/DS20" in c)
    # quoted: never run by the shell
    assert synth[synth.index("--set") + 1] == "noise_sigma=1 $(touch x)"
    assert _planned_jobs(out.stdout) == {
        "all": 1,
        "synth_photoset": 2,
        "measure": 3,
        "aggregate": 3,
        "model_curve": 2,
        "compare": 1,
        "force_synth_photoset": 1,
        "force_measure": 2,
        "force_aggregate": 1,
        "force_grasp": 1,
        "bench_default": 1,
        "resolved_config": 1,
        "report": 1,
    }
    # a folder's measure job waits for the digest of the folder's bytes (kept under
    # results/digests/)
    for line in (
        "input: results/digests/datasets/lab.sha256",
        "input: results/digests/force/force_lab.sha256",
    ):
        assert line in out.stdout
    assert (work / "results" / "digests" / "force" / "force_lab.sha256").is_file()


def test_slurm_profile_plans_the_workflow(repo, tmp_path):
    work = tmp_path / "clone"
    shutil.copytree(
        repo, work, ignore=shutil.ignore_patterns("results", ".snakemake", ".git", "__pycache__")
    )
    cfg = _tiny_config()
    cfg["datasets"][0]["path"] = "sample_images"
    # the test's own config, never the user's
    (work / "config.yaml").write_text(yaml.safe_dump(cfg))
    out = subprocess.run(
        [*SNAKEMAKE, "--executor", "slurm", "--profile", "rules/profiles/slurm", "-n"],
        cwd=work, capture_output=True, text=True,
        env={**os.environ, "SBATCH_ACCOUNT": "lab", "SBATCH_PARTITION": "debug"}, check=False,
    )
    assert out.returncode == 0, out.stdout[-3000:] + out.stderr[-3000:]
    assert _planned_jobs(out.stdout)["measure"] == len(cfg["datasets"])


@ON_THE_FINISHED_RUN
def test_a_replaced_photo_is_remeasured_alone_and_a_plain_rerun_after_ctrl_c_finishes(
    finished_run, sigint_as_in_a_terminal, tmp_path
):
    """A re-taken photo re-runs its set's jobs only; Ctrl-C mid-measure; a plain re-run
    completes."""
    repo, done = finished_run
    work = tmp_path / "wf"
    shutil.copytree(done, work)  # photos, results and Snakemake's records, modification times kept
    angles = work / "results" / "datasets" / "sample" / "angles.csv"
    before = pd.read_csv(angles).set_index("image")
    fixed, donor = "DS20_A1_t1_s003_up_30kPa.jpg", "DS20_A1_t1_s008_up_80kPa.jpg"
    shutil.copyfile(work / PHOTOS / donor, work / PHOTOS / fixed)  # the lab re-took one photo
    # run, and Ctrl-C it (SIGINT to the process group, as a terminal sends it) while measure runs
    run = subprocess.Popen(
        [*SNAKEMAKE, "-s", str(repo / "Snakefile"), "--directory", str(work), "--cores", "2"],
        start_new_session=True,
        stdout=subprocess.PIPE,
        stderr=subprocess.STDOUT,
        text=True,
    )
    partial = angles.parent / ".overlays.partial"
    deadline = time.monotonic() + 120
    while (
        time.monotonic() < deadline
        and run.poll() is None
        and not (partial.is_dir() and any(partial.iterdir()))
    ):
        time.sleep(0.01)
    assert run.poll() is None, "the run ended before it could be interrupted: " + (
        run.communicate()[0][-4000:]
    )
    os.killpg(run.pid, signal.SIGINT)
    try:
        interrupted, _ = run.communicate(timeout=120)
    except subprocess.TimeoutExpired as hung:
        # seen once in a full run under -n 2 (never alone): say which process hung, then clear up
        tree = subprocess.run(
            ["ps", "-o", "pid,ppid,stat,wchan:24,etime,cmd", "-g", str(run.pid)],
            capture_output=True, text=True, check=False,
        ).stdout
        os.killpg(run.pid, signal.SIGKILL)
        run.communicate()
        out = hung.output or ""
        said = out.decode(errors="replace") if isinstance(out, bytes) else out
        pytest.fail(f"Snakemake did not stop within 120 s of Ctrl-C:\n{tree}\n{said[-3000:]}")
    said = interrupted[-4000:]  # what Snakemake printed: the cause, should an assert fail
    assert run.returncode != 0, said
    only_this_set = {"measure": 1, "aggregate": 1, "compare": 1, "report": 1, "all": 1}
    # what the photo set off
    assert _planned_jobs(interrupted.split("Terminating")[0]) == only_this_set, said
    outputs = re.findall(r"output: (\S+)", interrupted)
    assert "results/datasets/sample/angles.csv," in outputs and not [
        o for o in outputs if "/tiny/" in o
    ], said
    assert any((work / ".snakemake" / "incomplete").iterdir()), said  # a job was cut short ...
    assert not partial.exists(), said  # ... and its half-written overlays are gone
    out = _snakemake(work, repo, "--cores", "2")  # ... and a plain re-run finishes it
    assert out.returncode == 0, out.stdout[-3000:] + out.stderr[-3000:]
    assert _planned_jobs(out.stderr) == only_this_set
    after = pd.read_csv(angles).set_index("image")
    assert after.loc[fixed, "psi_deg"] == pytest.approx(before.loc[donor, "psi_deg"], abs=1e-6)
    assert before.loc[fixed, "psi_deg"] != pytest.approx(before.loc[donor, "psi_deg"], abs=1.0)
    others = before.index.drop(fixed)
    assert (after.loc[others, "psi_deg"] == before.loc[others, "psi_deg"]).all()


@ON_THE_FINISHED_RUN
def test_a_background_photo_outside_the_folder_is_watched_like_its_photos(finished_run, tmp_path):
    """A set may name an empty-scene photo outside its folder (shared by several sets):
    replacing it re-measures the sets that use it, and only them."""
    repo, done = finished_run
    work = tmp_path / "wf"
    shutil.copytree(done, work)
    empty = work / "empty_scene.png"
    cv2.imwrite(str(empty), np.full((300, 400, 3), 200, np.uint8))
    settings = work / SHORT / "photoset.yaml"
    settings.write_text(settings.read_text() + "background: ../empty_scene.png\n")
    # the edited photoset.yaml re-runs its sets; mark them done without measuring (--touch)
    out = _snakemake(work, repo, "--cores", "1", "--touch")
    assert out.returncode == 0, out.stderr[-3000:]
    assert _snakemake(work, repo, "-n", "--cores", "1").stdout.count("rule measure") == 0
    cv2.imwrite(str(empty), np.full((300, 400, 3), 90, np.uint8))  # the empty scene re-taken
    plan = _snakemake(work, repo, "-n", "--cores", "1")
    assert plan.returncode == 0, plan.stderr[-3000:]
    # 'short' and 'soft' read that folder; 'sample', 'tiny' and the video do not
    assert _planned_jobs(plan.stdout).get("measure") == 2, plan.stdout[-3000:]
    measured = set(re.findall(r"output: results/datasets/(\w+)/angles\.csv", plan.stdout))
    assert measured == {"short", "soft"}


def test_a_failed_job_shows_the_end_of_its_log_on_the_console(tmp_path, repo):
    cfg = _tiny_config()
    cfg["datasets"] = cfg["datasets"][:1]
    cfg["force"] = {"grasp_log": "grasp.csv"}
    _workdir(tmp_path, repo, cfg)
    (tmp_path / "grasp.csv").write_text("material,mass_g\nDS20,10\n")  # columns missing
    out = _snakemake(tmp_path, repo, "--cores", "1", "results/force/grasp_summary.csv")
    assert out.returncode != 0
    message = (
        (tmp_path / "results" / "logs" / "force_grasp.log").read_text().strip().splitlines()[-1]
    )
    assert "grasp.csv: missing column(s)" in message  # the log names the file and the fix ...
    assert message in out.stderr  # ... and the console shows it, not only an exit status


@ON_THE_FINISHED_RUN
def test_a_labs_own_material_is_measured_and_reported_without_the_model(finished_run):
    """A material the materials file lacks (a lab's own actuator, or a typo) stopped the run at
    its model curve job, so no report: now its photos are measured and reported, the console
    says why it is not compared with the model (a close known name too), and so does rms.csv."""
    _repo, workdir = finished_run
    console = (workdir / "console.txt").read_text()
    # once, though jobs run inside Snakemake parse the workflow again
    assert console.count("names material 'OurGel', which the model does not have") == 1
    assert "names material 'DS-20'" in console and "did you mean 'DS20'" in console
    res = workdir / "results"
    doc = pdfium.PdfDocument(str(res / "report.pdf"))
    try:
        first_page = " ".join(doc[0].get_textpage().get_text_range().split())
    finally:
        doc.close()
    assert "OurGel: the model has no such material, so there is no model line" in first_page
    assert not (res / "model" / "OurGel.csv").exists()
    angles = pd.read_csv(res / "datasets" / OURS / "angles.csv")
    assert (angles["status"] == "ok").sum() >= len(angles) - 1
    rms = pd.read_csv(res / "rms.csv").set_index("material")
    assert "has no material 'OurGel'" in rms.loc["OurGel", "note"]
    assert np.isnan(rms.loc["OurGel", "rms_deg"]) and rms.loc["OurGel", "range_deg"] > 30


def test_rig_dataset_is_acquired_through_the_emulator_and_measured(tmp_path, repo):
    """A `rig` dataset: Snakemake runs `acquire` against the pty emulator, photos land outside
    results/."""
    from pipeline.rig.emulator import Emulator

    with Emulator(seed=4) as emu:
        cfg = {
            "datasets": [
                {
                    "name": "rigA1",
                    "source": "rig",
                    "path": "data/rigA1",
                    "port": emu.port,
                    "camera": "synthetic",
                    "material": "SS50",
                    "actuator": "A1",
                    "trials": 1,
                    "step_kpa": 100,
                    "max_kpa": 200,
                    "settle_s": 0,
                    "l0_mm": 270,
                },
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


@ON_THE_FINISHED_RUN
def test_a_video_dataset_runs_from_render_to_its_report_page(finished_run):
    """The video dataset of the finished run: rendered, measured frame by frame, aggregated as a
    continuous recording and given its report page (that a re-run does nothing, the video's jobs
    included, is ``test_rerun_does_nothing``)."""
    _repo, workdir = finished_run
    res = workdir / "results"
    angles = pd.read_csv(res / "datasets" / "vid" / "angles.csv")
    assert len(angles) == 135 and {"frame", "time_s"} <= set(angles.columns)
    accuracy = run_accuracy(res).set_index("dataset")
    assert accuracy.loc["vid", "n_ok"] >= 130 and accuracy.loc["vid", "median_deg"] < 0.1
    steps = pd.read_csv(res / "continuous" / "vid" / "steps.csv")
    assert list(steps["to_kpa"]) == [40, 80, 40, 0] and steps["rise_time_s"].notna().all()
    assert (res / "continuous" / "vid" / "strip.jpg").is_file()
    # each strip tile's caption, written on the page large enough to read (customer 27)
    strip = pd.read_csv(res / "continuous" / "vid" / "strip.csv")
    assert len(strip) == 6 and strip["frame"].is_monotonic_increasing
    doc = pdfium.PdfDocument(str(res / "report.pdf"))
    text = [doc[i].get_textpage().get_text_range() for i in range(len(doc))]
    doc.close()
    assert sum("Video dataset vid" in t for t in text) == 1
    (page,) = [" ".join(t.split()) for t in text if "Video dataset vid" in t]
    assert f"frame {int(strip['frame'].iloc[-1])}" in page


@ON_THE_FINISHED_RUN
def test_workflow_models_each_dataset_at_its_own_l0(finished_run, tmp_path):
    """SS50 photo sets of the finished run, 'short' of an actuator with l0 = 220 mm: its model
    curve and its RMS use 220 mm, tiny's the default, and the report says which l0 each curve used
    and that synthetic RMS is a self-check.  'soft', the photos of 'short', names its own
    materials file (SS50 at half the modulus): its model curve and RMS are that file's, the report
    names the file and its sha256."""
    import hashlib

    from pipeline import model

    repo, workdir = finished_run
    res = workdir / "results"
    angles = pd.read_csv(res / "datasets" / "short" / "angles.csv")
    assert (angles["l0_mm"] == 220.0).all()  # measure carries each photo's l0
    default = model.load_materials()["SS50"].l0_mm
    assert default != 220.0
    rms = pd.read_csv(res / "rms.csv").set_index("datasets")
    assert rms.loc["short", "curve"] == "SS50, l0 220 mm" and rms.loc["short", "l0_mm"] == 220.0
    assert rms.loc["short", "l0_source"] == "photo set"
    assert rms.loc["tiny", "l0_mm"] == default == 255.0
    synthetic = rms.drop(index=OURS)  # 'ours' is a real set (no truth.csv)
    assert (synthetic["rms_kind"] == "self-check").all()
    assert (synthetic["data_source"] == "synthetic").all()
    # 'soft': the photos of 'short', compared against its own file's SS50 (mu 0.34 MPa, not 0.68) at
    # their 220 mm
    soft = model.load_materials(workdir / SOFT_YAML)["SS50"]
    assert soft.mu_mpa == (0.34,) and model.load_materials()["SS50"].mu_mpa == (0.68,)
    assert (
        rms.loc["soft", "curve"]
        == "SS50, l0 220 mm, materials soft.yaml"
        != rms.loc["short", "curve"]
    )
    assert (
        rms.loc["soft", "materials_file"] == "soft.yaml"
        and rms.loc["soft", "l0_source"] == "photo set"
    )
    assert rms.loc["soft", "l0_mm"] == 220.0  # the photo set's l0 wins over the file's 240 mm
    assert (
        rms.loc[["tiny", "short"], "materials_file"] == "packaged (pipeline/model/materials.yaml)"
    ).all()
    h_short = pd.read_csv(res / "datasets" / "short" / "hysteresis.csv")
    h_soft = pd.read_csv(res / "datasets" / "soft" / "hysteresis.csv")
    pd.testing.assert_frame_equal(
        h_short, h_soft
    )  # same photos: any difference below is the model's
    p_s, psi_s = h_soft["pressure_kpa"].to_numpy(float), h_soft["psi_mean_deg"].to_numpy(float)
    at_soft = rms_deg(psi_s, model.psi_deg(soft, p_s, l0_mm=220.0))[0]
    assert rms.loc["soft", "rms_deg"] == pytest.approx(at_soft, rel=1e-4)
    assert (
        rms.loc["soft", "rms_deg"] > rms.loc["short", "rms_deg"] + 5.0
    )  # drawn from the paper's SS50, not the soft one
    # two datasets naming SS50 with different materials files: two model curves, neither overwritten
    own_curve = pd.read_csv(res / "datasets" / "soft" / "model" / "SS50.csv")
    run_curve = pd.read_csv(res / "model" / "SS50.csv")
    np.testing.assert_allclose(
        own_curve["pressure_kpa"], model.model_curve(soft)["pressure_kpa"], rtol=1e-9
    )
    np.testing.assert_allclose(
        run_curve["pressure_kpa"], model.model_curve("SS50")["pressure_kpa"], rtol=1e-9
    )
    assert not np.allclose(own_curve["pressure_kpa"], run_curve["pressure_kpa"], equal_nan=True)
    soft_compared = pd.read_csv(res / "compare_curves.csv").query(
        "curve == 'SS50, l0 220 mm, materials soft.yaml'"
    )
    np.testing.assert_allclose(
        soft_compared["pressure_kpa"],
        model.model_curve(soft, l0_mm=220.0)["pressure_kpa"],
        rtol=1e-5,
    )
    # the RMS of 'short' is against the model at 220 mm: recompute it from its hysteresis.csv
    hyst = pd.read_csv(res / "datasets" / "short" / "hysteresis.csv")
    p, psi = hyst["pressure_kpa"].to_numpy(float), hyst["psi_mean_deg"].to_numpy(float)
    at_220 = rms_deg(psi, model.psi_deg("SS50", p, l0_mm=220.0))[0]
    at_default = rms_deg(psi, model.psi_deg("SS50", p))[0]
    assert rms.loc["short", "rms_deg"] == pytest.approx(at_220, rel=1e-4)
    assert abs(at_220 - at_default) > 1e-3
    curves = pd.read_csv(res / "compare_curves.csv")
    c220 = curves[curves["curve"] == "SS50, l0 220 mm"]
    assert len(c220) == 400 and (c220["l0_mm"] == 220.0).all()
    np.testing.assert_allclose(
        c220["pressure_kpa"],
        model.model_curve("SS50", l0_mm=220.0)["pressure_kpa"],
        rtol=1e-5,
        atol=1e-9,
    )
    doc = pdfium.PdfDocument(str(res / "report.pdf"))
    pages = [" ".join(doc[i].get_textpage().get_text_range().split()) for i in range(len(doc))]
    doc.close()
    comparison = next(t for t in pages if "Model versus measurements, beside" in t)
    assert (
        "photos rendered from this package's model, so the RMS is a self-check, not a validation"
        in comparison
    )
    assert (
        "Materials file of the model curves: packaged (pipeline/model/materials.yaml) "
        "(ours, sample, vid, tiny, short); soft.yaml (soft)" in comparison
    )
    provenance = next(t for t in pages if "Model versus measurements: which model curve" in t)
    assert "SS50, l0 220 mm" in provenance and "220 (photo set)" in provenance
    assert "220 (photo set) soft.yaml" in provenance
    assert f"SS50, l0 {default:g} mm" in provenance
    inputs = " ".join(t for t in pages if "Input files" in t)  # the table may go on a page
    assert hashlib.sha256((workdir / SOFT_YAML).read_bytes()).hexdigest() in inputs.replace(
        " ", ""
    )
    material = next(t for t in pages if "SS50: bending angle versus pressure" in t)
    assert "model, l0 220 mm" in material and f"model, l0 {default:g} mm" in material
    assert "model, l0 220 mm, materials soft.yaml" in material
    # an edited materials file re-runs what it feeds (its model curve, the comparison, the report),
    # nothing else (in a copy: the finished run stays as it is for the other tests)
    work = tmp_path / "wf"
    shutil.copytree(workdir, work)  # photos, results and Snakemake's records, times kept
    with (work / SOFT_YAML).open("a") as fh:
        fh.write("# k_P re-measured\n")
    dry = _snakemake(work, repo, "--cores", "2", "-n")
    assert dry.returncode == 0, dry.stderr[-3000:]
    jobs = _planned_jobs(dry.stdout)
    assert jobs == {"all": 1, "compare": 1, "model_curve_dataset": 1, "report": 1}, dry.stdout[
        -2000:
    ]


@ON_THE_FINISHED_RUN
def test_a_run_that_fails_sets_the_old_report_aside_and_warnings_reach_the_console(
    finished_run, tmp_path
):
    # customer 47: after a run stopped on a set's photoset.yaml the earlier report stayed as
    # report.pdf; a key ignored (psi moved on every ok row) was said only in the job's log
    repo, done = finished_run
    work = tmp_path / "wf"
    shutil.copytree(done, work)
    settings = work / PHOTOS / "photoset.yaml"
    written = settings.read_text()
    report = work / "results" / "report.pdf"
    made = report.read_bytes()
    settings.write_text(written + "operator:\tAnn\n")  # a tab: not YAML
    out = _snakemake(work, repo, "--cores", "2")
    assert out.returncode != 0
    stale = work / "results" / "report.STALE.pdf"
    assert not report.exists() and stale.read_bytes() == made, out.stderr[-3000:]
    assert f"is now {Path('results') / 'report.STALE.pdf'}" in out.stderr, out.stderr[-3000:]
    settings.write_text(written + "operator: Ann\n")
    out = _snakemake(work, repo, "--cores", "2")
    assert out.returncode == 0, out.stderr[-3000:]
    assert report.is_file() and not stale.exists()
    end = out.stderr.split("sample: measured")[-1]  # the end of the run's console
    assert "photoset.yaml: warning: unknown key 'operator' is ignored" in end, end
