# Helpers shared by the rules: config validation, dataset lookup, result paths, the parts every
# rule repeats (log, benchmark, job size, logged shell command) and shell arguments from the config.
#
# The config schema ships inside the package (pipeline/config.schema.yaml, so `pipeline.config`
# validates a config without the workflow around it); it is applied here, before any job runs.
#
# Every value that reaches a shell command from the config is quoted: placeholders carry `:q`, and
# the option helpers below return lists of arguments, which `{params.x:q}` quotes one by one.
import re
import sys
from pathlib import Path

from snakemake.exceptions import WorkflowError

from pipeline.config import known_materials, unmodelled_material_note, validate_config
from pipeline.errors import UserInputError
from pipeline.folders import update_folder_digest
from pipeline.photoset import newer_spreadsheet_problems, read_manifest, referenced_files

try:
    _validated = validate_config(config, workdir=Path.cwd(), source="config")
except UserInputError as exc:
    raise WorkflowError(str(exc)) from None
config.clear()
config.update(_validated)

RESULTS = config["results_dir"]
DATASETS = {ds["name"]: ds for ds in config["datasets"]}
FORCE_DATASETS = {ds["name"]: ds for ds in config["force"]["datasets"]}
LOGS = f"{RESULTS}/logs"
BENCHMARKS = f"{RESULTS}/benchmarks"
CONDA_ENV = "envs/pipeline.yaml"

# Job sizes for a cluster (memory in MB, wall time in minutes); threads are set by each rule.
SMALL_JOB = {"mem_mb": 500, "runtime": 5}  # a model curve, a small table
TABLE_JOB = {"mem_mb": 1000, "runtime": 10}  # tables of a whole campaign
PHOTO_JOB = {"mem_mb": 2000, "runtime": 30}  # a photo set: render, measure, report

#: log lines a failed job shows on the console
LOG_TAIL_LINES = 25


wildcard_constraints:
    dataset="|".join(re.escape(n) for n in DATASETS) or "no-dataset",
    force_dataset="|".join(re.escape(n) for n in FORCE_DATASETS) or "no-dataset",
    material=r"[A-Za-z0-9_.-]+",


def log_file(job):
    """Log of one job, e.g. `log_file("measure/{dataset}")`."""
    return f"{LOGS}/{job}.log"


def benchmark_file(job):
    """Run-time and memory record of one job."""
    return f"{BENCHMARKS}/{job}.tsv"


def logged(command):
    """`command` with its output in the job's log; when it fails, the log's last lines are printed.

    Snakemake itself only reports the exit status; the message that names the file, the row and
    the fix is at the end of the log.
    """
    return (
        f"{{{{ {command}; }}}} > {{log:q}} 2>&1 || {{{{ status=$?;"
        f' echo "--- exit status $status; last {LOG_TAIL_LINES} lines of" {{log:q}}: >&2;'
        f" tail -n {LOG_TAIL_LINES} {{log:q}} >&2; exit $status; }}}}"
    )


def _digest(kind, name, folder):
    """Digest file of a photo-set folder and of the files outside it that it names (a background
    or calibration board photo), rewritten (at DAG build) only when one of them changed."""
    digest = f"{RESULTS}/digests/{kind}/{name}.sha256"
    return str(update_folder_digest(folder, digest, referenced_files(folder)))


# A folder's measure job depends on the bytes of every file in it (a photo replaced, added or
# removed, or manifest.csv/photoset.yaml edited) and of a background or board photo it names
# outside it, through a digest kept under results/digests/.
FOLDER_DIGESTS = {
    n: _digest("datasets", n, ds["path"]) for n, ds in DATASETS.items() if ds["source"] == "folder"
}
FORCE_FOLDER_DIGESTS = {
    n: _digest("force", n, ds["path"])
    for n, ds in FORCE_DATASETS.items()
    if ds["source"] == "folder"
}


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
    return FOLDER_DIGESTS[wildcards.dataset]


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


def materials_file(ds):
    """The materials file of a dataset's model: its own, else model.materials_file (None: packaged)."""
    return ds.get("materials_file") or config["model"]["materials_file"]


# Model curves: one per material in results/model/ for datasets on the run's materials file, and one
# per material of each dataset with its own file under its results folder (never the same path).
# A lab's own material that the materials file lacks has no curve: its photos are measured and
# reported, and the comparison says the model has no such material (how to add it).
MODEL_MATERIALS = known_materials(config["model"]["materials_file"])
_NAMED = {(name, m) for name, ds in DATASETS.items() if not ds.get("materials_file") for m in dataset_materials(ds)}
MATERIALS = sorted({m for _, m in _NAMED} & MODEL_MATERIALS)
# said once on the console (a job run inside Snakemake parses this file again): materials the
# model lacks, and a manifest edited in a spreadsheet and saved in its own format (not only in
# the measure job's log)
if workflow.is_main_process:
    for _name, _m in sorted(_NAMED):
        if _m not in MODEL_MATERIALS:
            print(unmodelled_material_note(_name, _m, MODEL_MATERIALS), file=sys.stderr)
    for _ds in [*DATASETS.values(), *FORCE_DATASETS.values()]:
        if _ds["source"] == "folder":
            for _problem in newer_spreadsheet_problems(Path(_ds["path"])):
                print(f"dataset {_ds['name']!r}: {_problem}", file=sys.stderr)
OWN_MODEL_CURVES = [
    f"{RESULTS}/datasets/{name}/model/{m}.csv"
    for name, ds in DATASETS.items()
    if ds.get("materials_file")
    for m in dataset_materials(ds)
]
# every materials file the run reads: an input of the jobs that use it, so an edit re-runs them
MATERIALS_FILES = sorted({f for f in [config["model"]["materials_file"]] + [materials_file(d) for d in DATASETS.values()] if f})


def per_dataset(pattern):
    """One path per configured dataset, in config order."""
    return [pattern.format(results=RESULTS, dataset=name) for name in DATASETS]


def materials_option():
    """`--materials FILE` when the config names a materials file."""
    path = config["model"]["materials_file"]
    return ["--materials", path] if path else []


def dataset_materials_option():
    """`--dataset-materials FILE|- ...` (one per dataset, in config order) when a dataset has its own file."""
    files = [ds.get("materials_file") or "-" for ds in DATASETS.values()]
    return ["--dataset-materials", *files] if any(f != "-" for f in files) else []


def model_readings_option():
    """`--<reading> VALUE` for `model` and `compare`: the readings model.readings gives."""
    readings = config["model"]["readings"]
    return [
        arg
        for key, value in sorted(readings.items())
        if value is not None
        for arg in (f"--{key.replace('_', '-')}", str(value))
    ]


def measure_method_option():
    """`--method NAME` unless the config asks for the package default."""
    method = config["measure"]["method"]
    return [] if method == "default" else ["--method", method]


def overlays_option(folder):
    """`--overlays DIR` when overlays are enabled."""
    return ["--overlays", folder] if config["measure"]["overlays"] else []


def scene_overrides(ds):
    """`--set KEY=VALUE` options of a synthetic dataset's scene overrides."""
    pairs = sorted(ds.get("scene_set", {}).items())
    return [arg for k, v in pairs for arg in ("--set", f"{k}={v}")]


def force_photoset_dir(name):
    """Folder of a blocked-force photo set (synthetic sets are rendered under results/)."""
    ds = FORCE_DATASETS[name]
    return f"{RESULTS}/force_photosets/{name}" if ds["source"] == "synthetic" else ds["path"]


def force_photoset_input(wildcards):
    """What a force measure job waits for (and re-runs on when it changes)."""
    ds = FORCE_DATASETS[wildcards.force_dataset]
    if ds["source"] == "synthetic":
        return f"{RESULTS}/force_photosets/{wildcards.force_dataset}"
    return FORCE_FOLDER_DIGESTS[wildcards.force_dataset]


FORCE_OUTPUTS = (
    [f"{RESULTS}/force/force_summary.csv"] if FORCE_DATASETS else []
) + ([f"{RESULTS}/force/grasp_summary.csv"] if config["force"]["grasp_log"] else [])
