"""MotorCommand / MotorState fields behave as the vendor's numpy arrays do where it matters:
element and slice assignment change the command; numpy converts them; numpy is not needed."""

import subprocess
import sys
import textwrap

import pytest

import robowire
from robowire.zsl1 import JointArray, MotorCommand, MotorState

COMMAND_FIELDS = [
    f"{q}_{j}" for q in ("q_des", "qd_des", "kp", "kd") for j in ("abad", "hip", "knee")
] + [f"tau_{j}_ff" for j in ("abad", "hip", "knee")]
STATE_FIELDS = [f"{q}_{j}" for q in ("q", "qd") for j in ("abad", "hip", "knee")] + [
    f"tau_{j}_fb" for j in ("abad", "hip", "knee")
]


def test_the_vendors_field_names_all_zero():
    cmd, state = MotorCommand(), MotorState()
    for name in COMMAND_FIELDS:
        assert list(getattr(cmd, name)) == [0.0] * 4, name
    for name in STATE_FIELDS:
        assert list(getattr(state, name)) == [0.0] * 4, name
    assert set(cmd.to_dict()) == set(COMMAND_FIELDS)


def test_element_assignment_changes_the_command():
    cmd = MotorCommand()
    cmd.q_des_knee[2] = -1.25
    cmd.q_des_knee[-1] = -1.5
    view = cmd.kp_hip
    view[0] = 30.0
    assert list(cmd.q_des_knee) == [0.0, 0.0, -1.25, -1.5]
    assert cmd.kp_hip[0] == 30.0
    assert isinstance(cmd.q_des_knee, JointArray)


def test_values_are_float32_like_the_vendors_arrays():
    cmd = MotorCommand()
    cmd.q_des_abad[0] = 0.1
    assert cmd.q_des_abad[0] == 0.10000000149011612


def test_slices_read_and_write_without_changing_the_length():
    cmd = MotorCommand()
    cmd.tau_hip_ff[1:3] = [1.0, 2.0]
    assert cmd.tau_hip_ff[:] == [0.0, 1.0, 2.0, 0.0]
    assert cmd.tau_hip_ff[::2] == [0.0, 2.0]
    cmd.tau_hip_ff[:] = (4, 3, 2, 1)
    assert list(reversed(list(cmd.tau_hip_ff))) == [1.0, 2.0, 3.0, 4.0]
    with pytest.raises(robowire.ArgumentError, match="4"):
        cmd.tau_hip_ff[0:2] = [1.0]


def test_whole_fields_can_be_assigned_and_are_checked():
    cmd = MotorCommand()
    cmd.kd_knee = [1, 2, 3, 4]
    assert cmd.kd_knee == [1.0, 2.0, 3.0, 4.0]
    with pytest.raises(robowire.ArgumentError, match="kd_knee takes 4 values"):
        cmd.kd_knee = [1, 2, 3]
    with pytest.raises(TypeError):
        cmd.kd_knee = ["a", "b", "c", "d"]
    with pytest.raises(TypeError):
        cmd.kd_knee[0] = "fast"
    with pytest.raises(IndexError):
        cmd.kd_knee[4] = 1.0
    with pytest.raises(AttributeError):
        cmd.not_a_field = 1
    assert cmd.kd_knee == [1.0, 2.0, 3.0, 4.0]  # nothing changed by the refusals


def test_len_iteration_tolist_and_equality():
    state = MotorState()
    state.q_hip[:] = [0.5, 0.25, 0.125, 0.0625]
    assert len(state.q_hip) == 4
    assert [x for x in state.q_hip] == [0.5, 0.25, 0.125, 0.0625]
    assert state.q_hip.tolist() == [0.5, 0.25, 0.125, 0.0625]
    assert state.q_hip == (0.5, 0.25, 0.125, 0.0625)
    assert state.q_hip != [0.0] * 4
    assert "JointArray([0.5, 0.25, 0.125, 0.0625])" == repr(state.q_hip)
    other = MotorState()
    other.q_hip = state.q_hip
    assert other == state


def test_numpy_converts_a_field():
    numpy = pytest.importorskip("numpy")
    cmd = MotorCommand()
    cmd.q_des_hip[:] = [0.7, 0.8, 0.9, 1.0]
    array = numpy.asarray(cmd.q_des_hip)
    assert array.dtype == numpy.float32
    assert array.tolist() == pytest.approx([0.7, 0.8, 0.9, 1.0])
    assert numpy.asarray(cmd.q_des_hip, dtype=numpy.float64).dtype == numpy.float64
    cmd.kp_knee = numpy.full(4, 25.0)  # numpy arrays assign too
    assert cmd.kp_knee == [25.0] * 4


def test_numpy_is_not_needed():
    script = textwrap.dedent(
        """
        import sys
        sys.modules["numpy"] = None  # any import of numpy fails
        from robowire.zsl1 import MotorCommand
        cmd = MotorCommand()
        cmd.q_des_knee[1] = -1.0
        cmd.kp_hip = [10.0] * 4
        assert list(cmd.q_des_knee) == [0.0, -1.0, 0.0, 0.0]
        try:
            cmd.q_des_knee.__array__()
        except ImportError:
            print("numpy asked for only by __array__")
        """
    )
    out = subprocess.run([sys.executable, "-c", script], check=True, capture_output=True, text=True)
    assert "only by __array__" in out.stdout
