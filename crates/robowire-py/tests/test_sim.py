"""robowire.sim: every simulator as a context manager, with its faults."""

import pytest

import robowire
import robowire.sim
import robowire.spline
from helpers import wait_until


def test_dog_addresses_snapshot_and_close(ip):
    dog = robowire.sim.Dog(ip=ip)
    with dog:
        assert dog.ip == ip
        assert dog.high_level_addr == (ip, 43997) and dog.low_level_addr == (ip, 43900)
        snapshot = dog.snapshot()
        assert snapshot["mode"] == 51 and snapshot["activity"] == "lying"
        dog.set_battery_percent(42.0)
        assert dog.snapshot()["battery_percent"] == 42.0
        with pytest.raises(robowire.ArgumentError):
            dog.set_battery_percent(101.0)
        with pytest.raises(robowire.ArgumentError):
            dog.inject_error_word(0)
    with pytest.raises(robowire.ClosedError):
        dog.snapshot()
    with robowire.sim.Dog(ip=ip):  # its ports are free again
        pass


def test_dog_free_ports_and_a_taken_port(ip):
    with robowire.sim.Dog(ip=ip, high_level_port=0, low_level_port=0) as dog:
        assert dog.high_level_addr[1] != 0
        with robowire.sim.Dog(ip=ip) as vendor_ports:
            with pytest.raises(robowire.BindError):
                robowire.sim.Dog(ip=ip)
            assert vendor_ports.high_level_addr == (ip, 43997)
    with pytest.raises(robowire.ArgumentError):
        robowire.sim.Dog("zsl2")


def test_spline_daemon_with_client_pause_and_faults():
    with robowire.sim.Spline() as daemon:
        assert daemon.spline_name.startswith("/robowire-py-")
        # This test is not about stalls: a bound a loaded machine cannot cross by starving the
        # daemon's thread (pause() below still ends in TimeoutError).
        joints = robowire.spline.SplineClient(daemon.spline_name, stall_after_s=1.0)
        pose = [[0.0, 0.72, -1.45, 0.0]] * 4
        joints.write_command(pose, kp=30.0, kd=1.0)
        state = wait_until(lambda: joints.try_read_state())
        assert len(state["p_rad"]) == 4 and len(state["p_rad"][0]) == 4

        def at_the_pose():
            # Refreshed like a client's loop: the daemon clears a command not renewed within 10 cycles.
            joints.write_command(pose, kp=30.0, kd=1.0)
            return abs(joints.wait_state(0.1)["p_rad"][2][1] - 0.72) < 0.02

        wait_until(at_the_pose)
        with pytest.raises(robowire.ArgumentError, match="finite"):
            joints.write_command(float("nan"))
        with pytest.raises(robowire.ArgumentError, match="16"):
            joints.write_command([0.0] * 15)
        daemon.inject_fault(1, 2, 0x04)
        wait_until(lambda: joints.wait_state(0.1)["flags"][1][2] & 0x04)
        daemon.pause()
        with pytest.raises((robowire.NoStateError, robowire.TimeoutError)):
            for _ in range(5):
                joints.wait_state(0.05)
        daemon.pause(False)
        joints.wait_state(0.5)
        imu = robowire.spline.ImuReader(daemon.imu_name).read()
        assert imu["quaternion_wxyz"] == [1.0, 0.0, 0.0, 0.0] and imu["timestamp_ns"] > 0
        assert daemon.stats()["cycles"] > 0
        joints.close()
    with pytest.raises(robowire.NoStateError, match="not running"):
        robowire.spline.SplineClient(daemon.spline_name)


def test_chassis_faults_and_stats():
    with robowire.sim.Chassis(command_watchdog_s=None) as chassis:
        assert chassis.path == chassis.pty_path
        chassis.inject_garbage(10)
        chassis.drop_responses(1)
        assert chassis.stats()["control_frames"] == 0
        assert chassis.state()["battery_volts"] == pytest.approx(25.2, abs=0.01)
    with pytest.raises(robowire.ArgumentError):
        robowire.sim.Chassis(battery_initial_volts=float("nan"))


def test_a_paused_daemon_is_reported_stalled_after_the_clients_bound():
    with robowire.sim.Spline() as daemon:
        with pytest.raises(robowire.ArgumentError, match="stall_after_s"):
            robowire.spline.SplineClient(daemon.spline_name, stall_after_s=-1.0)
        with robowire.spline.SplineClient(daemon.spline_name, stall_after_s=0.02) as joints:
            daemon.pause()
            with pytest.raises(robowire.NoStateError, match="stalled"):
                for _ in range(3):  # a state published before the pause may still be fresh
                    joints.wait_state(1.0)
            assert joints.is_stalled and joints.counters()["stalls"] == 1
