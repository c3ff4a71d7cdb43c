"""Unitree's Python SDK on CycloneDDS drives robowire's simulated Go2: motion_switcher CheckMode
and ReleaseMode (request/answer), then LowCmds at 500 Hz with Unitree's CRC toward the stand pose,
and one LowCmd with a wrong CRC. Prints what the services answered as JSON.
Usage: python cyclone_drives_lowcmd.py IFACE"""
import json
import sys
import time

from unitree_sdk2py.comm.motion_switcher.motion_switcher_client import MotionSwitcherClient
from unitree_sdk2py.core.channel import ChannelFactoryInitialize, ChannelPublisher
from unitree_sdk2py.idl.default import unitree_go_msg_dds__LowCmd_
from unitree_sdk2py.idl.unitree_go.msg.dds_ import LowCmd_
from unitree_sdk2py.utils.crc import CRC

ChannelFactoryInitialize(0, sys.argv[1])
switcher = MotionSwitcherClient()
switcher.SetTimeout(10.0)
switcher.Init()
code_before, before = switcher.CheckMode()
code_release, _ = switcher.ReleaseMode()
code_after, after = switcher.CheckMode()

publisher = ChannelPublisher("rt/lowcmd", LowCmd_)
publisher.Init()
cmd = unitree_go_msg_dds__LowCmd_()
cmd.head[0], cmd.head[1], cmd.level_flag = 0xFE, 0xEF, 0xFF
stand = [0.0, 0.67, -1.3]
for i in range(20):
    cmd.motor_cmd[i].mode = 0x01
for i in range(12):
    cmd.motor_cmd[i].q = stand[i % 3]
    cmd.motor_cmd[i].kp = 60.0
    cmd.motor_cmd[i].kd = 5.0
crc = CRC()
for _ in range(1500):
    cmd.crc = crc.Crc(cmd)
    publisher.Write(cmd)
    time.sleep(0.002)
bad = crc.Crc(cmd) ^ 1
cmd.crc = bad
for _ in range(5):
    publisher.Write(cmd)
    time.sleep(0.002)
time.sleep(0.2)
print(json.dumps({
    "check_mode_before": [code_before, before],
    "release": code_release,
    "check_mode_after": [code_after, after],
}))
