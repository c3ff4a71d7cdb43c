"""Reads a ROS 2 capture of the bridge (`BridgeOptions::record`; `robowire ros2 --record`) with
two ROS 2 readers independent of robowire's: `rosbags` (as a rosbag2 MCAP file) and
`mcap-ros2-support` (the `mcap` package's ROS 2 decoder), each decoding every message with the
`ros2msg` definition in the file, and prints what they found as one JSON line.

    python read_ros2.py FILE.mcap

The header's profile; per topic and reader: the message type and how many messages decoded; the
largest `linear.x` of the Twists on `*/cmd_vel` and of the odometry's twist on `*/odom`.
"""

import json
import sys
from pathlib import Path

from mcap.reader import make_reader
from mcap_ros2.reader import read_ros2_messages
from rosbags.highlevel import AnyReader


def main():
    path = sys.argv[1]
    with open(path, "rb") as f:
        reader = make_reader(f)
        profile = reader.get_header().profile
        encodings = sorted({(c.message_encoding) for c in reader.get_summary().channels.values()})
    found = {"profile": profile, "encodings": encodings, "rosbags": {}, "mcap_ros2": {}, "max_x": {}}
    with AnyReader([Path(path)]) as bag:
        for connection, _, raw in bag.messages():
            message = bag.deserialize(raw, connection.msgtype)
            topic = found["rosbags"].setdefault(connection.topic, {"type": connection.msgtype, "count": 0})
            topic["count"] += 1
            x = None
            if connection.topic.endswith("/cmd_vel"):
                x = message.linear.x
            elif connection.topic.endswith("/odom"):
                x = message.twist.twist.linear.x
            if x is not None:
                found["max_x"][connection.topic] = max(found["max_x"].get(connection.topic, x), x)
    for message in read_ros2_messages(path):
        topic = found["mcap_ros2"].setdefault(message.channel.topic, {"type": message.schema.name, "count": 0})
        topic["count"] += 1
    print(json.dumps(found))


if __name__ == "__main__":
    main()
