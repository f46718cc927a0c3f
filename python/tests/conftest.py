"""Shared fixtures of the Python module's tests (run by ctest: python.*)."""

import os
import pathlib
import subprocess

import pytest

ROOT = pathlib.Path(__file__).resolve().parents[2]
SCENES = ROOT / "scenes"


@pytest.fixture(scope="session")
def hapsim_bin():
    """The `hapsim` command built beside the module (ctest sets HAPSIM_BIN)."""
    path = os.environ.get("HAPSIM_BIN")
    if not path or not os.path.exists(path):
        pytest.skip("HAPSIM_BIN is not set to the hapsim binary")
    return path


def run_cli(hapsim_bin, *args):
    """Runs the CLI; returns the finished process (its output as text)."""
    return subprocess.run([hapsim_bin, *map(str, args)], capture_output=True, text=True,
                          check=False)
