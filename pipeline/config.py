"""Workflow configuration: defaults, JSON-schema validation and checks that need the file system.

The schema (``config.schema.yaml``, shipped inside this package so the package validates a config
without the workflow around it) is the single source of the keys, their defaults and their
descriptions; the enums of ``model.readings`` are taken from :data:`pipeline.model.CHOICES` when
it is loaded.  :func:`validate_config` fills defaults and refuses a bad config with one message
per problem, naming the key path (``datasets[2].material``) and the fix, before any Snakemake job
runs.
"""

from __future__ import annotations

import copy
import difflib
import hashlib
import json
import os
from collections.abc import Mapping
from dataclasses import fields
from importlib import resources
from pathlib import Path
from typing import Any

import jsonschema
import yaml

from pipeline.errors import UserInputError
from pipeline.model import CHOICES, ModelOptions, load_materials

#: the schema, as shipped in the package (named so in messages)
SCHEMA_NAME = "pipeline/config.schema.yaml"


def load_schema() -> dict[str, Any]:
    """Read the configuration JSON-schema (YAML) and complete it from the model's options.

    Each categorical key of ``model.readings`` gets ``type: string``, ``enum`` = the model's
    :data:`~pipeline.model.CHOICES` and ``default`` = :class:`~pipeline.model.ModelOptions`'s
    value; the numeric ones get their default from ``ModelOptions`` too.

    Returns
    -------
    dict

    Examples
    --------
    >>> readings = load_schema()["properties"]["model"]["properties"]["readings"]["properties"]
    >>> readings["l0_factor"]["enum"], readings["l0_factor"]["default"]
    (['metres', 'none', 'fitted_scale'], 'metres')
    """
    text = resources.files("pipeline").joinpath("config.schema.yaml").read_text(encoding="utf-8")
    schema = yaml.safe_load(text)
    readings = schema["properties"]["model"]["properties"]["readings"]["properties"]
    defaults = ModelOptions()
    options = {f.name for f in fields(ModelOptions)}
    for key, sub in readings.items():
        if key in CHOICES:
            sub.update(type="string", enum=list(CHOICES[key]))
        if key in options:
            sub["default"] = getattr(defaults, key)
    return schema


def fill_defaults(config: Any, schema: Mapping[str, Any]) -> Any:
    """Return a copy of ``config`` with every missing key set to its schema ``default``.

    Recurses into ``properties`` of objects and ``items`` of arrays, but not into an object
    marked ``overrides: true`` (a mapping whose absent keys mean "the default", such as
    ``model.readings``: only what the user gave is passed on).

    Examples
    --------
    >>> fill_defaults({}, {"type": "object", "properties": {"a": {"default": 1}}})
    {'a': 1}
    >>> fill_defaults({}, {"properties": {"o": {"default": {}, "overrides": True,
    ...                                         "properties": {"b": {"default": 2}}}}})
    {'o': {}}
    """
    config = copy.deepcopy(config)
    if schema.get("overrides"):
        return config
    if isinstance(config, dict) and "properties" in schema:
        for key, sub in schema["properties"].items():
            if key not in config and "default" in sub:
                config[key] = copy.deepcopy(sub["default"])
            if key in config:
                config[key] = fill_defaults(config[key], sub)
    elif isinstance(config, list) and isinstance(schema.get("items"), Mapping):
        config = [fill_defaults(item, schema["items"]) for item in config]
    return config


def _key_path(path: Any) -> str:
    out = ""
    for part in path:
        out += f"[{part}]" if isinstance(part, int) else (f".{part}" if out else str(part))
    return out or "(top level)"


def _schema_errors(config: Mapping[str, Any], schema: Mapping[str, Any]) -> list[str]:
    validator = jsonschema.Draft7Validator(schema)
    messages = []
    for err in sorted(validator.iter_errors(config), key=lambda e: list(map(str, e.absolute_path))):
        key = _key_path(err.absolute_path)
        hint = err.schema.get("description", "") if isinstance(err.schema, Mapping) else ""
        if err.validator == "required":
            # a conditional requirement (an if/then block) says why in its description
            why = (
                err.schema.get("description")
                if set(err.schema) <= {"required", "description"}
                else None
            )
            name = str(err.message).split("'")[1]  # "'port' is a required property"
            where = f"{key}.{name}" if err.absolute_path else name
            messages.append(f"{where}: required" + (f" {why}" if why else ""))
        elif err.validator == "additionalProperties":
            allowed = sorted(err.schema.get("properties", {}))
            messages.append(f"{key}: {err.message}; allowed keys here: {allowed}")
        elif err.validator == "enum":
            messages.append(f"{key}: {err.instance!r} is not one of {err.validator_value}")
        else:
            messages.append(
                f"{key}: {err.message}" + (f" (expected: {hint.strip()})" if hint else "")
            )
    return list(dict.fromkeys(messages))


def _materials_problem(
    key: str, path: str, workdir: Path, instead: str
) -> tuple[set[str] | None, str | None]:
    """The material names a config's materials file holds, or the problem that stops it being
    read."""
    file = workdir / path
    if not file.is_file():
        return None, (
            f"{key}: materials file {path!r} does not exist (relative to {workdir}); fix the path, "
            f"or set it to null for {instead}"
        )
    try:
        return set(load_materials(file)), None
    except UserInputError as exc:
        return None, f"{key}: materials file {path!r} cannot be used: {exc}"


def _folder_materials(folder: Path) -> list[str]:
    """Materials a folder photo set's manifest names ([] when it cannot be read: measure says
    why)."""
    from pipeline.photoset import read_manifest  # imported here: the measurement stack is heavy

    try:
        return sorted(read_manifest(folder)["material"].dropna().astype(str).unique())
    except UserInputError:
        return []


def _semantic_errors(
    config: Mapping[str, Any], workdir: Path, materials: set[str] | None
) -> list[str]:
    """Problems only the file system shows; ``materials``: model.materials_file's (None: it is
    unreadable)."""
    messages = []
    names: dict[str, int] = {}
    cased: dict[str, str] = {}
    packaged = known_materials()
    results = (workdir / str(config.get("results_dir", "results"))).resolve()
    for section in ("datasets",):
        for i, ds in enumerate(config.get(section, [])):
            key = f"{section}[{i}]"
            name = ds.get("name")
            if name in names:
                messages.append(
                    f"{key}.name: {name!r} is used twice (also {section}[{names[name]}]); give "
                    "each dataset a unique name"
                )
            elif str(name).casefold() in cased:
                # on a Mac or Windows disk (or a share) results/datasets/syn and .../Syn are one
                messages.append(
                    f"{key}.name: {name!r} and {cased[str(name).casefold()]!r} differ only in "
                    "case, and on a Mac or Windows disk their results would share one folder; "
                    "give each dataset a name of its own"
                )
            names.setdefault(name, i)
            cased.setdefault(str(name).casefold(), str(name))
            source = ds.get("source")
            folder_ok = source != "folder" or (workdir / ds["path"]).is_dir()
            if not folder_ok:
                messages.append(
                    f"{key}.path: photo-set folder {ds['path']!r} does not exist (relative to "
                    f"{workdir}); fix the path or copy the photo set there"
                )
            elif source == "folder":
                messages += _results_problems(key, ds["path"], (workdir / ds["path"]).resolve(),
                                              results, workdir.resolve())
            own = ds.get("materials_file")  # replaces model.materials_file for this dataset
            where, model_materials = "model.materials_file", materials
            if own:
                where = f"{key}.materials_file (dataset {name!r})"
                model_materials, problem = _materials_problem(
                    where, own, workdir, "model.materials_file"
                )
                messages += [problem] if problem else []
            named = (
                [ds["material"]]
                if ds.get("material")
                else (
                    _folder_materials(workdir / ds["path"])
                    if own and source == "folder" and folder_ok
                    else []
                )
            )
            missing = [m for m in named if model_materials is not None and m not in model_materials]
            for m in missing:
                if own:
                    messages.append(
                        f"{where}: material {m!r} (named by the dataset) is not in {own!r}, "
                        f"which holds {sorted(model_materials or ())}; add {m!r} to that file "
                        "or point materials_file at one holding it"
                    )
                else:
                    messages.append(
                        f"{key}.material: unknown material {m!r}; use one of "
                        f"{sorted(model_materials or ())} or add it to a materials file "
                        "(model.materials_file, or the dataset's own materials_file)"
                    )
            if (
                source in ("synthetic", "synthetic_video")
                and not missing
                and ds["material"] not in packaged
            ):
                messages.append(
                    f"{key}.material: synthetic photos are rendered from the packaged model, "
                    f"which has no material {ds['material']!r}; use one of {sorted(packaged)} "
                    "(a materials file changes the comparison, not the rendering)"
                )
            if source == "rig" and not ds["port"]:
                messages.append(
                    f"{key}.port: required for source 'rig' (the Pico's serial port, e.g. "
                    "/dev/ttyACM0)"
                )
    for i, ds in enumerate(config.get("force", {}).get("datasets", [])):
        if ds.get("source") == "folder" and not (workdir / ds["path"]).is_dir():
            messages.append(
                f"force.datasets[{i}].path: photo-set folder {ds.get('path')!r} does not exist"
            )
        elif (
            ds.get("source") == "synthetic"
            and materials is not None
            and ds.get("material") not in materials
        ):
            messages.append(
                f"force.datasets[{i}].material: unknown material {ds.get('material')!r}; "
                f"use one of {sorted(materials)}"
            )
    grasp = config.get("force", {}).get("grasp_log")
    if grasp and not (workdir / grasp).is_file():
        messages.append(
            f"force.grasp_log: file {grasp!r} does not exist; fix the path or set it to null"
        )
    return messages


def _results_problems(
    key: str, path: str, folder: Path, results: Path, workdir: Path
) -> list[str]:
    """A photo set and ``results_dir`` inside one another (customer 47: results inside the set
    failed in the measure job, naming a --cache it never typed; a set kept in results/, which
    the README calls the run's own and yours to delete, was taken without a word)."""
    if results == folder or results.is_relative_to(folder):
        return [(
            f"results_dir: {str(results)!r} lies inside the photo set {path!r} ({key}): the "
            "run's files would join its photos; give results_dir a folder outside it"
        )]
    if folder.is_relative_to(results) and not workdir.is_relative_to(results):
        return [(
            f"{key}.path: the photo set {path!r} lies inside results_dir ({str(results)!r}), "
            "the run's own folder, which may be deleted to run afresh; keep the photos in a "
            "folder outside it"
        )]
    return []


def known_materials(materials_file: str | Path | None = None) -> set[str]:
    """Names of the materials the model knows (built-in table, or ``materials_file``)."""
    return set(load_materials(materials_file) if materials_file else load_materials())


def _home_expanded(config: dict[str, Any]) -> dict[str, Any]:
    """``config`` with ``~`` in its paths turned into the home folder (``path: ~/data/june``).

    Examples
    --------
    >>> cfg = _home_expanded({"datasets": [{"path": "~/june"}], "force": {"grasp_log": None}})
    >>> cfg["datasets"][0]["path"] == os.path.expanduser("~/june")
    True
    """

    def home(value: Any) -> Any:
        return os.path.expanduser(value) if isinstance(value, str) else value

    out = copy.deepcopy(config)
    for section in (out, out.get("force") or {}):
        for ds in section.get("datasets") or []:
            if isinstance(ds, dict):
                for key in ("path", "materials_file"):
                    if key in ds:
                        ds[key] = home(ds[key])
    tops = (
        (out, "results_dir"),
        (out.get("model") or {}, "materials_file"),
        (out.get("force") or {}, "grasp_log"),
    )
    for parent, key in tops:
        if isinstance(parent, dict) and key in parent:
            parent[key] = home(parent[key])
    return out


def unmodelled_material_note(dataset: str, material: str, known: set[str]) -> str:
    """What a run says of a dataset's material that the model's materials file lacks.

    Its photos are measured, aggregated and reported all the same; only the model comparison
    is left out (a lab's own actuator), so this is a note, not a refusal, and it names a close
    known name in case of a typo.

    Examples
    --------
    >>> unmodelled_material_note("mine", "DS 20", {"DS20", "SS40"})[:60]
    "note: dataset 'mine' names material 'DS 20', which the model"
    >>> "did you mean 'DS20'" in unmodelled_material_note("mine", "DS 20", {"DS20"})
    True
    """
    close = difflib.get_close_matches(material, sorted(known), n=1, cutoff=0.6)
    typo = f" (did you mean {close[0]!r}? then correct manifest.csv)" if close else ""
    return (
        f"note: dataset {dataset!r} names material {material!r}, which the model does not have "
        f"(it has {', '.join(sorted(known))}){typo}: its photos are measured and reported, but "
        "not compared with the model; to compare, add the material to a materials file and name "
        "it in config.yaml (model.materials_file, or the dataset's materials_file)"
    )


def validate_config(
    config: Mapping[str, Any],
    *,
    workdir: str | Path = ".",
    source: str = "config.yaml",
) -> dict[str, Any]:
    """Fill defaults and validate a workflow configuration.

    Parameters
    ----------
    config : mapping
        The configuration as loaded from YAML.
    workdir : path
        Folder relative to which paths in the config are resolved.
    source : str
        Name of the config file, used in error messages.

    Returns
    -------
    dict
        The configuration with every default filled in.

    Raises
    ------
    UserInputError
        Listing every problem, each naming the key path and the fix.
    """
    schema = load_schema()
    filled = _home_expanded(fill_defaults(dict(config), schema))
    problems = _schema_errors(filled, schema)
    if not problems:
        workdir = Path(workdir)
        mfile = filled["model"]["materials_file"]
        materials, problem = (
            _materials_problem("model.materials_file", mfile, workdir, "the packaged materials")
            if mfile
            else (known_materials(), None)
        )
        problems = ([problem] if problem else []) + _semantic_errors(filled, workdir, materials)
    if problems:
        raise UserInputError(
            f"{source} is not valid ({len(problems)} problem(s)); nothing was run:\n  - "
            + "\n  - ".join(problems)
            + f"\n  Every key, its default and its meaning: {SCHEMA_NAME}"
        )
    return filled


def config_digest(config: Mapping[str, Any]) -> str:
    """Short, stable SHA-256 digest of a configuration (key order does not matter)."""
    text = json.dumps(config, sort_keys=True, default=str)
    return hashlib.sha256(text.encode()).hexdigest()[:16]


def write_resolved_config(config: Mapping[str, Any], path: str | Path) -> None:
    """Write the validated configuration (defaults filled in) as YAML, with its digest."""
    data = {"config_digest": config_digest(config), **dict(config)}
    Path(path).parent.mkdir(parents=True, exist_ok=True)
    Path(path).write_text(
        yaml.safe_dump(json.loads(json.dumps(data, default=str)), sort_keys=False)
    )
