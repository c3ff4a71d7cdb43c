//! The HighLevel datagrams (spec §5, §6): the 40-byte command with the vendor calls that fill
//! it, and the 560-byte state.

use zerocopy::little_endian::{F32, U16, U32};
use zerocopy::{FromBytes, FromZeros, Immutable, IntoBytes, KnownLayout, Unaligned};

use super::{Action, ControlMode, DatagramError, ReturnCode, command_codec, state_codec};

/// HighLevel command, client → dog, 40 bytes (spec §5).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, FromBytes, IntoBytes, KnownLayout, Immutable, Unaligned)]
#[repr(C)]
pub struct HighLevelCommand {
    magic: U16,
    /// Reserved, 0 in every captured datagram.
    pub reserved_02: U16,
    /// Forward velocity, m/s (`move`, `twoLegStand`; `frontJump` writes 1.0).
    pub vx: F32,
    /// Lateral velocity, m/s (`move`).
    pub vy: F32,
    /// Roll rate, rad/s (`attitudeControl`).
    pub roll_rate: F32,
    /// Pitch rate, rad/s (`attitudeControl`).
    pub pitch_rate: F32,
    /// Yaw rate, rad/s (`move`, `twoLegStand`, `attitudeControl`).
    pub yaw_rate: F32,
    /// Height rate, m/s (`attitudeControl`).
    pub height_rate: F32,
    /// Action code (§8.2).
    pub action: U16,
    /// Requested control mode (§8.1).
    pub mode: U16,
    /// 1 after every accepted call except `cancelTwoLegStand`; meaning unknown.
    pub flag: U16,
    /// Reserved, 0.
    pub reserved_22: U16,
    checksum: U32,
}

command_codec!(HighLevelCommand, 40, 0x24);

impl Default for HighLevelCommand {
    /// The idle command: every field zero (mode 0, no action, flag 0).
    fn default() -> Self {
        Self::new_zeroed()
    }
}

impl HighLevelCommand {
    /// The command of an accepted call: every field zero, then mode, action and flag 1 (§5.2).
    fn call(mode: ControlMode, action: Action) -> Self {
        let mut c = Self::new_zeroed();
        c.mode = (mode.raw() as u16).into();
        c.action = action.raw().into();
        c.flag = 1.into();
        c
    }

    /// `standUp()`: mode 1.
    pub fn stand_up() -> Self {
        Self::call(ControlMode::Stand, Action::None)
    }

    /// `lieDown()`: mode 51.
    pub fn lie_down() -> Self {
        Self::call(ControlMode::LieDown, Action::None)
    }

    /// `passive()`: mode 0.
    pub fn passive() -> Self {
        Self::call(ControlMode::Passive, Action::None)
    }

    /// `move(vx, vy, yaw_rate)`: mode 18 (m/s, m/s, rad/s).
    pub fn move_velocity(vx_mps: f32, vy_mps: f32, yaw_rate_radps: f32) -> Self {
        let mut c = Self::call(ControlMode::Move, Action::None);
        c.vx = vx_mps.into();
        c.vy = vy_mps.into();
        c.yaw_rate = yaw_rate_radps.into();
        c
    }

    /// `jump()`: mode 21, action 5.
    pub fn jump() -> Self {
        Self::call(ControlMode::Action, Action::Jump)
    }

    /// `frontJump()`: mode 21, action 6, vx 1.0.
    pub fn front_jump() -> Self {
        let mut c = Self::call(ControlMode::Action, Action::FrontJump);
        c.vx = 1.0.into();
        c
    }

    /// `backflip()`: mode 21, action 2.
    pub fn backflip() -> Self {
        Self::call(ControlMode::Action, Action::Backflip)
    }

    /// `shakeHand()`: mode 1, action 11.
    pub fn shake_hand() -> Self {
        Self::call(ControlMode::Stand, Action::ShakeHand)
    }

    /// `twoLegStand(vx, yaw_rate)`: mode 21, action 7 (sticky).
    pub fn two_leg_stand(vx_mps: f32, yaw_rate_radps: f32) -> Self {
        let mut c = Self::call(ControlMode::Action, Action::TwoLegStand);
        c.vx = vx_mps.into();
        c.yaw_rate = yaw_rate_radps.into();
        c
    }

    /// `cancelTwoLegStand()`: mode 21, action 0, flag **0**.
    pub fn cancel_two_leg_stand() -> Self {
        let mut c = Self::call(ControlMode::Action, Action::None);
        c.flag = 0.into();
        c
    }

    /// `attitudeControl(roll, pitch, yaw, height)` rates: mode 21.
    pub fn attitude(roll_radps: f32, pitch_radps: f32, yaw_radps: f32, height_mps: f32) -> Self {
        let mut c = Self::call(ControlMode::Action, Action::None);
        c.roll_rate = roll_radps.into();
        c.pitch_rate = pitch_radps.into();
        c.yaw_rate = yaw_radps.into();
        c.height_rate = height_mps.into();
        c
    }

    /// ZSL-1W `crawl(vx, vy, yaw_rate)`: mode 18, action 17 (sticky).
    pub fn crawl(vx_mps: f32, vy_mps: f32, yaw_rate_radps: f32) -> Self {
        let mut c = Self::move_velocity(vx_mps, vy_mps, yaw_rate_radps);
        c.action = Action::Crawl.raw().into();
        c
    }

    /// ZSL-1W `climb(vx, vy, yaw_rate)`: mode 18, action 16 (sticky).
    pub fn climb(vx_mps: f32, vy_mps: f32, yaw_rate_radps: f32) -> Self {
        let mut c = Self::move_velocity(vx_mps, vy_mps, yaw_rate_radps);
        c.action = Action::Climb.raw().into();
        c
    }

    /// ZSL-1W `cancelCrawl()` / `cancelClimb()`: mode 18, action 0, flag 0.
    pub fn cancel_crawl_or_climb() -> Self {
        let mut c = Self::call(ControlMode::Move, Action::None);
        c.flag = 0.into();
        c
    }

    /// The requested mode.
    pub fn control_mode(&self) -> ControlMode {
        ControlMode::from_raw(u32::from(self.mode.get()))
    }

    /// The action code.
    pub fn action_code(&self) -> Action {
        Action::from_raw(self.action.get())
    }
}

/// HighLevel state, dog → client, 560 bytes (spec §6).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, FromBytes, IntoBytes, KnownLayout, Immutable, Unaligned)]
#[repr(C)]
pub struct HighLevelState {
    /// Never read by the vendor SDK; robowire's simulator writes `a5 5a 00 00`.
    pub header: [u8; 4],
    /// Quaternion w, x, y, z.
    pub quaternion: [F32; 4],
    /// Body angular rate x, y, z, rad/s.
    pub gyro: [F32; 3],
    /// Body acceleration x, y, z, m/s².
    pub acc: [F32; 3],
    /// Roll, pitch, yaw, rad.
    pub rpy: [F32; 3],
    /// Body-frame velocity x, y, z, m/s.
    pub body_velocity: [F32; 3],
    /// World-frame velocity x, y, z, m/s.
    pub world_velocity: [F32; 3],
    /// Position x, y, z, m.
    pub position: [F32; 3],
    /// Unknown.
    pub unknown_05c: [u8; 12],
    /// Joint angles, rad: `[abad, hip, knee, foot][leg]`.
    pub joint_angle: [[F32; 4]; 4],
    /// Joint velocities, rad/s: `[abad, hip, knee, foot][leg]`.
    pub joint_velocity: [[F32; 4]; 4],
    /// Joint torques, N·m: `[abad, hip, knee, foot][leg]`.
    pub joint_torque: [[F32; 4]; 4],
    /// Unknown.
    pub unknown_128: [u8; 68],
    /// Current control mode (§8.1).
    pub control_mode: U32,
    /// Unknown.
    pub unknown_170: [u8; 128],
    /// Battery level, % (0–100 per docs).
    pub battery_percent: U32,
    /// Error word: non-zero = self-check failed (§8.3).
    pub error_word: U32,
    /// "SDK mismatch": exactly 1 stops the vendor's HighLevel sender for good.
    pub sdk_mismatch: U32,
    /// Unknown.
    pub unknown_1fc: [u8; 52],
}

/// The header robowire's simulator writes at HighLevel state offset 0.
pub const HIGH_LEVEL_STATE_HEADER: [u8; 4] = [0xa5, 0x5a, 0x00, 0x00];

state_codec!(
    HighLevelState,
    560,
    |s| if s.header[..2] == HIGH_LEVEL_STATE_HEADER[..2] {
        Ok(())
    } else {
        Err(DatagramError::Header([s.header[0], s.header[1]]))
    },
    |s| s.header[..2] == HIGH_LEVEL_STATE_HEADER[..2]
);
impl HighLevelState {
    /// Current control mode (state 0x16C).
    pub fn mode(&self) -> ControlMode {
        ControlMode::from_raw(self.control_mode.get())
    }

    /// The error word as a return code; `None` when it is 0 (no error).
    pub fn error(&self) -> Option<ReturnCode> {
        match self.error_word.get() {
            0 => None,
            word => Some(ReturnCode::from_raw(word)),
        }
    }

    /// Whether the robot raised "SDK mismatch" (exactly 1 stops the vendor's sender for good).
    pub fn has_sdk_mismatch(&self) -> bool {
        self.sdk_mismatch.get() == 1
    }
}
