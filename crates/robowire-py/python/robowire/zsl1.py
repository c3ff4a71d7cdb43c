"""A drop-in for ZsiBot's ZSL-1 module ``mc_sdk_zsl_1_py``.

``import robowire.zsl1 as mc_sdk_zsl_1_py`` is the only change a vendor script needs: the same
classes, methods, arguments and return codes (spec ``zsl1-udp.md``), on any CPython >= 3.9.

Where robowire differs from the vendor's module it is safer:

- NaN and infinities are refused (``0x3013``, ``sendMotorCmd`` -1) instead of sent to the robot;
  ``last_error`` says why a call returned a non-zero code.
- Getters raise :class:`robowire.NoStateError` before the first state and after the robot went
  silent, instead of returning zeros that look like data.
- A failed bind raises :class:`robowire.BindError` instead of printing and doing nothing.
- A robot silent for 3 s is reported (``checkConnect()`` False) and picked up again when it
  returns; the latched walk is stopped meanwhile.
- ``MotorCommand`` fields are live views: ``cmd.q_des_knee[i] = x`` changes the command, and a
  whole field can be assigned (``cmd.kp_hip = [20.0] * 4``); numpy is not required.

Against the simulator (:class:`robowire.sim.Zsl1`), the vendor's calls and return codes:

>>> import time
>>> import robowire.sim, robowire.zsl1 as mc_sdk_zsl_1_py
>>> with robowire.sim.Zsl1(ip="127.0.0.5") as sim:
...     robot = mc_sdk_zsl_1_py.HighLevel()
...     robot.initRobot("127.0.0.5", 43988, sim.ip)
...     robot.wait_connected(timeout_s=3.0)  # robowire's; the vendor's way polls checkConnect()
...     robot.standUp()
...     while robot.getCurrentCtrlmode() != 1:
...         time.sleep(0.01)
...     robot.move(0.5, 0.0, 0.0)
...     robot.move(float("nan"), 0.0, 0.0) == 0x3013, robot.last_error is not None
...     robot.close()
True
0
0
(True, True)
"""

from ._native import JointArray, MotorCommand, MotorState
from ._native import Zsl1HighLevel as HighLevel
from ._native import Zsl1LowLevel as LowLevel

__all__ = ["HighLevel", "LowLevel", "MotorCommand", "MotorState", "JointArray"]
