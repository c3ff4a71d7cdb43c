"""A Unitree robot's low-level interface over DDS (``rt/lowcmd``, ``rt/lowstate``, the
motion_switcher and sport services): the Go2, or an HG robot (G1, H1-2) with ``robot="hg"``.

Interoperable with Unitree's SDKs and CycloneDDS. Safe by default: commands are checked before
anything is sent, nothing is sent before the first command, a stale command (100 ms) becomes
damping, a silent robot is reported, and closing sends damping last.
"""

from ._native import Go2LowLevel as LowLevel

STAND_POSE_RAD = (0.0, 0.67, -1.3)
"""The stand pose of Unitree's examples, per leg (hip, thigh, calf), rad."""

__all__ = ["LowLevel", "STAND_POSE_RAD"]
