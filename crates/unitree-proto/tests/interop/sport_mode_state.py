"""Unitree's own IDL class of the Go2 SportModeState_ (cyclonedds' serializer): a sample with a
distinct value in every field (floats exact in float32), serialized in XCDR1 and XCDR2, printed
as one JSON line for tests/it/sport_mode_state.rs and tests/it/omgidl.rs."""
import dataclasses
import json

import numpy as np

from unitree_sdk2py.idl.unitree_go.msg.dds_ import IMUState_, PathPoint_, SportModeState_, TimeSpec_

n = 0


def f32s(count):
    """The next `count` floats of the sequence float32(k * 0.731 - 97.25) (k = 1, 2, ...; every
    mantissa bit in use)."""
    global n
    values = [float(np.float32((n + i + 1) * 0.731 - 97.25)) for i in range(count)]
    n += count
    return values


sample = SportModeState_(
    stamp=TimeSpec_(sec=-123456, nanosec=987654321),
    error_code=0xDEADBEEF,
    imu_state=IMUState_(quaternion=f32s(4), gyroscope=f32s(3), accelerometer=f32s(3), rpy=f32s(3), temperature=201),
    mode=7,
    progress=f32s(1)[0],
    gait_type=3,
    foot_raise_height=f32s(1)[0],
    position=f32s(3),
    body_height=f32s(1)[0],
    velocity=f32s(3),
    yaw_speed=f32s(1)[0],
    range_obstacle=f32s(4),
    foot_force=[-1, 300, -32768, 32767],
    foot_position_body=f32s(12),
    foot_speed_body=f32s(12),
    path_point=[PathPoint_(*f32s(7)) for _ in range(10)],
)
print(json.dumps({
    "fields": dataclasses.asdict(sample),
    "xcdr1": sample.serialize().hex(),
    "xcdr2": sample.serialize(use_version_2=True).hex(),
}))
