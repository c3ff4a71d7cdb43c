"""robowire.go2 against robowire.sim.Go2 over DDS (in this process's private network namespace
when loopback has no multicast)."""

import math
import time

import pytest

import robowire
import robowire.go2
import robowire.sim
from helpers import silence_is_noticed, wait_until
from robowire.unitree import LowCmd, LowState

STAND = list(robowire.go2.STAND_POSE_RAD) * 4


@pytest.fixture
def go2_sim(dds):
    with robowire.sim.Go2(domain=7) as sim:
        yield sim


@pytest.fixture
def robot(go2_sim):
    with robowire.go2.LowLevel(domain=7) as robot:
        yield robot


def test_release_the_sport_mode_and_stand(go2_sim, robot):
    state = robot.wait_state(timeout_s=5.0)
    assert isinstance(state, LowState) and robot.connection == "connected"
    assert robot.sport_mode() == "normal"
    assert robot.release_sport_mode() == 1
    assert robot.sport_mode() == ""
    deadline = time.monotonic() + 10.0  # a failure bound: it stands in about 0.3 s
    while time.monotonic() < deadline and abs(robot.joint_positions()[2] - STAND[2]) > 0.05:
        robot.set_joints(q=STAND, kp=60.0, kd=5.0)
        time.sleep(0.002)
    assert robot.joint_positions() == pytest.approx(STAND, abs=0.05)
    assert go2_sim.snapshot()["lowcmd"]["accepted"] > 0
    assert robot.state().motor_state[2].q == pytest.approx(STAND[2], abs=0.05)
    assert robot.state_age_s >= 0.0 and robot.connection == "connected"


def test_commands_are_checked_before_anything_is_sent(go2_sim, robot):
    robot.wait_state(timeout_s=5.0)
    for bad in (dict(q=math.nan, kp=60.0, kd=5.0), dict(q=STAND, kp=600.0, kd=5.0), dict(q=STAND, kp=60.0, kd=math.inf)):
        with pytest.raises(robowire.ArgumentError):
            robot.set_joints(**bad)
    with pytest.raises(robowire.ArgumentError, match="12"):
        robot.set_joints(q=[0.0] * 11, kp=1.0, kd=1.0)
    with pytest.raises(robowire.ArgumentError, match="LowCmd"):
        robot.set_command(object())
    assert robot.stats()["commands_sent"] == 0  # nothing before the first valid command


def test_a_whole_lowcmd_and_damping(go2_sim, robot):
    robot.wait_state(timeout_s=5.0)
    robot.release_sport_mode()
    cmd = LowCmd()
    for i, q in enumerate(STAND):
        m = cmd.motor_cmd[i]
        m.mode, m.q, m.dq, m.kp, m.kd, m.tau = 1, q, 0.0, 60.0, 5.0, 0.0
    robot.set_command(cmd)
    wait_until(lambda: robot.stats()["commands_sent"] > 10)
    wait_until(lambda: robot.stats()["command_timeouts"] == 1, timeout_s=10.0)  # stale after 100 ms: damping
    robot.damp()
    wait_until(lambda: robot.stats()["damping_sent"] > 0)


def test_a_silent_robot_is_noticed(go2_sim, robot):
    robot.wait_state(timeout_s=5.0)
    silence_is_noticed(go2_sim, robot)


def test_bit_flips_are_counted_and_dropped(go2_sim, robot):
    robot.wait_state(timeout_s=5.0)
    go2_sim.inject_bit_flips(5)
    wait_until(lambda: robot.stats()["lowstate"]["checksum_errors"] > 3, timeout_s=3.0)
    assert robot.connection == "connected"


def test_wait_state_times_out(dds):
    with robowire.go2.LowLevel(domain=8) as lonely:  # no robot in domain 8
        with pytest.raises(robowire.TimeoutError):
            lonely.wait_state(timeout_s=0.2)
        with pytest.raises(robowire.NoStateError):
            lonely.state()
    with pytest.raises(robowire.ClosedError):
        lonely.damp()


def test_bad_robot_and_options(dds):
    with pytest.raises(robowire.ArgumentError, match="go2"):
        robowire.go2.LowLevel(robot="h1")
    with pytest.raises(robowire.ArgumentError):
        robowire.sim.Go2(state_period_s=-1.0)
