"""The Unitree G1 humanoid over DDS, as Unitree's G1 examples drive it: ``rt/lowcmd`` with the
robot's ``mode_machine``, ``rt/arm_sdk`` with a ramped weight, the motion_switcher, the
locomotion (``sport``) and arm action (``arm``) services.

Interoperable with Unitree's SDKs and CycloneDDS. Safe by default: nothing goes on ``rt/lowcmd``
before the robot's first LowState (its ``mode_machine`` is copied into every command), every
command is checked for the robot's variant before it is latched, a stale command (100 ms)
becomes damping, the arm weight is ramped and never switched, and closing ramps the arm weight
out and damps last. Drive :class:`robowire.sim.G1` to try it without a robot.
"""

from ._native import G1
from ._native import G1ArmActions as ArmActions
from ._native import G1Loco as Loco
from ._native import (
    G1_ARM_JOINT_SLOTS,
    G1_DEFAULT_KD,
    G1_DEFAULT_KP,
    G1_JOINT_NAMES,
    G1_JOINTS,
    G1_VX_MAX_MPS,
    G1_VY_MAX_MPS,
    G1_YAW_RATE_MAX_RADPS,
)

JOINTS = G1_JOINTS
"""Joint slots of the G1 (29); every variant keeps this layout."""

JOINT_NAMES = tuple(G1_JOINT_NAMES)
"""The joints by slot, as the G1's URDF names them (left leg 0–5, right leg 6–11, waist 12–14,
left arm 15–21, right arm 22–28)."""

DEFAULT_KP = tuple(G1_DEFAULT_KP)
"""Position gains of Unitree's G1 low-level example by slot, N·m/rad (what ``G1.hold`` uses)."""

DEFAULT_KD = tuple(G1_DEFAULT_KD)
"""Velocity gains of Unitree's G1 low-level example by slot, N·m·s/rad."""

ARM_JOINT_SLOTS = tuple(G1_ARM_JOINT_SLOTS)
"""The slots ``G1.set_arm_joints`` takes, in its order: left arm 15–21, right arm 22–28, then
the waist 12, 13, 14."""

ARM_JOINTS = len(ARM_JOINT_SLOTS)
"""Joints of ``rt/arm_sdk`` (17)."""

VX_MAX_MPS = G1_VX_MAX_MPS
"""robowire's bound on ``Loco.set_velocity``'s forward velocity, m/s (either way)."""

VY_MAX_MPS = G1_VY_MAX_MPS
"""robowire's bound on the sideways velocity, m/s (either way)."""

YAW_RATE_MAX_RADPS = G1_YAW_RATE_MAX_RADPS
"""robowire's bound on the yaw rate, rad/s (either way)."""

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
