"""Settings of a cluster run, checked once where they enter: the SLURM profile's resources.

The SLURM profile (``rules/profiles/slurm/config.yaml``) takes the account and the partition
from ``SBATCH_ACCOUNT`` and ``SBATCH_PARTITION`` (the variables ``sbatch`` itself reads) or from
values written into the profile.  Left empty, the executor plugin would guess an account and
submit to whatever partition the cluster defaults to, or sbatch would fail job by job; this
module refuses such a run before any job is submitted, saying what to set.
"""

from __future__ import annotations

import string
from collections.abc import Mapping
from dataclasses import dataclass

from pipeline.errors import UserInputError
from pipeline.photoset import Problem

SLURM_PROFILE = "rules/profiles/slurm/config.yaml"


@dataclass(frozen=True)
class SlurmSetting:
    """One SLURM setting the profile passes as a default resource.

    Attributes
    ----------
    resource : str
        Snakemake resource read by the executor plugin (``slurm_account``).
    env : str
        Environment variable the profile takes it from (``SBATCH_ACCOUNT``).
    what : str
        Its name for people (``account``).
    lookup : str
        A command that lists the values a user may use.
    """

    resource: str
    env: str
    what: str
    lookup: str


SLURM_SETTINGS: tuple[SlurmSetting, ...] = (
    SlurmSetting("slurm_account", "SBATCH_ACCOUNT", "account",
                 "sacctmgr -nP show assoc user=$USER format=account"),
    SlurmSetting("slurm_partition", "SBATCH_PARTITION", "partition", "sinfo -s"),
)


def resolve_resource(raw: object, environ: Mapping[str, str]) -> str:
    """The value a profile resource takes: ``$VAR``/``${VAR}`` expanded, outer quotes removed.

    An unset variable stays as written (``$SBATCH_ACCOUNT``), as Snakemake leaves it.

    Examples
    --------
    >>> resolve_resource("$SBATCH_ACCOUNT", {"SBATCH_ACCOUNT": "lab"})
    'lab'
    >>> resolve_resource("'gpu'", {})
    'gpu'
    >>> resolve_resource("$SBATCH_ACCOUNT", {})
    '$SBATCH_ACCOUNT'
    """
    text = "" if raw is None else str(raw)
    text = string.Template(text).safe_substitute(environ).strip()
    if len(text) >= 2 and text[0] == text[-1] and text[0] in "'\"":
        text = text[1:-1].strip()
    return text


def slurm_problems(
    default_resources: Mapping[str, object], environ: Mapping[str, str]
) -> list[Problem]:
    """Every empty or unset SLURM account/partition among a run's default resources.

    Parameters
    ----------
    default_resources : mapping
        Resource name -> value as written in the profile or on the command line
        (``--default-resources``). A setting that is absent is not checked: a local run has
        none, and a cluster without accounts drops ``slurm_account`` (and sets
        ``slurm-no-account: true``).
    environ : mapping
        The environment the values are expanded in.

    Returns
    -------
    list of Problem
        One per setting that is present but resolves to nothing, with the fix.

    Examples
    --------
    >>> slurm_problems({"slurm_account": "$SBATCH_ACCOUNT", "slurm_partition": "debug"},
    ...                {"SBATCH_ACCOUNT": "lab"})
    []
    >>> [p.message for p in slurm_problems({"slurm_partition": ""}, {})]
    ['SLURM partition is empty (default-resources slurm_partition)']
    """
    problems = []
    for setting in SLURM_SETTINGS:
        if setting.resource not in default_resources:
            continue
        raw = default_resources[setting.resource]
        value = resolve_resource(raw, environ)
        if value and "$" not in value:
            continue
        unset = f"; {value} is not set" if value else ""
        problems.append(Problem(
            file=SLURM_PROFILE,
            line=None,
            message=f"SLURM {setting.what} is empty (default-resources {setting.resource}{unset})",
            fix=f"export {setting.env}=<your {setting.what}> (yours: `{setting.lookup}`) "
                f"or write it as {setting.resource} in the profile",
        ))
    return problems


def check_slurm_resources(
    default_resources: Mapping[str, object], environ: Mapping[str, str]
) -> None:
    """Refuse a run whose SLURM account or partition is empty, listing every problem.

    Raises
    ------
    UserInputError
        When :func:`slurm_problems` finds anything.
    """
    problems = slurm_problems(default_resources, environ)
    if problems:
        raise UserInputError("cannot submit to SLURM:\n  " + "\n  ".join(str(p) for p in problems))
