"""A trained locomotion policy (an ONNX model with unitree_rl_gym's deploy config) on a Unitree
G1 or Go2, or on their physics simulators, through the same LowCmd/LowState bytes in both cases:
what ``robowire policy run`` does, from Python. The inference is Rust (tract): no torch.

- :class:`PolicyConfig`: ``PolicyConfig.load(path)`` reads and checks a deploy config; a config
  that disagrees with itself raises :class:`robowire.ArgumentError` with one line naming the field.
- :func:`run`: starts the policy on a robot by address (``g1:eth0``, ``go2:eth0``, or
  ``sim:g1``/``sim:go2`` with ``physics=True``) and returns a :class:`Run`: ``set_command``,
  ``phase``, ``last_step``, ``wait``, ``stop``, and ``close()`` (also at the end of a ``with``
  block), which damps the robot and closes the device.

Any fault (a LowState older than 100 ms, a tilt past ``max_tilt_rad``, an action that is not
finite, a target the robot's rules refuse) damps the robot at once and ends the run.
"""

from ._native import PolicyConfig, Run
from ._native import run_policy as run

__all__ = ["PolicyConfig", "Run", "run"]
