"""record= on every client and simulator, and robowire.Recorder: captures read back by the robowire
CLI (``robowire decode --json --mcap``) and by the ``mcap`` Python package (an independent
reader, in the CPython 3.10 interop environment; skipped with a line where it is not installed,
unless ``ROBOWIRE_REQUIRE`` names ``mcap``)."""

import json
import pathlib
import subprocess
import time

import pytest

import robowire
import robowire.go2
import robowire.kmc
import robowire.sim
import robowire.spline
import robowire.zsl1
from conftest import cli, missing
from helpers import wait_until

# A loopback address of this module's own (conftest's `ip` hands out 127.0.0.x).
ZSL1_IP = "127.0.9.7"

SENT, RECEIVED = {"sent"}, {"received"}
BOTH = SENT | RECEIVED


def summary(path):
    """The capture's channels as the CLI reads them: {topic: channel}."""
    out = subprocess.run([cli(), "decode", "--json", "--mcap", str(path)], capture_output=True, text=True, timeout=60)
    assert out.returncode == 0, out.stderr
    return {c["topic"]: c for c in json.loads(out.stdout)["channels"]}


def mcap_channels(path):
    """The capture as the ``mcap`` package reads it: {topic: {"encoding", "metadata", "count",
    "json_ok", "schema_encoding", "schema_parses"}}."""
    try:
        from mcap.reader import make_reader
    except ImportError:
        missing("mcap", "the mcap Python package is not installed here (pip install mcap)")
    channels = {}
    with open(path, "rb") as f:
        for schema, channel, message in make_reader(f).iter_messages():
            c = channels.setdefault(
                channel.topic,
                {
                    "encoding": channel.message_encoding,
                    "metadata": dict(channel.metadata),
                    "schema_encoding": schema.encoding if schema else None,
                    "schema_parses": bool(schema and schema.encoding == "jsonschema" and json.loads(schema.data)),
                    "count": 0,
                    "json_ok": 0,
                },
            )
            c["count"] += 1
            if channel.message_encoding == "json":
                json.loads(message.data)
                c["json_ok"] += 1
    return channels


def frames_of(channels, link, direction):
    """`link`'s channels one way: {topic: channel}."""
    prefix = f"/{link}/{direction}"
    return {t: c for t, c in channels.items() if t == prefix or t.startswith(prefix + "/")}


@pytest.fixture(scope="module")
def captures(tmp_path_factory):
    """A KMC chassis, a ZSL-1 (HighLevel and LowLevel) and the spline daemon, each simulator
    recording its side into a file of its own (a str, a pathlib.Path), their clients all into one
    shared zstd Recorder; and `robowire.open("sim:zsl1", record=PATH)`. {name: (path, {link:
    directions})}, and the shared recorder's summary."""
    tmp = tmp_path_factory.mktemp("record")
    rec = robowire.Recorder(tmp / "clients.mcap", compression="zstd")
    assert rec.path == str(tmp / "clients.mcap") and not rec.closed

    with robowire.sim.Chassis(record=str(tmp / "chassis.mcap")) as chassis:
        driver = robowire.kmc.Driver(chassis.path, record=rec, poll_battery=True)
        with driver:
            chassis.inject_garbage(24)  # before its next answer: bytes the client's decoder skips

            def skipped():
                driver.set_command(0.3, 0.1)
                return driver.stats()["bytes_skipped"] > 0 and chassis.stats()["control_frames"] > 10

            wait_until(skipped)
        driver.close()

    with robowire.sim.Zsl1(ip=ZSL1_IP, record=tmp / "zsl1.mcap"):
        high, low = robowire.zsl1.HighLevel(record=rec), robowire.zsl1.LowLevel(record=rec)
        with high, low:
            high.initRobot(ZSL1_IP, 0, ZSL1_IP)
            low.initRobot(ZSL1_IP, 0, ZSL1_IP)
            assert high.wait_connected(5.0) and low.wait_connected(5.0)
            high.standUp()

    with robowire.sim.Spline(record=tmp / "spline.mcap") as daemon:
        joints = robowire.spline.SplineClient(daemon.spline_name, stall_after_s=1.0, record=rec)
        imu = robowire.spline.ImuReader(daemon.imu_name, record=rec)
        with joints, imu:
            for _ in range(5):
                joints.write_command([0.0, 0.72, -1.45, 0.0] * 4, kp=30.0, kd=1.0)
                joints.wait_state(1.0)
            wait_until(lambda: imu.read()["timestamp_ns"] > 0)

    with robowire.open("sim:zsl1", record=tmp / "open.mcap") as device:
        assert device.wait_state(timeout_s=5.0)

    shared = rec.close()
    assert rec.closed and rec.close() == shared  # a second close: the same summary
    return {
        "chassis": (tmp / "chassis.mcap", {"kmc/serial": BOTH}),
        "zsl1": (tmp / "zsl1.mcap", {"zsl1/high_level": BOTH, "zsl1/low_level": BOTH}),
        "spline": (tmp / "spline.mcap", {"spline/spline": BOTH, "spline/imu": SENT}),
        "open": (tmp / "open.mcap", {"zsl1/high_level": BOTH}),
        "clients": (
            tmp / "clients.mcap",
            {
                "kmc/serial": BOTH,
                "kmc/serial_skipped": RECEIVED,
                "zsl1/high_level": BOTH,
                "zsl1/low_level": BOTH,
                "spline/spline": BOTH,
                "spline/imu": RECEIVED,
            },
        ),
    }, shared


NAMES = ["chassis", "zsl1", "spline", "open", "clients"]


def test_the_shared_recorder_says_what_it_wrote(captures):
    _, shared = captures
    assert set(shared) == {"frames", "dropped", "oversize", "decode_errors", "json_skipped"}
    assert shared["dropped"] == 0 and shared["oversize"] == 0 and shared["decode_errors"] == 0
    channels = summary(captures[0]["clients"][0]).values()
    assert shared["frames"] == sum(c["count"] for c in channels if c["encoding"] != "json") > 0


@pytest.mark.parametrize("name", NAMES)
def test_every_link_is_recorded_each_way_it_carries_frames(captures, name):
    path, links = captures[0][name]
    channels = summary(path)
    recorded = {t.split("/")[1] + "/" + t.split("/")[2] for t in channels}
    assert recorded == set(links), channels.keys()
    for link, directions in links.items():
        for direction in ("sent", "received"):
            found = frames_of(channels, link, direction)
            if direction not in directions:
                assert not found, (link, direction)
                continue
            raw = found.pop(f"/{link}/{direction}/raw")
            assert raw["encoding"] == "robowire.raw" and raw["count"] > 0, (link, direction, raw)
            # Beside the raw frames, their messages as JSON (a channel per message type).
            assert found and all(c["encoding"] == "json" and c["count"] > 0 for c in found.values()), found
            assert raw["decode_errors"] == 0


@pytest.mark.parametrize("name", NAMES)
def test_the_mcap_package_reads_every_capture(captures, name):
    path, links = captures[0][name]
    channels = mcap_channels(path)
    assert channels
    for topic, c in channels.items():
        link, direction = c["metadata"]["link"], topic.split("/")[3]
        assert direction in links[link], topic
        if c["encoding"] == "json":
            assert c["schema_encoding"] == "jsonschema" and c["schema_parses"], topic
            assert c["json_ok"] == c["count"] > 0, topic
        else:
            assert c["metadata"]["direction"] == direction and c["count"] > 0, topic


def test_a_simulated_go2_and_its_client_record_both_ends(dds, tmp_path):
    sim_path, client_path = tmp_path / "go2-sim.mcap", tmp_path / "go2-client.mcap"
    with robowire.Recorder(client_path) as rec:
        with robowire.sim.Go2(domain=11, record=sim_path), robowire.go2.LowLevel(domain=11, record=rec) as robot:
            robot.wait_state(timeout_s=5.0)
            assert robot.release_sport_mode() == 1
            for _ in range(50):
                robot.set_joints(q=list(robowire.go2.STAND_POSE_RAD) * 4, kp=60.0, kd=5.0)
                time.sleep(0.002)
    for path in (sim_path, client_path):
        channels = summary(path)
        for link in ("go2/low_level", "go2/api"):
            for direction in ("sent", "received"):
                wire = channels[f"/{link}/{direction}"]  # DDS payloads in their own encoding
                assert wire["encoding"] == "cdr" and wire["count"] > 0, (path, link, direction)


def test_bad_arguments_raise_and_create_nothing(tmp_path):
    with pytest.raises(robowire.ArgumentError, match="compression"):
        robowire.Recorder(tmp_path / "x.mcap", compression="gzip")
    assert not (tmp_path / "x.mcap").exists()
    with pytest.raises(robowire.Error, match="cannot create"):
        robowire.Recorder(tmp_path / "no-such-dir" / "x.mcap")
    with pytest.raises(robowire.Error, match="cannot create"):
        robowire.sim.Chassis(record=tmp_path / "no-such-dir" / "x.mcap")
    for bad in (42, object()):
        with pytest.raises(robowire.ArgumentError, match="record"):
            robowire.sim.Chassis(record=bad)
    with pytest.raises(TypeError):
        robowire.Recorder(42)


def test_a_closed_recorder_refuses_new_devices_and_running_ones_go_on(tmp_path):
    rec = robowire.Recorder(tmp_path / "x.mcap", json=False)
    with robowire.sim.Chassis(record=rec) as chassis, robowire.kmc.Driver(chassis.path, record=rec) as driver:
        driver.set_command(0.2, 0.0)
        wait_until(lambda: chassis.stats()["control_frames"] > 5)
        closed = rec.close()
        assert closed["frames"] > 0
        # The simulator and the driver keep working; their frames are dropped, nothing crashes.
        driver.set_command(0.4, 0.0)
        wait_until(lambda: chassis.state()["commanded_velocity_mps"] == pytest.approx(0.4))
        with pytest.raises(robowire.ClosedError):
            robowire.kmc.Driver(chassis.path, record=rec)
        with pytest.raises(robowire.ClosedError):
            robowire.open("sim:kmc", record=rec)
    assert rec.close() == closed
    channels = summary(tmp_path / "x.mcap")
    assert channels and all(t.endswith("/raw") for t in channels)  # json=False: raw frames only


def test_a_path_capture_is_finished_by_close_and_records_no_second_session(tmp_path):
    path = pathlib.Path(tmp_path / "high.mcap")
    with robowire.sim.Zsl1(ip=ZSL1_IP):
        high = robowire.zsl1.HighLevel(record=path)
        high.initRobot(ZSL1_IP, 0, ZSL1_IP)
        assert high.wait_connected(5.0)
        high.close()
        assert frames_of(summary(path), "zsl1/high_level", "received")  # finished: readable now
        with pytest.raises(robowire.ClosedError, match="capture"):
            high.initRobot(ZSL1_IP, 0, ZSL1_IP)
