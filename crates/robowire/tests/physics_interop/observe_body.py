"""Watches where a simulated Go2's body is beside a LowCmd client, with Unitree's SDK.

Subscribes `rt/lowcmd` (what the client commands) and `rt/sportmodestate` (the body, from the
simulator's physics), and sorts each body height by the command in force when it arrived:
`stand` (the 12 targets at Unitree's stand pose), `lie` (at the stand example's last pose),
`damp` (every kp 0, some kd), `other`. Prints `ready` once a first body state arrived, then,
when stdin closes, one JSON line: per phase the samples, the lowest, highest and last height.

    observe_body.py IFACE
"""

import json
import os
import sys
import threading

from unitree_sdk2py.core.channel import ChannelFactoryInitialize, ChannelSubscriber
from unitree_sdk2py.idl.unitree_go.msg.dds_ import LowCmd_, SportModeState_

STAND = [0.0, 0.67, -1.3] * 4
LIE = [-0.35, 1.36, -2.65, 0.35, 1.36, -2.65, -0.5, 1.36, -2.65, 0.5, 1.36, -2.65]


def near(q, pose):
    return all(abs(a - b) < 1e-3 for a, b in zip(q, pose))


class Observer:
    def __init__(self):
        self.lock = threading.Lock()
        self.ready = threading.Event()
        self.phase = "none"
        self.commands = 0
        self.phases = {}

    def command(self, msg: LowCmd_):
        motors = msg.motor_cmd[:12]
        q = [m.q for m in motors]
        if all(m.kp == 0.0 for m in motors) and any(m.kd > 0.0 for m in motors):
            phase = "damp"
        elif near(q, STAND):
            phase = "stand"
        elif near(q, LIE):
            phase = "lie"
        else:
            phase = "other"
        with self.lock:
            self.commands += 1
            self.phase = phase

    def body(self, msg: SportModeState_):
        with self.lock:
            p = self.phases.setdefault(self.phase, {"samples": 0, "min": 1e9, "max": -1e9, "last": None})
            h = msg.body_height
            p["samples"] += 1
            p["min"] = min(p["min"], h)
            p["max"] = max(p["max"], h)
            p["last"] = h
        self.ready.set()

    def summary(self, timed_out):
        with self.lock:
            return {"timed_out": timed_out, "commands": self.commands, "phases": self.phases}


def main():
    interface = sys.argv[1]
    ChannelFactoryInitialize(0, interface)
    observer = Observer()
    commands = ChannelSubscriber("rt/lowcmd", LowCmd_)
    commands.Init(observer.command, 10)
    bodies = ChannelSubscriber("rt/sportmodestate", SportModeState_)
    bodies.Init(observer.body, 10)
    if not observer.ready.wait(60.0):
        print(json.dumps(observer.summary(True)), flush=True)
        return
    print("ready", flush=True)
    sys.stdin.read()
    print(json.dumps(observer.summary(False)), flush=True)


if __name__ == "__main__":
    main()
    # CycloneDDS's threads are not Python's: leave at once.
    os._exit(0)
