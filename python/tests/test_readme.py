"""The Python code blocks of python/README.md and of the repository's README run as written
from the repository root."""

from __future__ import annotations

import re
import subprocess
import sys

import pytest

from conftest import ROOT

READMES = [ROOT / "python" / "README.md", ROOT / "README.md"]
BLOCKS = [
    block
    for readme in READMES
    for block in re.findall(r"^```python\n(.*?)^```", readme.read_text(), flags=re.S | re.M)
]


def test_the_readmes_have_python_examples():
    assert len(BLOCKS) >= 5


@pytest.mark.parametrize("index", range(len(BLOCKS)))
def test_readme_block_runs(index, tmp_path):
    script = tmp_path / f"block_{index}.py"
    script.write_text(BLOCKS[index])
    run = subprocess.run(
        [sys.executable, str(script)],
        cwd=ROOT,
        capture_output=True,
        text=True,
        timeout=600,
    )
    assert run.returncode == 0, f"block {index}:\n{BLOCKS[index]}\n{run.stdout}\n{run.stderr}"
