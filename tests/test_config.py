"""Config validation: defaults filled from the schema, bad configs refused naming key and fix."""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

from pipeline.config import config_digest, load_schema, validate_config
from pipeline.errors import UserInputError
from pipeline.measure.settings import resolve_settings
from pipeline.photoset import referenced_files


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
    scenes = [
        schema["datasets"]["items"]["properties"]["scene"],
        schema["force"]["properties"]["datasets"]["items"]["properties"]["scene"],
    ]
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


def test_a_config_that_would_mix_results_and_photos_or_share_a_folder_is_refused(tmp_path):
    # customer 47: results_dir inside a photo set failed in the measure job, naming a --cache
    # the Snakemake user never typed; a set kept in results/ (the run's own, to delete freely)
    # passed; 'syn' and 'Syn' share one results folder on a Mac or Windows disk
    (tmp_path / "set").mkdir()
    (tmp_path / "results" / "mine").mkdir(parents=True)
    cases = [
        ({"results_dir": "set/out", "datasets": [{"name": "a", "source": "folder", "path": "set"}]},
         "results_dir: "),
        ({"datasets": [{"name": "a", "source": "folder", "path": "results/mine"}]},
         "datasets[0].path: the photo set 'results/mine' lies inside results_dir"),
        ({"datasets": [{"name": "syn", "source": "synthetic", "material": "DS20"},
                       {"name": "Syn", "source": "synthetic", "material": "DS20"}]},
         "datasets[1].name: 'Syn' and 'syn' differ only in case"),
    ]
    for config, message in cases:
        with pytest.raises(UserInputError) as exc:
            validate_config(config, workdir=tmp_path)
        assert message in str(exc.value), str(exc.value)
    assert "lies inside the photo set 'set'" in str(
        pytest.raises(UserInputError, validate_config, cases[0][0], workdir=tmp_path).value
    )
    validate_config({"datasets": [{"name": "a", "source": "folder", "path": "set"}]},
                    workdir=tmp_path)


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
        text=True,
        check=False,
    )
    assert build.returncode == 0, build.stderr[-2000:]
    assert (lib / "pipeline" / "config.schema.yaml").is_file()
    check = subprocess.run(
        [
            sys.executable,
            "-c",
            (
                "from pipeline.config import validate_config; "
                "print(validate_config({'datasets': [{'name': 'a', 'source': 'synthetic', "
                "'material': 'DS20'}]})['datasets'][0]['scene'])"
            ),
        ],
        cwd=tmp_path,
        env={**os.environ, "PYTHONPATH": str(lib)},
        capture_output=True,
        text=True,
        check=False,
    )
    assert check.returncode == 0 and check.stdout.strip() == "lab", check.stderr[-2000:]


def test_scene_enums_are_the_synth_presets():
    from pipeline.config import load_schema
    from pipeline.synth.presets import SCENE_PRESETS

    props = load_schema()["properties"]
    dataset = props["datasets"]["items"]["properties"]
    assert dataset["scene"]["enum"] == list(SCENE_PRESETS)


SOFT_SS50 = (
    "materials:\n  SS50: {mu_mpa: [0.34], alpha: [2.0], k_p: 2.2}\n"
    "geometry: {b_mm: 3.8, a0_mm: 6.4, t0_mm: 3.8, psi0_deg: 210, l0_mm: 240}\n"
)


def _refused(config, workdir):
    with pytest.raises(UserInputError) as exc:
        validate_config(config, workdir=workdir)
    assert "nothing was run" in str(exc.value)
    return str(exc.value)


def test_a_dataset_names_its_own_materials_file(tmp_path):
    (tmp_path / "soft.yaml").write_text(SOFT_SS50)
    cfg = validate_config(
        {
            "datasets": [
                {
                    "name": "soft",
                    "source": "synthetic",
                    "material": "SS50",
                    "materials_file": "soft.yaml",
                },
                {"name": "std", "source": "synthetic", "material": "SS50"},
            ]
        },
        workdir=tmp_path,
    )
    assert [d["materials_file"] for d in cfg["datasets"]] == ["soft.yaml", None]
    assert cfg["model"]["materials_file"] is None  # the global file is untouched


@pytest.mark.parametrize(
    "text, message",
    [
        (
            None,
            (
                "datasets[1].materials_file (dataset 'soft'): materials file 'soft.yaml' does not "
                "exist (relative to"
            ),
        ),
        (
            "materials: [unclosed\n",
            (
                "datasets[1].materials_file (dataset 'soft'): materials file 'soft.yaml' cannot be "
                "used: "
            ),
        ),
        ("materials:\n  SS50: {mu_mpa: [0.3], alpha: [2.0]}\n", "missing key 'k_p'"),
        (
            (
                "materials:\n  EF30: {mu_mpa: [0.05], alpha: [2.0], k_p: 2.0}\n"
                "geometry: {b_mm: 3.8, a0_mm: 6.4, t0_mm: 3.8, psi0_deg: 210, l0_mm: 220}\n"
            ),
            (
                "datasets[1].materials_file (dataset 'soft'): material 'SS50' (named by the "
                "dataset) is not in 'soft.yaml', which holds ['EF30']; add 'SS50' to that file"
            ),
        ),
    ],
)
def test_a_bad_dataset_materials_file_is_refused_naming_key_dataset_and_fix(
    tmp_path, text, message
):
    if text is not None:
        (tmp_path / "soft.yaml").write_text(text)
    out = _refused(
        {
            "datasets": [
                {"name": "std", "source": "synthetic", "material": "SS50"},
                {
                    "name": "soft",
                    "source": "synthetic",
                    "material": "SS50",
                    "materials_file": "soft.yaml",
                },
            ]
        },
        tmp_path,
    )
    assert message in out
    assert "datasets[0]" not in out  # the other dataset is fine
    if text is None:
        assert "fix the path, or set it to null for model.materials_file" in out
    elif "unclosed" in text:
        assert "not valid YAML" in out and "fix the syntax" in out


def test_a_folder_dataset_materials_file_must_hold_the_manifests_materials(tmp_path, repo):
    (tmp_path / "soft.yaml").write_text(SOFT_SS50)
    folder = {
        "name": "sample",
        "source": "folder",
        "path": str(repo / "sample_images"),
        "materials_file": "soft.yaml",
    }
    out = _refused({"datasets": [folder]}, tmp_path)
    assert (
        "datasets[0].materials_file (dataset 'sample'): material 'DS20' (named by the dataset) "
        "is not in 'soft.yaml'" in out
    )
    (tmp_path / "soft.yaml").write_text(SOFT_SS50.replace("SS50", "DS20"))
    assert (
        validate_config({"datasets": [folder]}, workdir=tmp_path)["datasets"][0]["materials_file"]
        == "soft.yaml"
    )


def test_a_bad_global_materials_file_is_refused_and_synthetic_sets_need_a_packaged_material(
    tmp_path,
):
    (tmp_path / "bad.yaml").write_text("materials: [unclosed\n")
    out = _refused(
        {
            "datasets": [{"name": "a", "source": "synthetic", "material": "SS50"}],
            "model": {"materials_file": "bad.yaml"},
        },
        tmp_path,
    )
    assert (
        "model.materials_file: materials file 'bad.yaml' cannot be used" in out
        and "not valid YAML" in out
    )
    (tmp_path / "own.yaml").write_text(SOFT_SS50.replace("SS50", "EF30"))
    out = _refused(
        {
            "datasets": [
                {
                    "name": "a",
                    "source": "synthetic",
                    "material": "EF30",
                    "materials_file": "own.yaml",
                }
            ]
        },
        tmp_path,
    )
    assert (
        "datasets[0].material: synthetic photos are rendered from the packaged model, which has "
        "no material 'EF30'" in out
    )


def test_a_path_written_from_the_home_folder_is_found(tmp_path, repo, monkeypatch):
    """``path: ~/photos/june`` was 'does not exist (relative to ...)': ``~`` is the home folder in
    the config, and in a set's ``background``, which the digest then watches."""
    home = tmp_path / "home"
    monkeypatch.setenv("HOME", str(home))
    june = home / "photos" / "june"
    shutil.copytree(repo / "sample_images", june)
    (home / "empty.jpg").write_bytes((june / "DS20_A1_t1_s000_up_0kPa.jpg").read_bytes())
    work = tmp_path / "work"
    work.mkdir()
    cfg = validate_config(
        {"datasets": [{"name": "june", "source": "folder", "path": "~/photos/june"}]},
        workdir=work,
    )
    assert cfg["datasets"][0]["path"] == str(june)
    settings = resolve_settings({"l0_mm": 200, "background": "~/empty.jpg"}, folder=june)
    assert settings.background_path is not None
    assert Path(settings.background_path) == home / "empty.jpg"
    (june / "photoset.yaml").write_text("l0_mm: 270\nbackground: ~/empty.jpg\n")
    assert referenced_files(june) == ((home / "empty.jpg").resolve(),)
