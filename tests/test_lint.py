"""Lint and types of the package, run with the suite (and so in CI): ruff with the configured rules
and line length, mypy on ``pipeline``.  Each fails with the tool's own report."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[1]


def _run(*args: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run(
        [sys.executable, "-m", *args], cwd=REPO, capture_output=True, text=True, check=False
    )


def test_ruff_passes():
    res = _run("ruff", "check", "--no-cache", "pipeline", "tests")
    assert res.returncode == 0, res.stdout + res.stderr


@pytest.mark.slow
def test_mypy_passes():
    res = _run("mypy", "pipeline")  # the cache is .mypy_cache (git-ignored), per pyproject.toml
    assert res.returncode == 0 and "Success: no issues found" in res.stdout, (
        res.stdout + res.stderr
    )
