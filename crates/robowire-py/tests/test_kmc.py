"""robowire.kmc against robowire.sim.Chassis on a pseudo-terminal."""

import math
import time

import pytest

import robowire
import robowire.kmc as kmc
import robowire.sim
from helpers import wait_until


@pytest.fixture
def chassis():
    with robowire.sim.Chassis() as chassis:
        yield chassis


def test_driver_streams_the_command_and_reports_speed(chassis):
    with kmc.Driver(chassis.path, poll_battery=True, poll_allstate=True) as driver:
        assert driver.is_running and driver.link_state == "connected"
        seen = set()
        deadline = time.monotonic() + 10.0  # a failure bound
        while time.monotonic() < deadline and not {"speed", "battery", "motor"} <= seen:
            driver.set_command(0.5, 0.2)
            for frame in driver.messages(timeout_s=0.05):
                if isinstance(frame, kmc.VehicleSpeed):
                    seen.add("speed")
                    assert isinstance(frame.speed_mps, float)
                elif isinstance(frame, kmc.BatteryVoltage):
                    seen.add("battery")
                    assert 20.0 < frame.volts < 26.0 and frame.motor_id == 0
                elif isinstance(frame, kmc.MotorState):
                    seen.add("motor")
                    assert frame.motor_id in (0, 1) and len(frame.reserved) == 3
        assert seen == {"speed", "battery", "motor"}
        state = chassis.state()
        assert state["commanded_velocity_mps"] == 0.5
        assert math.isclose(state["commanded_curvature_per_m"], 0.4, rel_tol=1e-6)  # 0.2 / 0.5
        stats = driver.stats()
        assert stats["control_frames_sent"] > 0 and stats["frames_received"] > 0


def test_with_block_sends_the_stop_burst_even_on_an_exception(chassis):
    with pytest.raises(RuntimeError, match="in the block"):
        with kmc.Driver(chassis.path) as driver:
            driver.set_command(0.25, 0.0)
            wait_until(lambda: chassis.state()["commanded_velocity_mps"] == 0.25)
            raise RuntimeError("in the block")
    assert not driver.is_running
    # The burst is on the line when stop() returns; the simulator reads it on its own thread.
    stop = {"frame": "pc_control", "velocity_mps": 0.0, "curvature_per_m": 0.0}
    wait_until(lambda: chassis.received()[-3:] == [stop] * 3)
    assert chassis.state()["commanded_velocity_mps"] == 0.0


def test_a_stale_command_stops_the_chassis(chassis):
    with kmc.Driver(chassis.path, command_timeout_ms=100) as driver:
        driver.set_command(0.5, 0.0)
        wait_until(lambda: chassis.state()["commanded_velocity_mps"] == 0.5)
        wait_until(lambda: chassis.state()["commanded_velocity_mps"] == 0.0, timeout_s=1.0)
        assert driver.stats()["command_timeouts"] >= 1


@pytest.mark.parametrize("bad", [math.nan, math.inf])
def test_non_finite_commands_raise_and_keep_the_previous_command(chassis, bad):
    with kmc.Driver(chassis.path) as driver:
        driver.set_command(0.375, 0.0)
        with pytest.raises(robowire.ArgumentError, match="finite"):
            driver.set_command(bad, 0.0)
        with pytest.raises(robowire.ArgumentError):
            driver.set_command_curvature(0.375, bad)
        wait_until(lambda: chassis.state()["commanded_velocity_mps"] == 0.375)


def test_bad_options_and_ports():
    with pytest.raises(robowire.ArgumentError, match="control_rate_hz"):
        kmc.Driver("/dev/null", control_rate_hz=0.0)
    with pytest.raises(robowire.ArgumentError, match="realtime_priority"):
        kmc.Driver("/dev/null", realtime_priority=150)
    with pytest.raises(robowire.PortError) as raised:
        kmc.Driver("/dev/robowire-no-such-port").start()
    assert isinstance(raised.value, OSError)
    with pytest.raises(robowire.PortError):
        kmc.UartClient("/dev/robowire-no-such-port")


def test_a_closed_driver_raises_closed(chassis):
    driver = kmc.Driver(chassis.path)
    driver.start()
    driver.close()
    with pytest.raises(robowire.ClosedError):
        driver.set_command(0.1, 0.0)
    driver.close()  # idempotent


def test_messages_ends_at_its_timeout_and_when_stopped(chassis):
    with kmc.Driver(chassis.path) as driver:
        started = time.monotonic()
        frames = list(driver.messages(timeout_s=0.3))
        assert time.monotonic() - started > 0.25  # not before its timeout
        assert frames  # 50 Hz speed answers
    leftover = list(driver.messages())  # stopped: what is still queued, then the end (no wait)
    assert all(isinstance(f, (kmc.VehicleSpeed, kmc.BatteryVoltage, kmc.MotorState, kmc.AfResponse)) for f in leftover)


def test_the_driver_reopens_after_a_hang_up():
    with robowire.sim.Chassis(link=f"/tmp/robowire-py-{id(object())}") as chassis:
        with kmc.Driver(chassis.path) as driver:
            chassis.hang_up()
            wait_until(lambda: driver.link_state == "disconnected", timeout_s=3)
            chassis.replug()
            wait_until(lambda: driver.link_state == "connected", timeout_s=5)
            assert driver.stats()["disconnects"] >= 1


def test_uart_client_one_frame_at_a_time(chassis):
    with kmc.UartClient(chassis.path) as client:
        client.send_pc_control(0.25, 0.0)
        client.request_vehicle_speed()
        frame = client.poll(timeout_s=2.0)
        assert isinstance(frame, kmc.VehicleSpeed)
        client.request_battery_voltage(0)
        frame = client.poll(timeout_s=2.0)
        assert isinstance(frame, kmc.BatteryVoltage)
        assert client.poll(timeout_s=0.05) is None
        with pytest.raises(robowire.ArgumentError):
            client.send_pc_control(math.nan, 0.0)
    with pytest.raises(robowire.ClosedError):
        client.request_vehicle_speed()
    assert {"frame": "pc_control", "velocity_mps": 0.25, "curvature_per_m": 0.0} in chassis.received()


def test_the_chassis_state_speed_battery_motors_and_odometry(chassis):
    with kmc.Driver(chassis.path, poll_battery=True, poll_allstate=True) as driver:
        assert isinstance(driver.wait_state(timeout_s=3.0), kmc.ChassisState)
        assert driver.connection == "connected" and driver.state_age_s >= 0.0

        def moved():
            driver.set_command(0.5, 0.0)
            return driver.state().odometry.x_m > 0.01

        wait_until(moved)
        state = wait_until(lambda: (lambda s: s if s.battery and all(s.motors) else None)(driver.state()))
        assert 20.0 < state.battery.volts < 26.0
        assert [m.motor_id for m in state.motors] == [0, 1]
        assert isinstance(state.speed_mps, float) and isinstance(state.odometry, kmc.Odometry)
    assert driver.connection == "stopped"
    with pytest.raises(robowire.ClosedError, match="start"):
        driver.state()


def test_stop_closes_the_port_and_start_opens_it_again(chassis):
    driver = kmc.Driver(chassis.path)
    with pytest.raises(robowire.ClosedError, match="start"):
        driver.set_command(0.1, 0.0)
    driver.start()
    driver.start()  # already streaming: nothing
    driver.set_command(0.25, 0.0)
    wait_until(lambda: chassis.state()["commanded_velocity_mps"] == 0.25)
    driver.stop()
    assert not driver.is_running and driver.link_state == "stopped"
    wait_until(lambda: chassis.state()["commanded_velocity_mps"] == 0.0)  # the stop burst
    driver.start()
    driver.set_command(0.125, 0.0)
    wait_until(lambda: chassis.state()["commanded_velocity_mps"] == 0.125)
    driver.close()
    with pytest.raises(robowire.ClosedError):
        driver.start()


def test_set_command_timeout_now_and_for_the_next_start(chassis):
    driver = kmc.Driver(chassis.path)
    driver.set_command_timeout(0.05)
    with driver:
        driver.set_command(0.5, 0.0)
        wait_until(lambda: driver.stats()["command_timeouts"] >= 1)
        driver.set_command_timeout(0.08)
        driver.set_command(0.5, 0.0)
        wait_until(lambda: driver.stats()["command_timeouts"] >= 2)
        for bad in (0.0, 7200.0, math.nan):
            with pytest.raises(robowire.ArgumentError):
                driver.set_command_timeout(bad)
