"""Type stubs of robowire.g1 (see g1.py)."""

from os import PathLike
from typing import Any, Dict, List, Literal, Optional, Sequence, Tuple, Union

from typing_extensions import Self

from .record import Recorder
from .unitree import HgLowCmd, HgLowState

__all__ = [
    "G1",
    "Loco",
    "ArmActions",
    "JOINTS",
    "JOINT_NAMES",
    "DEFAULT_KP",
    "DEFAULT_KD",
    "ARM_JOINT_SLOTS",
    "ARM_JOINTS",
    "VX_MAX_MPS",
    "VY_MAX_MPS",
    "YAW_RATE_MAX_RADPS",
]

JOINTS: int
JOINT_NAMES: Tuple[str, ...]
DEFAULT_KP: Tuple[float, ...]
DEFAULT_KD: Tuple[float, ...]
ARM_JOINT_SLOTS: Tuple[int, ...]
ARM_JOINTS: int
VX_MAX_MPS: float
VY_MAX_MPS: float
YAW_RATE_MAX_RADPS: float

_Joints = Union[float, Sequence[float]]
_Variant = Literal["29dof", "23dof", "29dof_waist_locked", "dual_arm"]

class Loco:
    """The locomotion service (sport); refusals are ServiceError (7301 after release, 7302, 7303)."""
    def fsm_id(self) -> int:
        """0 zero torque, 1 damp, 2 squat, 3 sit, 4 stand up, 500 walking, …"""
    def fsm_mode(self) -> int: ...
    def set_fsm(self, fsm_id: int) -> None: ...
    def zero_torque(self) -> None: ...
    def damp(self) -> None: ...
    def squat(self) -> None: ...
    def sit(self) -> None: ...
    def stand_up(self) -> None: ...
    def start(self) -> None:
        """FSM 500, the walking controller."""
    def set_velocity(self, vx_mps: float, vy_mps: float, yaw_radps: float, duration_s: float = 1.0) -> None:
        """|vx| ≤ 1 m/s, |vy| ≤ 0.5 m/s, |yaw| ≤ 1 rad/s, duration 0–864000 s; ArgumentError otherwise."""
    def stop_move(self) -> None: ...
    def set_balance_mode(self, mode: int) -> None:
        """0 balance stand, 1 continuous gait."""
    def balance_mode(self) -> int: ...
    def set_stand_height(self, height_m: float) -> None: ...
    def stand_height(self) -> float: ...
    def set_swing_height(self, height_m: float) -> None: ...
    def swing_height(self) -> float: ...
    def set_arm_task(self, task: int) -> None: ...

class ArmActions:
    """The arm action service (arm); refusals are ServiceError (7400, 7401, 7402, 7404)."""
    def execute_action(self, action_id: int) -> None: ...
    def release_arm(self) -> None:
        """Action 99."""
    def action_list(self) -> str:
        """The robot's answer, JSON text."""

class G1:
    """The Unitree G1 humanoid over DDS."""
    def __init__(
        self,
        interface: Optional[str] = None,
        domain: int = 0,
        *,
        variant: Optional[_Variant] = None,
        service_timeout_s: float = 5.0,
        record: Union[str, PathLike[str], Recorder, None] = None,
    ) -> None:
        """record: g1/low_level, g1/api and g1/arm_sdk, the client's side, into a path or a Recorder."""
    def release(self) -> int:
        """ReleaseMode calls taken (0: nothing owned the motors); raises ServiceError."""
    def mode(self) -> str:
        """The mode owning the motors ("": released)."""
    def select_mode(self, name: str) -> None: ...
    @property
    def mode_machine(self) -> Optional[int]:
        """From the robot's latest LowState; None before the first."""
    @property
    def variant(self) -> Optional[_Variant]: ...
    def state(self) -> HgLowState:
        """Raises NoStateError before the first state and while the robot is silent."""
    @property
    def state_age_s(self) -> Optional[float]: ...
    def wait_state(self, timeout_s: float = 3.0) -> HgLowState:
        """Raises TimeoutError."""
    @property
    def connection(self) -> str: ...
    def set_command(self, command: HgLowCmd) -> None:
        """Checked for the robot's mode_machine and variant; raises ArgumentError."""
    def set_joints(
        self, q: _Joints, kp: _Joints, kd: _Joints, dq: Optional[_Joints] = None, tau: Optional[_Joints] = None
    ) -> None:
        """29 slots (rad, kp 0-500, kd 0-50, rad/s, N·m); raises ArgumentError."""
    def hold(self, q: _Joints) -> None:
        """q rad with DEFAULT_KP/DEFAULT_KD on every driven joint."""
    def damp(self) -> None: ...
    def joint_positions(self) -> List[float]:
        """29 positions, rad; raises NoStateError."""
    def set_arm_joints(
        self, q: _Joints, kp: _Joints, kd: _Joints, dq: Optional[_Joints] = None, tau: Optional[_Joints] = None
    ) -> None:
        """17 joints in ARM_JOINT_SLOTS order; raises ArgumentError."""
    def set_arm_weight(self, weight: float) -> None:
        """0..=1, ramped at 0.5/s; raises ArgumentError."""
    @property
    def arm_weight(self) -> float: ...
    @property
    def loco(self) -> Loco: ...
    @property
    def arm(self) -> ArmActions: ...
    def stats(self) -> Dict[str, Any]: ...
    def close(self) -> None:
        """Arm weight ramped out, damping last, then leaves the domain; idempotent."""
    def __enter__(self) -> Self: ...
    def __exit__(self, *exc: Any) -> None: ...
