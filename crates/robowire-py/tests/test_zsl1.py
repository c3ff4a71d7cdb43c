"""robowire.zsl1 as a drop-in for mc_sdk_zsl_1_py, call by call against robowire.sim.Zsl1, with
the vendor's return codes (spec zsl1-udp.md §8.3, §9) and robowire's safer differences."""

import inspect
import math
import os
import signal
import threading
import time

import pytest

import robowire
import robowire.sim
import robowire.zsl1 as mc_sdk_zsl_1_py
from helpers import wait_until

SWITCH_FAILED = 0x3007
SPEED_TOO_LARGE = 0x3013
MOTOR_FAULT = 0x3011

# The vendor module's classes and methods (its pybind11 signatures; compared with the vendor's
# own module in test_vendor_side_by_side.py wherever it loads).
HIGH_LEVEL_METHODS = {
    "initRobot": ["local_ip", "local_port", "dog_ip"],
    "checkConnect": [],
    "standUp": [],
    "lieDown": [],
    "passive": [],
    "move": ["vx", "vy", "yaw_rate"],
    "jump": [],
    "frontJump": [],
    "backflip": [],
    "shakeHand": [],
    "twoLegStand": ["vx", "yaw_rate"],
    "cancelTwoLegStand": [],
    "attitudeControl": ["yaw_vel", "roll_vel", "pitch_vel", "height_vel"],
    **{
        name: []
        for name in [
            "getQuaternion",
            "getRPY",
            "getBodyAcc",
            "getBodyGyro",
            "getPosition",
            "getWorldVelocity",
            "getBodyVelocity",
            "getBatteryPower",
            "getCurrentCtrlmode",
            "getLegAbadJoint",
            "getLegHipJoint",
            "getLegKneeJoint",
            "getLegAbadJointVel",
            "getLegHipJointVel",
            "getLegKneeJointVel",
            "getLegAbadJointTorque",
            "getLegHipJointTorque",
            "getLegKneeJointTorque",
        ]
    },
}
LOW_LEVEL_METHODS = {
    "initRobot": ["local_ip", "local_port", "dog_ip"],
    "checkConnect": [],
    "sendMotorCmd": ["cmd"],
    "getMotorState": [],
    "haveMotorData": [],
    "getQuaternion": [],
    "getRPY": [],
    "getBodyAcc": [],
    "getBodyGyro": [],
}


def parameters(method):
    return [p for p in inspect.signature(method).parameters if p != "self"]


@pytest.mark.parametrize("cls, methods", [(mc_sdk_zsl_1_py.HighLevel, HIGH_LEVEL_METHODS), (mc_sdk_zsl_1_py.LowLevel, LOW_LEVEL_METHODS)])
def test_the_vendors_methods_with_the_vendors_parameter_names(cls, methods):
    for name, params in methods.items():
        assert parameters(getattr(cls, name)) == params, name
    assert inspect.signature(cls.initRobot).parameters["dog_ip"].default == "192.168.234.1"


def connect(ip, cls=mc_sdk_zsl_1_py.HighLevel):
    robot = cls()
    robot.initRobot(ip, 43988, ip)
    assert robot.wait_connected(3.0)
    return robot


def stand(robot):
    assert robot.standUp() == 0
    wait_until(lambda: robot.getCurrentCtrlmode() == 1)


def test_before_init_robot_calls_raise_closed_and_check_connect_is_false():
    robot = mc_sdk_zsl_1_py.HighLevel()
    assert robot.checkConnect() is False
    assert robot.connection == "closed"
    for call in (robot.standUp, robot.getRPY, lambda: robot.move(0.5, 0, 0)):
        with pytest.raises(robowire.ClosedError, match="initRobot"):
            call()


def test_init_robot_refuses_bad_addresses(ip):
    robot = mc_sdk_zsl_1_py.HighLevel()
    with pytest.raises(robowire.ArgumentError, match="local_ip"):
        robot.initRobot("not-an-ip", 43988, ip)
    with pytest.raises(robowire.ArgumentError, match="local_port"):
        robot.initRobot(ip, 70000, ip)
    with pytest.raises(robowire.ArgumentError, match="dog_ip"):
        robot.initRobot(ip, 43988, "192.168.234")


def test_a_taken_port_raises_bind_error_where_the_vendor_only_prints(ip):
    with connect_plain(ip) as first:
        second = mc_sdk_zsl_1_py.HighLevel()
        with pytest.raises(robowire.BindError, match=f"{ip}:43988") as raised:
            second.initRobot(ip, 43988, ip)
        assert isinstance(raised.value, OSError)
        assert first.connection in ("waiting", "connected")


def connect_plain(ip):
    robot = mc_sdk_zsl_1_py.HighLevel()
    robot.initRobot(ip, 43988, ip)
    return robot


def test_getters_raise_no_state_before_the_first_state_instead_of_zeros(ip):
    with connect_plain(ip) as robot:  # no dog at ip
        assert robot.checkConnect() is False
        assert robot.connection == "waiting"
        for getter in (robot.getRPY, robot.getQuaternion, robot.getBatteryPower, robot.getLegKneeJoint):
            with pytest.raises(robowire.NoStateError, match=f"robot at {ip}"):
                getter()


def test_stand_walk_and_read_every_getter(dog, ip):
    with connect(ip) as robot:
        assert robot.checkConnect() is True
        assert robot.getCurrentCtrlmode() == 51  # the simulator boots lying down, joints locked
        stand(robot)
        assert robot.move(0.5, 0.0, 0.2) == 0
        wait_until(lambda: robot.getBodyVelocity()[0] > 0.3)
        assert robot.getCurrentCtrlmode() == 18
        for name in [m for m in HIGH_LEVEL_METHODS if m.startswith("get")]:
            value = getattr(robot, name)()
            if name in ("getBatteryPower", "getCurrentCtrlmode"):
                assert isinstance(value, int), name
            else:
                assert isinstance(value, list) and all(isinstance(v, float) for v in value), name
                assert len(value) == (4 if name in ("getQuaternion",) or name.startswith("getLeg") else 3), name
        assert abs(robot.getPosition()[2] - 0.3) < 0.05
        assert 0 < robot.getBatteryPower() <= 100
        assert robot.move(0.0, 0.0, 0.0) == 0
        wait_until(lambda: abs(robot.getBodyVelocity()[0]) < 0.05)
        assert dog.snapshot()["high_level"]["invalid"] == 0


def test_lying_down_refuses_motion_with_0x3007(dog, ip):
    with connect(ip) as robot:
        for call in (lambda: robot.move(0.5, 0, 0), robot.jump, robot.frontJump, robot.backflip,
                     lambda: robot.twoLegStand(0.3, 0), lambda: robot.attitudeControl(0.1, 0, 0, 0)):
            assert call() == SWITCH_FAILED
            assert "stand" in robot.last_error
        assert robot.passive() == 0
        assert robot.last_error is None


def test_argument_ranges_return_0x3013_and_send_nothing(dog, ip):
    with connect(ip) as robot:
        stand(robot)
        assert robot.move(0.04, 0, 0) == SPEED_TOO_LARGE  # |vx| 0 or 0.05..3.0
        assert robot.move(3.1, 0, 0) == SPEED_TOO_LARGE
        assert robot.move(0, 0.09, 0) == SPEED_TOO_LARGE  # |vy| 0 or 0.1..1.0
        assert robot.move(0, 0, 3.5) == SPEED_TOO_LARGE  # |yaw rate| 0 or 0.02..3.0
        assert robot.attitudeControl(0.61, 0, 0, 0) == SPEED_TOO_LARGE  # each |v| <= 0.6
        assert robot.twoLegStand(0.1, 0) == SPEED_TOO_LARGE  # |vx| 0 or 0.2..0.5
        assert "outside" in robot.last_error
        assert dog.snapshot()["mode"] == 1  # nothing was sent: still standing
        assert robot.move(-3.0, 1.0, -0.02) == 0  # the band edges pass


@pytest.mark.parametrize("bad", [math.nan, math.inf, -math.inf])
def test_nan_and_infinities_are_refused_where_the_vendor_sends_nan(dog, ip, bad):
    with connect(ip) as robot:
        stand(robot)
        assert robot.move(bad, 0, 0) == SPEED_TOO_LARGE
        assert "finite" in robot.last_error
        assert robot.attitudeControl(0, bad, 0, 0) == SPEED_TOO_LARGE
        # A sentinel: once the dog walks, whatever was sent before the walk has arrived.
        assert robot.move(0.5, 0, 0) == 0
        wait_until(lambda: dog.snapshot()["mode"] == 18)
        assert dog.snapshot()["high_level"]["invalid"] == 0


def test_wrong_types_raise_type_error(ip):
    with connect_plain(ip) as robot:
        with pytest.raises(TypeError):
            robot.move("fast", 0, 0)
        with pytest.raises(TypeError):
            robot.initRobot(ip, "43988", ip)


def test_two_leg_stand_blocks_move_until_cancelled(dog, ip):
    with connect(ip) as robot:
        stand(robot)
        assert robot.twoLegStand(0.3, 0.0) == 0
        wait_until(lambda: robot.getCurrentCtrlmode() == 21)
        assert robot.move(0.5, 0, 0) == SWITCH_FAILED
        assert "two-leg stand" in robot.last_error
        assert robot.cancelTwoLegStand() is None
        assert robot.move(0.5, 0, 0) == 0


def test_tricks_go_out_and_come_back_to_their_mode(dog, ip):
    with connect(ip) as robot:
        stand(robot)
        wait_until(lambda: dog.snapshot()["activity"] == "standing")  # up, not getting up
        assert robot.jump() == 0
        wait_until(lambda: dog.snapshot()["tricks_done"] >= 1, timeout_s=5)
        assert robot.shakeHand() == 0
        wait_until(lambda: dog.snapshot()["tricks_done"] >= 2, timeout_s=5)


def test_the_robots_error_word_is_returned_by_every_call(dog, ip):
    with connect(ip) as robot:
        dog.inject_error_word(MOTOR_FAULT)
        wait_until(lambda: robot.standUp() == MOTOR_FAULT)
        assert robot.passive() == MOTOR_FAULT
        assert "self-check" in robot.last_error
        dog.clear_faults()
        wait_until(lambda: robot.passive() == 0)


def test_a_silent_robot_is_noticed_and_picked_up_again(dog, ip):
    with connect(ip) as robot:
        stand(robot)
        dog.inject_silence()
        wait_until(lambda: not robot.checkConnect(), timeout_s=4.5)
        assert robot.connection == "disconnected"
        with pytest.raises(robowire.NoStateError, match="silent"):
            robot.getRPY()
        dog.clear_faults()
        wait_until(robot.checkConnect, timeout_s=2)
        stats = robot.stats()
        assert (stats["disconnects"], stats["reconnects"]) == (1, 1)
        assert robot.getCurrentCtrlmode() == 1


def test_sdk_mismatch_stops_the_client_and_says_so(dog, ip):
    with connect(ip) as robot:
        stand(robot)
        dog.inject_sdk_mismatch()
        wait_until(lambda: robot.move(0.5, 0, 0) == SWITCH_FAILED)
        assert "SDK mismatch" in robot.last_error
        with pytest.raises(robowire.Error, match="SDK mismatch"):
            robot.cancelTwoLegStand()


def test_with_block_closes_and_frees_the_port(dog, ip):
    with mc_sdk_zsl_1_py.HighLevel() as robot:
        robot.initRobot(ip, 43988, ip)
        assert robot.local_addr == (ip, 43988)
    assert robot.connection == "closed"
    again = mc_sdk_zsl_1_py.HighLevel()
    again.initRobot(ip, 43988, ip)  # the port is free again
    again.close()
    again.close()  # idempotent


def test_init_robot_again_replaces_the_connection(dog, ip):
    with connect(ip) as robot:
        robot.initRobot(ip, 43988, ip)  # the vendor's aborts the process here
        assert robot.wait_connected(3.0)


def test_ctrl_c_interrupts_a_blocking_wait(ip):
    # Ctrl-C as in a terminal: a process started in the background inherits SIGINT ignored, and
    # Python then raises no KeyboardInterrupt at all.
    previous = signal.signal(signal.SIGINT, signal.default_int_handler)
    try:
        with connect_plain(ip) as robot:  # nobody answers
            timer = threading.Timer(0.2, os.kill, (os.getpid(), signal.SIGINT))
            timer.start()
            started = time.monotonic()
            with pytest.raises(KeyboardInterrupt):
                robot.wait_connected(30.0)
            assert time.monotonic() - started < 30.0  # interrupted, not ended by its timeout
            timer.join()
    finally:
        signal.signal(signal.SIGINT, previous)


def test_a_blocking_wait_releases_the_gil(ip):
    with connect_plain(ip) as robot:
        counter = [0]
        stop = threading.Event()

        def count():
            while not stop.is_set():
                counter[0] += 1

        worker = threading.Thread(target=count)
        worker.start()
        assert robot.wait_connected(0.5) is False
        seen = counter[0]
        stop.set()
        worker.join()
        assert seen > 10_000  # the other thread ran while this one waited


# --- LowLevel ----------------------------------------------------------------------------------


def low_level(ip):
    robot = mc_sdk_zsl_1_py.LowLevel()
    robot.initRobot(ip, 43989, ip)
    assert robot.wait_connected(3.0)
    return robot


def stand_command():
    cmd = mc_sdk_zsl_1_py.MotorCommand()
    cmd.q_des_abad[:] = [0.0] * 4
    cmd.q_des_hip[:] = [0.72] * 4
    cmd.q_des_knee[:] = [-1.45] * 4
    cmd.kp_abad[:] = cmd.kp_hip[:] = cmd.kp_knee[:] = [40.0] * 4
    cmd.kd_abad = cmd.kd_hip = cmd.kd_knee = [1.0] * 4
    return cmd


def test_low_level_drives_the_motors(dog, ip):
    with low_level(ip) as robot:
        assert robot.checkConnect()
        assert robot.haveMotorData() is True
        assert robot.sendMotorCmd(stand_command()) == 0
        wait_until(lambda: abs(robot.getMotorState().q_knee[0] + 1.45) < 0.05)
        state = robot.getMotorState()
        assert isinstance(state, mc_sdk_zsl_1_py.MotorState)
        assert len(state.q_hip) == 4 and abs(state.q_hip[3] - 0.72) < 0.05
        state.q_hip[0] = 99.0  # a copy: the client's state is untouched
        assert robot.getMotorState().q_hip[0] != 99.0
        assert len(robot.getRPY()) == 3 and len(robot.getQuaternion()) == 4
        assert dog.snapshot()["activity"] == "low_level"


def test_send_motor_cmd_returns_the_vendors_minus_one(dog, ip):
    with low_level(ip) as robot:
        assert robot.sendMotorCmd(mc_sdk_zsl_1_py.MotorCommand()) == -1  # knee 0 is out of range
        assert "knee" in robot.last_error
        cmd = stand_command()
        cmd.q_des_knee[2] = -2.9  # as float32 just below -2.9: the vendor refuses it too
        assert robot.sendMotorCmd(cmd) == -1
        cmd = stand_command()
        cmd.kp_hip[1] = math.nan  # the vendor sends NaN gains
        assert robot.sendMotorCmd(cmd) == -1
        assert "finite" in robot.last_error
        assert robot.sendMotorCmd(stand_command()) == 0
        assert robot.last_error is None


def test_low_level_getters_raise_no_state_without_a_robot(ip):
    robot = mc_sdk_zsl_1_py.LowLevel()
    robot.initRobot(ip, 43989, ip)
    try:
        assert robot.haveMotorData() is False
        with pytest.raises(robowire.NoStateError):
            robot.getMotorState()
    finally:
        robot.close()
