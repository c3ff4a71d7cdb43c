"""Type stubs of robowire.kmc (see kmc.py)."""

from dataclasses import dataclass
from os import PathLike
from typing import Any, Dict, Iterator, Optional, Tuple, Union

from typing_extensions import Self

from .record import Recorder

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
    speed_mps: float

@dataclass(frozen=True)
class BatteryVoltage:
    motor_id: int
    volts: float

@dataclass(frozen=True)
class MotorState:
    motor_id: int
    id: int
    position_deg: float
    speed_rpm: float
    current_a: float
    temperature_c: float
    error_code: int
    reserved: Tuple[float, float, float]

@dataclass(frozen=True)
class AfResponse:
    motor_id: int
    rw: str
    ids: Tuple[int, ...]
    slots: Tuple[bytes, ...]

@dataclass(frozen=True)
class Odometry:
    x_m: float
    y_m: float
    heading_rad: float
    speed_mps: float
    yaw_rate_radps: float

@dataclass(frozen=True)
class ChassisState:
    speed_mps: Optional[float]
    battery: Optional[BatteryVoltage]
    motors: Tuple[Optional[MotorState], Optional[MotorState]]
    odometry: Odometry

Frame = Union[VehicleSpeed, BatteryVoltage, MotorState, AfResponse]

class Messages:
    """The iterator of Driver.messages()."""
    def __iter__(self) -> Iterator[Frame]: ...
    def __next__(self) -> Frame: ...

class Driver:
    """The chassis's streaming driver, with the vendor's options and defaults."""
    def __init__(
        self,
        port: str,
        *,
        control_rate_hz: float = 100.0,
        vehicle_speed_rate_hz: float = 50.0,
        poll_battery: bool = False,
        poll_allstate: bool = False,
        command_timeout_ms: int = 300,
        stop_burst_count: int = 3,
        realtime_priority: int = -1,
        cpu_affinity: int = -1,
        max_queue: int = 1024,
        lock_memory: bool = False,
        max_speed_mps: float = 20.0,
        reopen: bool = True,
        baud_rate: int = 115200,
        record: Union[str, PathLike[str], Recorder, None] = None,
    ) -> None:
        """record (robowire's): kmc/serial and kmc/serial_skipped into a path (finished by close()) or a Recorder."""
    @property
    def port(self) -> str: ...
    def start(self) -> None:
        """Opens the port and starts streaming (nothing if it streams already); raises PortError."""
    def stop(self) -> None:
        """Stop burst, then both threads end and the port closes; idempotent; start() opens it again."""
    @property
    def is_running(self) -> bool: ...
    @property
    def link_state(self) -> str:
        """stopped, connected or disconnected."""
    @property
    def connection(self) -> str:
        """stopped, waiting, connected or disconnected (no frame for 500 ms)."""
    def set_command(self, velocity_mps: float, yaw_rate_radps: float) -> None:
        """Raises ArgumentError (NaN, inf), ClosedError unless started."""
    def set_command_curvature(self, velocity_mps: float, curvature_per_m: float) -> None: ...
    def set_command_timeout(self, timeout_s: float) -> None:
        """0.001-3600 s, now and for the next start(); raises ArgumentError."""
    def state(self) -> ChassisState:
        """Raises NoStateError before the first frame."""
    @property
    def state_age_s(self) -> Optional[float]: ...
    def wait_state(self, timeout_s: float = 3.0) -> ChassisState:
        """Raises TimeoutError."""
    def try_pop_message(self) -> Optional[Frame]: ...
    def wait_message(self, timeout_s: float = 1.0) -> Optional[Frame]: ...
    def messages(self, timeout_s: Optional[float] = None) -> Messages: ...
    def request_battery_once(self, motor_id: int = 0) -> None: ...
    def request_all_state_once(self, motor_id: int = 0) -> None: ...
    def stats(self) -> Dict[str, Any]: ...
    def close(self) -> None: ...
    def __enter__(self) -> Self: ...
    def __exit__(self, *exc: Any) -> None: ...

class UartClient:
    """One frame at a time over the serial port, no threads."""
    def __init__(self, port: str, *, baud_rate: int = 115200) -> None: ...
    @property
    def port(self) -> str: ...
    def send_pc_control(self, velocity_mps: float, curvature_per_m: float) -> None: ...
    def request_vehicle_speed(self) -> None: ...
    def request_battery_voltage(self, motor_id: int = 0) -> None: ...
    def request_all_state(self, motor_id: int = 0) -> None: ...
    def write_speed_erpm(self, motor_id: int, erpm: float) -> None: ...
    def write_servo_pulse_us(self, motor_id: int, pulse_us: float) -> None: ...
    def system_reset(self, motor_id: int) -> None: ...
    def poll(self, timeout_s: float = 1.0) -> Optional[Frame]: ...
    def close(self) -> None: ...
    def __enter__(self) -> Self: ...
    def __exit__(self, *exc: Any) -> None: ...
