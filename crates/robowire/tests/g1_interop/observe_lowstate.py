"""Watches `rt/lowstate` of a G1 beside one of Unitree's G1 examples, with Unitree's SDK.

Checks every sample's CRC with Unitree's `CRC` and follows the joints by phase. Prints `ready`
once a first state arrived, then, when done, one JSON line (the Rust test asserts on it).

    observe_lowstate.py IFACE low_level   # done once the AB stage swung the ankle's A motor
    observe_lowstate.py IFACE low_level_hanging   # the same on a hanging physics G1, whose waist
                                                  # pitch bows under its upper body (zero within 0.35)
    observe_lowstate.py IFACE arm         # done when stdin closes (the example has ended)

A state arriving late is no failure here: the test's bound is its own timeout.
"""

import json
import os
import sys
import threading

from unitree_sdk2py.core.channel import ChannelFactoryInitialize, ChannelSubscriber
from unitree_sdk2py.idl.unitree_hg.msg.dds_ import LowState_
from unitree_sdk2py.utils.crc import CRC

JOINTS = 29
WAIST_PITCH = 14


class Range:
    """Per joint minimum and maximum over a phase."""

    def __init__(self):
        self.samples = 0
        self.min = [float("inf")] * JOINTS
        self.max = [float("-inf")] * JOINTS
        self.max_abs = {}  # named extra quantities: largest magnitude seen

    def add(self, q, **extra):
        self.samples += 1
        for i, v in enumerate(q):
            self.min[i] = min(self.min[i], v)
            self.max[i] = max(self.max[i], v)
        for name, v in extra.items():
            self.max_abs[name] = max(self.max_abs.get(name, 0.0), abs(v))

    def summary(self):
        if self.samples == 0:
            return {"samples": 0}
        return {"samples": self.samples, "min": self.min, "max": self.max, "max_abs": self.max_abs}


class Observer:
    def __init__(self, mode):
        self.mode = mode
        # How near 0 each joint must be for the zero posture.
        self.zero_tolerance = [0.05] * JOINTS
        if mode == "low_level_hanging":
            self.zero_tolerance[WAIST_PITCH] = 0.35
        self.crc = CRC()
        self.lock = threading.Lock()
        self.done = threading.Event()
        self.ready = threading.Event()
        self.samples = 0
        self.bad_crc = 0
        self.mode_machines = set()
        self.first = None
        self.last = None
        self.zero = None  # (sample index, q) when every joint first was within 0.05 rad of 0
        self.pr = Range()
        self.ab = Range()
        self.all = Range()

    def handle(self, msg: LowState_):
        with self.lock:
            self.samples += 1
            if self.crc.Crc(msg) != msg.crc:
                self.bad_crc += 1
            self.mode_machines.add(msg.mode_machine)
            q = [msg.motor_state[i].q for i in range(JOINTS)]
            if self.first is None:
                self.first = q
            self.last = q
            self.all.add(q)
            if self.mode.startswith("low_level"):
                self.follow_low_level(msg, q)
        self.ready.set()

    def follow_low_level(self, msg, q):
        if self.zero is None:
            if all(abs(v) < t for v, t in zip(q, self.zero_tolerance)):
                self.zero = (self.samples, q)
            return
        if msg.mode_pr == 0 and self.ab.samples == 0:
            # Stage 2: pitches equal, rolls opposite.
            self.pr.add(q, pitch_difference=q[4] - q[10], roll_sum=q[5] + q[11])
        elif msg.mode_pr == 1:
            self.ab.add(q)
            if self.ab.max[5] > 0.3 and self.ab.min[5] < -0.3:
                self.done.set()

    def summary(self, timed_out):
        with self.lock:
            return {
                "timed_out": timed_out,
                "samples": self.samples,
                "bad_crc": self.bad_crc,
                "mode_machine": sorted(self.mode_machines),
                "first": self.first,
                "last": self.last,
                "zero": None if self.zero is None else {"sample": self.zero[0], "q": self.zero[1]},
                "pr": self.pr.summary(),
                "ab": self.ab.summary(),
                "all": self.all.summary(),
            }


def main():
    interface, mode = sys.argv[1], sys.argv[2]
    timeout_s = 120.0
    ChannelFactoryInitialize(0, interface)
    observer = Observer(mode)
    subscriber = ChannelSubscriber("rt/lowstate", LowState_)
    subscriber.Init(observer.handle, 10)
    if not observer.ready.wait(timeout_s):
        print(json.dumps(observer.summary(True)), flush=True)
        return
    print("ready", flush=True)
    if mode == "arm":
        # Until the test closes stdin.
        threading.Thread(target=lambda: (sys.stdin.read(), observer.done.set()), daemon=True).start()
    timed_out = not observer.done.wait(timeout_s)
    print(json.dumps(observer.summary(timed_out)), flush=True)


if __name__ == "__main__":
    main()
    # CycloneDDS's threads are not Python's: leave at once.
    os._exit(0)
