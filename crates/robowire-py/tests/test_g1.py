"""robowire.g1 against robowire.sim.G1 over DDS (in this process's private network namespace
when loopback has no multicast)."""

import math
import time

import pytest

import robowire
import robowire.g1
import robowire.go2
import robowire.sim
from helpers import silence_is_noticed, wait_until
from robowire.unitree import HgLowCmd, HgLowState
from test_record import summary

DOMAIN = 22


@pytest.fixture
def g1_sim(dds):
    with robowire.sim.G1(domain=DOMAIN) as sim:
        yield sim


@pytest.fixture
def robot(g1_sim):
    with robowire.g1.G1(domain=DOMAIN) as robot:
        robot.wait_state(timeout_s=5.0)
        yield robot


def near_zero(q, slots=range(29), tolerance=0.05):
    return all(abs(q[i]) < tolerance for i in slots)


def test_constants_mirror_the_rust_tables():
    g1 = robowire.g1
    assert g1.JOINTS == 29 == len(g1.JOINT_NAMES) == len(g1.DEFAULT_KP) == len(g1.DEFAULT_KD)
    assert g1.JOINT_NAMES[0] == "left_hip_pitch_joint" and g1.JOINT_NAMES[28] == "right_wrist_yaw_joint"
    assert g1.DEFAULT_KP[3] == 100.0 and g1.DEFAULT_KD[3] == 2.0  # Unitree's example: the knees
    assert g1.ARM_JOINTS == 17 and g1.ARM_JOINT_SLOTS[:2] == (15, 16) and g1.ARM_JOINT_SLOTS[-3:] == (12, 13, 14)


def test_commands_are_refused_before_the_first_lowstate(dds):
    with robowire.g1.G1(domain=21) as lonely:  # no robot in domain 21
        assert lonely.mode_machine is None and lonely.variant is None and lonely.connection == "waiting"
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


def test_the_mode_machine_is_the_robots_and_a_wrong_one_is_refused(g1_sim, robot):
    assert robot.mode_machine == 5 and robot.variant == "29dof" and robot.connection == "connected"
    state = robot.state()
    assert isinstance(state, HgLowState) and state.mode_machine == 5 and robot.state_age_s >= 0.0
    wrong = HgLowCmd(mode_machine=6)
    with pytest.raises(robowire.ArgumentError, match=r"mode_machine 6 is not the robot's \(5"):
        robot.set_command(wrong)
    disabled = HgLowCmd(mode_machine=5)
    disabled.motor_cmd[0].kp = 10.0  # mode 0: the robot would ignore it
    with pytest.raises(robowire.ArgumentError, match="motor 0 has mode 0"):
        robot.set_command(disabled)
    assert robot.stats()["commands_sent"] == 0


def test_release_zero_posture_damp_and_locomotion_refused_until_select_mode(g1_sim, robot):
    assert robot.mode() == "ai" and robot.loco.fsm_id() == 500
    assert robot.release() >= 1
    assert robot.mode() == "" and g1_sim.snapshot()["mode"] == ""
    with pytest.raises(robowire.ServiceError, match="select_mode") as refused:
        robot.loco.set_velocity(0.2, 0.0, 0.0, 1.0)
    assert (refused.value.service, refused.value.api_id, refused.value.code) == ("sport", 7105, 7301)

    deadline = time.monotonic() + 15.0  # a failure bound: the sim gets there in about a second
    while time.monotonic() < deadline and not near_zero(robot.joint_positions()):
        robot.hold(0.0)
        time.sleep(0.002)
    assert near_zero(robot.joint_positions()), robot.joint_positions()
    snapshot = g1_sim.snapshot()
    assert near_zero(snapshot["joints_rad"]), snapshot["joints_rad"]
    counted = snapshot["lowcmd"]
    assert counted["accepted"] > 0 and counted["bad_mode_machine"] == 0 and counted["disabled_motors"] == 0

    robot.damp()
    wait_until(lambda: robot.stats()["damping_sent"] > 0)
    robot.select_mode("ai")
    assert robot.mode() == "ai" and robot.loco.fsm_id() == 500
    robot.loco.set_velocity(0.2, 0.0, 0.0, 1.0)


def test_the_arm_sdk_weight_is_ramped_never_switched(g1_sim, robot):
    with pytest.raises(robowire.ArgumentError, match="set_arm_joints"):
        robot.set_arm_weight(0.5)  # no arm targets yet
    robot.set_arm_joints(q=0.0, kp=60.0, kd=1.5)
    with pytest.raises(robowire.ArgumentError, match="0..=1"):
        robot.set_arm_weight(1.5)

    def ramp(target):
        """Refreshes the target until the weight is there; the (frames sent, weight) seen."""
        seen = []
        deadline = time.monotonic() + 20.0  # a failure bound: 0.5/s takes 2 s
        while time.monotonic() < deadline:
            robot.set_arm_weight(target)
            stats = robot.stats()
            seen.append((stats["arm_sdk_sent"], stats["arm_sdk_weight"]))
            if seen[-1][1] == target and g1_sim.snapshot()["arm_sdk"]["weight"] == target:
                return seen
            time.sleep(0.005)
        raise AssertionError(f"the weight did not reach {target}: {seen[-5:]}")

    up = ramp(1.0)
    assert robot.arm_weight == 1.0
    down = ramp(0.0)
    for seen, rising in ((up, True), (down, False)):
        assert len({w for _, w in seen}) > 20, "ramped through many values"
        for (sent0, w0), (sent1, w1) in zip(seen, seen[1:]):
            # 0.5/s at 50 Hz: at most 0.01 per frame (one frame of slack: the two counters are read
            # one after the other while the stream runs).
            assert abs(w1 - w0) <= 0.01 * (sent1 - sent0 + 1) + 1e-5, (sent0, w0, sent1, w1)
            assert (w1 >= w0) if rising else (w1 <= w0)
    arm_sdk = g1_sim.snapshot()["arm_sdk"]
    assert arm_sdk["accepted"] > 100 and arm_sdk["ignored_released"] == 0 and arm_sdk["unsealed"] == 0
    assert robot.stats()["arm_sdk_write_drops"] == 0


def test_the_sim_counts_a_wrong_mode_machine_and_a_disabled_motor(g1_sim, robot):
    robot.release()
    # A client without the G1's rules sends what robowire.g1 refuses.
    with robowire.go2.LowLevel(domain=DOMAIN, robot="hg") as raw:
        raw.wait_state(timeout_s=5.0)
        wrong = HgLowCmd(mode_machine=3)
        raw.set_command(wrong)
        wait_until(lambda: g1_sim.snapshot()["lowcmd"]["bad_mode_machine"] > 0)
        assert any("mode_machine 3" in line for line in g1_sim.take_log())
        disabled = HgLowCmd(mode_machine=5)
        disabled.motor_cmd[0].kp = 10.0
        raw.set_command(disabled)
        wait_until(lambda: g1_sim.snapshot()["lowcmd"]["disabled_motors"] > 0)
    assert g1_sim.snapshot()["lowcmd"]["bad_crc"] == 0


def test_a_23_dof_g1_refuses_commands_on_its_missing_joints(dds):
    with robowire.sim.G1(domain=23, dof=23) as sim, robowire.g1.G1(domain=23) as robot:
        robot.wait_state(timeout_s=5.0)
        assert robot.mode_machine == 4 and robot.variant == "23dof"
        robot.release()
        with pytest.raises(robowire.ArgumentError, match="motor 13 is not driven"):
            robot.set_joints(q=[0.0] * 29, kp=[60.0] * 29, kd=1.0)  # the waist roll: slot 13
        with pytest.raises(robowire.ArgumentError, match="motor 20 is not driven"):
            robot.set_arm_joints(q=0.0, kp=[60.0] * 17, kd=1.0)  # the left wrist pitch: slot 20
        assert robot.stats()["commands_sent"] == 0
        driven = [i for i in range(29) if i not in (13, 14, 20, 21, 27, 28)]
        deadline = time.monotonic() + 15.0
        while time.monotonic() < deadline and not near_zero(robot.joint_positions(), driven):
            robot.set_joints(q=0.0, kp=60.0, kd=1.0)  # a number: the driven joints only
            time.sleep(0.002)
        with pytest.raises(robowire.ArgumentError, match="motor 13 is not driven"):
            robot.set_joints(q=0.0, kp=robowire.g1.DEFAULT_KP, kd=1.0)
        robot.set_joints(q=0.0, kp=[k if i in driven else 0.0 for i, k in enumerate(robowire.g1.DEFAULT_KP)], kd=1.0)
        assert near_zero(sim.snapshot()["joints_rad"], driven)
        assert sim.snapshot()["lowcmd"]["disabled_motors"] == 0


def test_bad_arguments_raise_and_send_nothing(g1_sim, robot):
    robot.release()
    for bad in (
        dict(q=math.nan, kp=60.0, kd=1.0),
        dict(q=0.0, kp=60.0, kd=math.inf),
        dict(q=0.0, kp=600.0, kd=1.0),
        dict(q=[0.0] * 30, kp=60.0, kd=1.0),
        dict(q=0.0, kp=[60.0] * 12, kd=1.0),
        dict(q=[0.0, 0.0, 0.0, -0.5] + [0.0] * 25, kp=60.0, kd=1.0),  # the left knee bends one way
        dict(q=0.0, kp=60.0, kd=1.0, tau=[0.0] * 20 + [6.0] + [0.0] * 8),  # a wrist motor: 5 N·m
    ):
        with pytest.raises(robowire.ArgumentError):
            robot.set_joints(**bad)
    with pytest.raises(robowire.ArgumentError):
        robot.hold([0.0] * 28)
    with pytest.raises(robowire.ArgumentError, match="HgLowCmd"):
        robot.set_command(object())
    with pytest.raises(TypeError):
        robot.set_joints(q="twenty-nine", kp=60.0, kd=1.0)
    assert robot.stats()["commands_sent"] == 0
    with pytest.raises(robowire.ArgumentError, match="vx_mps"):
        robot.loco.set_velocity(2.0, 0.0, 0.0)
    with pytest.raises(robowire.ArgumentError, match="stand_height_m"):
        robot.loco.set_stand_height(-0.1)


def test_service_refusals_are_typed(g1_sim, robot):
    with pytest.raises(robowire.ServiceError) as fsm:
        robot.loco.set_fsm(12345)
    assert (fsm.value.service, fsm.value.api_id, fsm.value.code) == ("sport", 7101, 7302)
    with pytest.raises(robowire.ServiceError) as action:
        robot.arm.execute_action(1234)
    assert (action.value.service, action.value.code) == ("arm", 7402)
    assert "clap" in robot.arm.action_list()
    robot.arm.execute_action(17)
    robot.arm.release_arm()
    robot.loco.set_balance_mode(1)
    assert robot.loco.balance_mode() == 1
    robot.release()
    with pytest.raises(robowire.ServiceError) as after_release:
        robot.loco.fsm_id()
    assert (after_release.value.api_id, after_release.value.code) == (7001, 7301)


def test_faults_snapshot_and_options(dds):
    with robowire.sim.G1(domain=24, mode_machine=0) as sim, robowire.g1.G1(domain=24) as robot:
        robot.wait_state(timeout_s=5.0)
        assert robot.mode_machine == 0 and robot.variant == "29dof"  # a simulator's 0: checked as a 29-dof G1
        assert sim.domain == 24 and sim.snapshot()["fsm_id"] == 500
        silence_is_noticed(sim, robot)
        sim.inject_bit_flips(5)
        wait_until(lambda: robot.stats()["lowstate"]["checksum_errors"] > 3, timeout_s=10.0)
        sim.clear_faults()
        for bad in (lambda: sim.inject_motor_fault(29), lambda: sim.inject_bit_flips(0)):
            with pytest.raises(robowire.ArgumentError):
                bad()
    with robowire.g1.G1(domain=24, variant="23dof") as told:
        assert told.variant == "23dof"
    with pytest.raises(robowire.ArgumentError, match="dof"):
        robowire.sim.G1(domain=24, dof=25)
    with pytest.raises(robowire.ArgumentError, match="state_period_s"):
        robowire.sim.G1(domain=24, state_period_s=-1.0)
    with pytest.raises(robowire.ArgumentError, match="29dof"):
        robowire.g1.G1(variant="31dof")
    with pytest.raises(robowire.ArgumentError, match="service_timeout_s"):
        robowire.g1.G1(service_timeout_s=math.nan)
    with pytest.raises(robowire.ClosedError):
        sim.snapshot()


def test_a_simulated_g1_and_its_client_record_both_ends(dds, tmp_path):
    sim_path, client_path = tmp_path / "g1-sim.mcap", tmp_path / "g1-client.mcap"
    with robowire.Recorder(client_path) as rec:
        with robowire.sim.G1(domain=25, record=sim_path), robowire.g1.G1(domain=25, record=rec) as robot:
            robot.wait_state(timeout_s=5.0)
            robot.release()
            for _ in range(50):
                robot.hold(0.0)
                time.sleep(0.002)
    for path in (sim_path, client_path):
        channels = summary(path)
        for link in ("g1/low_level", "g1/api"):
            for direction in ("sent", "received"):
                wire = channels[f"/{link}/{direction}"]
                assert wire["encoding"] == "cdr" and wire["count"] > 0, (path, link, direction)
