"""Type stubs of robowire.zsl1, the drop-in for mc_sdk_zsl_1_py (see zsl1.py)."""

from os import PathLike
from typing import Any, Dict, Iterable, Iterator, List, Optional, Tuple, Union, overload

from typing_extensions import Self

from .record import Recorder

__all__ = ["HighLevel", "LowLevel", "MotorCommand", "MotorState", "JointArray"]

_Floats4 = Iterable[float]

class JointArray:
    """One field's four legs (FR, FL, RR, RL) as float32: a live view that writes through."""
    def __len__(self) -> int: ...
    @overload
    def __getitem__(self, index: int) -> float: ...
    @overload
    def __getitem__(self, index: slice) -> List[float]: ...
    @overload
    def __setitem__(self, index: int, value: float) -> None: ...
    @overload
    def __setitem__(self, index: slice, value: Iterable[float]) -> None: ...
    def __iter__(self) -> Iterator[float]: ...
    def tolist(self) -> List[float]: ...
    def __array__(self, dtype: Any = None, copy: Optional[bool] = None) -> Any: ...

class MotorCommand:
    """A LowLevel motor command: fifteen fields of four legs, zero when made."""
    def __init__(self) -> None: ...
    @property
    def q_des_abad(self) -> JointArray:
        """Abad position targets, rad (-0.7..0.7)."""
    @q_des_abad.setter
    def q_des_abad(self, value: _Floats4) -> None: ...
    @property
    def q_des_hip(self) -> JointArray:
        """Hip position targets, rad (-1.15..3.0)."""
    @q_des_hip.setter
    def q_des_hip(self, value: _Floats4) -> None: ...
    @property
    def q_des_knee(self) -> JointArray:
        """Knee position targets, rad (-2.9..-0.65, both ends excluded at float32)."""
    @q_des_knee.setter
    def q_des_knee(self, value: _Floats4) -> None: ...
    @property
    def qd_des_abad(self) -> JointArray:
        """Abad velocity targets, rad/s."""
    @qd_des_abad.setter
    def qd_des_abad(self, value: _Floats4) -> None: ...
    @property
    def qd_des_hip(self) -> JointArray:
        """Hip velocity targets, rad/s."""
    @qd_des_hip.setter
    def qd_des_hip(self, value: _Floats4) -> None: ...
    @property
    def qd_des_knee(self) -> JointArray:
        """Knee velocity targets, rad/s."""
    @qd_des_knee.setter
    def qd_des_knee(self, value: _Floats4) -> None: ...
    @property
    def kp_abad(self) -> JointArray:
        """Abad position gains, N·m/rad."""
    @kp_abad.setter
    def kp_abad(self, value: _Floats4) -> None: ...
    @property
    def kp_hip(self) -> JointArray:
        """Hip position gains, N·m/rad."""
    @kp_hip.setter
    def kp_hip(self, value: _Floats4) -> None: ...
    @property
    def kp_knee(self) -> JointArray:
        """Knee position gains, N·m/rad."""
    @kp_knee.setter
    def kp_knee(self, value: _Floats4) -> None: ...
    @property
    def kd_abad(self) -> JointArray:
        """Abad velocity gains, N·m·s/rad."""
    @kd_abad.setter
    def kd_abad(self, value: _Floats4) -> None: ...
    @property
    def kd_hip(self) -> JointArray:
        """Hip velocity gains, N·m·s/rad."""
    @kd_hip.setter
    def kd_hip(self, value: _Floats4) -> None: ...
    @property
    def kd_knee(self) -> JointArray:
        """Knee velocity gains, N·m·s/rad."""
    @kd_knee.setter
    def kd_knee(self, value: _Floats4) -> None: ...
    @property
    def tau_abad_ff(self) -> JointArray:
        """Abad feed-forward torques, N·m."""
    @tau_abad_ff.setter
    def tau_abad_ff(self, value: _Floats4) -> None: ...
    @property
    def tau_hip_ff(self) -> JointArray:
        """Hip feed-forward torques, N·m."""
    @tau_hip_ff.setter
    def tau_hip_ff(self, value: _Floats4) -> None: ...
    @property
    def tau_knee_ff(self) -> JointArray:
        """Knee feed-forward torques, N·m."""
    @tau_knee_ff.setter
    def tau_knee_ff(self, value: _Floats4) -> None: ...
    def to_dict(self) -> Dict[str, List[float]]: ...

class MotorState:
    """The twelve motors as the robot reports them, legs FR, FL, RR, RL."""
    def __init__(self) -> None: ...
    @property
    def q_abad(self) -> JointArray:
        """Abad positions, rad."""
    @q_abad.setter
    def q_abad(self, value: _Floats4) -> None: ...
    @property
    def q_hip(self) -> JointArray:
        """Hip positions, rad."""
    @q_hip.setter
    def q_hip(self, value: _Floats4) -> None: ...
    @property
    def q_knee(self) -> JointArray:
        """Knee positions, rad."""
    @q_knee.setter
    def q_knee(self, value: _Floats4) -> None: ...
    @property
    def qd_abad(self) -> JointArray:
        """Abad velocities, rad/s."""
    @qd_abad.setter
    def qd_abad(self, value: _Floats4) -> None: ...
    @property
    def qd_hip(self) -> JointArray:
        """Hip velocities, rad/s."""
    @qd_hip.setter
    def qd_hip(self, value: _Floats4) -> None: ...
    @property
    def qd_knee(self) -> JointArray:
        """Knee velocities, rad/s."""
    @qd_knee.setter
    def qd_knee(self, value: _Floats4) -> None: ...
    @property
    def tau_abad_fb(self) -> JointArray:
        """Abad torque feedback, N·m."""
    @tau_abad_fb.setter
    def tau_abad_fb(self, value: _Floats4) -> None: ...
    @property
    def tau_hip_fb(self) -> JointArray:
        """Hip torque feedback, N·m."""
    @tau_hip_fb.setter
    def tau_hip_fb(self, value: _Floats4) -> None: ...
    @property
    def tau_knee_fb(self) -> JointArray:
        """Knee torque feedback, N·m."""
    @tau_knee_fb.setter
    def tau_knee_fb(self, value: _Floats4) -> None: ...
    def to_dict(self) -> Dict[str, List[float]]: ...

class _Session:
    """robowire's additions to the vendor's clients."""
    @property
    def last_error(self) -> Optional[str]:
        """Why the last call returned a non-zero code (None after a 0)."""
    @property
    def connection(self) -> str:
        """One of: waiting, connected, disconnected, closed."""
    @property
    def local_addr(self) -> Tuple[str, int]: ...
    def wait_connected(self, timeout_s: float = 3.0) -> bool:
        """Waits up to timeout_s for state (GIL released, Ctrl-C interrupts)."""
    def stats(self) -> Dict[str, Any]: ...
    def close(self) -> None:
        """Stops streaming and frees the port, and finishes the capture of record=PATH; idempotent."""
    def __enter__(self) -> Self: ...
    def __exit__(self, *exc: Any) -> None: ...

class HighLevel(_Session):
    """The ZSL-1 HighLevel client (mc_sdk_zsl_1_py.HighLevel): the vendor's calls and codes."""
    def __init__(self, *, record: Union[str, PathLike[str], Recorder, None] = None) -> None:
        """record (robowire's): zsl1/high_level into a path or a Recorder."""
    def initRobot(self, local_ip: str, local_port: int, dog_ip: str = "192.168.234.1") -> None:
        """Binds local_ip:local_port, streams to dog_ip:43997 every 2 ms; raises BindError."""
    def checkConnect(self) -> bool: ...
    def standUp(self) -> int: ...
    def lieDown(self) -> int: ...
    def passive(self) -> int: ...
    def move(self, vx: float, vy: float, yaw_rate: float) -> int:
        """m/s, m/s, rad/s; each |v| 0 or vx 0.05-3.0, vy 0.1-1.0, yaw rate 0.02-3.0; 0x3013 out of range or NaN."""
    def jump(self) -> int: ...
    def frontJump(self) -> int: ...
    def backflip(self) -> int: ...
    def shakeHand(self) -> int: ...
    def twoLegStand(self, vx: float, yaw_rate: float) -> int:
        """|vx| 0 or 0.2-0.5 m/s, |yaw rate| 0 or 0.2-1.0 rad/s."""
    def cancelTwoLegStand(self) -> None: ...
    def attitudeControl(self, yaw_vel: float, roll_vel: float, pitch_vel: float, height_vel: float) -> int:
        """Each |v| <= 0.6; sent in argument order as roll, pitch, yaw, height rate (spec §5.2)."""
    def getQuaternion(self) -> List[float]:
        """w, x, y, z; raises NoStateError without state."""
    def getRPY(self) -> List[float]:
        """rad."""
    def getBodyAcc(self) -> List[float]:
        """m/s²."""
    def getBodyGyro(self) -> List[float]:
        """rad/s."""
    def getPosition(self) -> List[float]:
        """m."""
    def getWorldVelocity(self) -> List[float]:
        """m/s."""
    def getBodyVelocity(self) -> List[float]:
        """m/s."""
    def getBatteryPower(self) -> int:
        """%, 0-100."""
    def getCurrentCtrlmode(self) -> int:
        """0 passive, 1 standing, 10/51 lying, 18 moving, 21 action."""
    def getLegAbadJoint(self) -> List[float]:
        """rad, legs FR, FL, RR, RL."""
    def getLegHipJoint(self) -> List[float]: ...
    def getLegKneeJoint(self) -> List[float]: ...
    def getLegAbadJointVel(self) -> List[float]:
        """rad/s."""
    def getLegHipJointVel(self) -> List[float]: ...
    def getLegKneeJointVel(self) -> List[float]: ...
    def getLegAbadJointTorque(self) -> List[float]:
        """N·m."""
    def getLegHipJointTorque(self) -> List[float]: ...
    def getLegKneeJointTorque(self) -> List[float]: ...

class LowLevel(_Session):
    """The ZSL-1 LowLevel client (mc_sdk_zsl_1_py.LowLevel)."""
    def __init__(self, *, record: Union[str, PathLike[str], Recorder, None] = None) -> None:
        """record (robowire's): zsl1/low_level into a path or a Recorder."""
    def initRobot(self, local_ip: str, local_port: int, dog_ip: str = "192.168.234.1") -> None:
        """Binds local_ip:local_port, streams to dog_ip:43900 every 2 ms; raises BindError."""
    def checkConnect(self) -> bool: ...
    def sendMotorCmd(self, cmd: MotorCommand) -> int:
        """0 accepted; -1 refused (positions out of the vendor's bounds, NaN, infinities)."""
    def getMotorState(self) -> MotorState:
        """A new MotorState; raises NoStateError without state."""
    def haveMotorData(self) -> bool: ...
    def getQuaternion(self) -> List[float]: ...
    def getRPY(self) -> List[float]: ...
    def getBodyAcc(self) -> List[float]: ...
    def getBodyGyro(self) -> List[float]: ...
