"""One vendor-style ZSL-1 script, run unchanged with the vendor's module or robowire's.

    python zsl_vendor_script.py MODULE high|low|nan IP LOCAL_PORT

MODULE is ``mc_sdk_zsl_1_py`` (the vendor's; its directory on ``PYTHONPATH``) or
``robowire.zsl1``. Prints one JSON object: every call's return value and every getter's.
"""

import importlib
import json
import math
import sys
import time

module_name, part, ip, port = sys.argv[1], sys.argv[2], sys.argv[3], int(sys.argv[4])
mc = importlib.import_module(module_name)
out = {}


def call(label, fn, *args, **kwargs):
    out[label] = fn(*args, **kwargs)
    time.sleep(0.04)  # about 20 datagrams: one-shot actions are cleared after 6


def floats(values):
    return [float(v) for v in values]


if part in ("high", "nan"):
    robot = mc.HighLevel()
    robot.initRobot(ip, port, ip)
    time.sleep(0.2)
    out["checkConnect"] = robot.checkConnect()
    if part == "high":
        call("standUp", robot.standUp)
        call("move", robot.move, 0.5, -0.25, 1.5)
        call("attitudeControl", robot.attitudeControl, yaw_vel=0.1, roll_vel=-0.2, pitch_vel=0.3, height_vel=-0.4)
        call("twoLegStand", robot.twoLegStand, 0.3, -0.5)
        call("move during two-leg stand", robot.move, 0.5, 0.0, 0.0)
        call("cancelTwoLegStand", robot.cancelTwoLegStand)
        call("jump", robot.jump)
        call("frontJump", robot.frontJump)
        call("backflip", robot.backflip)
        call("shakeHand", robot.shakeHand)
        call("lieDown", robot.lieDown)
        call("passive", robot.passive)
        call("move too slow", robot.move, 0.04, 0.0, 0.0)
        call("move at the band edges", robot.move, -3.0, 1.0, -0.02)
        call("attitude too fast", robot.attitudeControl, 0.61, 0.0, 0.0, 0.0)
        for name in [
            "getQuaternion", "getRPY", "getBodyAcc", "getBodyGyro", "getPosition", "getWorldVelocity",
            "getBodyVelocity", "getLegAbadJoint", "getLegHipJoint", "getLegKneeJoint", "getLegAbadJointVel",
            "getLegHipJointVel", "getLegKneeJointVel", "getLegAbadJointTorque", "getLegHipJointTorque",
            "getLegKneeJointTorque",
        ]:
            out[name] = floats(getattr(robot, name)())
        out["getBatteryPower"] = robot.getBatteryPower()
        out["getCurrentCtrlmode"] = robot.getCurrentCtrlmode()
    else:
        call("standUp", robot.standUp)
        call("move NaN", robot.move, math.nan, 0.0, 0.0)
        call("move inf", robot.move, math.inf, 0.0, 0.0)
elif part == "low":
    robot = mc.LowLevel()
    robot.initRobot(ip, port, ip)
    time.sleep(0.2)
    out["checkConnect"] = robot.checkConnect()
    cmd = mc.MotorCommand()
    fields = [
        "q_des_abad", "q_des_hip", "q_des_knee", "qd_des_abad", "qd_des_hip", "qd_des_knee", "kp_abad", "kp_hip",
        "kp_knee", "kd_abad", "kd_hip", "kd_knee", "tau_abad_ff", "tau_hip_ff", "tau_knee_ff",
    ]
    base = {"q_des_abad": -0.15, "q_des_hip": 0.5, "q_des_knee": -1.0}
    for k, name in enumerate(fields):
        for leg in range(4):
            step = -0.1 if name == "q_des_knee" else 0.1
            getattr(cmd, name)[leg] = base.get(name, 1.0 + k) + step * leg
    call("sendMotorCmd", robot.sendMotorCmd, cmd)
    cmd.q_des_knee[3] = 0.0  # out of range: refused, the previous command keeps streaming
    call("sendMotorCmd knee 0", robot.sendMotorCmd, cmd)
    state = robot.getMotorState()
    for name in ["q_abad", "q_hip", "q_knee", "qd_abad", "qd_hip", "qd_knee", "tau_abad_fb", "tau_hip_fb", "tau_knee_fb"]:
        out[name] = floats(getattr(state, name))
    for name in ["getQuaternion", "getRPY", "getBodyAcc", "getBodyGyro"]:
        out[name] = floats(getattr(robot, name)())
    out["haveMotorData"] = robot.haveMotorData()
print(json.dumps(out))
