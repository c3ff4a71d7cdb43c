//! The fault injection and log of the simulated Unitree robots (`Go2`, `G1`): one fault type
//! (`robowire_sim::unitree::Fault`, as each robot's module re-exports it) behind both.

/// `inject_silence`, `inject_motor_fault`, `inject_bit_flips`, `clear_faults` and `take_log`
/// for `$class`, whose field `sim` is an `Owned` simulator taking `$fault`; its motors are
/// `0..$motors` (`$range` says so in the error).
macro_rules! faults {
    ($class:ty, $fault:path, $motors:expr, $range:literal) => {
        #[pyo3::pymethods]
        impl $class {
            /// Stop `rt/lowstate` (a client's watchdog reports the robot lost).
            fn inject_silence(&self) -> pyo3::PyResult<()> {
                use $fault as Fault;
                self.sim.with(|s| s.inject(Fault::Silence))
            }

            /// Motor `motor` fails: it reports mode 0 and exerts no torque.
            fn inject_motor_fault(&self, motor: usize) -> pyo3::PyResult<()> {
                use $fault as Fault;
                if motor >= $motors {
                    return Err($crate::errors::error(
                        $crate::errors::Kind::Argument,
                        format!("motor {motor}: {}", $range),
                    ));
                }
                self.sim.with(|s| s.inject(Fault::MotorFault { motor }))
            }

            /// Every `every`-th LowState goes out with one bit flipped after its CRC (a client counts
            /// and drops it).
            fn inject_bit_flips(&self, every: u32) -> pyo3::PyResult<()> {
                use $fault as Fault;
                if every == 0 {
                    return Err($crate::errors::error($crate::errors::Kind::Argument, "every must be at least 1"));
                }
                self.sim.with(|s| s.inject(Fault::BitFlips { every }))
            }

            /// Clear every fault.
            fn clear_faults(&self) -> pyo3::PyResult<()> {
                self.sim.with(|s| s.clear_faults())
            }

            /// What the robot did that a user should know, since the last call.
            fn take_log(&self) -> pyo3::PyResult<Vec<String>> {
                self.sim.with(|s| s.take_log())
            }
        }
    };
}

pub(crate) use faults;

/// The physics a simulator's `physics`/`model` arguments ask for (`hanging`: the base held).
#[cfg(feature = "mujoco")]
pub(crate) fn physics_arg(
    physics: bool,
    model: Option<std::path::PathBuf>,
    hanging: bool,
) -> pyo3::PyResult<Option<robowire_sim::physics::PhysicsOptions>> {
    if model.is_some() && !physics {
        return Err(crate::errors::error(crate::errors::Kind::Argument, "model needs physics=True"));
    }
    Ok(physics.then_some(robowire_sim::physics::PhysicsOptions { model, hanging }))
}

/// A wheel without MuJoCo refuses `physics=True`.
#[cfg(not(feature = "mujoco"))]
pub(crate) fn physics_arg(
    physics: bool,
    model: Option<std::path::PathBuf>,
    _hanging: bool,
) -> pyo3::PyResult<Option<()>> {
    if model.is_some() && !physics {
        return Err(crate::errors::error(crate::errors::Kind::Argument, "model needs physics=True"));
    }
    if physics {
        return Err(crate::errors::error(
            crate::errors::Kind::Error,
            "this robowire wheel was built without physics (MuJoCo): build it with the cargo feature `mujoco`",
        ));
    }
    Ok(None)
}

/// The `base`, `sim_time_s` and `wall_time_s` entries of a snapshot.
pub(crate) fn body<'py>(
    py: pyo3::Python<'py>,
    base: Option<robowire_sim::go2::BasePose>,
    sim_time_s: f64,
    wall_time_s: f64,
) -> pyo3::PyResult<pyo3::Bound<'py, pyo3::types::PyDict>> {
    use pyo3::types::PyDictMethods;
    let out = pyo3::types::PyDict::new(py);
    let base = match base {
        Some(b) => Some(crate::stats::dict!(py, {
            "position_m" => b.position_m.to_vec(),
            "velocity_mps" => b.velocity_mps.to_vec(),
            "rpy_rad" => b.rpy_rad.to_vec(),
        })),
        None => None,
    };
    out.set_item("base", base)?;
    out.set_item("sim_time_s", sim_time_s)?;
    out.set_item("wall_time_s", wall_time_s)?;
    Ok(out)
}
