"""robowire.sim: every simulator as a context manager, with its faults."""

import pytest

import robowire
import robowire.sim
import robowire.spline
from helpers import wait_until


def test_zsl1_addresses_snapshot_and_close(ip):
    sim = robowire.sim.Zsl1(ip=ip)
    with sim:
        assert sim.ip == ip
        assert sim.high_level_addr == (ip, 43997) and sim.low_level_addr == (ip, 43900)
        snapshot = sim.snapshot()
        assert snapshot["mode"] == 51 and snapshot["activity"] == "lying"
        sim.set_battery_percent(42.0)
        assert sim.snapshot()["battery_percent"] == 42.0
        with pytest.raises(robowire.ArgumentError):
            sim.set_battery_percent(101.0)
        with pytest.raises(robowire.ArgumentError):
            sim.inject_error_word(0)
    with pytest.raises(robowire.ClosedError, match="ZSL-1 simulator is closed"):
        sim.snapshot()
    with robowire.sim.Zsl1(ip=ip):  # its ports are free again
        pass


def test_zsl1_free_ports_and_a_taken_port(ip):
    with robowire.sim.Zsl1(ip=ip, high_level_port=0, low_level_port=0) as sim:
        assert sim.high_level_addr[1] != 0
        with robowire.sim.Zsl1(ip=ip) as vendor_ports:
            with pytest.raises(robowire.BindError):
                robowire.sim.Zsl1(ip=ip)
            assert vendor_ports.high_level_addr == (ip, 43997)
    with pytest.raises(robowire.ArgumentError):
        robowire.sim.Zsl1("zsl2")


def test_dog_is_the_old_name_of_zsl1_kept_one_release(ip):
    with pytest.warns(DeprecationWarning, match="robowire.sim.Dog is now robowire.sim.Zsl1"):
        dog = robowire.sim.Dog
    assert dog is robowire.sim.Zsl1
    with pytest.warns(DeprecationWarning):
        from robowire.sim import Dog
    assert Dog is robowire.sim.Zsl1 and "Dog" not in robowire.sim.__all__
    with Dog("zsl1w", ip=ip) as sim:
        assert isinstance(sim, robowire.sim.Zsl1) and repr(sim).startswith("Zsl1(")
        assert sim.snapshot()["model"] == "zsl1w"
    with pytest.raises(AttributeError):
        robowire.sim.Cat


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
