"""Config validation: defaults filled from the schema, bad configs refused naming key and fix."""

from __future__ import annotations

import os
import shutil
import subprocess
import sys

import pytest

from pipeline.config import config_digest, load_schema, validate_config
from pipeline.errors import UserInputError


def _walk(schema, path="config", required=frozenset()):
    """Every (path, sub-schema, required-here) of the schema; conditional (if/then) requirements
    count."""
    yield path, schema, path.rsplit(".", 1)[-1] in required
    needed = set(schema.get("required", []))
    for block in schema.get("allOf", []):
        needed |= set(block.get("then", {}).get("required", []))
    for key, sub in schema.get("properties", {}).items():
        yield from _walk(sub, f"{path}.{key}", frozenset(needed))
    if isinstance(schema.get("items"), dict):
        yield from _walk(schema["items"], f"{path}[]")


def test_every_key_has_a_description_and_every_leaf_a_default_or_is_required():
    schema = load_schema()
    leaves = 0
    for path, sub, required in _walk(schema):
        assert sub.get("description"), f"{path} has no description"
        if "properties" not in sub and "items" not in sub:
            leaves += 1
            assert "default" in sub or required, f"{path} has no default and is not marked required"
    assert leaves >= 45  # the walk saw the whole schema
    for key, sub in schema["properties"].items():
        assert "default" in sub, f"{key} has no default"


def test_the_schema_ships_in_the_package_and_repeats_no_model_choice(repo):
    import yaml as _yaml

    raw = _yaml.safe_load((repo / "pipeline" / "config.schema.yaml").read_text())
    readings = raw["properties"]["model"]["properties"]["readings"]["properties"]
    # only pipeline.model's CHOICES
    assert not [key for key, sub in readings.items() if "enum" in sub]
    assert not (repo / "rules" / "config.schema.yaml").exists()  # one schema, not two


def test_schema_defaults_alone_make_a_valid_config(repo):
    cfg = validate_config({}, workdir=repo)
    assert [(d["name"], d["source"], d["path"]) for d in cfg["datasets"]] == [
        ("sample", "folder", "sample_images")
    ]
    assert cfg["measure"] == {"method": "default", "jobs": 2, "overlays": True}
    # readings stay what the user gave
    assert cfg["model"] == {"materials_file": None, "readings": {}}
    assert cfg["force"] == {"datasets": [], "grasp_log": None} and cfg["results_dir"] == "results"


def test_scene_presets_in_the_schema_are_the_renderers():
    from pipeline.synth import SCENE_PRESETS

    schema = load_schema()["properties"]
    scenes = [schema["datasets"]["items"]["properties"]["scene"],
              schema["force"]["properties"]["datasets"]["items"]["properties"]["scene"]]
    assert all(sorted(s["enum"]) == sorted(SCENE_PRESETS) for s in scenes)


@pytest.mark.parametrize(
    "datasets, message",
    [
        (
            [{"name": "a", "source": "synthetic", "material": "DS25"}],
            "datasets[0].material: unknown material 'DS25'",
        ),
        (
            [{"name": "a", "source": "folder", "path": "no/such/folder"}],
            "datasets[0].path: photo-set folder 'no/such/folder' does not exist",
        ),
        (
            [{"name": "a", "source": "synthetic", "material": "DS20", "trials": "six"}],
            "datasets[0].trials: 'six' is not of type 'integer'",
        ),
        ([{"name": "a", "source": "camera"}], "datasets[0].source: 'camera' is not one of"),
        ([{"name": "a", "source": "synthetic", "material": "DS20"}] * 2, "'a' is used twice"),
        (
            [{"name": "a", "source": "rig", "path": "x", "material": "DS20"}],
            "datasets[0].port: required for source 'rig'",
        ),
        ([{"name": "a", "source": "folder"}], "datasets[0].path: required for source 'folder'"),
        (
            [{"name": "a", "source": "synthetic"}],
            "datasets[0].material: required for source 'synthetic'",
        ),
        ([{"source": "synthetic", "material": "DS20"}], "datasets[0].name: required"),
    ],
)
def test_bad_config_is_refused_with_key_and_fix(tmp_path, datasets, message):
    with pytest.raises(UserInputError) as exc:
        validate_config({"datasets": datasets}, workdir=tmp_path)
    assert message in str(exc.value)
    assert "nothing was run" in str(exc.value)


def test_unknown_key_lists_allowed_keys(tmp_path):
    with pytest.raises(UserInputError, match="allowed keys here"):
        validate_config({"measure": {"metod": "pratt"}}, workdir=tmp_path)


def test_digest_is_stable_and_order_free():
    assert config_digest({"a": 1, "b": [1, 2]}) == config_digest({"b": [1, 2], "a": 1})
    assert config_digest({"a": 1}) != config_digest({"a": 2})


def test_model_readings_in_the_schema_are_the_model_options():
    from pipeline.model import CHOICES, ModelOptions

    readings = load_schema()["properties"]["model"]["properties"]["readings"]["properties"]
    assert set(readings) == set(CHOICES) | {"eq12_scale", "l0_mm"}
    defaults = ModelOptions()
    for key, choices in CHOICES.items():
        assert readings[key]["enum"] == list(choices), key
        assert readings[key]["default"] == getattr(defaults, key)


def test_a_bad_model_reading_is_refused(tmp_path):
    with pytest.raises(UserInputError) as exc:
        validate_config({"model": {"readings": {"l0_factor": "inches"}}}, workdir=tmp_path)
    assert "model.readings.l0_factor: 'inches' is not one of" in str(exc.value)
    synthetic = [{"name": "a", "source": "synthetic", "material": "SS50"}]
    cfg = validate_config(
        {"datasets": synthetic, "model": {"readings": {"l0_factor": "metres"}}}, workdir=tmp_path
    )
    assert cfg["model"] == {"materials_file": None, "readings": {"l0_factor": "metres"}}


def test_the_built_package_ships_the_schema_and_validates_without_the_workflow(repo, tmp_path):
    """setuptools' build_py (what a wheel holds) from a copy of the sources; validate with that
    alone."""
    src = tmp_path / "src"
    shutil.copytree(
        repo / "pipeline", src / "pipeline", ignore=shutil.ignore_patterns("__pycache__")
    )
    for name in ("pyproject.toml", "README.md"):
        shutil.copy(repo / name, src / name)
    lib = tmp_path / "lib"
    build = subprocess.run(
        [
            sys.executable,
            "-c",
            "import setuptools; setuptools.setup()",
            "-q",
            "build_py",
            "-d",
            str(lib),
        ],
        cwd=src,
        capture_output=True,
        text=True, check=False,
    )
    assert build.returncode == 0, build.stderr[-2000:]
    assert (lib / "pipeline" / "config.schema.yaml").is_file()
    check = subprocess.run(
        [
            sys.executable,
            "-c",
            ("from pipeline.config import validate_config; "
            "print(validate_config({'datasets': [{'name': 'a', 'source': 'synthetic', 'material': "
            "'DS20'}]})['datasets'][0]['scene'])"),
        ],
        cwd=tmp_path,
        env={**os.environ, "PYTHONPATH": str(lib)},
        capture_output=True,
        text=True, check=False,
    )
    assert check.returncode == 0 and check.stdout.strip() == "lab", check.stderr[-2000:]


def test_scene_enums_are_the_synth_presets():
    from pipeline.config import load_schema
    from pipeline.synth.presets import SCENE_PRESETS

    props = load_schema()["properties"]
    dataset = props["datasets"]["items"]["properties"]
    assert dataset["scene"]["enum"] == list(SCENE_PRESETS)
