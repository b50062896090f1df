"""Helpers of the workflow's video rules (``rules/video.smk``): which datasets are videos, options.

Examples
--------
>>> is_video_dataset({"source": "synthetic_video"})
True
>>> is_video_dataset({"source": "rig", "record": "photos"})
False
>>> names_pattern(["a.b", "c"]), names_pattern([])
('a\\\\.b|c', '(?!)')
"""

from __future__ import annotations

import re
from collections.abc import Iterable, Mapping
from typing import Any

from pipeline.errors import UserInputError
from pipeline.photoset import is_video_manifest, read_manifest


def is_video_dataset(ds: Mapping[str, Any]) -> bool:
    """Whether a config dataset's photo set lists videos (rendered, recorded, or a folder's
    manifest)."""
    source = ds["source"]
    if source == "synthetic_video":
        return True
    if source == "rig":
        return ds.get("record") == "video"
    if source != "folder":
        return False
    try:
        return is_video_manifest(read_manifest(ds["path"]))
    except UserInputError:
        return False


def names_pattern(names: Iterable[str]) -> str:
    """A wildcard constraint matching exactly these dataset names (nothing when there are none)."""
    return "|".join(re.escape(n) for n in names) or "(?!)"


def profile_options(ds: Mapping[str, Any]) -> str:
    """The pressure-profile options shared by ``synth-video`` and ``acquire --record video``."""
    return (
        f"--profile {ds['profile']} --max-kpa {ds['max_kpa']} --rate-kpa-s {ds['rate_kpa_s']}"
        f" --step-kpa {ds['step_kpa']} --hold-s {ds['hold_s']} --cycles {ds['cycles']} --fps "
        f"{ds['fps']}"
        f" --rest-s {ds['rest_s']}"
    )
