"""The examples in examples/python, each run short (--quick) into a temporary folder: they finish
and draw their PNG."""

import pathlib
import subprocess
import sys

import pytest

from conftest import ROOT

EXAMPLES = sorted((ROOT / "examples" / "python").glob("*.py"))


def test_there_are_the_three_examples():
    names = {p.stem for p in EXAMPLES}
    assert {"stiffness_sweep", "contact_methods", "glove_palpation"} <= names


@pytest.mark.parametrize("example", EXAMPLES, ids=lambda p: p.stem)
def test_the_example_runs_and_draws(example, tmp_path):
    done = subprocess.run([sys.executable, str(example), "--quick", "--out", str(tmp_path)],
                          capture_output=True, text=True, check=False, timeout=120)
    assert done.returncode == 0, done.stdout + done.stderr
    pngs = list(pathlib.Path(tmp_path).glob("*.png"))
    assert len(pngs) == 1, done.stdout
    assert pngs[0].read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert pngs[0].stat().st_size > 20_000  # a drawn plot, not an empty figure
