"""Small helpers of the suite."""

import time


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
