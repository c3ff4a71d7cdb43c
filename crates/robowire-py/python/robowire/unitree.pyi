"""Type stubs of robowire.unitree (see unitree.py). Nested structs are StructView at run time;
the `_MotorCmd`-style classes here only give editors their fields."""

from typing import Any, ClassVar, Dict, Generic, Iterator, List, Literal, Mapping, TypeVar, Union, overload

Buffer = Union[bytes, bytearray, memoryview]
_T = TypeVar("_T")

__all__ = ["LowCmd", "LowState", "HgLowCmd", "HgLowState", "StructView", "ArrayView"]

class StructView:
    """A nested struct of a message: its IDL fields as attributes, writing through."""
    @property
    def __idl_name__(self) -> str: ...
    def to_dict(self) -> Dict[str, Any]: ...
    def __getattr__(self, name: str) -> Any: ...

class ArrayView(Generic[_T]):
    """An array field: fixed length; elements are values or StructViews; writes through."""
    def __len__(self) -> int: ...
    @overload
    def __getitem__(self, index: int) -> _T: ...
    @overload
    def __getitem__(self, index: slice) -> List[_T]: ...
    @overload
    def __setitem__(self, index: int, value: Any) -> None: ...
    @overload
    def __setitem__(self, index: slice, value: Any) -> None: ...
    def __iter__(self) -> Iterator[_T]: ...
    def tolist(self) -> List[Any]: ...
    def __array__(self, dtype: Any = None, copy: Any = None) -> Any: ...


class _MotorCmd(StructView):
    mode: int
    q: float
    dq: float
    tau: float
    kp: float
    kd: float
    reserve: ArrayView[int]

class _BmsCmd(StructView):
    off: int
    reserve: ArrayView[int]

class _ImuState(StructView):
    quaternion: ArrayView[float]
    gyroscope: ArrayView[float]
    accelerometer: ArrayView[float]
    rpy: ArrayView[float]
    temperature: int

class _MotorState(StructView):
    mode: int
    q: float
    dq: float
    ddq: float
    tau_est: float
    q_raw: float
    dq_raw: float
    ddq_raw: float
    temperature: int
    lost: int
    reserve: ArrayView[int]

class _BmsState(StructView):
    version_high: int
    version_low: int
    status: int
    soc: int
    current: int
    cycle: int
    bq_ntc: ArrayView[int]
    mcu_ntc: ArrayView[int]
    cell_vol: ArrayView[int]

class _HgMotorCmd(StructView):
    mode: int
    q: float
    dq: float
    tau: float
    kp: float
    kd: float
    reserve: int

class _HgImuState(StructView):
    quaternion: ArrayView[float]
    gyroscope: ArrayView[float]
    accelerometer: ArrayView[float]
    rpy: ArrayView[float]
    temperature: int

class _HgMotorState(StructView):
    mode: int
    q: float
    dq: float
    ddq: float
    tau_est: float
    temperature: ArrayView[int]
    vol: float
    sensor: ArrayView[int]
    motorstate: int
    reserve: ArrayView[int]

class LowCmd:
    """Go2 `unitree_go::msg::dds_::LowCmd_` (812-byte image, topic `rt/lowcmd`)."""
    head: ArrayView[int]
    level_flag: int
    frame_reserve: int
    sn: ArrayView[int]
    version: ArrayView[int]
    bandwidth: int
    motor_cmd: ArrayView[_MotorCmd]
    bms_cmd: _BmsCmd
    wireless_remote: ArrayView[int]
    led: ArrayView[int]
    fan: ArrayView[int]
    gpio: int
    reserve: int
    crc: int

    IMAGE_LEN: ClassVar[int]
    """Struct image length, bytes."""
    DDS_TYPE_NAME: ClassVar[str]
    TOPIC: ClassVar[str]
    def __init__(self, **fields: Any) -> None:
        """The safe default (LowCmd: head FE EF, level_flag 0xFF, every motor holding nothing;
        the others all zero), then the given IDL fields."""
    @staticmethod
    def zeroed() -> LowCmd:
        """Every field zero (the IDL default)."""
    def encode(self) -> bytes:
        """The struct image: padding zeroed, CRC written (into this object too)."""
    def __bytes__(self) -> bytes: ...
    def encode_cdr(self, encoding: Literal["xcdr1", "xcdr2"] = "xcdr1") -> bytes:
        """The DDS payload (encapsulation header and CDR body), CRC written."""
    @staticmethod
    def decode(data: Buffer, *, verify: bool = True) -> LowCmd:
        """From a struct image; raises DecodeError or CrcError (verify=False decodes anyway)."""
    @staticmethod
    def decode_cdr(data: Buffer, *, verify: bool = True) -> LowCmd:
        """From a DDS payload (XCDR1 or XCDR2); errors as decode."""
    def to_dict(self) -> Dict[str, Any]:
        """What `robowire decode --json` prints."""
    @staticmethod
    def from_dict(fields: Mapping[str, Any]) -> LowCmd:
        """From to_dict()'s shape; raises ArgumentError naming what is wrong."""
    def computed_crc(self) -> int:
        """The CRC of the zero-padded image."""
    def copy(self) -> LowCmd: ...
    def __copy__(self) -> LowCmd: ...
    def __deepcopy__(self, memo: Any) -> LowCmd: ...

class LowState:
    """Go2 `unitree_go::msg::dds_::LowState_` (1180-byte image, topic `rt/lowstate`)."""
    head: ArrayView[int]
    level_flag: int
    frame_reserve: int
    sn: ArrayView[int]
    version: ArrayView[int]
    bandwidth: int
    imu_state: _ImuState
    motor_state: ArrayView[_MotorState]
    bms_state: _BmsState
    foot_force: ArrayView[int]
    foot_force_est: ArrayView[int]
    tick: int
    wireless_remote: ArrayView[int]
    bit_flag: int
    adc_reel: float
    temperature_ntc1: int
    temperature_ntc2: int
    power_v: float
    power_a: float
    fan_frequency: ArrayView[int]
    reserve: int
    crc: int

    IMAGE_LEN: ClassVar[int]
    """Struct image length, bytes."""
    DDS_TYPE_NAME: ClassVar[str]
    TOPIC: ClassVar[str]
    def __init__(self, **fields: Any) -> None:
        """The safe default (LowCmd: head FE EF, level_flag 0xFF, every motor holding nothing;
        the others all zero), then the given IDL fields."""
    @staticmethod
    def zeroed() -> LowState:
        """Every field zero (the IDL default)."""
    def encode(self) -> bytes:
        """The struct image: padding zeroed, CRC written (into this object too)."""
    def __bytes__(self) -> bytes: ...
    def encode_cdr(self, encoding: Literal["xcdr1", "xcdr2"] = "xcdr1") -> bytes:
        """The DDS payload (encapsulation header and CDR body), CRC written."""
    @staticmethod
    def decode(data: Buffer, *, verify: bool = True) -> LowState:
        """From a struct image; raises DecodeError or CrcError (verify=False decodes anyway)."""
    @staticmethod
    def decode_cdr(data: Buffer, *, verify: bool = True) -> LowState:
        """From a DDS payload (XCDR1 or XCDR2); errors as decode."""
    def to_dict(self) -> Dict[str, Any]:
        """What `robowire decode --json` prints."""
    @staticmethod
    def from_dict(fields: Mapping[str, Any]) -> LowState:
        """From to_dict()'s shape; raises ArgumentError naming what is wrong."""
    def computed_crc(self) -> int:
        """The CRC of the zero-padded image."""
    def copy(self) -> LowState: ...
    def __copy__(self) -> LowState: ...
    def __deepcopy__(self, memo: Any) -> LowState: ...

class HgLowCmd:
    """HG (G1, H1-2) `unitree_hg::msg::dds_::LowCmd_` (1004-byte image)."""
    mode_pr: int
    mode_machine: int
    motor_cmd: ArrayView[_HgMotorCmd]
    reserve: ArrayView[int]
    crc: int

    IMAGE_LEN: ClassVar[int]
    """Struct image length, bytes."""
    DDS_TYPE_NAME: ClassVar[str]
    TOPIC: ClassVar[str]
    def __init__(self, **fields: Any) -> None:
        """The safe default (LowCmd: head FE EF, level_flag 0xFF, every motor holding nothing;
        the others all zero), then the given IDL fields."""
    @staticmethod
    def zeroed() -> HgLowCmd:
        """Every field zero (the IDL default)."""
    def encode(self) -> bytes:
        """The struct image: padding zeroed, CRC written (into this object too)."""
    def __bytes__(self) -> bytes: ...
    def encode_cdr(self, encoding: Literal["xcdr1", "xcdr2"] = "xcdr1") -> bytes:
        """The DDS payload (encapsulation header and CDR body), CRC written."""
    @staticmethod
    def decode(data: Buffer, *, verify: bool = True) -> HgLowCmd:
        """From a struct image; raises DecodeError or CrcError (verify=False decodes anyway)."""
    @staticmethod
    def decode_cdr(data: Buffer, *, verify: bool = True) -> HgLowCmd:
        """From a DDS payload (XCDR1 or XCDR2); errors as decode."""
    def to_dict(self) -> Dict[str, Any]:
        """What `robowire decode --json` prints."""
    @staticmethod
    def from_dict(fields: Mapping[str, Any]) -> HgLowCmd:
        """From to_dict()'s shape; raises ArgumentError naming what is wrong."""
    def computed_crc(self) -> int:
        """The CRC of the zero-padded image."""
    def copy(self) -> HgLowCmd: ...
    def __copy__(self) -> HgLowCmd: ...
    def __deepcopy__(self, memo: Any) -> HgLowCmd: ...

class HgLowState:
    """HG (G1, H1-2) `unitree_hg::msg::dds_::LowState_` (2092-byte image)."""
    version: ArrayView[int]
    mode_pr: int
    mode_machine: int
    tick: int
    imu_state: _HgImuState
    motor_state: ArrayView[_HgMotorState]
    wireless_remote: ArrayView[int]
    reserve: ArrayView[int]
    crc: int

    IMAGE_LEN: ClassVar[int]
    """Struct image length, bytes."""
    DDS_TYPE_NAME: ClassVar[str]
    TOPIC: ClassVar[str]
    def __init__(self, **fields: Any) -> None:
        """The safe default (LowCmd: head FE EF, level_flag 0xFF, every motor holding nothing;
        the others all zero), then the given IDL fields."""
    @staticmethod
    def zeroed() -> HgLowState:
        """Every field zero (the IDL default)."""
    def encode(self) -> bytes:
        """The struct image: padding zeroed, CRC written (into this object too)."""
    def __bytes__(self) -> bytes: ...
    def encode_cdr(self, encoding: Literal["xcdr1", "xcdr2"] = "xcdr1") -> bytes:
        """The DDS payload (encapsulation header and CDR body), CRC written."""
    @staticmethod
    def decode(data: Buffer, *, verify: bool = True) -> HgLowState:
        """From a struct image; raises DecodeError or CrcError (verify=False decodes anyway)."""
    @staticmethod
    def decode_cdr(data: Buffer, *, verify: bool = True) -> HgLowState:
        """From a DDS payload (XCDR1 or XCDR2); errors as decode."""
    def to_dict(self) -> Dict[str, Any]:
        """What `robowire decode --json` prints."""
    @staticmethod
    def from_dict(fields: Mapping[str, Any]) -> HgLowState:
        """From to_dict()'s shape; raises ArgumentError naming what is wrong."""
    def computed_crc(self) -> int:
        """The CRC of the zero-padded image."""
    def copy(self) -> HgLowState: ...
    def __copy__(self) -> HgLowState: ...
    def __deepcopy__(self, memo: Any) -> HgLowState: ...
