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
