"""A G1's low-level side on CycloneDDS with Unitree's Python SDK (its HG IDL classes and CRC):
publishes HG LowStates with mode_machine 5 and Unitree's CRC every 2 ms, reads rt/lowcmd and
checks each LowCmd's CRC with Unitree's code. Prints "pattern" once it has PATTERN_FRAMES LowCmds
with a position gain (the client then stops refreshing), waits for DAMPING_FRAMES LowCmds
without one (the client's damping), and prints a JSON summary as its last line.
Usage: python cyclone_hg_robot.py IFACE"""
import json
import sys
import threading
import time

from unitree_sdk2py.core.channel import ChannelFactoryInitialize, ChannelPublisher, ChannelSubscriber
from unitree_sdk2py.idl.default import unitree_hg_msg_dds__LowState_
from unitree_sdk2py.idl.unitree_hg.msg.dds_ import LowCmd_, LowState_
from unitree_sdk2py.utils.crc import CRC

PATTERN_FRAMES = 200
DAMPING_FRAMES = 20
DEADLINE_S = 60.0

ChannelFactoryInitialize(0, sys.argv[1])
crc = CRC()
lock = threading.Lock()
frames = []  # (LowCmd_, CRC Unitree's code computes for it)


def on_lowcmd(msg):
    computed = crc.Crc(msg)
    with lock:
        frames.append((msg, computed))


subscriber = ChannelSubscriber("rt/lowcmd", LowCmd_)
subscriber.Init(on_lowcmd, 0)
publisher = ChannelPublisher("rt/lowstate", LowState_)
publisher.Init()

state = unitree_hg_msg_dds__LowState_()
state.mode_machine = 5
for i in range(29):
    state.motor_state[i].mode = 1
    state.motor_state[i].q = 0.01 * i


def counts():
    with lock:
        pattern = [f for f, _ in frames if f.motor_cmd[0].kp > 0]
        damping_after = 0
        seen_pattern = False
        for f, _ in frames:
            seen_pattern |= f.motor_cmd[0].kp > 0
            damping_after += seen_pattern and f.motor_cmd[0].kp == 0
        return len(pattern), damping_after


start = time.time()
said_pattern = False
tick = 0
while time.time() - start < DEADLINE_S:
    tick += 1
    state.tick = tick
    state.crc = crc.Crc(state)
    publisher.Write(state)
    pattern, damping = counts()
    if pattern >= PATTERN_FRAMES and not said_pattern:
        print("pattern", flush=True)
        said_pattern = True
    if said_pattern and damping >= DAMPING_FRAMES:
        break
    time.sleep(0.002)

with lock:
    received = list(frames)
pattern_frames = [f for f, _ in received if f.motor_cmd[0].kp > 0]
damping_frames = [f for f, _ in received if f.motor_cmd[0].kp == 0]


def fields(cmd):
    motors = cmd.motor_cmd
    return {
        "mode_pr": cmd.mode_pr,
        "mode_machine": cmd.mode_machine,
        "mode": [m.mode for m in motors],
        "q": [m.q for m in motors],
        "dq": [m.dq for m in motors],
        "tau": [m.tau for m in motors],
        "kp": [m.kp for m in motors],
        "kd": [m.kd for m in motors],
        "motor_reserve": [m.reserve for m in motors],
        "reserve": list(cmd.reserve),
    }


print(json.dumps({
    "states_sent": tick,
    "lowcmds": len(received),
    "crc_ok": sum(1 for f, c in received if f.crc == c),
    "crc_bad": sum(1 for f, c in received if f.crc != c),
    "mode_machines": sorted({f.mode_machine for f, _ in received}),
    "pattern_frames": len(pattern_frames),
    "damping_frames": len(damping_frames),
    "last_pattern": fields(pattern_frames[-1]) if pattern_frames else None,
    "last_damping": fields(damping_frames[-1]) if damping_frames else None,
}))
