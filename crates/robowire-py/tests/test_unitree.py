"""robowire.unitree: the golden vectors of Unitree's own SDK, the CLI's JSON, and Unitree's
Python SDK as a live peer (CRC and CDR) wherever it is installed."""

import json
import math
import os
import struct
import subprocess
from pathlib import Path

import pytest

import robowire
from conftest import REPO, cli, missing
from robowire.unitree import ArrayView, HgLowCmd, HgLowState, LowCmd, LowState, StructView

FIXTURES = Path(os.environ.get("ROBOWIRE_FIXTURES", REPO / "fixtures"))  # the golden vectors, in the repo
VECTORS = json.loads((FIXTURES / "unitree" / "vectors.json").read_text())
CLASSES = {"lowcmd": LowCmd, "lowstate": LowState}


def f32(x):
    return struct.unpack("<f", struct.pack("<f", x))[0]


def same_at_f32(a, b):
    """JSON shapes equal, floats compared as the float32 they hold."""
    if isinstance(a, dict):
        return isinstance(b, dict) and a.keys() == b.keys() and all(same_at_f32(a[k], b[k]) for k in a)
    if isinstance(a, list):
        return isinstance(b, list) and len(a) == len(b) and all(same_at_f32(x, y) for x, y in zip(a, b))
    if isinstance(a, float) or isinstance(b, float):
        return isinstance(a, (int, float)) and isinstance(b, (int, float)) and f32(a) == f32(b)
    return a == b


@pytest.mark.parametrize("kind, vector", [(k, v) for k in CLASSES for v in VECTORS[k]], ids=lambda v: v if isinstance(v, str) else v["name"])
def test_golden_images_both_ways(kind, vector):
    cls = CLASSES[kind]
    image = bytes.fromhex(vector["packed_hex"])
    message = cls.decode(image)
    assert same_at_f32(message.to_dict(), vector["fields"])
    assert message.crc == int(vector["crc"]) == message.computed_crc()
    assert cls.from_dict(vector["fields"]).encode() == image


@pytest.mark.parametrize("vector", VECTORS["cdr"], ids=lambda v: v["name"])
def test_golden_cdr_both_ways(vector):
    cls = LowCmd if vector["topic"] == "rt/lowcmd" else LowState
    payload = bytes.fromhex(vector["cdr_hex"])
    message = cls.decode_cdr(payload)
    encoding = "xcdr2" if vector["encoding"].startswith("XCDR2") else "xcdr1"
    assert message.encode_cdr(encoding) == payload
    source = next(v for v in VECTORS[vector["topic"][3:]] if v["name"] == vector["source_vector"])
    assert message.encode() == bytes.fromhex(source["packed_hex"])


def test_fields_are_live_views():
    cmd = LowCmd()
    assert list(cmd.head) == [0xFE, 0xEF] and cmd.level_flag == 0xFF  # the safe command
    assert cmd.motor_cmd[0].kp == 0.0 and cmd.motor_cmd[0].q == 2.146e9  # holding nothing
    assert isinstance(cmd.motor_cmd, ArrayView) and isinstance(cmd.motor_cmd[3], StructView)
    motor = cmd.motor_cmd[3]
    motor.q = 0.5
    motor.kp = 60
    cmd.motor_cmd[4] = {"mode": 1, "q": -1.3, "kd": 5.0}
    cmd.wireless_remote[0:2] = [7, 8]
    assert (cmd.motor_cmd[3].q, cmd.motor_cmd[3].kp) == (0.5, 60.0)
    assert cmd.motor_cmd[4].q == f32(-1.3) and cmd.motor_cmd[4].kd == 5.0
    assert cmd.wireless_remote[:3] == [7, 8, 0]
    assert len(cmd.motor_cmd) == 20 and len(list(cmd.motor_cmd)) == 20
    assert LowCmd.zeroed().motor_cmd[0].q == 0.0
    assert LowCmd(gpio=3).gpio == 3
    assert "motor_cmd" in dir(cmd)
    assert cmd.motor_cmd[-1] == cmd.motor_cmd[19] and cmd.motor_cmd[3] != cmd.motor_cmd[4]
    cmd.motor_cmd[5] = cmd.motor_cmd[3]
    assert cmd.motor_cmd[5] == cmd.motor_cmd[3] and cmd.motor_cmd[5].kp == 60.0
    copy = cmd.copy()
    copy.motor_cmd[3].q = 0.0
    assert cmd.motor_cmd[3].q == 0.5


def test_bad_values_raise_and_change_nothing():
    cmd = LowCmd()
    with pytest.raises(robowire.ArgumentError, match="uint8"):
        cmd.level_flag = 256
    with pytest.raises(robowire.ArgumentError, match="motor_cmd\\[0\\].mode"):
        cmd.motor_cmd[0].mode = -1
    with pytest.raises(robowire.ArgumentError, match="2 elements"):
        cmd.head = [1, 2, 3]
    with pytest.raises(TypeError):
        cmd.level_flag = 1.5
    with pytest.raises(AttributeError, match="no field"):
        cmd.motor_cmd[0].nope = 1
    with pytest.raises(IndexError):
        cmd.motor_cmd[20]
    with pytest.raises(IndexError):
        cmd.motor_cmd[-21]
    with pytest.raises(robowire.ArgumentError, match="MotorCmd_"):
        cmd.motor_cmd[0] = HgLowCmd().motor_cmd[0]  # a G1 motor is not a Go2 motor
    with pytest.raises(robowire.ArgumentError, match="has no field"):
        cmd.motor_cmd[0] = {"nope": 1}
    assert cmd == LowCmd()


def test_encode_writes_the_crc_and_decode_verifies_it():
    cmd = LowCmd()
    cmd.motor_cmd[0].q = 0.25
    image = cmd.encode()
    assert len(image) == LowCmd.IMAGE_LEN == 812 and bytes(cmd) == image
    assert cmd.crc == cmd.computed_crc() == int.from_bytes(image[-4:], "little")
    broken = bytearray(image)
    broken[30] ^= 0x01
    with pytest.raises(robowire.CrcError) as raised:
        LowCmd.decode(bytes(broken))
    assert raised.value.found == cmd.crc and raised.value.expected != cmd.crc
    assert f"0x{raised.value.expected:08x}" in str(raised.value)
    assert LowCmd.decode(bytearray(broken), verify=False).crc == cmd.crc
    with pytest.raises(robowire.DecodeError, match="812"):
        LowCmd.decode(image[:-1])
    with pytest.raises(robowire.DecodeError, match="encapsulation"):
        LowCmd.decode_cdr(b"\x00\x09\x00\x00" + image)
    with pytest.raises(robowire.ArgumentError, match="xcdr"):
        cmd.encode_cdr("xcdr3")


def test_dicts_round_trip_with_non_finite_floats():
    state = LowState()
    state.imu_state.rpy = [math.nan, math.inf, -0.5]
    d = state.to_dict()
    assert d["imu_state"]["rpy"] == ["NaN", "Infinity", -0.5]
    assert LowState.from_dict(d) == LowState.decode(state.encode())
    d["imu_state"]["rpy"] = [float("nan"), 0.0, 0.0]
    with pytest.raises(robowire.ArgumentError, match="NaN"):
        LowState.from_dict(d)
    d["imu_state"]["rpy"] = ["NaN", 0.0, 0.0]
    del d["tick"]
    with pytest.raises(robowire.ArgumentError, match="tick"):
        LowState.from_dict(d)


def test_hg_messages():
    cmd = HgLowCmd(mode_machine=5)
    cmd.motor_cmd[34].q = 0.1
    assert HgLowCmd.decode(cmd.encode()).motor_cmd[34].q == f32(0.1)
    assert HgLowCmd.IMAGE_LEN == 1004 and HgLowState.IMAGE_LEN == 2092
    state = HgLowState.decode_cdr(HgLowState().encode_cdr("xcdr2"))
    assert len(state.motor_state) == 35


def numpy_or_skip():
    return pytest.importorskip("numpy")


def test_numeric_arrays_convert_to_numpy():
    numpy = numpy_or_skip()
    state = LowState()
    state.foot_force = [1, 2, 3, 4]
    assert numpy.asarray(state.foot_force).dtype == numpy.int16
    assert numpy.asarray(state.imu_state.quaternion).dtype == numpy.float32


@pytest.mark.parametrize("kind", ["lowcmd", "lowstate"])
def test_to_dict_is_what_robowire_decode_json_prints(kind):
    binary = cli()
    cls = CLASSES[kind]
    message = cls.from_dict(VECTORS[kind][-1]["fields"])  # random contents
    message_hex = message.encode().hex()
    printed = subprocess.run([binary, "decode", kind, "--json", message_hex], check=True, capture_output=True, text=True)
    assert json.loads(printed.stdout) == message.to_dict()
    encoded = subprocess.run(
        [binary, "encode", kind, "-"], input=json.dumps(message.to_dict()), check=True, capture_output=True, text=True
    )
    assert encoded.stdout.split() == [message_hex] or bytes.fromhex("".join(encoded.stdout.split())) == message.encode()


# --- Unitree's Python SDK as the other end ------------------------------------------------------


@pytest.fixture
def sdk():
    try:
        from unitree_sdk2py.idl.default import unitree_go_msg_dds__LowCmd_
        from unitree_sdk2py.utils.crc import CRC
    except ImportError as e:
        missing("sdk", f"Unitree's Python SDK is not installed here ({e})")
    return unitree_go_msg_dds__LowCmd_, CRC()


def test_same_crc_and_cdr_as_unitrees_sdk(sdk):
    make, crc = sdk
    theirs = make()
    theirs.head[0], theirs.head[1], theirs.level_flag, theirs.gpio = 0xFE, 0xEF, 0xFF, 0
    ours = LowCmd.zeroed()
    ours.head, ours.level_flag = [0xFE, 0xEF], 0xFF
    for i in range(12):
        q, kp, kd = [0.0, 0.67, -1.3][i % 3], 60.0, 5.0
        for cmd in (theirs.motor_cmd[i], ours.motor_cmd[i]):
            cmd.mode, cmd.q, cmd.dq, cmd.kp, cmd.kd, cmd.tau = 0x01, q, 0.0, kp, kd, 0.0
    theirs.crc = crc.Crc(theirs)
    ours.encode()
    assert ours.crc == theirs.crc
    assert ours.encode_cdr() == theirs.serialize()
    back = LowCmd.decode_cdr(theirs.serialize())
    assert back == ours
