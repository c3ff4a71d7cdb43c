"""robowire: low-level robot protocols from Python, byte-exact, safe by default.

- :mod:`robowire.zsl1`, :mod:`robowire.zsl1w`: drop-ins for ZsiBot's ``mc_sdk_zsl_1_py`` and
  ``mc_sdk_zsl_1w_py`` (``import robowire.zsl1 as mc_sdk_zsl_1_py``).
- :mod:`robowire.kmc`: the KMC UART chassis.
- :mod:`robowire.unitree`: Unitree LowCmd/LowState (Go2 and HG), struct image and CDR.
- :mod:`robowire.go2`: the Go2's low-level interface over DDS.
- :mod:`robowire.g1`: the Unitree G1 humanoid over DDS (low level, ``rt/arm_sdk``, its services).
- :mod:`robowire.sim`: every simulator, in-process, as a context manager.
- :mod:`robowire.policy`: a trained locomotion policy (ONNX) on a G1 or Go2, or their physics
  simulators, as ``robowire policy run`` runs it.
- :func:`robowire.open`: any device by its address (``kmc:/dev/ttyUSB0``, ``zsl1:IP``,
  ``go2:eth0``, ``sim:zsl1``, …) as a :class:`robowire.Device` of one shape.
- :class:`robowire.Recorder`: an MCAP capture of the links of every device given ``record=``.

Importing robowire starts no thread and opens nothing.
"""

from ._native import __version__
from .device import Device, open
from .record import Recorder
from .errors import (
    ArgumentError,
    BindError,
    ClosedError,
    CrcError,
    DecodeError,
    Error,
    NoStateError,
    PortError,
    ServiceError,
    TimeoutError,
)

__all__ = [
    "__version__",
    "open",
    "Device",
    "Recorder",
    "Error",
    "ArgumentError",
    "ClosedError",
    "BindError",
    "PortError",
    "NoStateError",
    "TimeoutError",
    "DecodeError",
    "CrcError",
    "ServiceError",
]
