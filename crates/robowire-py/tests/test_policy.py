"""robowire.policy: a deploy config read and checked, refusals before anything is sent (the
same lines as ``robowire policy run``), and, on the physics Go2 (a wheel built with the cargo
feature ``mujoco``, gated as test_physics.py's), a run that stands, holds, walks and is damped."""

import math
import threading

import pytest

import robowire
import robowire.policy
from conftest import missing
from helpers import wait_until
from tiny_onnx import matmul

# Unitree's G1 deploy config with its fields unchanged.
G1_YAML = """control_dt: 0.02
msg_type: "hg"
imu_type: "pelvis"
lowcmd_topic: "rt/lowcmd"
lowstate_topic: "rt/lowstate"
policy_path: "g1.onnx"
leg_joint2motor_idx: [0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11]
kps: [100, 100, 100, 150, 40, 40, 100, 100, 100, 150, 40, 40]
kds: [2, 2, 2, 4, 2, 2, 2, 2, 2, 4, 2, 2]
default_angles: [-0.1, 0.0, 0.0, 0.3, -0.2, 0.0, -0.1, 0.0, 0.0, 0.3, -0.2, 0.0]
ang_vel_scale: 0.25
dof_pos_scale: 1.0
dof_vel_scale: 0.05
action_scale: 0.25
cmd_scale: [2.0, 2.0, 0.25]
num_actions: 12
num_obs: 47
max_cmd: [0.8, 0.5, 1.57]
"""

# unitree_rl_gym's Go2 deploy values; the observation starts with the base's velocity.
GO2_YAML = """control_dt: 0.02
msg_type: go
policy_path: go2.onnx
leg_joint2motor_idx: [3, 4, 5, 0, 1, 2, 9, 10, 11, 6, 7, 8]
kps: [20, 20, 20, 20, 20, 20, 20, 20, 20, 20, 20, 20]
kds: [0.5, 0.5, 0.5, 0.5, 0.5, 0.5, 0.5, 0.5, 0.5, 0.5, 0.5, 0.5]
default_angles: [0.1, 0.8, -1.5, -0.1, 0.8, -1.5, 0.1, 1.0, -1.5, -0.1, 1.0, -1.5]
lin_vel_scale: 2.0
ang_vel_scale: 0.25
dof_pos_scale: 1.0
dof_vel_scale: 0.05
action_scale: 0.25
cmd_scale: [2.0, 2.0, 0.25]
num_actions: 12
num_obs: 48
max_cmd: [1.0, 0.5, 1.0]
observation: [base_lin_vel, base_ang_vel, projected_gravity, command, joint_pos, joint_vel, last_action]
"""


def write_config(tmp_path, yaml, name, n_obs):
    """The config beside a model of zeros (it holds the default pose) of ``n_obs`` inputs."""
    matmul(tmp_path / f"{name}.onnx", n_obs, 12, [0.0] * (n_obs * 12))
    path = tmp_path / f"{name}.yaml"
    path.write_text(yaml)
    return path


def test_a_config_reads_as_written(tmp_path):
    config = robowire.policy.PolicyConfig.load(write_config(tmp_path, G1_YAML, "g1", 47))
    assert (config.msg_type, config.imu_type, config.num_obs, config.num_actions) == ("hg", "pelvis", 47, 12)
    assert config.control_dt == 0.02 and config.kps[3] == 150.0 and config.leg_joint2motor_idx[11] == 11
    assert config.policy_path == str(tmp_path / "g1.onnx"), "relative to the config"
    assert config.observation[0] == "base_ang_vel" and config.observation[-1] == "gait_phase", "deploy_real.py's"
    assert (config.gait_period, config.max_tilt_rad) == (0.8, 1.0)
    assert [round(v, 2) for v in config.max_cmd] == [0.8, 0.5, 1.57]


def test_a_config_whose_sizes_disagree_is_one_line_naming_the_field(tmp_path):
    path = write_config(tmp_path, G1_YAML.replace("num_obs: 47", "num_obs: 48"), "g1", 47)
    with pytest.raises(robowire.ArgumentError) as raised:
        robowire.policy.PolicyConfig.load(path)
    assert str(raised.value) == "num_obs: is 48, the observation's terms make 47"
    # run() reads it the same way.
    with pytest.raises(robowire.ArgumentError, match="^num_obs: is 48"):
        robowire.policy.run(path, "g1:lo")


def test_an_unknown_field_or_a_missing_file_says_so(tmp_path):
    path = write_config(tmp_path, G1_YAML + "kp_scale: 2\n", "g1", 47)
    with pytest.raises(robowire.ArgumentError, match="kp_scale"):
        robowire.policy.PolicyConfig.load(path)
    with pytest.raises(robowire.Error, match="cannot read"):
        robowire.policy.PolicyConfig.load(tmp_path / "absent.yaml")


@pytest.mark.parametrize(
    "device, line",
    [
        ("sim:g1", "sim:g1 is the kinematic simulator: its joints follow the commands and nothing walks"),
        ("sim:kmc", "sim:kmc: a policy drives a Unitree robot"),
        ("hg:lo", "hg:lo: a policy drives a G1 as g1:IFACE"),
        ("go2:lo", "msg_type: the config is for hg (G1, H1-2) robots, go2:lo speaks go (Go2)"),
        ("tank:1", 'device address "tank:1": unknown kind'),
    ],
)
def test_a_device_a_policy_cannot_drive_is_refused_before_anything_opens(tmp_path, device, line):
    config = robowire.policy.PolicyConfig.load(write_config(tmp_path, G1_YAML, "g1", 47))
    with pytest.raises(robowire.ArgumentError) as raised:
        robowire.policy.run(config, device)
    assert str(raised.value).startswith(line), raised.value
    assert "\n" not in str(raised.value)


def test_a_model_that_disagrees_with_the_config_or_a_command_that_is_not_finite_is_refused(tmp_path):
    path = write_config(tmp_path, G1_YAML, "g1", 47)
    with pytest.raises(robowire.ArgumentError, match="finite"):
        robowire.policy.run(path, "g1:lo", cmd=(0.5, math.nan, 0.0))
    matmul(tmp_path / "g1.onnx", 48, 12, [0.0] * 48 * 12)
    with pytest.raises(robowire.ArgumentError, match="num_obs: the config says 47, input obs takes 48"):
        robowire.policy.run(path, "g1:lo")


def physics_run(path, domain, **options):
    """The policy on a physics Go2 started here, or a skip (a failure where ``physics`` is
    required)."""
    try:
        return robowire.policy.run(path, "sim:go2", physics=True, domain=domain, **options)
    except robowire.Error as e:
        if "without physics" not in str(e):
            raise
        missing("physics", f"this wheel has no physics: {e}")


def test_a_run_stands_holds_walks_and_stop_damps(dds, tmp_path):
    path = write_config(tmp_path, GO2_YAML, "go2", 48)
    capture = tmp_path / "go2.mcap"
    with physics_run(path, 20, cmd=(0.5, 0.0, 0.0), record=capture) as walk:
        phases = [walk.phase]
        while phases[-1] != "walking":  # 2 s standing, 1 s holding
            phase = walk.phase
            if phase != phases[-1]:
                phases.append(phase)
            assert walk.wait(timeout_s=0.01) is None, walk.reason
        assert phases == ["standing", "holding", "walking"], phases
        step = wait_until(lambda: walk.last_step, timeout_s=30.0)
        assert (len(step["obs"]), len(step["actions"]), step["step"] >= 1) == (48, 12, True), step
        assert step["actions"] == [0.0] * 12 and step["inference_s"] > 0.0
        # A command past max_cmd is clamped there.
        walk.set_command(2.0, 0.0, -0.25)
        assert walk.command == (2.0, 0.0, -0.25)
        wait_until(lambda: walk.last_step["command"] == [1.0, 0.0, -0.25], timeout_s=30.0)
        with pytest.raises(robowire.ArgumentError):
            walk.set_command(math.inf, 0.0, 0.0)
        assert walk.reason is None
        # A thread waits without a timeout, the GIL released: this one stops the run meanwhile.
        ended = []
        waiter = threading.Thread(target=lambda: ended.append(walk.wait()))
        waiter.start()
        assert walk.stop() == "stopped"
        waiter.join()
        assert ended == ["stopped"]
        assert (walk.phase, walk.wait(), walk.reason) == ("damped", "stopped", "stopped")
    assert walk.phase == "damped" and walk.wait(timeout_s=0.0) == "stopped"
    with pytest.raises(robowire.ClosedError):
        walk.last_step
    assert capture.stat().st_size > 0


def test_a_run_ends_when_its_duration_runs_out(dds, tmp_path):
    path = write_config(tmp_path, GO2_YAML, "go2", 48)
    with physics_run(path, 21, duration_s=0.2, stand=False) as walk:
        assert walk.wait() == "duration"
        assert walk.reason == "the duration ran out" and walk.phase == "damped"
        assert walk.last_step["step"] >= 1


def test_a_robot_that_sends_no_state_raises_no_state_error(dds, tmp_path):
    path = write_config(tmp_path, G1_YAML, "g1", 47)
    capture = tmp_path / "silent.mcap"
    with pytest.raises(robowire.NoStateError, match="no LowState from the robot within 3 s"):
        robowire.policy.run(path, "g1:lo", domain=22, record=capture)
    assert capture.stat().st_size > 0, "the capture was finished"
