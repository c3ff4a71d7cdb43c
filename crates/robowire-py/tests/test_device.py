"""robowire.open(address): every device in one shape, against the simulators of ``sim:`` addresses."""

import math
import subprocess
import sys
from pathlib import Path

import pytest

import robowire
from helpers import wait_until


def test_a_simulated_zsl1_stands_up_and_walks():
    with robowire.open("sim:zsl1") as dog:
        assert isinstance(dog, robowire.Device)
        assert (dog.address, dog.kind) == ("sim:zsl1", "zsl1")
        assert dog.wait_state(timeout_s=5.0)
        assert dog.connection == "connected"
        assert dog.services == ["stand_up", "lie_down", "passive"] and dog.can_drive
        assert "stand_up sent" in dog.call("stand_up")
        wait_until(lambda: dog.status()["mode"] == 1, timeout_s=5.0)
        assert "mode" in dog.status_text()
        dog.drive(0.5, 0.0, 0.0)
        wait_until(lambda: dog.observe()["odometry"]["linear_mps"][0] > 0.1, timeout_s=5.0)
        seen = dog.observe()
        assert seen["joints"]["names"][:3] == ["FR_abad", "FR_hip", "FR_knee"]
        assert len(seen["joints"]["position_rad"]) == len(seen["joints"]["names"]) == 12
        assert len(seen["imu"]["orientation_xyzw"]) == 4
        assert 0.0 <= seen["battery"]["charge_fraction"] <= 1.0
        dog.drive(0.0, 0.0, 0.0)


def test_a_refused_drive_raises_and_sends_nothing():
    with robowire.open("sim:zsl1") as dog:
        assert dog.wait_state(timeout_s=5.0)
        dog.call("stand_up")
        wait_until(lambda: dog.status()["mode"] == 1, timeout_s=5.0)
        with pytest.raises(robowire.ArgumentError):
            dog.drive(math.nan, 0.0, 0.0)
        with pytest.raises(robowire.ArgumentError):
            dog.drive(9.0, 0.0, 0.0)  # beyond the ZSL-1's 3 m/s
        assert dog.status()["mode"] == 1  # still standing: nothing was sent
        with pytest.raises(robowire.ArgumentError, match="fly"):
            dog.call("fly")


def test_a_lying_dog_refuses_to_walk():
    with robowire.open("sim:zsl1") as dog:
        assert dog.wait_state(timeout_s=5.0)
        with pytest.raises(robowire.Error, match="stand first"):
            dog.drive(0.5, 0.0, 0.0)


def part(device, name):
    """One part of the latest observation (a chassis's observation holds what its latest frame
    carried: mostly its speed and odometry, at times a battery or motor report)."""
    seen = device.observe()
    return seen[name] if seen else None


def test_a_simulated_chassis_drives_and_reports_odometry():
    with robowire.open("sim:kmc") as chassis:
        assert chassis.kind == "kmc" and chassis.can_drive and chassis.services == []
        assert chassis.wait_state(timeout_s=5.0)
        chassis.drive(0.5, 0.0, 0.0)
        wait_until(lambda: (chassis.status()["speed_mps"] or 0.0) > 0.1, timeout_s=5.0)

        def moved():
            odometry = part(chassis, "odometry")
            return odometry is not None and odometry["position_m"][0] > 0.01

        wait_until(moved, timeout_s=5.0)
        volts = wait_until(lambda: chassis.status()["battery_v"], timeout_s=5.0)  # polled at 1 Hz
        assert 20.0 < volts < 26.0
        assert chassis.status()["odometry"]["x_m"] > 0.0
        assert "speed" in chassis.status_text()
        with pytest.raises(robowire.ArgumentError, match="finite"):
            chassis.drive(math.inf, 0.0, 0.0)
        with pytest.raises(robowire.ArgumentError):
            chassis.call("stand_up")


def test_close_is_idempotent_and_a_closed_device_raises_closed():
    device = robowire.open("sim:kmc")
    assert device.wait_state(timeout_s=5.0)
    device.close()
    device.close()
    assert device.connection == "closed"
    for use in (device.status, device.observe, lambda: device.drive(0.1, 0.0, 0.0), lambda: device.call("x")):
        with pytest.raises(robowire.ClosedError):
            use()


@pytest.mark.parametrize("address", ["", "zsl1", "zsl1:not-an-ip", "sim:tank", "tank:/dev/ttyUSB0", "go2:"])
def test_a_bad_address_is_an_argument_error(address):
    with pytest.raises(robowire.ArgumentError, match="address") as raised:
        robowire.open(address)
    assert isinstance(raised.value, ValueError)


@pytest.mark.parametrize("address", ["sim:kmc", "sim:zsl1", "go2:lo", "kmc:/dev/robowire-no-such-port"])
def test_physics_of_a_device_without_a_simulated_body_is_an_argument_error(address):
    with pytest.raises(robowire.ArgumentError, match="MuJoCo simulates the bodies of sim:go2 and sim:g1 only"):
        robowire.open(address, physics=True)


def test_a_model_or_a_free_base_needs_physics():
    for extra in ({"model": "scene.xml"}, {"free_base": True}):
        with pytest.raises(robowire.ArgumentError, match="physics=True"):
            robowire.open("sim:go2", **extra)


def test_a_missing_serial_port_is_a_port_error():
    with pytest.raises(robowire.PortError) as raised:
        robowire.open("kmc:/dev/robowire-no-such-port")
    assert isinstance(raised.value, OSError)


def test_a_simulated_go2_over_dds(dds):
    with robowire.open("sim:go2", domain=11) as go2:
        assert go2.kind == "go2" and not go2.can_drive
        assert go2.wait_state(timeout_s=10.0)
        seen = go2.observe()
        assert len(seen["joints"]["names"]) == 12
        assert seen["passthrough"]["type_name"] == "unitree_go::msg::dds_::LowState_"
        assert isinstance(seen["passthrough"]["body"], bytes)
        assert "tick" in go2.status()
        with pytest.raises(robowire.Error, match="does not support"):
            go2.drive(0.5, 0.0, 0.0)


def test_the_readme_example_runs():
    readme = (Path(__file__).parents[1] / "README.md").read_text()
    block = readme.split("## Any device by its address", 1)[1].split("```python\n", 1)[1].split("```", 1)[0]
    result = subprocess.run([sys.executable, "-c", block], capture_output=True, text=True, timeout=60)
    assert result.returncode == 0, result.stderr
    assert "stand_up sent" in result.stdout and "FR_abad" in result.stdout
