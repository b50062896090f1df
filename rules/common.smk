# Helpers shared by the rules: config validation, dataset lookup, result paths.
import re
from pathlib import Path

from snakemake.exceptions import WorkflowError

from pipeline.config import validate_config
from pipeline.errors import UserInputError
from pipeline.photoset import read_manifest

try:
    _schema = Path(workflow.basedir) / "rules" / "config.schema.yaml"
    _validated = validate_config(config, workdir=Path.cwd(), source="config", schema_path=_schema)
except UserInputError as exc:
    raise WorkflowError(str(exc)) from None
config.clear()
config.update(_validated)

RESULTS = config["results_dir"]
DATASETS = {ds["name"]: ds for ds in config["datasets"]}
FORCE_DATASETS = {ds["name"]: ds for ds in config["force"]["datasets"]}
LOGS = f"{RESULTS}/logs"
CONDA_ENV = "envs/pipeline.yaml"
BENCHMARKS = f"{RESULTS}/benchmarks"


wildcard_constraints:
    dataset="|".join(re.escape(n) for n in DATASETS) or "no-dataset",
    force_dataset="|".join(re.escape(n) for n in FORCE_DATASETS) or "no-dataset",
    material=r"[A-Za-z0-9_.-]+",


def photoset_dir(name):
    """Folder of a dataset's photo set (synthetic sets are rendered under results/)."""
    ds = DATASETS[name]
    return f"{RESULTS}/photosets/{name}" if ds["source"] in ("synthetic", "synthetic_video") else ds["path"]


def photoset_input(wildcards):
    """What the measure job of a dataset waits for (and re-runs on when it changes)."""
    ds = DATASETS[wildcards.dataset]
    if ds["source"] in ("synthetic", "synthetic_video"):
        return f"{RESULTS}/photosets/{wildcards.dataset}"
    if ds["source"] == "rig":
        return f"{RESULTS}/acquired/{wildcards.dataset}.done"
    return [f"{ds['path']}/manifest.csv", f"{ds['path']}/photoset.yaml"]


def dataset_materials(ds):
    """Materials a dataset holds: from the config, or from a folder's manifest."""
    if ds.get("material"):
        return [ds["material"]]
    if ds["source"] == "folder":
        try:
            return sorted(read_manifest(ds["path"])["material"].dropna().astype(str).unique())
        except UserInputError as exc:
            raise WorkflowError(f"dataset {ds['name']!r}: {exc}") from None
    return []


MATERIALS = sorted({m for ds in DATASETS.values() for m in dataset_materials(ds)})


def per_dataset(pattern):
    """One path per configured dataset, in config order."""
    return [pattern.format(results=RESULTS, dataset=name) for name in DATASETS]


def materials_option():
    """`--materials FILE` when the config names a materials file."""
    path = config["model"]["materials_file"]
    return f"--materials {path}" if path else ""


def model_readings_option():
    """`--<reading> VALUE` flags for `model` and `compare` from config key model.readings."""
    readings = config["model"]["readings"]
    return " ".join(f"--{key.replace('_', '-')} {value}" for key, value in sorted(readings.items()))


def measure_method_option():
    """`--method NAME` unless the config asks for the package default."""
    method = config["measure"]["method"]
    return "" if method == "default" else f"--method {method}"


def overlays_option(folder):
    """`--overlays DIR` when overlays are enabled."""
    return f"--overlays {folder}" if config["measure"]["overlays"] else ""


def scene_overrides(ds):
    """`--set KEY=VALUE` options of a synthetic dataset's scene overrides."""
    return " ".join(f"--set {k}={v}" for k, v in sorted(ds.get("scene_set", {}).items()))


def force_photoset_dir(name):
    """Folder of a blocked-force photo set (synthetic sets are rendered under results/)."""
    ds = FORCE_DATASETS[name]
    return f"{RESULTS}/force_photosets/{name}" if ds["source"] == "synthetic" else ds["path"]


def force_photoset_input(wildcards):
    """What a force measure job waits for."""
    ds = FORCE_DATASETS[wildcards.force_dataset]
    if ds["source"] == "synthetic":
        return f"{RESULTS}/force_photosets/{wildcards.force_dataset}"
    return [f"{ds['path']}/manifest.csv", f"{ds['path']}/photoset.yaml"]


FORCE_OUTPUTS = (
    [f"{RESULTS}/force/force_summary.csv"] if FORCE_DATASETS else []
) + ([f"{RESULTS}/force/grasp_summary.csv"] if config["force"]["grasp_log"] else [])

