"""Shared fixtures of robowire's Python suite.

Everything runs on loopback (each ZSL-1 test on its own 127.0.0.x) or, for DDS, in a private
network namespace entered here before any robowire thread starts (as root, or as the root of a
user namespace: ``cargo xtask test`` runs pytest under ``unshare --user --map-root-user --net``). Tests that need something
this machine may lack (the vendor's CPython 3.10 module, Unitree's SDK, the mcap package, DDS multicast) skip,
unless ``ROBOWIRE_REQUIRE`` names it (``vendor``, ``sdk``, ``mcap``, ``dds``, ``cli``; ``cargo xtask test`` sets
it): then a missing peer fails the run instead of hiding it.
"""

import itertools
import os
import platform
import sys
from pathlib import Path

import pytest

import robowire.errors
import robowire.sim

REPO = Path(__file__).resolve().parents[3]
REQUIRED = set(filter(None, os.environ.get("ROBOWIRE_REQUIRE", "").split(",")))


def peers_dir() -> Path:
    """The vendors' software: ``$ROBOWIRE_PEERS``, else ``../shared/peers`` beside the repo."""
    return Path(os.environ.get("ROBOWIRE_PEERS", REPO.parent / "shared" / "peers"))


def missing(what: str, reason: str) -> None:
    """Skips, or fails if ``what`` is required here."""
    if what in REQUIRED:
        pytest.fail(f"{reason} (required here: ROBOWIRE_REQUIRE={','.join(sorted(REQUIRED))})")
    pytest.skip(reason)


def cli() -> str:
    """The robowire CLI: ``$ROBOWIRE_CLI``, else the workspace's build (skips without one)."""
    path = os.environ.get("ROBOWIRE_CLI") or next(
        (str(p) for p in (REPO / "target/debug/robowire", REPO / "target/release/robowire") if p.exists()), None
    )
    if not path:
        missing("cli", "the robowire CLI is not built (cargo build -p robowire, or set ROBOWIRE_CLI)")
    return path


DDS_READY = False
DDS_MISSING = (
    "DDS needs multicast on loopback, which it lacks here: run as root, or as the root of a user namespace "
    "(unshare --user --map-root-user --net, as cargo xtask test does), or enable multicast on lo"
)


def pytest_configure(config):
    """DDS discovery needs multicast; without it on loopback, move this process into a private
    network namespace (root, or root of a user namespace) before anything starts a thread."""
    global DDS_READY, DDS_MISSING
    if robowire.sim.loopback_has_multicast():
        DDS_READY = True
    elif os.geteuid() == 0:
        try:
            robowire.sim.enter_loopback_namespace()
            DDS_READY = robowire.sim.loopback_has_multicast()
        except robowire.errors.Error as e:
            DDS_MISSING = f"DDS needs multicast on loopback, and no private network namespace can be made: {e}"


_addresses = itertools.count(10)


@pytest.fixture
def ip() -> str:
    """A loopback address of its own (127.0.0.10, .11, …): the vendor's fixed ports can be
    bound once per test."""
    n = next(_addresses)
    return f"127.0.{n // 250}.{2 + n % 250}"


@pytest.fixture
def dog(ip):
    """A ZSL-1 simulator on the vendor's ports at ``ip``."""
    with robowire.sim.Zsl1(ip=ip) as dog:
        yield dog


@pytest.fixture
def dds():
    """DDS is usable here (multicast on loopback)."""
    if not DDS_READY:
        missing("dds", DDS_MISSING)


def vendor_module_dir(model: str) -> Path:
    return peers_dir() / "zsibot_sdk" / "lib" / model / "x86_64"


@pytest.fixture
def vendor_python():
    """Whether the vendor's modules can load here: CPython 3.10 on x86_64, with numpy."""
    if sys.version_info[:2] != (3, 10) or platform.machine() != "x86_64":
        missing("vendor", "the vendor's ZSL-1 modules are built for CPython 3.10 on x86_64 only")
    if not vendor_module_dir("zsl-1").is_dir():
        missing("vendor", f"the vendor's modules are not in {vendor_module_dir('zsl-1')} (set ROBOWIRE_PEERS)")
    try:
        import numpy  # noqa: F401  (the vendor's module needs it)
    except ImportError:
        missing("vendor", "the vendor's module needs numpy")
    return sys.executable
