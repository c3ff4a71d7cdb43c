"""Type stubs of robowire.policy (see policy.py)."""

from os import PathLike
from typing import Any, Dict, List, Optional, Tuple, Union

from typing_extensions import Self

from .record import Recorder

__all__ = ["PolicyConfig", "Run", "run"]

class PolicyConfig:
    """A deploy config: unitree_rl_gym's fields unchanged, and robowire's optional additions."""
    @staticmethod
    def load(path: Union[str, PathLike[str]]) -> PolicyConfig:
        """Reads and checks it; ArgumentError (one line naming the field) for a config that is not one, robowire.Error
        for a file that cannot be read. policy_path becomes relative to the config's directory."""
    @property
    def path(self) -> str: ...
    @property
    def control_dt(self) -> float:
        """Seconds between two policy steps."""
    @property
    def msg_type(self) -> str:
        """hg (G1, H1-2) or go (Go2)."""
    @property
    def imu_type(self) -> str:
        """pelvis or torso."""
    @property
    def policy_path(self) -> str: ...
    @property
    def leg_joint2motor_idx(self) -> List[int]: ...
    @property
    def kps(self) -> List[float]: ...
    @property
    def kds(self) -> List[float]: ...
    @property
    def default_angles(self) -> List[float]: ...
    @property
    def arm_waist_joint2motor_idx(self) -> List[int]: ...
    @property
    def action_scale(self) -> float: ...
    @property
    def cmd_scale(self) -> List[float]: ...
    @property
    def max_cmd(self) -> List[float]:
        """m/s, m/s, rad/s: commands are clamped to it."""
    @property
    def num_actions(self) -> int: ...
    @property
    def num_obs(self) -> int: ...
    @property
    def observation(self) -> List[str]:
        """The observation's terms in order (base_ang_vel, projected_gravity, command, …)."""
    @property
    def gait_period(self) -> float: ...
    @property
    def max_tilt_rad(self) -> float: ...

class Run:
    """A policy running on a robot, started by run(); close() (or leaving a with block) damps it and closes the
    device."""
    @property
    def address(self) -> str: ...
    @property
    def command(self) -> Tuple[float, float, float]: ...
    def set_command(self, vx: float, vy: float, wz: float) -> None:
        """m/s, m/s, rad/s from the next policy step on, clamped to max_cmd; ArgumentError if not finite."""
    @property
    def phase(self) -> str:
        """standing, holding, walking or damped."""
    @property
    def last_step(self) -> Optional[Dict[str, Any]]:
        """step, obs, actions, command, inference_s, clamped; None before the first step."""
    def wait(self, timeout_s: Optional[float] = None) -> Optional[str]:
        """duration, stopped, fault or refused (the robot damped); None if it still runs after timeout_s."""
    @property
    def reason(self) -> Optional[str]:
        """Why it ended, one line; None while it runs."""
    def stop(self) -> str:
        """Damps the robot at the next policy tick; how the run ended."""
    def close(self) -> None:
        """Stops the run, closes the device (and its simulator), finishes record=PATH; idempotent."""
    def __enter__(self) -> Self: ...
    def __exit__(self, *exc: Any) -> None: ...

def run(
    config: Union[str, PathLike[str], PolicyConfig],
    device: str,
    *,
    cmd: Tuple[float, float, float] = (0.0, 0.0, 0.0),
    duration_s: Optional[float] = None,
    stand: bool = True,
    record: Union[str, PathLike[str], Recorder, None] = None,
    domain: int = 0,
    physics: bool = False,
    model: Union[str, PathLike[str], None] = None,
) -> Run:
    """Starts the policy on g1:IFACE, go2:IFACE, or sim:g1/sim:go2 with physics=True (started here, its base free):
    waits for the state, releases the robot's controller, stands 2 s, holds 1 s, then the policy every control_dt
    until duration_s or a fault. ArgumentError (nothing sent) for a kinematic simulator, a robot of the other
    family, a config or model that disagree; NoStateError without a state within 3 s."""
