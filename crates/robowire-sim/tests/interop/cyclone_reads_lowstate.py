"""CycloneDDS (Unitree's IDL classes) reads rt/lowstate from robowire's simulated Go2 and prints
one sample's fields as JSON, with Unitree's own CRC of it. Usage: python cyclone_reads_lowstate.py IFACE"""
import json
import sys
import time

from cyclonedds.domain import DomainParticipant
from cyclonedds.sub import DataReader
from cyclonedds.topic import Topic
from unitree_sdk2py.core.channel import ChannelFactoryInitialize
from unitree_sdk2py.idl.unitree_go.msg.dds_ import LowState_
from unitree_sdk2py.utils.crc import CRC

ChannelFactoryInitialize(0, sys.argv[1])
participant = DomainParticipant(0)
reader = DataReader(participant, Topic(participant, "rt/lowstate", LowState_))
deadline = time.time() + 20
samples = []
while time.time() < deadline and len(samples) < 10:
    samples.extend(reader.take(N=10))
    time.sleep(0.01)
if not samples:
    print(json.dumps({"error": "no LowState within 20 s"}))
    sys.exit(1)
m = samples[-1]
print(json.dumps({
    "samples": len(samples),
    "crc": m.crc,
    "unitree_crc": CRC().Crc(m),
    "head": list(m.head),
    "tick": m.tick,
    "q": [m.motor_state[i].q for i in range(12)],
    "mode": [m.motor_state[i].mode for i in range(12)],
    "quaternion": list(m.imu_state.quaternion),
    "accelerometer": list(m.imu_state.accelerometer),
    "soc": m.bms_state.soc,
    "cell_vol": list(m.bms_state.cell_vol),
    "power_v": m.power_v,
}))
