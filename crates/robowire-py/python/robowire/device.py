"""Any device by its address, in the one shape every robowire app drives.

:func:`open` takes an address (``kmc:/dev/ttyUSB0``, ``zsl1:192.168.234.1``, ``zsl1w:IP``,
``go2:eth0``, ``hg:eth0``, or a simulator started in this process: ``sim:kmc``, ``sim:zsl1``,
``sim:zsl1w``, ``sim:go2``) and returns a :class:`Device`: its status (the fields of
``robowire status --json``), its connection, a device-neutral observation (odometry, IMU, joints,
battery, motors), ``drive`` for mobile bases, its named services, and ``close()`` with the
device's safe action (a stop burst, a stop, damping), also at the end of a ``with`` block.

>>> import robowire
>>> with robowire.open("sim:zsl1") as dog:
...     dog.wait_state(timeout_s=5.0)
...     dog.services
...     sorted(dog.observe())
True
['stand_up', 'lie_down', 'passive']
['battery', 'imu', 'joints', 'motors', 'odometry', 'passthrough']
"""

from ._native import Device, open

__all__ = ["Device", "open"]
