"""The README is all a lab reads before writing its first photo set: its reference tables hold
every manifest column and every photoset.yaml key the code reads, its example settings are valid,
and it points at nothing a clean checkout lacks."""

from __future__ import annotations

import re

import pytest
import yaml

from pipeline.measure import METHODS
from pipeline.measure.colors import NAMED_COLORS
from pipeline.measure.settings import KEYS, resolve_settings
from pipeline.photoset import OPTIONAL_COLUMNS, REQUIRED_COLUMNS


@pytest.fixture
def readme(repo) -> str:
    return (repo / "README.md").read_text(encoding="utf-8")


def _section(text: str, heading: str) -> str:
    """The text under a heading (any level) up to the next heading."""
    start = text.index(heading)
    rest = text[start + len(heading) :]
    nxt = re.search(r"^#{1,4} ", rest, re.MULTILINE)
    return rest[: nxt.start()] if nxt else rest


def _first_cells(section: str) -> set[str]:
    """The back-quoted names in the first column of a Markdown table."""
    return {
        name
        for row in re.findall(r"^\| ([^|]+) \|", section, re.MULTILINE)
        for name in re.findall(r"`([^`]+)`", row)
    }


def test_every_photoset_key_is_in_the_readmes_reference_table(readme):
    keys = _first_cells(_section(readme, "### `photoset.yaml`"))
    assert keys == set(KEYS)


def test_every_manifest_column_is_in_the_readmes_reference_table(readme):
    columns = _first_cells(_section(readme, "### `manifest.csv`"))
    assert set(REQUIRED_COLUMNS) | set(OPTIONAL_COLUMNS) <= columns


def test_the_reference_names_every_colour_and_method(readme):
    table = _section(readme, "### `photoset.yaml`")
    row = {r.split("|")[1].strip(): r for r in table.splitlines() if r.startswith("| `")}
    colours = row["`line_color`"]
    assert all(f"`{name}`" in colours for name in NAMED_COLORS)
    assert all(f"`{name}`" in row["`method`"] for name in METHODS)


def test_the_body_example_settings_are_valid(readme, tmp_path):
    section = _section(readme, "### Measuring photos without a drawn line")
    block = re.search(r"```yaml\n(.*?)```", section, re.DOTALL)
    assert block is not None
    raw = yaml.safe_load(block[1])
    assert set(raw) <= set(KEYS) and raw["target"] == "body"
    (tmp_path / raw["background"]).write_bytes(b"")  # resolving checks the file is there
    settings = resolve_settings(raw, folder=tmp_path)
    assert settings.target == "body" and settings.sealed_end_mm == raw["sealed_end_mm"]


def test_the_readme_points_at_nothing_a_clean_checkout_lacks(readme, repo):
    assert "../shared" not in readme  # the company's own folders are not shipped
    named = re.findall(r"`((?:docs|pipeline|tests|rules|profiles)/[\w./-]+\.\w+)`", readme)
    assert named and all((repo / path).exists() for path in named), named
