# Cluster runs: an empty SLURM account or partition of the profile is refused before any job is
# submitted (also on a dry run), naming what to set. Jobs running on the cluster skip the check.
import os

from snakemake.exceptions import WorkflowError

from pipeline.cluster import check_slurm_resources
from pipeline.errors import UserInputError


if workflow.exec_mode.name == "DEFAULT":
    _resources = workflow.resource_settings.default_resources or {}
    try:
        check_slurm_resources({k: getattr(v, "raw", v) for k, v in _resources.items()}, os.environ)
    except UserInputError as exc:
        raise WorkflowError(str(exc)) from None
