"""The Python examples of the docs run as written, each in a fresh interpreter: the repository
README's, `docs/python.md`'s, and the recording example of the package's own README."""

import re
import subprocess
import sys

import pytest

from conftest import REPO


def python_blocks(path):
    return re.findall(r"```python\n(.*?)```", (REPO / path).read_text(), flags=re.S)


DEVICE_BLOCKS = python_blocks("docs/python.md")
BLOCKS = python_blocks("README.md") + DEVICE_BLOCKS


def test_the_python_docs_have_an_example_per_device():
    text = "".join(DEVICE_BLOCKS)
    for module in ["robowire.zsl1", "robowire.kmc", "robowire.go2", "robowire.g1", "robowire.unitree", "robowire.spline", "robowire.policy"]:
        assert module in text, module


@pytest.mark.parametrize("block", [b for b in BLOCKS if "robowire.sim" in b or "LowCmd" in b], ids=lambda b: b.split("\n")[0])
def test_a_readme_example_runs(block, request):
    if "robowire.go2" in block or "robowire.g1" in block:
        request.getfixturevalue("dds")  # the child inherits this process's network namespace
    result = subprocess.run([sys.executable, "-c", block], capture_output=True, text=True, timeout=60)
    assert result.returncode == 0, result.stderr
    assert result.stdout.strip(), "every example prints what it did"


def test_the_recording_example_of_the_package_readme_runs():
    readme = (REPO / "crates/robowire-py/README.md").read_text()
    section = readme.split("\n## Recording\n", 1)[1].split("\n## ", 1)[0]
    (block,) = re.findall(r"```python\n(.*?)```", section, flags=re.S)
    result = subprocess.run([sys.executable, "-c", block], capture_output=True, text=True, timeout=60)
    assert result.returncode == 0, result.stderr
    assert "host.mcap: {'frames'" in result.stdout and "chassis.mcap" in result.stdout, result.stdout
