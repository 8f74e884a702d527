"""Test-wide settings: hypothesis profiles (derandomized unless HYPOTHESIS_PROFILE=dev), the
``slow`` marker.

The test directory is on ``sys.path`` through pytest's rootdir import mode, so helper modules
(``shared``, ``fixtures_cad``, ``mix_oracle``) are imported by name. ``pytest`` runs the
default suite; ``pytest -m slow`` the long end-to-end checks (``.ci/run`` runs both).
"""

from __future__ import annotations

import os
import tempfile

import pytest
from hypothesis import HealthCheck, settings

settings.register_profile(
    "ci",
    derandomize=True,
    deadline=None,
    print_blob=True,
    suppress_health_check=[HealthCheck.too_slow],
)
settings.register_profile("dev", deadline=None)
settings.load_profile(os.environ.get("HYPOTHESIS_PROFILE", "ci"))


@pytest.fixture(autouse=True)
def _temp_files_in_the_test_folder(tmp_path_factory, monkeypatch):
    """The system temp folder of every test is a folder of its own, so the crash logs the
    error tests provoke (``feederkit.cli.app.write_crash_log``) do not pile up in /tmp."""
    folder = tmp_path_factory.mktemp("tmp")
    monkeypatch.setattr(tempfile, "tempdir", str(folder))
    monkeypatch.setenv("TMPDIR", str(folder))
