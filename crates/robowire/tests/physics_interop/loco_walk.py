"""Walks a simulated G1 through Unitree's LocoClient and watches its pelvis, with Unitree's SDK.

Subscribes `rt/sportmodestate` (the pelvis, from the simulator's physics). Once a first state
arrived, calls `LocoClient.Move(VX, VY, WZ)` every 0.1 s for SECONDS (each call holds 1 s, as a
joystick does), then `StopMove` and `Damp`. Prints one JSON line: the Move calls' return codes
(distinct), the pelvis's first and last position and yaw while moving, and its lowest height.

    loco_walk.py IFACE VX VY WZ SECONDS
"""

import json
import sys
import threading
import time

from unitree_sdk2py.core.channel import ChannelFactoryInitialize, ChannelSubscriber
from unitree_sdk2py.g1.loco.g1_loco_client import LocoClient
from unitree_sdk2py.idl.unitree_go.msg.dds_ import SportModeState_


class Track:
    def __init__(self):
        self.lock = threading.Lock()
        self.ready = threading.Event()
        self.moving = False
        self.first = None
        self.last = None
        self.lowest = 1e9
        self.samples = 0

    def body(self, msg: SportModeState_):
        pose = [msg.position[0], msg.position[1], msg.position[2], msg.imu_state.rpy[2]]
        with self.lock:
            if self.moving:
                self.first = self.first or pose
                self.last = pose
                self.lowest = min(self.lowest, pose[2])
                self.samples += 1
        self.ready.set()


def main():
    iface, vx, vy, wz, seconds = sys.argv[1], *map(float, sys.argv[2:6])
    ChannelFactoryInitialize(0, iface)
    track = Track()
    sub = ChannelSubscriber("rt/sportmodestate", SportModeState_)
    sub.Init(track.body, 10)
    loco = LocoClient()
    loco.SetTimeout(3.0)
    loco.Init()
    timed_out = not track.ready.wait(20.0)
    print("ready", flush=True)
    fsm = None
    if not timed_out:
        fsm = loco.GetFsmId()
        with track.lock:
            track.moving = True
        end = time.monotonic() + seconds
        while time.monotonic() < end:
            loco.Move(vx, vy, wz)
            time.sleep(0.1)
        with track.lock:
            track.moving = False
        loco.StopMove()
        loco.Damp()
    with track.lock:
        print(json.dumps({
            "timed_out": timed_out,
            "fsm": fsm,
            "samples": track.samples,
            "first": track.first,
            "last": track.last,
            "lowest": track.lowest,
        }), flush=True)


if __name__ == "__main__":
    main()
