"""Config validation: defaults filled from the schema, bad configs refused naming key and fix."""

from __future__ import annotations

import pytest
import yaml

from pipeline.config import config_digest, load_schema, validate_config
from pipeline.errors import UserInputError


def _walk(schema, path="config"):
    yield path, schema
    for key, sub in schema.get("properties", {}).items():
        yield from _walk(sub, f"{path}.{key}")
    if isinstance(schema.get("items"), dict):
        yield from _walk(schema["items"], f"{path}[]")


def test_every_key_has_description_and_top_level_keys_have_defaults():
    schema = load_schema()
    for path, sub in _walk(schema):
        assert sub.get("description"), f"{path} has no description"
    for key, sub in schema["properties"].items():
        assert "default" in sub, f"{key} has no default"


def test_default_config_is_valid(repo):
    cfg = validate_config(yaml.safe_load((repo / "config.yaml").read_text()), workdir=repo)
    names = [d["name"] for d in cfg["datasets"]]
    assert "sample" in names and {"DS20", "DS30", "SS40", "SS50"} <= set(names)
    synth = [d for d in cfg["datasets"] if d["source"] == "synthetic"]
    assert all(d["actuators"] == 3 and d["trials"] == 6 for d in synth)
    assert cfg["measure"]["jobs"] == 2 and cfg["aggregate"]["bin_kpa"] is None


@pytest.mark.parametrize(
    "datasets, message",
    [
        ([{"name": "a", "source": "synthetic", "material": "DS25"}], "datasets[0].material: unknown material 'DS25'"),
        ([{"name": "a", "source": "folder", "path": "no/such/folder"}], "datasets[0].path: photo-set folder 'no/such/folder' does not exist"),
        ([{"name": "a", "source": "synthetic", "material": "DS20", "trials": "six"}], "datasets[0].trials: 'six' is not of type 'integer'"),
        ([{"name": "a", "source": "camera"}], "datasets[0].source: 'camera' is not one of"),
        ([{"name": "a", "source": "synthetic", "material": "DS20"}] * 2, "'a' is used twice"),
        ([{"name": "a", "source": "rig", "path": "x", "material": "DS20"}], "datasets[0].port: required"),
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
    from pipeline.model import CHOICES

    readings = load_schema()["properties"]["model"]["properties"]["readings"]["properties"]
    assert set(readings) == set(CHOICES) | {"eq12_scale", "l0_mm"}
    for key, choices in CHOICES.items():
        assert readings[key]["enum"] == list(choices), key


def test_a_bad_model_reading_is_refused(tmp_path):
    with pytest.raises(UserInputError) as exc:
        validate_config({"model": {"readings": {"l0_factor": "inches"}}}, workdir=tmp_path)
    assert "model.readings.l0_factor: 'inches' is not one of" in str(exc.value)
    synthetic = [{"name": "a", "source": "synthetic", "material": "SS50"}]
    cfg = validate_config({"datasets": synthetic, "model": {"readings": {"l0_factor": "metres"}}}, workdir=tmp_path)
    assert cfg["model"] == {"materials_file": None, "readings": {"l0_factor": "metres"}}
