"""Type stubs of robowire.go2 (see go2.py)."""

from os import PathLike
from typing import Any, Dict, List, Literal, Optional, Sequence, Tuple, Union

from typing_extensions import Self

from .record import Recorder
from .unitree import HgLowCmd, HgLowState, LowCmd, LowState

__all__ = ["LowLevel", "STAND_POSE_RAD"]

STAND_POSE_RAD: Tuple[float, float, float]

_Joints = Union[float, Sequence[float]]

class LowLevel:
    """A Unitree robot's low-level interface over DDS (Go2, or HG with robot="hg")."""
    def __init__(
        self,
        *,
        domain: int = 0,
        interface: Optional[str] = None,
        robot: Literal["go2", "hg"] = "go2",
        service_timeout_s: float = 5.0,
        record: Union[str, PathLike[str], Recorder, None] = None,
    ) -> None:
        """record: go2/low_level and go2/api (hg/… for robot="hg") into a path or a Recorder."""
    @property
    def robot(self) -> str: ...
    def release_sport_mode(self) -> int:
        """ReleaseMode calls taken (0: nothing owned the motors); raises ServiceError."""
    def sport_mode(self) -> str: ...
    def set_joints(
        self, q: _Joints, kp: _Joints, kd: _Joints, dq: Optional[_Joints] = None, tau: Optional[_Joints] = None
    ) -> None:
        """Go2: 12 joints (rad, kp 0-500, kd 0-50, rad/s, N·m); raises ArgumentError."""
    def set_command(self, command: Union[LowCmd, HgLowCmd]) -> None: ...
    def damp(self) -> None: ...
    def state(self) -> Union[LowState, HgLowState]:
        """Raises NoStateError before the first state and while the robot is silent."""
    @property
    def state_age_s(self) -> Optional[float]: ...
    def wait_state(self, timeout_s: float = 3.0) -> Union[LowState, HgLowState]:
        """Raises TimeoutError."""
    def joint_positions(self) -> List[float]: ...
    @property
    def connection(self) -> str: ...
    def stats(self) -> Dict[str, Any]: ...
    def close(self) -> None:
        """Damping last, then leaves the domain; idempotent."""
    def __enter__(self) -> Self: ...
    def __exit__(self, *exc: Any) -> None: ...
