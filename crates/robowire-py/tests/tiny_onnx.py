"""Tiny ONNX models the tests write themselves: protobuf encoded here, no ``onnx`` package."""

import struct


def _varint(n: int) -> bytes:
    out = bytearray()
    while True:
        byte, n = n & 0x7F, n >> 7
        out.append(byte | (0x80 if n else 0))
        if not n:
            return bytes(out)


def _field(number: int, value) -> bytes:
    """One protobuf field: an int as a varint, bytes or str length-delimited."""
    if isinstance(value, int):
        return _varint(number << 3) + _varint(value)
    if isinstance(value, str):
        value = value.encode()
    return _varint(number << 3 | 2) + _varint(len(value)) + value


FLOAT = 1  # TensorProto.DataType.FLOAT


def _value_info(name: str, dims) -> bytes:
    shape = b"".join(_field(1, _field(1, d)) for d in dims)  # TensorShapeProto.dim.dim_value
    tensor_type = _field(1, FLOAT) + _field(2, shape)  # TypeProto.Tensor: elem_type, shape
    return _field(1, name) + _field(2, _field(1, tensor_type))  # ValueInfoProto: name, type


def matmul(path, n_obs: int, n_actions: int, weights) -> None:
    """Writes to ``path`` the model ``actions [1, n_actions] = obs [1, n_obs] · w``, ``weights``
    row-major [n_obs, n_actions]."""
    assert len(weights) == n_obs * n_actions
    node = _field(1, "obs") + _field(1, "w") + _field(2, "actions") + _field(3, "matmul") + _field(4, "MatMul")
    weight = (
        _field(1, n_obs)
        + _field(1, n_actions)
        + _field(2, FLOAT)
        + _field(8, "w")
        + _field(9, struct.pack(f"<{len(weights)}f", *weights))  # raw_data
    )
    graph = (
        _field(1, node)
        + _field(2, "tiny")
        + _field(5, weight)
        + _field(11, _value_info("obs", [1, n_obs]))
        + _field(12, _value_info("actions", [1, n_actions]))
    )
    opset = _field(1, "") + _field(2, 17)
    model = _field(1, 8) + _field(7, graph) + _field(8, opset)  # ir_version, graph, opset_import
    with open(path, "wb") as f:
        f.write(model)
