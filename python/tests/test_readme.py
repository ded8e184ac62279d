"""python/README.md's Python code blocks run as written from the repository root."""

from __future__ import annotations

import re
import subprocess
import sys

import pytest

from conftest import ROOT

README = ROOT / "python" / "README.md"
BLOCKS = re.findall(r"^```python\n(.*?)^```", README.read_text(), flags=re.S | re.M)


def test_the_readme_has_python_examples():
    assert len(BLOCKS) >= 3


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
