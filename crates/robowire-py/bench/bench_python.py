"""robowire from Python beside the vendors' Python modules, same process, interleaved rounds.

    python bench_python.py OUT.json [--quick]

1. ZSL-1 call to wire: from ``move()`` being called to the datagram carrying it read by a
   socket standing in for the dog, for ``robowire.zsl1.HighLevel`` and the vendor's
   ``mc_sdk_zsl_1_py.HighLevel`` (its directory on ``PYTHONPATH``; CPython 3.10 on x86_64),
   beside the floor: a plain Python socket sending the datagram itself.
2. LowCmd encode with CRC: ``robowire.unitree.LowCmd.encode()`` beside Unitree's SDK
   ``CRC().Crc(cmd)`` (its packer and compiled CRC, the SDK's default on Linux) and the SDK's
   pure-Python CRC over the same packed words.

The process runs on CPU 0, all its threads, like the client side of the Rust benches.

Writes percentiles (ns) and means to OUT.json for ``cargo xtask bench``.
"""

import json
import os
import random
import socket
import struct
import sys
import time
import timeit

QUICK = "--quick" in sys.argv
OUT = sys.argv[1]
SAMPLES_PER_ROUND = 20 if QUICK else 50
ROUNDS = 5 if QUICK else 20


def percentile(samples, p):
    ordered = sorted(samples)
    return ordered[min(len(ordered) - 1, int(round(p / 100 * (len(ordered) - 1))))]


def state_datagram() -> bytes:
    """Standing in mode 18 (walking), not moving: every move() is acknowledged."""
    s = bytearray(560)
    s[0:4] = b"\xa5\x5a\x00\x00"
    struct.pack_into("<4f", s, 0x04, 1.0, 0.0, 0.0, 0.0)
    struct.pack_into("<I", s, 0x16C, 18)
    struct.pack_into("<I", s, 0x1F0, 90)
    return bytes(s)


class Dog:
    """A socket at ip:43997; answers with a state after each sample."""

    def __init__(self, ip):
        self.sock = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
        self.sock.bind((ip, 43997))
        self.state = state_datagram()
        self.client = None

    def drain(self):
        self.sock.setblocking(False)
        try:
            while True:
                _, self.client = self.sock.recvfrom(64)
        except BlockingIOError:
            pass
        self.sock.setblocking(True)

    def wait_for_vx(self, vx_bits: bytes):
        self.sock.settimeout(2.0)  # a client that stopped sending fails the run, never hangs it
        try:
            while True:
                data, self.client = self.sock.recvfrom(64)
                if data[4:8] == vx_bits:
                    return
        except socket.timeout:
            raise RuntimeError("no datagram with the new vx within 2 s") from None
        finally:
            self.sock.settimeout(None)

    def answer(self):
        if self.client:
            self.sock.sendto(self.state, self.client)


def call_to_wire(clients):
    """Interleaved rounds of samples per client; ns per sample."""
    samples = {name: [] for name in clients}
    speeds = [0.5, 0.75]
    for _ in range(ROUNDS):
        for name, (robot, dog) in clients.items():
            for i in range(SAMPLES_PER_ROUND):
                vx = speeds[i % 2]
                bits = struct.pack("<f", vx)
                time.sleep(random.uniform(0.0005, 0.003))  # any phase of a 2 ms tick
                dog.drain()
                start = time.perf_counter_ns()
                code = robot.move(vx, 0.0, 0.0)
                dog.wait_for_vx(bits)
                assert code in (0, None), f"{name}: move() returned {code:#x}"
                samples[name].append(time.perf_counter_ns() - start)
                dog.answer()
    return {
        name: {"p50_ns": percentile(s, 50), "p99_ns": percentile(s, 99), "count": len(s)} for name, s in samples.items()
    }


class RawSender:
    """The baseline: a plain socket sending the 40-byte datagram itself, no client in between."""

    def __init__(self, ip):
        self.sock = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
        self.sock.bind((ip, 43988))
        self.target = (ip, 43997)
        self.datagram = bytearray(40)

    def move(self, vx, vy, yaw_rate):
        struct.pack_into("<f", self.datagram, 4, vx)
        self.sock.sendto(self.datagram, self.target)


def connect(module, ip):
    robot = module.HighLevel()
    dog = Dog(ip)
    robot.initRobot(ip, 43988, ip)
    for _ in range(20):  # a few states first: connected, mode 18
        time.sleep(0.005)
        dog.drain()
        dog.answer()
    if not robot.checkConnect():
        raise RuntimeError(f"{module.__name__} did not connect to the stand-in dog")
    return robot, dog


def encode_crc():
    from robowire.unitree import LowCmd

    ours = LowCmd.zeroed()
    ours.head, ours.level_flag = [0xFE, 0xEF], 0xFF
    for i in range(12):
        m = ours.motor_cmd[i]
        m.mode, m.q, m.kp, m.kd = 1, [0.0, 0.67, -1.3][i % 3], 60.0, 5.0
    number = 2_000 if QUICK else 20_000
    result = {"robowire_encode_ns": min(timeit.repeat(ours.encode, number=number, repeat=5)) / number * 1e9}
    try:
        from unitree_sdk2py.idl.default import unitree_go_msg_dds__LowCmd_
        from unitree_sdk2py.utils.crc import CRC
    except ImportError:
        return result
    theirs = unitree_go_msg_dds__LowCmd_()
    theirs.head[0], theirs.head[1], theirs.level_flag = 0xFE, 0xEF, 0xFF
    for i in range(12):
        m = theirs.motor_cmd[i]
        m.mode, m.q, m.kp, m.kd = 1, [0.0, 0.67, -1.3][i % 3], 60.0, 5.0
    crc = CRC()
    n = max(number // 10, 200)
    result["sdk_crc_ns"] = min(timeit.repeat(lambda: crc.Crc(theirs), number=n, repeat=5)) / n * 1e9
    pack = crc._CRC__PackLowCmd  # the SDK's packer (name-mangled private method)
    n = max(number // 1000, 5)
    result["sdk_pure_python_crc_ns"] = min(timeit.repeat(lambda: crc._crc_py(pack(theirs)), number=n, repeat=3)) / n * 1e9
    ours.encode()
    theirs.crc = crc.Crc(theirs)
    assert theirs.crc == crc._crc_py(pack(theirs)), "the SDK's two CRCs disagree"
    assert ours.crc == theirs.crc, "robowire's CRC is not the SDK's"
    return result


def main():
    # Every thread of this process (the clients' and the stand-in dogs') on one CPU, as the Rust
    # bench pins its client and its dog socket: on this VM, waking an idle second vCPU costs
    # tens of µs and would be measured instead of the client.
    os.sched_setaffinity(0, {0})
    import robowire.zsl1

    clients = {"raw_socket": (RawSender("127.0.0.4"), Dog("127.0.0.4")), "robowire": connect(robowire.zsl1, "127.0.0.2")}
    try:
        import mc_sdk_zsl_1_py

        clients["vendor"] = connect(mc_sdk_zsl_1_py, "127.0.0.3")
    except ImportError as e:
        print(f"the vendor's module is not loadable here ({e}); robowire only", file=sys.stderr)
    report = {"call_to_wire": call_to_wire(clients), "lowcmd_encode": encode_crc(), "python": sys.version.split()[0]}
    with open(OUT, "w") as f:
        json.dump(report, f, indent=2)
    print(json.dumps(report, indent=2))


if __name__ == "__main__":
    main()
