"""robowire.sim.Go2 and robowire.sim.G1 with physics (MuJoCo, a wheel built with the cargo
feature ``mujoco``; ``cargo xtask test`` builds one when MuJoCo is here), and the same bodies by
address (``robowire.open("sim:go2", physics=True)``). A wheel without it refuses ``physics=True``
with robowire.Error."""

import math
import time

import pytest

import robowire
import robowire.go2
import robowire.sim
from conftest import missing

STAND = list(robowire.go2.STAND_POSE_RAD) * 4
CALF_MIN_RAD = -2.7227  # the Go2's calf range's lower end


def physics_go2(domain):
    """A physics Go2 on ``domain``, or a skip (a failure where ``physics`` is required)."""
    try:
        return robowire.sim.Go2(domain=domain, physics=True)
    except robowire.Error as e:
        if "without physics" not in str(e):
            raise
        missing("physics", f"this wheel has no physics: {e}")


def test_without_physics_the_simulators_say_so_or_have_a_body(dds):
    try:
        sim = robowire.sim.Go2(domain=8, physics=True)
    except robowire.Error as e:
        assert "built without physics" in str(e) and "mujoco" in str(e)
        with pytest.raises(robowire.Error, match="without physics"):
            robowire.sim.G1(domain=8, physics=True)
        return
    with sim:
        body = sim.snapshot()["body"]
        assert body["base"] is not None and 0.05 < body["base"]["position_m"][2] < 0.2, body


def test_without_physics_open_by_address_says_so_or_has_a_body(dds):
    try:
        go2 = robowire.open("sim:go2", domain=12, physics=True)
    except robowire.Error as e:
        assert "without physics" in str(e) and "mujoco" in str(e), e
        with pytest.raises(robowire.Error, match="without physics"):
            robowire.open("sim:g1", domain=12, physics=True)
        return
    with go2:
        assert go2.wait_state(timeout_s=10.0)
        # The hips splay under the body's weight from the lying pose the kinematic body holds
        # exactly (at 0).
        q = go2.observe()["joints"]["position_rad"]
        assert min(abs(q[0]), abs(q[3])) > 0.01, q


def tilt_rad(device):
    """The base's tilt from upright a second from now, by its IMU."""
    assert device.wait_state(timeout_s=10.0)
    time.sleep(1.0)
    x, y, _, _ = device.observe()["imu"]["orientation_xyzw"]
    return 2.0 * math.asin(min(1.0, math.hypot(x, y)))


def test_the_physics_g1_by_address_hangs_or_stands_on_its_band(dds):
    physics_go2(13).close()  # skips without physics
    with robowire.open("sim:g1", domain=13, physics=True) as g1:
        assert tilt_rad(g1) < 0.1, "hanging by its pelvis"
    # Free: on the floor, held on its band until a LowCmd stream drives its legs (robowire-sim's
    # tests/it/physics.rs lets it go).
    with robowire.open("sim:g1", domain=13, physics=True, free_base=True) as g1:
        assert tilt_rad(g1) < 0.1, "standing on its band"


def test_a_model_needs_physics(dds):
    with pytest.raises(robowire.ArgumentError, match="physics"):
        robowire.sim.Go2(domain=8, model="go2.xml")


def test_the_physics_go2_stands_under_the_stand_gains_and_sinks_when_damped(dds):
    with physics_go2(9) as sim, robowire.go2.LowLevel(domain=9) as robot:
        robot.wait_state(timeout_s=5.0)
        assert sim.snapshot()["body"]["base"]["position_m"][2] < 0.15, "lying"
        robot.release_sport_mode()
        # A lying robot's calves press against their stop and may read a hair past it (the
        # client refuses a target outside the range): start the move at the stop.
        start = [max(q, CALF_MIN_RAD) if m % 3 == 2 else q for m, q in enumerate(robot.joint_positions())]
        began = time.monotonic()
        while (t := time.monotonic() - began) < 3.0:  # 1.5 s up (Unitree's stand), 1.5 s held
            ratio = min(t / 1.5, 1.0)
            robot.set_joints(q=[(1 - ratio) * s + ratio * q for s, q in zip(start, STAND)], kp=60.0, kd=5.0)
            time.sleep(0.002)
        body = sim.snapshot()["body"]
        assert body["base"]["position_m"][2] > 0.25, body
        assert body["sim_time_s"] > 2.0 and body["wall_time_s"] > 0.0
        robot.damp()
        deadline = time.monotonic() + 10.0  # a failure bound: it sinks in well under a second
        while time.monotonic() < deadline and sim.snapshot()["body"]["base"]["position_m"][2] > 0.15:
            time.sleep(0.01)
        assert sim.snapshot()["body"]["base"]["position_m"][2] < 0.15


def test_the_physics_g1_hangs_by_its_pelvis(dds):
    physics_go2(10).close()  # skips without physics
    with robowire.sim.G1(domain=10, physics=True) as sim:
        deadline = time.monotonic() + 10.0
        while time.monotonic() < deadline and sim.snapshot()["body"]["sim_time_s"] < 0.5:
            time.sleep(0.01)
        base = sim.snapshot()["body"]["base"]
        assert base["position_m"][2] > 0.85, base
