"""The README's Python examples run as written (from the repository's root) and print what
they say."""

from __future__ import annotations

import re
import subprocess
import sys

import pytest

from helpers import REPO


def _python_blocks() -> list[str]:
    text = (REPO / "README.md").read_text()
    return re.findall(r"```python\n(.*?)```", text, flags=re.S)


def _run(code: str, tmp_path, timeout: float) -> subprocess.CompletedProcess:
    script = tmp_path / "example.py"  # a file: the dask workers re-import it
    script.write_text(code)
    p = subprocess.run([sys.executable, str(script)], cwd=REPO, capture_output=True, text=True,
                       timeout=timeout)
    assert p.returncode == 0, p.stdout + p.stderr
    return p


def test_the_readme_has_the_three_examples():
    blocks = _python_blocks()
    assert len(blocks) == 3, blocks
    assert "from pxr import" in blocks[0] and "stage.sample(" in blocks[1]
    assert "luxeval.dask" in blocks[2]


def test_the_usd_core_example(tmp_path):
    pytest.importorskip("pxr", reason="the example uses usd-core (pip install usd-core)")
    out = _run(_python_blocks()[0], tmp_path, 300).stdout.splitlines()
    assert out[0] == "['key', 'fill', 'top', 'tube', 'sun', 'sky']", out
    assert out[1] == "[2. 2. 2.]", out


def test_the_sampling_example(tmp_path):
    out = _run(_python_blocks()[1], tmp_path, 300).stdout.splitlines()
    assert out == ["[1. 1.]", "[1. 1.]"], out


def test_the_dask_example(tmp_path):
    pytest.importorskip("distributed")
    out = _run(_python_blocks()[2], tmp_path, 300).stdout.splitlines()
    assert out[-1] == "(1000000, 3) float32", out
