"""The same vendor-style script with ZsiBot's own module and with robowire.zsl1, each against
a fake robot that records every datagram and answers with a fixed state: the same return
codes, the same getter values, the same datagrams byte for byte. Where robowire deliberately
differs (NaN), the difference is asserted. Needs CPython 3.10 on x86_64 (the vendor's build).
"""

import json
import os
import socket
import struct
import subprocess
import sys
import threading
from pathlib import Path

import pytest

from conftest import vendor_module_dir

SCRIPT = Path(__file__).parent / "scripts" / "zsl_vendor_script.py"


def high_level_state() -> bytes:
    """A 560-byte HighLevel state: standing (mode 1), not moving, a distinct value per getter."""
    s = bytearray(560)
    s[0:4] = b"\xa5\x5a\x00\x00"
    struct.pack_into("<4f", s, 0x04, 1.0, 0.01, 0.02, 0.03)  # quaternion
    struct.pack_into("<3f", s, 0x14, 0.001, 0.002, 0.003)  # gyro (|z| < 0.2: not running)
    struct.pack_into("<3f", s, 0x20, 0.1, 0.2, 9.8)  # acc
    struct.pack_into("<3f", s, 0x2C, 0.011, 0.012, 0.013)  # rpy
    struct.pack_into("<3f", s, 0x38, 0.01, 0.02, 0.03)  # body velocity (< 0.2)
    struct.pack_into("<3f", s, 0x44, 0.04, 0.05, 0.06)  # world velocity
    struct.pack_into("<3f", s, 0x50, 1.0, 2.0, 0.3)  # position
    for k in range(12):  # joint angle, velocity, torque slots of four joints
        base = 0x68 + 0x40 * (k // 4) + 0x10 * (k % 4)
        struct.pack_into("<4f", s, base, *(0.1 * k + 0.01 * leg for leg in range(4)))
    struct.pack_into("<I", s, 0x16C, 1)  # mode: standing
    struct.pack_into("<I", s, 0x1F0, 87)  # battery %
    return bytes(s)


def low_level_state() -> bytes:
    s = bytearray(272)
    struct.pack_into("<H", s, 0, 0x5AA5)
    for k in range(9):
        struct.pack_into("<4f", s, 0x04 + 16 * k, *(0.2 * k + 0.01 * leg for leg in range(4)))
    struct.pack_into("<4f", s, 0x94, 1.0, 0.1, 0.2, 0.3)
    struct.pack_into("<3f", s, 0xA4, 0.4, 0.5, 0.6)
    struct.pack_into("<3f", s, 0xB0, 0.7, 0.8, 9.9)
    struct.pack_into("<3f", s, 0xBC, 0.01, 0.02, 0.03)
    return bytes(s)


class FakeDog:
    """A UDP socket at the robot's port: records every datagram, answers each with `state`."""

    def __init__(self, ip: str, port: int, state: bytes):
        self.socket = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
        self.socket.bind((ip, port))
        self.socket.settimeout(0.1)
        self.state = state
        self.datagrams = []
        self.running = True
        self.thread = threading.Thread(target=self.serve, daemon=True)
        self.thread.start()

    def serve(self):
        while self.running:
            try:
                data, sender = self.socket.recvfrom(2048)
            except socket.timeout:
                continue
            self.datagrams.append(data)
            self.socket.sendto(self.state, sender)

    def distinct(self):
        """The datagrams with consecutive repeats collapsed: what was commanded, in order."""
        out = []
        for d in self.datagrams:
            if not out or out[-1] != d:
                out.append(d)
        return out

    def close(self):
        self.running = False
        self.thread.join()
        self.socket.close()


def run(module: str, part: str, ip: str, dog_port: int, state: bytes):
    dog = FakeDog(ip, dog_port, state)
    try:
        env = dict(os.environ, PYTHONPATH=os.pathsep.join([str(vendor_module_dir("zsl-1")), *sys.path]))
        out = subprocess.run(
            [sys.executable, str(SCRIPT), module, part, ip, "43988"], env=env, capture_output=True, text=True, timeout=60
        )
        assert out.returncode == 0, out.stderr
        result = json.loads(out.stdout.strip().splitlines()[-1])
    finally:
        dog.close()
    return result, dog.distinct()


def side_by_side(part, dog_port, state, ip):
    vendor = run("mc_sdk_zsl_1_py", part, ip, dog_port, state)
    ours = run("robowire.zsl1", part, ip, dog_port, state)
    return vendor, ours


def hexes(datagrams):
    return [d.hex() for d in datagrams]


def and_the_stop_burst(vendor_wire, our_wire):
    """robowire's datagrams as far as the vendor's went, and the rest: what closing sent (the
    script ends without closing; robowire's client sends its stop burst as it goes, the vendor's
    nothing)."""
    return our_wire[: len(vendor_wire)], our_wire[len(vendor_wire) :]


def test_high_level_same_codes_getters_and_datagrams(vendor_python, ip):
    (vendor, vendor_wire), (ours, our_wire) = side_by_side("high", 43997, high_level_state(), ip)
    assert ours == vendor
    assert vendor["move during two-leg stand"] == 0x3007 and vendor["move too slow"] == 0x3013
    same, stop = and_the_stop_burst(vendor_wire, our_wire)
    assert hexes(same) == hexes(vendor_wire)
    assert len(vendor_wire) >= 15  # idle, every accepted call, every cleared action
    # The stop: the last mode kept, every velocity and rate zero, no action.
    assert [(struct.unpack_from("<6f", d, 4), d[28:32]) for d in stop] == [((0.0,) * 6, b"\0\0" + vendor_wire[-1][30:32])]


def test_low_level_same_codes_getters_and_datagrams(vendor_python, ip):
    (vendor, vendor_wire), (ours, our_wire) = side_by_side("low", 43900, low_level_state(), ip)
    assert ours == vendor
    assert (vendor["sendMotorCmd"], vendor["sendMotorCmd knee 0"]) == (0, -1)
    same, stop = and_the_stop_burst(vendor_wire, our_wire)
    assert hexes(same) == hexes(vendor_wire)
    assert [len(d) for d in vendor_wire] == [248, 248]  # idle, then the command
    # The stop: the last command with its velocity targets (bytes 52..100) zeroed.
    last = vendor_wire[-1]
    assert [(d[:52], d[52:100], d[100:244]) for d in stop] == [(last[:52], bytes(48), last[100:244])]


def test_nan_is_where_robowire_differs_on_purpose(vendor_python, ip):
    (vendor, vendor_wire), (ours, our_wire) = side_by_side("nan", 43997, high_level_state(), ip)
    assert (vendor["move NaN"], ours["move NaN"]) == (0, 0x3013)  # the vendor sends NaN
    assert vendor["move inf"] == ours["move inf"] == 0x3013
    nan_vx = struct.pack("<f", float("nan"))
    assert any(d[4:8] == nan_vx for d in vendor_wire)
    assert not any(d[4:8] == nan_vx for d in our_wire)
    assert hexes(our_wire) == hexes(vendor_wire)[: len(our_wire)]  # identical up to the NaN


def test_the_vendors_classes_have_robowires_names(vendor_python):
    sys.path.insert(0, str(vendor_module_dir("zsl-1")))
    sys.path.insert(0, str(vendor_module_dir("zsl-1w")))
    try:
        import mc_sdk_zsl_1_py
        import mc_sdk_zsl_1w_py
    finally:
        del sys.path[:2]
    import robowire.zsl1
    import robowire.zsl1w

    def public(cls):
        return {n for n in dir(cls) if not n.startswith("_")}

    for vendor_mod, ours in [(mc_sdk_zsl_1_py, robowire.zsl1), (mc_sdk_zsl_1w_py, robowire.zsl1w)]:
        for name in [n for n in dir(vendor_mod) if not n.startswith("_")]:
            vendor_cls, our_cls = getattr(vendor_mod, name), getattr(ours, name)
            missing = public(vendor_cls) - public(our_cls)
            assert not missing, f"{name} lacks {missing}"
