"""robowire.zsl1w as a drop-in for mc_sdk_zsl_1w_py, against a ZSL-1W simulator."""

import pytest

import robowire.sim
import robowire.zsl1w as mc_sdk_zsl_1w_py
from helpers import wait_until

ZSL1W_ONLY = ["crawl", "climb", "cancelCrawl", "cancelClimb", "getLegFootJoint", "getLegFootJointVel", "getLegFootJointTorque"]
ZSL1_ONLY = ["jump", "frontJump", "backflip", "twoLegStand", "cancelTwoLegStand"]


def test_the_vendors_zsl1w_method_set():
    for name in ZSL1W_ONLY + ["move", "shakeHand", "attitudeControl", "standUp", "getLegKneeJoint"]:
        assert callable(getattr(mc_sdk_zsl_1w_py.HighLevel, name)), name
    for name in ZSL1_ONLY:
        assert not hasattr(mc_sdk_zsl_1w_py.HighLevel, name), name


@pytest.fixture
def wheel_dog(ip):
    with robowire.sim.Zsl1("zsl1w", ip=ip) as dog:
        yield dog


def test_crawl_climb_and_the_wheel_joints(wheel_dog, ip):
    with mc_sdk_zsl_1w_py.HighLevel() as robot:
        robot.initRobot(ip, 43988, ip)
        assert robot.wait_connected(3.0)
        assert robot.standUp() == 0
        wait_until(lambda: robot.getCurrentCtrlmode() == 1)
        assert robot.crawl(0.3, 0.0, 0.0) == 0
        wait_until(lambda: robot.getCurrentCtrlmode() == 18)
        assert robot.cancelCrawl() is None
        assert robot.climb(0.3, 0.0, 0.0) == 0
        assert robot.cancelClimb() is None
        assert robot.move(3.5, 0, 0) == 0  # the ZSL-1W's vx band reaches 3.7
        assert robot.move(0, 0, 0.05) == 0x3013  # and its yaw-rate band starts at 0.1
        for getter in (robot.getLegFootJoint, robot.getLegFootJointVel, robot.getLegFootJointTorque):
            assert len(getter()) == 4
        snapshot = wheel_dog.snapshot()
        assert snapshot["model"] == "zsl1w"
        assert snapshot["faults"]["sdk_mismatch"] is False  # the commands carry the 0x5AA6 magic
        assert snapshot["high_level"]["invalid"] == 0
