"""Small helpers of the suite."""

import time

import pytest

import robowire


def wait_until(predicate, timeout_s: float = 10.0, step_s: float = 0.01):
    """Polls ``predicate`` until it returns something truthy (returned) or ``timeout_s``
    passes (``AssertionError``)."""
    deadline = time.monotonic() + timeout_s
    while True:
        value = predicate()
        if value:
            return value
        if time.monotonic() > deadline:
            raise AssertionError(f"not true within {timeout_s} s: {predicate}")
        time.sleep(step_s)


def silence_is_noticed(sim, robot):
    """A simulated Unitree robot silenced: its client says so (``NoStateError``), and picks it up
    again once the fault is cleared."""
    sim.inject_silence()
    wait_until(lambda: robot.connection == "disconnected", timeout_s=10.0)
    with pytest.raises(robowire.NoStateError, match="silent"):
        robot.state()
    sim.clear_faults()
    wait_until(lambda: robot.connection == "connected", timeout_s=10.0)
