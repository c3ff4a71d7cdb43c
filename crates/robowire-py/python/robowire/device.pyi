"""Type stubs of robowire.device (see device.py)."""

from os import PathLike
from typing import Any, Dict, List, Optional, Union

from typing_extensions import Self

from .record import Recorder

__all__ = ["Device", "open"]

def open(
    address: str,
    *,
    domain: int = 0,
    record: Union[str, PathLike[str], Recorder, None] = None,
    physics: bool = False,
    model: Union[str, PathLike[str], None] = None,
    free_base: bool = False,
) -> Device:
    """kmc:PATH, zsl1:IP, zsl1w:IP, go2:IFACE, hg:IFACE, sim:kmc|zsl1|zsl1w|go2; a bad address raises ArgumentError.
    record: a path (a capture of its own, finished by close()) or a Recorder. physics: sim:go2's or sim:g1's body in
    MuJoCo (a wheel built with the `mujoco` feature, else robowire.Error; ArgumentError for any other address), the G1
    hanging by its pelvis unless free_base (then on the floor, held on a band until a LowCmd stream has driven its
    legs for 3.5 s); model: a user's MJCF instead of robowire's model."""

class Device:
    """A device opened by robowire.open(address)."""
    @property
    def address(self) -> str: ...
    @property
    def kind(self) -> str:
        """kmc, zsl1, zsl1w, go2 or hg."""
    @property
    def connection(self) -> str:
        """waiting, connected, disconnected or closed."""
    def wait_state(self, timeout_s: float = 3.0) -> bool: ...
    def status(self) -> Dict[str, Any]:
        """The fields of `robowire status --json`; raises NoStateError before the first state."""
    def status_text(self) -> str: ...
    def observe(self) -> Optional[Dict[str, Any]]:
        """odometry, imu, joints, battery (dicts or None), motors (list), passthrough; None before the first state."""
    @property
    def can_drive(self) -> bool: ...
    def drive(self, vx: float, vy: float, yaw_rate: float) -> None:
        """m/s forward, m/s left, rad/s; raises ArgumentError (nothing sent) or Error (not a mobile base)."""
    @property
    def services(self) -> List[str]: ...
    def call(self, name: str) -> str: ...
    def close(self) -> None:
        """The device's safe action, then closed (and its simulator stopped); idempotent."""
    def __enter__(self) -> Self: ...
    def __exit__(self, *exc: Any) -> None: ...
