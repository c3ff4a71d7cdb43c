"""The KMC UART wheeled chassis (0xA5 control, 0xB3 speed, 0xAF parameters).

- :class:`Driver`: the vendor's streaming driver (its options and defaults): the latched
  command at 100 Hz, speed polls, a command timeout that stops the chassis, a stop burst on
  ``stop()`` and at the end of a ``with`` block; the chassis's latest :class:`ChassisState`
  (speed, battery, motors, :class:`Odometry`).
- :class:`UartClient`: one frame at a time, no threads.

Frames from the chassis arrive as :class:`VehicleSpeed`, :class:`BatteryVoltage`,
:class:`MotorState` or :class:`AfResponse`.

>>> import robowire.kmc, robowire.sim
>>> with robowire.sim.Chassis() as chassis, robowire.kmc.Driver(chassis.path) as driver:
...     driver.set_command(0.5, 0.0)
...     speed = next(f for f in driver.messages(timeout_s=2.0) if isinstance(f, robowire.kmc.VehicleSpeed))
...     state = driver.wait_state(timeout_s=2.0)
>>> isinstance(speed.speed_mps, float), isinstance(state.odometry.x_m, float)
(True, True)
"""

from dataclasses import dataclass
from typing import Optional, Tuple

from ._native import Driver, Messages, UartClient

__all__ = [
    "Driver",
    "UartClient",
    "Messages",
    "VehicleSpeed",
    "BatteryVoltage",
    "MotorState",
    "AfResponse",
    "ChassisState",
    "Odometry",
]


@dataclass(frozen=True)
class VehicleSpeed:
    """``0xB3`` answer: the vehicle's speed."""

    speed_mps: float
    """Speed, m/s (signed)."""


@dataclass(frozen=True)
class BatteryVoltage:
    """``0xAF`` answer to a battery read (ID 0x07)."""

    motor_id: int
    """Motor controller, 0 (left) or 1 (right)."""
    volts: float
    """Battery voltage, V."""


@dataclass(frozen=True)
class MotorState:
    """``0xAF`` answer to an all-state read (ID 0x06) of one motor controller."""

    motor_id: int
    """Motor controller, 0 (left) or 1 (right)."""
    id: int
    """The controller's own ID word."""
    position_deg: float
    """Rotor position, degrees."""
    speed_rpm: float
    """Speed, rpm."""
    current_a: float
    """Current, A."""
    temperature_c: float
    """Temperature, °C."""
    error_code: int
    """Error bits (0: none)."""
    reserved: Tuple[float, float, float]
    """Three reserved floats, as sent."""


@dataclass(frozen=True)
class AfResponse:
    """Any other well-formed ``0xAF`` frame from the chassis, raw."""

    motor_id: int
    rw: str
    """``"read"`` or ``"write"``."""
    ids: Tuple[int, ...]
    """Parameter IDs."""
    slots: Tuple[bytes, ...]
    """One 4-byte slot per ID, in wire order."""


@dataclass(frozen=True)
class Odometry:
    """x, y and heading integrated from the speed reports and the commanded curvature, since the
    driver started."""

    x_m: float
    """x, m."""
    y_m: float
    """y, m."""
    heading_rad: float
    """Heading, rad, in (-π, π]."""
    speed_mps: float
    """Forward speed, m/s."""
    yaw_rate_radps: float
    """Yaw rate, rad/s."""


@dataclass(frozen=True)
class ChassisState:
    """The chassis as the driver last heard it: the latest of each report, and the odometry."""

    speed_mps: Optional[float]
    """The latest ``0xB3`` speed report, m/s (``None`` before the first)."""
    battery: Optional[BatteryVoltage]
    """The latest battery report."""
    motors: Tuple[Optional[MotorState], Optional[MotorState]]
    """The latest all-state report of motors 0 and 1."""
    odometry: Odometry
    """Pose and velocities."""
