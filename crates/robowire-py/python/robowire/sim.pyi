"""Type stubs of robowire.sim (see sim.py)."""

from os import PathLike
from typing import Any, Dict, List, Literal, Optional, Tuple, Union

from typing_extensions import Self

from .record import Recorder

__all__ = ["Zsl1", "Chassis", "Spline", "Go2", "G1", "loopback_has_multicast", "enter_loopback_namespace"]

class _Simulator:
    def close(self) -> None:
        """Stops the simulator, then finishes the capture of record=PATH; idempotent."""
    def __enter__(self) -> Self: ...
    def __exit__(self, *exc: Any) -> None: ...

class Zsl1(_Simulator):
    """A ZSL-1 / ZSL-1W on UDP (HighLevel 43997, LowLevel 43900 by default)."""
    def __init__(
        self,
        model: Literal["zsl1", "zsl1w"] = "zsl1",
        *,
        ip: str = "127.0.0.1",
        high_level_port: int = 43997,
        low_level_port: int = 43900,
        state_period_s: float = 0.002,
        record: Union[str, PathLike[str], Recorder, None] = None,
    ) -> None:
        """record: zsl1/high_level and zsl1/low_level, the robot's side."""
    @property
    def ip(self) -> str: ...
    @property
    def high_level_addr(self) -> Tuple[str, int]: ...
    @property
    def low_level_addr(self) -> Tuple[str, int]: ...
    def inject_error_word(self, code: int) -> None: ...
    def inject_sdk_mismatch(self) -> None: ...
    def inject_silence(self) -> None: ...
    def inject_garbage(self) -> None: ...
    def clear_faults(self) -> None: ...
    def set_battery_percent(self, percent: float) -> None: ...
    def snapshot(self) -> Dict[str, Any]: ...

Dog = Zsl1
"""The old name of Zsl1, kept for one release (deprecated: a DeprecationWarning when used)."""

class Chassis(_Simulator):
    """A KMC chassis behind a pseudo-terminal."""
    def __init__(
        self,
        *,
        speed_time_constant_s: float = 0.2,
        battery_initial_volts: float = 25.2,
        battery_drain_volts_per_s: float = 0.0005,
        command_watchdog_s: Optional[float] = 1.0,
        link: Optional[str] = None,
        seed: int = 0x5EEDCAFE,
        record: Union[str, PathLike[str], Recorder, None] = None,
    ) -> None:
        """record: kmc/serial and kmc/serial_skipped, the chassis's side."""
    @property
    def path(self) -> str: ...
    @property
    def pty_path(self) -> str: ...
    def inject_garbage(self, count: int) -> None: ...
    def drop_responses(self, count: int) -> None: ...
    def hang_up(self) -> None: ...
    def replug(self) -> str: ...
    def state(self) -> Dict[str, Any]: ...
    def stats(self) -> Dict[str, Any]: ...
    def received(self) -> List[Dict[str, Any]]: ...

class Spline(_Simulator):
    """The ZSL-1 spline daemon on POSIX shared memory (private object names by default)."""
    def __init__(
        self,
        *,
        spline_name: Optional[str] = None,
        imu_name: Optional[str] = None,
        period_s: float = 0.001,
        record: Union[str, PathLike[str], Recorder, None] = None,
    ) -> None:
        """record: spline/spline (the daemon's side) and spline/imu."""
    @property
    def spline_name(self) -> str: ...
    @property
    def imu_name(self) -> str: ...
    def pause(self, paused: bool = True) -> None: ...
    def inject_fault(self, leg: int, joint: int, bits: int) -> None: ...
    def state(self) -> Dict[str, Any]: ...
    def stats(self) -> Dict[str, Any]: ...

class _UnitreeSimulator(_Simulator):
    @property
    def domain(self) -> int: ...
    def inject_silence(self) -> None: ...
    def inject_motor_fault(self, motor: int) -> None: ...
    def inject_bit_flips(self, every: int) -> None: ...
    def clear_faults(self) -> None: ...
    def take_log(self) -> List[str]: ...
    def snapshot(self) -> Dict[str, Any]: ...

class Go2(_UnitreeSimulator):
    """A Unitree Go2 on DDS (motors 0..12)."""
    def __init__(
        self,
        *,
        domain: int = 0,
        interface: Optional[str] = None,
        state_period_s: float = 0.002,
        record: Union[str, PathLike[str], Recorder, None] = None,
        physics: bool = False,
        model: Union[str, PathLike[str], None] = None,
    ) -> None:
        """record: go2/low_level and go2/api, the robot's side; physics: the body in MuJoCo (a wheel
        built with the `mujoco` feature), lying on its floor; model: a user's MJCF instead of
        robowire's model of the Go2 (its joints named FR_hip_joint, ...)."""

class G1(_UnitreeSimulator):
    """A Unitree G1 humanoid on DDS (motors 0..29); boots standing, the mode "ai" owning the motors."""
    def __init__(
        self,
        interface: Optional[str] = "lo",
        domain: int = 0,
        *,
        dof: Literal[29, 27, 23, 14] = 29,
        mode_machine: Optional[int] = None,
        state_period_s: float = 0.002,
        record: Union[str, PathLike[str], Recorder, None] = None,
        physics: bool = False,
        model: Union[str, PathLike[str], None] = None,
        free_base: bool = False,
    ) -> None:
        """mode_machine None: the variant's (5 for 29 dof, 4 for 23); record: g1/low_level and g1/api, the robot's side;
        physics: the body in MuJoCo (a wheel built with the `mujoco` feature), its pelvis held (hanging) unless
        free_base (then on the floor, held on a band until a LowCmd stream has driven its legs for 3.5 s); model: a user's MJCF instead of robowire's model of the G1."""
    @property
    def variant(self) -> Literal["29dof", "23dof", "29dof_waist_locked", "dual_arm"]: ...
    @property
    def mode_machine(self) -> int: ...

def loopback_has_multicast() -> bool: ...
def enter_loopback_namespace() -> None:
    """A private network namespace with multicast on loopback (root, or root of a user namespace;
    iproute2)."""
