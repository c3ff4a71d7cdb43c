"""robowire.g1 against robowire.sim.G1 over DDS (in this process's private network namespace
when loopback has no multicast)."""

import math

import pytest

import robowire
import robowire.g1
from robowire.unitree import HgLowCmd


def test_constants_mirror_the_rust_tables():
    g1 = robowire.g1
    assert g1.JOINTS == 29 == len(g1.JOINT_NAMES) == len(g1.DEFAULT_KP) == len(g1.DEFAULT_KD)
    assert g1.JOINT_NAMES[0] == "left_hip_pitch_joint" and g1.JOINT_NAMES[28] == "right_wrist_yaw_joint"
    assert g1.DEFAULT_KP[3] == 100.0 and g1.DEFAULT_KD[3] == 2.0  # Unitree's example: the knees
    assert g1.ARM_JOINTS == 17 and g1.ARM_JOINT_SLOTS[:2] == (15, 16) and g1.ARM_JOINT_SLOTS[-3:] == (12, 13, 14)


def test_commands_are_refused_before_the_first_lowstate(dds):
    with robowire.g1.G1(domain=21) as lonely:  # no robot in domain 21
        assert lonely.mode_machine is None and lonely.variant is None
        for command in (
            lambda: lonely.hold(0.0),
            lambda: lonely.set_joints(q=0.0, kp=60.0, kd=1.0),
            lambda: lonely.damp(),
            lambda: lonely.set_arm_joints(q=0.0, kp=60.0, kd=1.5),
            lambda: lonely.set_command(HgLowCmd()),
        ):
            with pytest.raises(robowire.ArgumentError, match="mode_machine"):
                command()
        with pytest.raises(robowire.NoStateError):
            lonely.state()
        with pytest.raises(robowire.NoStateError):
            lonely.joint_positions()
        with pytest.raises(robowire.TimeoutError):
            lonely.wait_state(timeout_s=0.2)
        assert lonely.stats()["commands_sent"] == 0 and lonely.stats()["arm_sdk_sent"] == 0
        # Arguments are checked before the robot is asked.
        with pytest.raises(robowire.ArgumentError, match="29"):
            lonely.set_joints(q=[0.0] * 28, kp=60.0, kd=1.0)
        with pytest.raises(robowire.ArgumentError, match="17"):
            lonely.set_arm_joints(q=[0.0] * 29, kp=60.0, kd=1.0)
        with pytest.raises(robowire.ArgumentError, match="0..=1"):
            lonely.set_arm_weight(math.nan)
        with pytest.raises(robowire.ArgumentError, match="vx_mps"):
            lonely.loco.set_velocity(math.nan, 0.0, 0.0)
        with pytest.raises(robowire.ArgumentError, match="yaw_radps"):
            lonely.loco.set_velocity(0.0, 0.0, 2.0, 1.0)
        with pytest.raises(robowire.ArgumentError, match="balance"):
            lonely.loco.set_balance_mode(2)
        loco = lonely.loco
    with pytest.raises(robowire.ClosedError):
        lonely.damp()
    with pytest.raises(robowire.ClosedError):
        loco.fsm_id()


def test_bad_options(dds):
    with pytest.raises(robowire.ArgumentError, match="29dof"):
        robowire.g1.G1(variant="31dof")
    with pytest.raises(robowire.ArgumentError, match="service_timeout_s"):
        robowire.g1.G1(service_timeout_s=math.nan)
