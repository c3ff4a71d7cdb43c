"""The ZSL-1's joint interface on POSIX shared memory: :class:`SplineClient` writes the sixteen
joints' PD targets to ``/spline_shm`` and reads the state the spline daemon publishes;
:class:`ImuReader` reads ``/imu_shm``. :class:`robowire.sim.Spline` is a daemon to test with.
"""

from ._native import ImuReader, SplineClient

__all__ = ["SplineClient", "ImuReader"]
