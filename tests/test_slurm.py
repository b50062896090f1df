"""The workflow on a real SLURM cluster, through the executor plugin and rules/profiles/slurm.

The cluster tests need a running cluster: `.ci/slurm-up` starts a single-node one on this
machine (`.ci/run` does, and sets PIPELINE_REQUIRE_SLURM=1 so that a missing cluster fails
there instead of skipping). Jobs go to account/partition SBATCH_ACCOUNT/SBATCH_PARTITION,
by default those of .ci/slurm-up (lab, debug). The profile checks need no cluster.
"""

from __future__ import annotations

import os
import re
import shutil
import subprocess
import sys
from pathlib import Path

import pytest
import yaml

from pipeline.cluster import SLURM_SETTINGS, slurm_problems

SNAKEMAKE = [sys.executable, "-m", "snakemake"]
PROFILE = "rules/profiles/slurm"
NO_SBATCH_ENV = {
    k: v for k, v in os.environ.items() if k not in ("SBATCH_ACCOUNT", "SBATCH_PARTITION")
}


def _tiny_config(repo: Path) -> dict:
    """Every rule of the default target but the speed study (2.5 min; timings differ run to run).

    One small synthetic ramp and one blocked-force set: each SLURM job costs seconds of start-up,
    so the run is kept to one job per rule and wildcard (11 jobs).
    """
    return {
        "datasets": [
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
        "force": {
            "datasets": [
                {
                    "name": "force_SS50",
                    "source": "synthetic",
                    "material": "SS50",
                    "trials": 1,
                    "step_kpa": 60,
                    "seed": 50,
                }
            ],
            "grasp_log": str(repo / "pipeline" / "force" / "data" / "grasp_example.csv"),
        },
    }


def _snakemake(workdir: Path, repo: Path, *args: str, env=None, **kw):
    return subprocess.run(
        [*SNAKEMAKE, "-s", str(repo / "Snakefile"), "--directory", str(workdir), *args],
        capture_output=True, text=True, env=env, **kw, check=False,
    )


# --- the profile (no cluster needed) -------------------------------------------------------------


def test_profile_refuses_an_unset_account_and_partition_before_any_job(repo, tmp_path):
    (tmp_path / "config.yaml").write_text(yaml.safe_dump(_tiny_config(repo)))
    out = _snakemake(tmp_path, repo, "--profile", str(repo / PROFILE), "-n", env=NO_SBATCH_ENV)
    text = out.stdout + out.stderr
    assert out.returncode != 0, text[-2000:]
    assert "SLURM account is empty" in text and "export SBATCH_ACCOUNT=" in text
    assert "SLURM partition is empty" in text and "export SBATCH_PARTITION=" in text
    assert "Job stats" not in text and not (tmp_path / "results").exists()


@pytest.mark.parametrize(
    "resources, environ, empty",
    [
        ({"slurm_account": "$SBATCH_ACCOUNT", "slurm_partition": "${SBATCH_PARTITION}"},
         {"SBATCH_ACCOUNT": "lab", "SBATCH_PARTITION": "debug"}, []),
        ({"slurm_account": "'lab'", "slurm_partition": "gpu"}, {}, []),
        ({"slurm_account": "", "slurm_partition": "  "}, {}, ["account", "partition"]),
        ({"slurm_account": "''", "slurm_partition": "$SBATCH_PARTITION"}, {"SBATCH_PARTITION": ""},
         ["account", "partition"]),
        ({"slurm_account": "$SBATCH_ACCOUNT"}, {}, ["account"]),
        ({"mem_mb": 1000}, {}, []),  # a run without the profile: nothing to check
    ],
)
def test_slurm_problems_name_each_empty_setting(resources, environ, empty):
    problems = slurm_problems(resources, environ)
    assert [p.message.split()[1] for p in problems] == empty
    for p in problems:
        setting = next(s for s in SLURM_SETTINGS if s.what in p.message)
        assert setting.env in p.fix and p.file == PROFILE + "/config.yaml"


def test_profile_polls_soon_keeps_logs_and_shows_failures(repo):
    profile = yaml.safe_load((repo / PROFILE / "config.yaml").read_text())
    assert profile["executor"] == "slurm"
    assert profile["default-resources"]["slurm_account"] == "$SBATCH_ACCOUNT"
    assert profile["default-resources"]["slurm_partition"] == "$SBATCH_PARTITION"
    assert profile["slurm-init-seconds-before-status-checks"] <= 10  # the plugin's 40 s idles
    assert profile["slurm-logdir"].startswith("results/logs/")
    assert profile["show-failed-logs"] is True


def test_slurm_extra_installs_the_plugin_and_the_readme_uses_it(repo):
    tomllib = pytest.importorskip("tomllib")  # Python >= 3.11
    extras = tomllib.loads((repo / "pyproject.toml").read_text())["project"][
        "optional-dependencies"
    ]
    assert any(req.startswith("snakemake-executor-plugin-slurm") for req in extras["slurm"])
    assert any(req.endswith("[slurm]") for req in extras["test"])
    readme = (repo / "README.md").read_text()
    section = readme.split("## Running on a SLURM cluster", 1)[1].split("\n## ", 1)[0]
    assert "python -m pip install -e '.[slurm]'" in section
    assert f"snakemake --profile {PROFILE}" in section


# --- on the cluster ------------------------------------------------------------------------------


def _cluster_problem() -> str | None:
    """Why no cluster can take jobs here, or None when its node is up."""
    if shutil.which("sinfo") is None:
        return "no SLURM client (sinfo) on PATH"
    try:
        out = subprocess.run(
            ["sinfo", "-h", "-o", "%T"], capture_output=True, text=True, timeout=30, check=False
        )
    except subprocess.TimeoutExpired:
        return "sinfo did not answer within 30 s"
    states = out.stdout.split()
    if out.returncode != 0 or not any(
        s.rstrip("*~#") in ("idle", "mixed", "allocated", "completing") for s in states
    ):
        return (
            f"no SLURM node is up (sinfo: {(out.stdout + out.stderr).strip()[:300] or 'no nodes'})"
        )
    return None


@pytest.fixture(scope="module")
def slurm_env() -> dict[str, str]:
    """Environment for a run on the cluster; skips (fails under PIPELINE_REQUIRE_SLURM=1) without
    one."""
    problem = _cluster_problem()
    if problem:
        message = f"{problem}; start a single-node cluster with .ci/slurm-up"
        if os.environ.get("PIPELINE_REQUIRE_SLURM") == "1":
            pytest.fail(message)
        pytest.skip(message)
    return {**os.environ, "SBATCH_ACCOUNT": os.environ.get("SBATCH_ACCOUNT") or "lab",
            "SBATCH_PARTITION": os.environ.get("SBATCH_PARTITION") or "debug"}


def _slurm_jobs(output: str) -> list[dict[str, str]]:
    """The SLURM jobs of one Snakemake run (by its run ID), from the accounting database."""
    run_id = re.search(r"SLURM run ID: (\S+)", output)
    assert run_id, "the executor plugin printed no run ID:\n" + output[-3000:]
    out = subprocess.run(
        ["sacct", "-n", "-P", "-X", f"--name={run_id[1]}", "-S", "now-6hours",
         "-o", "Comment,State,AllocCPUS,Account,Partition"],
        capture_output=True, text=True, check=True,
    )
    keys = ("comment", "state", "cpus", "account", "partition")
    return [dict(zip(keys, line.split("|"))) for line in out.stdout.splitlines() if line]


def _rule(job: dict[str, str]) -> str:
    return job["comment"].removeprefix("rule_").split("_wildcards_")[0]


def _logs(results: Path) -> list[str]:
    return sorted(str(p.relative_to(results)) for p in (results / "logs").rglob("*.log")
                  if "slurm" not in p.relative_to(results).parts)


@pytest.mark.slow
def test_workflow_on_slurm_gives_the_same_report_as_the_local_run(repo, tmp_path, slurm_env):
    cfg = yaml.safe_dump(_tiny_config(repo))
    local, cluster = tmp_path / "local", tmp_path / "slurm"
    for d in (local, cluster):
        d.mkdir()
        (d / "config.yaml").write_text(cfg)
    log = (cluster / "snakemake.out").open("w+")
    slurm_run = subprocess.Popen(
        [
            *SNAKEMAKE,
            "-s",
            str(repo / "Snakefile"),
            "--directory",
            str(cluster),
            "--profile",
            str(repo / PROFILE),
        ],
        stdout=log,
        stderr=subprocess.STDOUT,
        text=True,
        env=slurm_env,
    )
    try:
        local_run = _snakemake(local, repo, "--cores", "2")
        slurm_run.wait(timeout=900)
    finally:
        if slurm_run.poll() is None:
            slurm_run.terminate()
            slurm_run.wait(timeout=60)
    log.seek(0)
    output = log.read()
    assert local_run.returncode == 0, local_run.stderr[-3000:]
    assert slurm_run.returncode == 0, output[-5000:]

    # the same bytes where the inputs are the same
    assert (cluster / "results/report.pdf").read_bytes() == (
        local / "results/report.pdf"
    ).read_bytes()
    for table in ("rms.csv", "force/force_summary.csv", "datasets/tiny/hysteresis.csv"):
        assert (cluster / "results" / table).read_bytes() == (
            local / "results" / table
        ).read_bytes(), table

    # every rule ran as a SLURM job of the profile's account and partition, threads -> CPUs
    jobs = _slurm_jobs(output)
    assert {_rule(j) for j in jobs} == {
        "synth_photoset",
        "measure",
        "aggregate",
        "model_curve",
        "compare",
        "resolved_config",
        "report",
        "force_synth_photoset",
        "force_measure",
        "force_aggregate",
        "force_grasp",
    }
    assert all(j["state"] == "COMPLETED" for j in jobs), jobs
    assert {(j["account"], j["partition"]) for j in jobs} == {
        (slurm_env["SBATCH_ACCOUNT"], slurm_env["SBATCH_PARTITION"])}
    cpus = {_rule(j): int(j["cpus"]) for j in jobs}
    assert cpus["measure"] == 2 and cpus["synth_photoset"] == 2 and cpus["aggregate"] == 1

    # rule logs where a local run puts them; SLURM's own logs of successful jobs are not kept
    assert _logs(cluster / "results") == _logs(local / "results")
    assert not list((cluster / "results/logs/slurm").rglob("*.log"))


@pytest.mark.slow
def test_a_failing_rule_on_slurm_fails_the_run_and_shows_its_log(repo, tmp_path, slurm_env):
    """The rig dataset is acquired from the emulator inside a SLURM job; the grasp log is bad.

    With --keep-going the acquisition finishes although the grasp job failed.
    """
    from pipeline.rig.emulator import Emulator

    (tmp_path / "grasp.csv").write_text(
        "material,object,side,diameter_mm,mass_g,pressure_kpa,held\n"
        "DS20,ring,inside,90,700,20,maybe\n"
    )
    with Emulator(seed=4) as emu:
        cfg = {
            "datasets": [{"name": "rigA1", "source": "rig", "path": "data/rigA1", "port": emu.port,
                          "camera": "synthetic", "material": "SS50", "actuator": "A1", "trials": 1,
                          "step_kpa": 100, "max_kpa": 200, "settle_s": 0, "l0_mm": 270}],
            "bench": {"in_report": False},
            "force": {"grasp_log": "grasp.csv"},
        }
        (tmp_path / "config.yaml").write_text(yaml.safe_dump(cfg))
        out = _snakemake(tmp_path, repo, "--profile", str(repo / PROFILE), "--keep-going",
                         "results/acquired/rigA1.done", "results/force/grasp_summary.csv",
                         env=slurm_env, timeout=900)
    text = out.stdout + out.stderr
    assert out.returncode != 0, text[-3000:]
    assert "Error in rule force_grasp" in text
    # the rule's own log, with the row and the fix, is on the console
    assert "grasp.csv line 2, column held: 'maybe' (fix: write yes or no)" in text, text[-3000:]
    assert not (tmp_path / "results/force/grasp_summary.csv").exists()
    # the other branch went on and finished on the cluster
    assert (tmp_path / "results/acquired/rigA1.done").is_file()
    assert len(list((tmp_path / "data/rigA1").glob("*.jpg"))) == 5
    states = {_rule(j): j["state"] for j in _slurm_jobs(text)}
    assert states["force_grasp"] == "FAILED" and states["acquire_rig"] == "COMPLETED", states
    # SLURM's log of the failed job is kept for a look
    assert list((tmp_path / "results/logs/slurm/rule_force_grasp").rglob("*.log"))
