"""A ROS 2 peer on CycloneDDS (no ROS install): drives the bridge (robowire-ros2, the library
behind `robowire ros2`) the way a ROS 2 node on rmw_cyclonedds would, and prints what it saw as
one JSON line.

    python ros2_peer.py SCENARIO NAMESPACE

Scenarios:
- drive: publishes geometry_msgs/Twist on rt/NS/cmd_vel at 20 Hz for 2 s, then nothing; reads
  rt/NS/odom throughout (speeds while driving, after the deadman, the last pose).
- sense: reads one sample of each of rt/NS/joint_states, rt/NS/imu, rt/NS/battery_state,
  rt/NS/tf, rt/NS/odom, field for field.
- stand_up: calls the std_srvs/Trigger service NS/stand_up (rq/…Request, rr/…Reply).
- stand_and_drive: stand_up, then drive once rt/NS/odom shows the standing height (a dog must
  stand before it walks).
- sense_chassis: rt/NS/battery_state and rt/NS/diagnostics of a KMC chassis.
- sense_go2: rt/NS/joint_states and rt/NS/imu of a Go2, and rt/NS/lowstate with Unitree's class.
- sense_g1: rt/NS/joint_states and rt/NS/battery_state of a G1, and rt/NS/lowstate with Unitree's
  HG class.
- graph_jazzy, graph_humble (NAMESPACE unused): reads ros_discovery_info as rmw does (reliable,
  transient local, keep all; 16- or 24-byte GIDs) and DDS discovery's DCPSPublication and
  DCPSSubscription, until the other participant's sample lists every endpoint discovery shows of
  it; prints its nodes with each GID and the endpoint whose discovery key it equals.
"""

import json
import sys
import time
from dataclasses import asdict

from cyclonedds.builtin import BuiltinDataReader, BuiltinTopicDcpsPublication, BuiltinTopicDcpsSubscription
from cyclonedds.core import Policy, Qos
from cyclonedds.domain import DomainParticipant
from cyclonedds.pub import DataWriter
from cyclonedds.sub import DataReader
from cyclonedds.topic import Topic
from cyclonedds.util import duration

from ros2_types import BatteryState, DiagnosticArray, Imu, JointState, Odometry, TFMessage, TriggerRequest, TriggerResponse, Twist, Vector3, graph_types

RELIABLE = Qos(Policy.Reliability.Reliable(duration(milliseconds=100)), Policy.History.KeepLast(10))
SENSOR = Qos(Policy.Reliability.BestEffort, Policy.History.KeepLast(5))


def topic(ns, name):
    return f"rt{ns}/{name}"


def take_one(reader, timeout_s=10.0):
    sample = poll_one(reader, timeout_s)
    if sample is None:
        raise SystemExit(f"nothing on {reader.topic.name} within {timeout_s} s")
    return sample


def poll_one(reader, timeout_s):
    """The next sample, or None after timeout_s."""
    deadline = time.monotonic() + timeout_s
    while time.monotonic() < deadline:
        for sample in reader.take(N=1):
            return sample
        time.sleep(0.005)
    return None


def latest(reader):
    samples = reader.take(N=100)
    return samples[-1] if samples else None


# The simulated dog's body height once it stood up (0.30 m; 0.10 m lying), m.
STANDING_Z_M = 0.29


def stand_and_drive(dp, ns):
    stood = stand_up(dp, ns)
    odom = DataReader(dp, Topic(dp, topic(ns, "odom"), Odometry), qos=RELIABLE)
    deadline = time.monotonic() + 10.0
    while take_one(odom).pose.pose.position.z < STANDING_Z_M:
        if time.monotonic() > deadline:
            raise SystemExit("the dog did not stand up within 10 s")
    return {"stand_up": stood, **drive(dp, ns)}


def drive(dp, ns):
    writer = DataWriter(dp, Topic(dp, topic(ns, "cmd_vel"), Twist), qos=RELIABLE)
    odom = DataReader(dp, Topic(dp, topic(ns, "odom"), Odometry), qos=RELIABLE)
    first = take_one(odom)
    start_x = first.pose.pose.position.x
    twist = Twist(linear=Vector3(x=0.5), angular=Vector3(z=0.0))
    speeds = []
    last = first
    end = time.monotonic() + 2.0
    while time.monotonic() < end:
        writer.write(twist)
        time.sleep(0.05)
        sample = latest(odom)
        if sample:
            speeds.append(sample.twist.twist.linear.x)
            last = sample
    stopped_at = time.monotonic()
    after = []
    while time.monotonic() < stopped_at + 2.0:
        time.sleep(0.05)
        sample = latest(odom)
        if sample:
            after.append((time.monotonic() - stopped_at, sample.twist.twist.linear.x))
            last = sample
    return {
        "max_speed": max(speeds, default=0.0),
        "speed_after_2s": after[-1][1] if after else None,
        "still_after_s": next((t for t, v in after if abs(v) < 0.02), None),
        "moved_m": last.pose.pose.position.x - start_x,
        "frame_id": first.header.frame_id,
        "child_frame_id": first.child_frame_id,
    }


def sense_chassis(dp, ns):
    """The chassis's battery_state and per-motor diagnostics."""
    battery = take_one(DataReader(dp, Topic(dp, topic(ns, "battery_state"), BatteryState), qos=SENSOR))
    diagnostics = take_one(DataReader(dp, Topic(dp, topic(ns, "diagnostics"), DiagnosticArray), qos=RELIABLE))
    return {"battery": asdict(battery), "diagnostics": asdict(diagnostics)}


def sense(dp, ns):
    readers = {
        "joint_states": DataReader(dp, Topic(dp, topic(ns, "joint_states"), JointState), qos=SENSOR),
        "imu": DataReader(dp, Topic(dp, topic(ns, "imu"), Imu), qos=SENSOR),
        "battery_state": DataReader(dp, Topic(dp, topic(ns, "battery_state"), BatteryState), qos=SENSOR),
        "tf": DataReader(dp, Topic(dp, topic(ns, "tf"), TFMessage), qos=RELIABLE),
        "odom": DataReader(dp, Topic(dp, topic(ns, "odom"), Odometry), qos=RELIABLE),
    }
    out = {}
    for name, reader in readers.items():
        out[name] = asdict(take_one(reader))
    return out


def sensed(dp, ns, name, message_type):
    """One sample of rt/NS/NAME, read with the sensor-data QoS."""
    return take_one(DataReader(dp, Topic(dp, topic(ns, name), message_type), qos=SENSOR))


def sense_go2(dp, ns):
    """joint_states and imu from the Go2's LowState, and the LowState itself passed through as
    unitree_go/msg/LowState (read with Unitree's own IDL class, its CRC checked by Unitree's code)."""
    from unitree_sdk2py.idl.unitree_go.msg.dds_ import LowState_
    from unitree_sdk2py.utils.crc import CRC

    joints, imu, low = (sensed(dp, ns, name, t) for name, t in [("joint_states", JointState), ("imu", Imu), ("lowstate", LowState_)])
    return {
        "names": joints.name,
        "position": joints.position,
        "lowstate_q": [m.q for m in low.motor_state[:12]],
        "crc_ok": CRC().Crc(low) == low.crc,
        "imu_w": imu.orientation.w,
        "lowstate_quaternion_w": low.imu_state.quaternion[0],
    }


def sense_g1(dp, ns):
    """joint_states and battery_state from the G1's LowState and BmsState, and the LowState itself
    passed through as unitree_hg/msg/LowState (read with Unitree's own HG IDL class, its CRC
    checked by Unitree's code)."""
    from unitree_sdk2py.idl.unitree_hg.msg.dds_ import LowState_
    from unitree_sdk2py.utils.crc import CRC

    joints, battery, low = (
        sensed(dp, ns, name, t) for name, t in [("joint_states", JointState), ("battery_state", BatteryState), ("lowstate", LowState_)]
    )
    return {
        "names": joints.name,
        "position": joints.position,
        "lowstate_q": [m.q for m in low.motor_state[:29]],
        "mode_machine": low.mode_machine,
        "crc_ok": CRC().Crc(low) == low.crc,
        "battery": asdict(battery),
    }


def stand_up(dp, ns):
    requests = DataWriter(dp, Topic(dp, f"rq{ns}/stand_upRequest", TriggerRequest), qos=RELIABLE)
    replies = DataReader(dp, Topic(dp, f"rr{ns}/stand_upReply", TriggerResponse), qos=RELIABLE)
    # A request written before both sides discovered each other is lost (volatile durability):
    # the same request (same id) again until answered, as a client waiting for its service would.
    # The bridge acts on an id once: however many were sent, the dog stands up once.
    guid = 0x1234_5678_9ABC_DEF0
    deadline = time.monotonic() + 10.0
    reply = None
    while reply is None:
        if time.monotonic() > deadline:
            raise SystemExit("no reply from stand_up within 10 s")
        requests.write(TriggerRequest(guid=guid, seq=1))
        reply = poll_one(replies, timeout_s=0.2)
    return {"guid_matches": reply.guid == guid, "seq": reply.seq, "success": reply.success, "message": reply.message}


def graph(dp, gid_len):
    Gid, NodeEntitiesInfo, ParticipantEntitiesInfo = graph_types(gid_len)
    qos = Qos(
        Policy.Reliability.Reliable(duration(milliseconds=100)),
        Policy.Durability.TransientLocal,
        Policy.History.KeepAll,
    )
    infos = DataReader(dp, Topic(dp, "ros_discovery_info", ParticipantEntitiesInfo), qos=qos)
    publications = BuiltinDataReader(dp, BuiltinTopicDcpsPublication)
    subscriptions = BuiltinDataReader(dp, BuiltinTopicDcpsSubscription)
    endpoints = {}  # discovery key (GUID bytes) -> endpoint
    latest = None
    deadline = time.monotonic() + 20.0
    while True:
        for info in infos.take(N=100):
            latest = info
        for kind, reader in (("writer", publications), ("reader", subscriptions)):
            for e in reader.take(N=100):
                endpoints[e.key.bytes] = {
                    "kind": kind,
                    "topic": e.topic_name,
                    "type": e.type_name,
                    "participant": e.participant_key.bytes.hex(),
                }
        if latest is not None and graph_complete(latest, endpoints):
            break
        if time.monotonic() > deadline:
            raise SystemExit(f"no complete ros_discovery_info within 20 s: {latest} {endpoints}")
        time.sleep(0.02)

    def resolved(gids):
        return [{"gid": bytes(g.data).hex(), **endpoints.get(bytes(g.data)[:16], {})} for g in gids]

    return {
        "gid": bytes(latest.gid.data).hex(),
        "nodes": [
            {
                "namespace": n.node_namespace,
                "name": n.node_name,
                "writers": resolved(n.writer_gid_seq),
                "readers": resolved(n.reader_gid_seq),
            }
            for n in latest.node_entities_info_seq
        ],
    }


def graph_complete(info, endpoints):
    """Whether every GID of `info` is a discovered endpoint's key and every endpoint discovered of
    its participant (but ros_discovery_info's) is listed."""
    gid = bytes(info.gid.data)[:16]
    listed = [bytes(g.data)[:16] for n in info.node_entities_info_seq for g in n.reader_gid_seq + n.writer_gid_seq]
    theirs = [k for k, e in endpoints.items() if k[:12] == gid[:12] and e["topic"] != "ros_discovery_info"]
    return bool(listed) and all(k in endpoints for k in listed) and sorted(listed) == sorted(theirs)


def no_nan(value):
    """JSON has no NaN: ROS's "not measured" becomes null."""
    if isinstance(value, float) and value != value:
        return None
    if isinstance(value, dict):
        return {k: no_nan(v) for k, v in value.items()}
    if isinstance(value, list):
        return [no_nan(v) for v in value]
    return value


def main():
    scenario, ns = sys.argv[1], sys.argv[2]
    dp = DomainParticipant(0)
    scenarios = {
        "drive": drive,
        "stand_and_drive": stand_and_drive,
        "sense": sense,
        "sense_go2": sense_go2,
        "sense_g1": sense_g1,
        "sense_chassis": sense_chassis,
        "stand_up": stand_up,
        "graph_jazzy": lambda dp, _ns: graph(dp, 16),
        "graph_humble": lambda dp, _ns: graph(dp, 24),
    }
    result = scenarios[scenario](dp, ns)
    print(json.dumps(no_nan(result), allow_nan=False))


if __name__ == "__main__":
    main()
