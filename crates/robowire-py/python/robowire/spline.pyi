"""Type stubs of robowire.spline (see spline.py)."""

from os import PathLike
from typing import Any, Dict, Optional, Sequence, Union

from typing_extensions import Self

from .record import Recorder

__all__ = ["SplineClient", "ImuReader"]

_Joints = Union[float, Sequence[float], Sequence[Sequence[float]]]

class SplineClient:
    def __init__(
        self,
        name: str = "/spline_shm",
        *,
        stall_after_s: Optional[float] = None,
        record: Union[str, PathLike[str], Recorder, None] = None,
    ) -> None:
        """stall_after_s: no fresh state for this long while waiting raises NoStateError (None: 10 ms).
        record: spline/spline into a path or a Recorder."""
    def write_command(
        self,
        p_des: _Joints,
        *,
        v_des: Optional[_Joints] = None,
        kp: Optional[_Joints] = None,
        kd: Optional[_Joints] = None,
        t_ff: Optional[_Joints] = None,
    ) -> None: ...
    def try_read_state(self) -> Optional[Dict[str, Any]]: ...
    def wait_state(self, timeout_s: float = 0.1) -> Dict[str, Any]: ...
    @property
    def is_stalled(self) -> bool: ...
    def counters(self) -> Dict[str, int]: ...
    def close(self) -> None: ...
    def __enter__(self) -> Self: ...
    def __exit__(self, *exc: Any) -> None: ...

class ImuReader:
    def __init__(self, name: str = "/imu_shm", *, record: Union[str, PathLike[str], Recorder, None] = None) -> None:
        """record: spline/imu into a path or a Recorder."""
    def read(self) -> Dict[str, Any]: ...
    def close(self) -> None: ...
    def __enter__(self) -> Self: ...
    def __exit__(self, *exc: Any) -> None: ...
