"""Fixtures for the package's docstring examples (the tests' own are in ``tests/conftest.py``)."""

import tempfile

import pytest
from _pytest.doctest import DoctestItem


@pytest.fixture(autouse=True)
def _doctest_temporary_files_in_tmp_path(
    request: pytest.FixtureRequest, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Make a docstring example's ``tempfile.mkdtemp()`` land in pytest's ``tmp_path``.

    The examples show the plain call a reader would write; run as tests, each would otherwise
    leave a folder in the system's temporary directory on every run of the suite.
    """
    if isinstance(request.node, DoctestItem):
        monkeypatch.setattr(tempfile, "tempdir", str(request.getfixturevalue("tmp_path")))
