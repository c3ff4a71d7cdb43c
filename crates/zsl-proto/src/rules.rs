//! The vendor client's rules as pure functions (spec §5.3, §9), shared by robowire's client
//! facade and the dog simulator: argument ranges with the 1e-6 zero band, the mode gate, the
//! "robot is running" test, the 11-call acknowledgement counter, the 6-datagram action clear,
//! and the LowLevel position bounds. robowire additionally refuses NaN (spec decision 1).

use robowire_core::{NonFinite, finite};

use crate::udp::{Action, ControlMode, HighLevelCommand, Model, MotorCommand, ReturnCode};

/// |v| at or below this counts as zero and is always allowed.
pub const ZERO_TOLERANCE: f64 = 1e-6;

/// Why an argument is refused.
#[derive(Debug, Clone, Copy, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum ArgumentError {
    /// NaN or an infinity (the vendor sends NaN; robowire does not).
    #[error(transparent)]
    NonFinite(#[from] NonFinite),
    /// |value| outside the allowed band (the vendor's 0x3013).
    #[error("{name} = {value} is outside the allowed |v| of 0 or {min}..={max}")]
    OutOfRange {
        /// Argument name.
        name: &'static str,
        /// Value given.
        value: f32,
        /// Smallest allowed non-zero |v|.
        min: f64,
        /// Largest allowed |v|.
        max: f64,
    },
    /// A LowLevel position outside the vendor's inclusive f64 bounds (the vendor's -1).
    #[error("{name}[{leg}] = {value} rad is outside {min}..={max} rad")]
    Position {
        /// Field name.
        name: &'static str,
        /// Leg index.
        leg: usize,
        /// Value given.
        value: f32,
        /// Lower bound.
        min: f64,
        /// Upper bound.
        max: f64,
    },
}

impl ArgumentError {
    /// The vendor's return code for this refusal (0x3013 for ranges and infinities).
    pub fn return_code(&self) -> ReturnCode {
        ReturnCode::SpeedTooLarge
    }
}

/// An allowed |v| band: zero, or `min ..= max` (each with the 1e-6 tolerance).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Range {
    /// Argument name.
    pub name: &'static str,
    /// Smallest non-zero |v| (0 for none).
    pub min: f64,
    /// Largest |v|.
    pub max: f64,
}

impl Range {
    /// Checks `value` like the vendor (|v| as f64, 1e-6 tolerance), refusing NaN and infinities.
    pub fn check(&self, value: f32) -> Result<f32, ArgumentError> {
        finite(self.name, value)?;
        let v = f64::from(value).abs();
        if v <= ZERO_TOLERANCE || (self.min - ZERO_TOLERANCE <= v && v <= self.max + ZERO_TOLERANCE) {
            Ok(value)
        } else {
            Err(ArgumentError::OutOfRange { name: self.name, value, min: self.min, max: self.max })
        }
    }
}

const fn range(name: &'static str, min: f64, max: f64) -> Range {
    Range { name, min, max }
}

/// `move` ranges (vx, vy, yaw rate) of a model. ZSL-1W: vx 0.05..3.7 and yaw 0.1..3.0 were
/// measured; its vy range was not, so the ZSL-1 band is used (spec §10, U).
pub const fn move_ranges(model: Model) -> [Range; 3] {
    match model {
        Model::Zsl1 => [range("vx", 0.05, 3.0), range("vy", 0.1, 1.0), range("yaw_rate", 0.02, 3.0)],
        Model::Zsl1W => [range("vx", 0.05, 3.7), range("vy", 0.1, 1.0), range("yaw_rate", 0.1, 3.0)],
    }
}

/// `twoLegStand` ranges (vx, yaw rate).
pub const TWO_LEG_STAND_RANGES: [Range; 2] = [range("vx", 0.2, 0.5), range("yaw_rate", 0.2, 1.0)];

/// `attitudeControl` ranges (roll, pitch, yaw, height rates): |v| ≤ 0.6, no lower bound.
pub const ATTITUDE_RANGES: [Range; 4] = [
    range("roll_rate", 0.0, 0.6),
    range("pitch_rate", 0.0, 0.6),
    range("yaw_rate", 0.0, 0.6),
    range("height_rate", 0.0, 0.6),
];

/// Checks each argument against its range, in order.
pub fn check_all<const N: usize>(ranges: &[Range; N], values: [f32; N]) -> Result<[f32; N], ArgumentError> {
    for (range, value) in ranges.iter().zip(values) {
        range.check(value)?;
    }
    Ok(values)
}

/// LowLevel position bounds `[min, max]` (inclusive, compared as f64) for abad, hip, knee.
/// At f32, -2.9 and -0.65 both fail the knee bounds: as f64 they are just outside.
pub const POSITION_BOUNDS: [(&str, f64, f64); 3] =
    [("q_des_abad", -0.7, 0.7), ("q_des_hip", -1.15, 3.0), ("q_des_knee", -2.9, -0.65)];

/// The vendor's `sendMotorCmd` check plus robowire's: all 60 floats finite, positions within
/// [`POSITION_BOUNDS`]. The all-zero command fails (knee 0 is out of range).
pub fn check_motor_command(command: &MotorCommand) -> Result<(), ArgumentError> {
    let groups: [(&str, &[[zerocopy::little_endian::F32; 4]; 3]); 5] = [
        ("q_des", &command.q_des),
        ("qd_des", &command.qd_des),
        ("kp", &command.kp),
        ("kd", &command.kd),
        ("tau_ff", &command.tau_ff),
    ];
    for (name, arrays) in groups {
        for legs in arrays {
            for v in legs {
                finite(name, v.get())?;
            }
        }
    }
    for (joint, (name, min, max)) in POSITION_BOUNDS.iter().enumerate() {
        for (leg, q) in command.q_des[joint].iter().enumerate() {
            let v = f64::from(q.get());
            if !(*min <= v && v <= *max) {
                return Err(ArgumentError::Position { name, leg, value: q.get(), min: *min, max: *max });
            }
        }
    }
    Ok(())
}

/// The mode gate of `move`, tricks, `twoLegStand`, `attitudeControl`: refused while the robot
/// reports 0, 10 or 51 (lying); every other value passes, undefined ones included.
pub fn mode_gate_passes(state_mode: ControlMode) -> bool {
    !matches!(state_mode, ControlMode::Passive | ControlMode::LieDownFree | ControlMode::LieDown)
}

/// "Robot is running": |body vx| > 0.2 or |body vy| > 0.2 or |gyro z| > 0.2.
pub fn is_running(body_vx_mps: f32, body_vy_mps: f32, gyro_z_radps: f32) -> bool {
    body_vx_mps.abs() > 0.2 || body_vy_mps.abs() > 0.2 || gyro_z_radps.abs() > 0.2
}

/// Per-call acknowledgement counter (spec §9.1 step 7): the call returns 0 while the robot's
/// mode differs from the target, except on the 11th miss in a row, which returns 0x3007.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct AckCounter {
    misses: u32,
}

impl AckCounter {
    /// Misses before the one that reports 0x3007.
    pub const LIMIT: u32 = 11;

    /// The return code of a call whose target mode is `target`, the robot reporting `state`.
    pub fn on_call(&mut self, state: ControlMode, target: ControlMode) -> ReturnCode {
        if state == target {
            self.misses = 0;
            return ReturnCode::Queued;
        }
        self.misses += 1;
        if self.misses >= Self::LIMIT {
            self.misses = 0;
            ReturnCode::SwitchFailed
        } else {
            ReturnCode::Queued
        }
    }
}

/// The sender's automatic action clear (spec §5.3): one-shot tricks (2, 5, 6, 11) go out in
/// exactly 6 consecutive datagrams, then the action field becomes 0; 7 and the ZSL-1W actions are
/// sticky; the count does not restart when another trick arrives mid-count.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct ActionClear {
    last: u16,
    count: u32,
}

impl ActionClear {
    /// Datagrams a one-shot trick is sent in.
    pub const DATAGRAMS: u32 = 6;

    /// Applies the rule to the command about to be sent (call once per sent datagram).
    pub fn before_send(&mut self, command: &mut HighLevelCommand) {
        let sticky_or_none = |a: u16| !Action::from_raw(a).is_one_shot();
        if sticky_or_none(self.last) {
            self.last = command.action.get();
            self.count = 1;
            return;
        }
        if self.count >= Self::DATAGRAMS {
            command.action = 0.into();
            self.last = 0;
            self.count = 0;
        } else {
            self.count += 1;
        }
    }
}

/// The mode a HighLevel call waits to see acknowledged (spec §9.1 step 7).
pub fn target_mode(command: &HighLevelCommand) -> ControlMode {
    command.control_mode()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn range_boundaries_with_the_zero_band() {
        let [vx, vy, yaw] = move_ranges(Model::Zsl1);
        assert!(vx.check(0.0).is_ok());
        assert!(vx.check(1e-6).is_ok(), "inside the zero band");
        assert!(vx.check(0.04).is_err(), "between zero and the minimum");
        assert!(vx.check(0.05).is_ok());
        assert!(vx.check(-0.0499995).is_ok(), "tolerance below the minimum");
        assert!(vx.check(3.0).is_ok());
        assert!(vx.check(3.000_001).is_ok(), "tolerance above the maximum");
        assert!(vx.check(3.01).is_err());
        assert!(vy.check(0.09).is_err() && vy.check(1.0).is_ok());
        assert!(yaw.check(-0.02).is_ok() && yaw.check(0.019).is_err());
        assert!(matches!(vx.check(f32::NAN), Err(ArgumentError::NonFinite(_))), "robowire refuses NaN");
        assert!(vx.check(f32::INFINITY).is_err());
        assert!(ATTITUDE_RANGES[0].check(0.6).is_ok() && ATTITUDE_RANGES[0].check(0.61).is_err());
        assert!(ATTITUDE_RANGES[3].check(0.000_01).is_ok(), "no lower bound");
    }

    #[test]
    fn lowlevel_bounds_are_inclusive_in_f64() {
        let mut cmd = MotorCommand::default();
        assert!(check_motor_command(&cmd).is_err(), "knee 0 is out of range");
        for leg in 0..4 {
            cmd.q_des[0][leg] = 0.7.into();
            cmd.q_des[1][leg] = 3.0.into();
            cmd.q_des[2][leg] = (-1.5).into();
        }
        // 0.7f32 as f64 is 0.699999988: inside; 3.0 is exact.
        assert!(check_motor_command(&cmd).is_ok());
        cmd.q_des[2][1] = (-2.9f32).into();
        assert!(matches!(check_motor_command(&cmd), Err(ArgumentError::Position { leg: 1, .. })), "-2.9f fails");
        cmd.q_des[2][1] = (-0.65f32).into();
        assert!(check_motor_command(&cmd).is_err(), "-0.65f fails too");
        cmd.q_des[2][1] = (-1.5).into();
        cmd.kp[2][3] = f32::NAN.into();
        assert!(matches!(check_motor_command(&cmd), Err(ArgumentError::NonFinite(NonFinite { name: "kp", .. }))));
    }

    #[test]
    fn eleventh_unacknowledged_call_fails() {
        let mut ack = AckCounter::default();
        let codes: [ReturnCode; 13] = core::array::from_fn(|_| ack.on_call(ControlMode::Stand, ControlMode::Move));
        assert_eq!(codes.iter().filter(|c| **c == ReturnCode::SwitchFailed).count(), 1);
        assert_eq!(codes[10], ReturnCode::SwitchFailed);
        assert_eq!(ack.on_call(ControlMode::Move, ControlMode::Move), ReturnCode::Queued);
    }

    #[test]
    fn one_shot_tricks_go_out_in_six_datagrams() {
        let mut clear = ActionClear::default();
        let mut cmd = HighLevelCommand::jump();
        let sent: [u16; 10] = core::array::from_fn(|_| {
            clear.before_send(&mut cmd);
            cmd.action.get()
        });
        assert_eq!(sent, [5, 5, 5, 5, 5, 5, 0, 0, 0, 0]);
        assert_eq!(cmd.mode.get(), 21, "the mode stays");
        let mut sticky = HighLevelCommand::two_leg_stand(0.3, 0.0);
        for _ in 0..20 {
            clear.before_send(&mut sticky);
        }
        assert_eq!(sticky.action.get(), 7);
    }

    #[test]
    fn gates() {
        assert!(!mode_gate_passes(ControlMode::LieDown));
        assert!(!mode_gate_passes(ControlMode::Passive));
        assert!(mode_gate_passes(ControlMode::Unknown(99)));
        assert!(is_running(0.0, 0.21, 0.0) && !is_running(0.2, -0.2, 0.2));
    }
}
