"""The package itself: importing starts nothing, one exception hierarchy, the version."""

import doctest
import importlib
import subprocess
import sys
import textwrap

import pytest

import robowire
from robowire import errors


def test_importing_every_module_starts_no_thread_and_opens_nothing():
    script = textwrap.dedent(
        """
        import os
        def tasks(): return len(os.listdir("/proc/self/task"))
        def fds(): return len(os.listdir("/proc/self/fd"))
        before = (tasks(), fds())
        import robowire, robowire.zsl1, robowire.zsl1w, robowire.kmc, robowire.unitree
        import robowire.go2, robowire.g1, robowire.sim, robowire.spline, robowire.errors, robowire.device, robowire.record
        import robowire.policy
        after = (tasks(), fds())
        print(before, after)
        assert before == after, (before, after)
        """
    )
    subprocess.run([sys.executable, "-c", script], check=True)


def test_version_is_the_workspace_version():
    assert robowire.__version__ == "0.1.0"


@pytest.mark.parametrize(
    "name, builtin",
    [
        ("ArgumentError", ValueError),
        ("BindError", OSError),
        ("PortError", OSError),
        ("TimeoutError", TimeoutError),
        ("DecodeError", ValueError),
        ("CrcError", ValueError),
        ("ClosedError", None),
        ("NoStateError", None),
        ("ServiceError", None),
    ],
)
def test_every_exception_is_a_robowire_error_and_its_builtin(name, builtin):
    cls = getattr(robowire, name)
    assert cls is getattr(errors, name)
    assert issubclass(cls, robowire.Error)
    if builtin is not None:
        assert issubclass(cls, builtin)


def test_crc_error_carries_both_crcs():
    e = robowire.CrcError("bad", 1, 2)
    assert (e.expected, e.found, str(e)) == (1, 2, "bad")
    assert isinstance(e, robowire.DecodeError)


@pytest.mark.parametrize(
    "module", ["robowire.zsl1", "robowire.kmc", "robowire.unitree", "robowire.device", "robowire.record"]
)
def test_the_examples_in_the_module_docs_run(module):
    result = doctest.testmod(importlib.import_module(module), optionflags=doctest.ELLIPSIS)
    assert result.attempted > 0
    assert result.failed == 0
