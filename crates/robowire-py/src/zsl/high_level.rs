//! The drop-in `HighLevel` of `robowire.zsl1` and `robowire.zsl1w`: the vendor's methods with
//! the vendor's names, arguments and return codes, over the `zsl` facade.

use super::session::session_methods;
use pyo3::prelude::*;
use zsl::udp::{HighLevel, Model};

use super::session::Session;

type Floats = Vec<f64>;

fn floats<const N: usize>(v: [f32; N]) -> Floats {
    v.iter().map(|x| f64::from(*x)).collect()
}

/// One drop-in `HighLevel` class: the calls both models have, then `$extra` (the model's own).
macro_rules! high_level_class {
    (
        $(#[$doc:meta])*
        $class:ident, $module:literal, $model:expr, { $($extra:tt)* }
    ) => {
        $(#[$doc])*
        #[pyclass(name = "HighLevel", module = $module, frozen)]
        pub(crate) struct $class {
            session: Session<HighLevel>,
        }

        #[allow(non_snake_case)]
        #[pymethods]
        impl $class {
            /// Not connected until `initRobot`. `record` (not the vendor's): a path or a
            /// `robowire.Recorder` to record every datagram both ways into (`zsl1/high_level`).
            #[new]
            #[pyo3(signature = (*, record = None))]
            fn new(record: Option<&Bound<'_, PyAny>>) -> PyResult<Self> {
                Ok(Self { session: Session::new($model, record)? })
            }

            /// Binds `local_ip:local_port` (where the robot sends its state; its
            /// `sdk_config.yaml` `target_port`, 43988 by default) and starts streaming to
            /// `dog_ip:43997` every 2 ms. Raises `BindError` if the address cannot be bound
            /// (the vendor only prints); a second call replaces the first connection.
            #[pyo3(signature = (local_ip, local_port, dog_ip = "192.168.234.1"))]
            fn initRobot(&self, py: Python<'_>, local_ip: &str, local_port: i64, dog_ip: &str) -> PyResult<()> {
                self.session.init(py, local_ip, local_port, dog_ip)
            }

            /// State arrived within the last 3 s. Unlike the vendor's, a client that lost the
            /// robot reconnects by itself when state returns.
            fn checkConnect(&self) -> bool {
                self.session.is_connected()
            }

            /// Stand up (mode 1). 0 queued; 0x3007 refused while moving in mode 18/21 (nothing
            /// sent), or sent but not acknowledged by the robot 11 calls in a row; the robot's
            /// error word if it reports one. `last_error` says which.
            fn standUp(&self) -> PyResult<u32> {
                let c = self.session.running()?.client;
                Ok(self.session.code(c.stand_up()))
            }

            /// Lie down, joints locked (mode 51). Codes as `standUp`.
            fn lieDown(&self) -> PyResult<u32> {
                let c = self.session.running()?.client;
                Ok(self.session.code(c.lie_down()))
            }

            /// Motors damped (mode 0). Refused only by the robot's error word.
            fn passive(&self) -> PyResult<u32> {
                let c = self.session.running()?.client;
                Ok(self.session.code(c.passive()))
            }

            /// Walk at `vx` m/s forward, `vy` m/s left, `yaw_rate` rad/s; latched until
            /// replaced (`move(0, 0, 0)` stops). Each |value| 0 or in its band: vx 0.05–3.0
            /// (ZSL-1W 3.7), vy 0.1–1.0, yaw rate 0.02–3.0 (ZSL-1W 0.1–3.0). 0 queued; 0x3013
            /// out of range, NaN or infinite (nothing sent; the vendor sends NaN); 0x3007 lying
            /// down or during a two-leg stand.
            #[pyo3(name = "move")]
            fn move_(&self, vx: f32, vy: f32, yaw_rate: f32) -> PyResult<u32> {
                let c = self.session.running()?.client;
                Ok(self.session.code(c.move_velocity(vx, vy, yaw_rate)))
            }

            /// Shake hands (mode 1, action 11, sent for 6 datagrams). 0x3007 while moving.
            fn shakeHand(&self) -> PyResult<u32> {
                let c = self.session.running()?.client;
                Ok(self.session.code(c.shake_hand()))
            }

            /// Body attitude rates, each |value| ≤ 0.6 (rad/s, rad/s, rad/s, m/s). The
            /// arguments keep the vendor's names and order, which is the order on the wire:
            /// the first is sent as the roll rate, the second pitch, the third yaw (spec
            /// `zsl1-udp.md` §5.2). 0x3007 when lying down, moving outside mode 21, or |roll|
            /// above 1 rad.
            fn attitudeControl(
                &self,
                yaw_vel: f32,
                roll_vel: f32,
                pitch_vel: f32,
                height_vel: f32,
            ) -> PyResult<u32> {
                let c = self.session.running()?.client;
                Ok(self.session.code(c.attitude_control(yaw_vel, roll_vel, pitch_vel, height_vel)))
            }

            /// Orientation quaternion w, x, y, z. Raises `NoStateError` without state (the
            /// vendor returns zeros).
            fn getQuaternion(&self) -> PyResult<Floats> {
                self.session.read(|c| c.quaternion().map(floats))
            }

            /// Roll, pitch, yaw, rad.
            fn getRPY(&self) -> PyResult<Floats> {
                self.session.read(|c| c.rpy().map(floats))
            }

            /// Body acceleration x, y, z, m/s².
            fn getBodyAcc(&self) -> PyResult<Floats> {
                self.session.read(|c| c.body_acc().map(floats))
            }

            /// Body angular rate x, y, z, rad/s.
            fn getBodyGyro(&self) -> PyResult<Floats> {
                self.session.read(|c| c.body_gyro().map(floats))
            }

            /// Position x, y, z, m.
            fn getPosition(&self) -> PyResult<Floats> {
                self.session.read(|c| c.position().map(floats))
            }

            /// World-frame velocity x, y, z, m/s.
            fn getWorldVelocity(&self) -> PyResult<Floats> {
                self.session.read(|c| c.world_velocity().map(floats))
            }

            /// Body-frame velocity x, y, z, m/s.
            fn getBodyVelocity(&self) -> PyResult<Floats> {
                self.session.read(|c| c.body_velocity().map(floats))
            }

            /// Battery level, % (0–100).
            fn getBatteryPower(&self) -> PyResult<u32> {
                self.session.read(HighLevel::battery_percent)
            }

            /// The robot's control mode: 0 passive, 1 standing, 10/51 lying, 18 moving,
            /// 21 action.
            fn getCurrentCtrlmode(&self) -> PyResult<u32> {
                self.session.read(|c| c.control_mode().map(|m| m.raw()))
            }

            /// Abad joint angles, rad, legs FR, FL, RR, RL.
            fn getLegAbadJoint(&self) -> PyResult<Floats> {
                self.session.read(|c| c.leg_abad_joint().map(floats))
            }

            /// Hip joint angles, rad.
            fn getLegHipJoint(&self) -> PyResult<Floats> {
                self.session.read(|c| c.leg_hip_joint().map(floats))
            }

            /// Knee joint angles, rad.
            fn getLegKneeJoint(&self) -> PyResult<Floats> {
                self.session.read(|c| c.leg_knee_joint().map(floats))
            }

            /// Abad joint velocities, rad/s.
            fn getLegAbadJointVel(&self) -> PyResult<Floats> {
                self.session.read(|c| c.leg_abad_joint_vel().map(floats))
            }

            /// Hip joint velocities, rad/s.
            fn getLegHipJointVel(&self) -> PyResult<Floats> {
                self.session.read(|c| c.leg_hip_joint_vel().map(floats))
            }

            /// Knee joint velocities, rad/s.
            fn getLegKneeJointVel(&self) -> PyResult<Floats> {
                self.session.read(|c| c.leg_knee_joint_vel().map(floats))
            }

            /// Abad joint torques, N·m.
            fn getLegAbadJointTorque(&self) -> PyResult<Floats> {
                self.session.read(|c| c.leg_abad_joint_torque().map(floats))
            }

            /// Hip joint torques, N·m.
            fn getLegHipJointTorque(&self) -> PyResult<Floats> {
                self.session.read(|c| c.leg_hip_joint_torque().map(floats))
            }

            /// Knee joint torques, N·m.
            fn getLegKneeJointTorque(&self) -> PyResult<Floats> {
                self.session.read(|c| c.leg_knee_joint_torque().map(floats))
            }

            $($extra)*
        }
    };
}

high_level_class! {
    /// The ZSL-1 HighLevel client, a drop-in for `mc_sdk_zsl_1_py.HighLevel`: the vendor's
    /// methods, arguments and return codes. Where robowire differs, it is safer: NaN and
    /// infinities are refused (0x3013) instead of sent, getters raise `NoStateError` instead
    /// of returning zeros, a failed bind raises `BindError`, and a robot that went silent is
    /// picked up again when it returns.
    Zsl1HighLevel, "robowire.zsl1", Model::Zsl1, {
        /// Jump (mode 21, action 5, sent for 6 datagrams). 0x3007 lying down or moving.
        fn jump(&self) -> PyResult<u32> {
            let c = self.session.running()?.client;
            Ok(self.session.code(c.jump()))
        }

        /// Jump forward (mode 21, action 6). Codes as `jump`.
        fn frontJump(&self) -> PyResult<u32> {
            let c = self.session.running()?.client;
            Ok(self.session.code(c.front_jump()))
        }

        /// Backflip (mode 21, action 2). Codes as `jump`.
        fn backflip(&self) -> PyResult<u32> {
            let c = self.session.running()?.client;
            Ok(self.session.code(c.backflip()))
        }

        /// Stand on the hind legs (sticky until `cancelTwoLegStand`) moving at `vx` m/s
        /// (|vx| 0 or 0.2–0.5) and `yaw_rate` rad/s (0 or 0.2–1.0).
        fn twoLegStand(&self, vx: f32, yaw_rate: f32) -> PyResult<u32> {
            let c = self.session.running()?.client;
            Ok(self.session.code(c.two_leg_stand(vx, yaw_rate)))
        }

        /// End a two-leg stand (mode 21, action 0). Returns nothing, like the vendor's; raises
        /// `robowire.Error` if the client stopped on the robot's SDK-mismatch flag.
        fn cancelTwoLegStand(&self) -> PyResult<()> {
            let c = self.session.running()?.client;
            super::unit(&self.session, c.cancel_two_leg_stand())
        }
    }
}

high_level_class! {
    /// The ZSL-1W (wheel-legged) HighLevel client, a drop-in for `mc_sdk_zsl_1w_py.HighLevel`:
    /// the vendor's ZSL-1W method set (crawl, climb, the foot/wheel joints; no jumps or two-leg
    /// stand). Commands carry the ZSL-1W magic 0x5AA6.
    Zsl1wHighLevel, "robowire.zsl1w", Model::Zsl1W, {
        /// Crawl (mode 18, action 17, sticky until `cancelCrawl`); `move`'s ranges.
        fn crawl(&self, vx: f32, vy: f32, yaw_rate: f32) -> PyResult<u32> {
            let c = self.session.running()?.client;
            Ok(self.session.code(c.crawl(vx, vy, yaw_rate)))
        }

        /// Climb (mode 18, action 16, sticky until `cancelClimb`); `move`'s ranges.
        fn climb(&self, vx: f32, vy: f32, yaw_rate: f32) -> PyResult<u32> {
            let c = self.session.running()?.client;
            Ok(self.session.code(c.climb(vx, vy, yaw_rate)))
        }

        /// End a crawl (mode 18, action 0). Returns nothing, like the vendor's.
        fn cancelCrawl(&self) -> PyResult<()> {
            let c = self.session.running()?.client;
            super::unit(&self.session, c.cancel_crawl())
        }

        /// End a climb (the same datagram as `cancelCrawl`).
        fn cancelClimb(&self) -> PyResult<()> {
            let c = self.session.running()?.client;
            super::unit(&self.session, c.cancel_climb())
        }

        /// Foot/wheel joint angles, legs FR, FL, RR, RL.
        fn getLegFootJoint(&self) -> PyResult<Floats> {
            self.session.read(|c| c.leg_foot_joint().map(floats))
        }

        /// Foot/wheel joint velocities.
        fn getLegFootJointVel(&self) -> PyResult<Floats> {
            self.session.read(|c| c.leg_foot_joint_vel().map(floats))
        }

        /// Foot/wheel joint torques.
        fn getLegFootJointTorque(&self) -> PyResult<Floats> {
            self.session.read(|c| c.leg_foot_joint_torque().map(floats))
        }
    }
}

session_methods!(Zsl1HighLevel);
session_methods!(Zsl1wHighLevel);
