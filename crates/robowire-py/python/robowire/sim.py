"""Every robowire simulator in-process, as a context manager, with its fault injection: test
without hardware exactly as robowire's own Rust tests do.

- :class:`Zsl1`: a ZSL-1 / ZSL-1W on UDP (drive it with :mod:`robowire.zsl1`); ``Dog`` is its old
  name, kept for one release (deprecated).
- :class:`Chassis`: a KMC chassis behind a pseudo-terminal (drive it with :mod:`robowire.kmc`).
- :class:`Spline`: the ZSL-1 spline daemon on POSIX shared memory.
- :class:`Go2`: a Unitree Go2 on DDS (drive it with :mod:`robowire.go2` or Unitree's SDK).
- :class:`G1`: a Unitree G1 humanoid on DDS (drive it with :mod:`robowire.g1` or Unitree's SDK).

Each starts in its constructor and stops on ``close()`` or at the end of a ``with`` block.
"""

import warnings as _warnings

from ._native import SimChassis as Chassis
from ._native import SimG1 as G1
from ._native import SimGo2 as Go2
from ._native import SimSpline as Spline
from ._native import SimZsl1 as Zsl1
from ._native import enter_loopback_namespace, loopback_has_multicast

__all__ = ["Zsl1", "Chassis", "Spline", "Go2", "G1", "loopback_has_multicast", "enter_loopback_namespace"]


def __getattr__(name: str):
    # ``Dog``: the old name of ``Zsl1``, kept for one release.
    if name == "Dog":
        _warnings.warn(
            "robowire.sim.Dog is now robowire.sim.Zsl1; the old name goes in the next release",
            DeprecationWarning,
            stacklevel=2,
        )
        return Zsl1
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
