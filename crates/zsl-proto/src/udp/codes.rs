//! Control modes, actions and return codes (spec §8).

/// Control modes, shared by command 0x1E and state 0x16C (spec §8.1; meanings from the docs).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum ControlMode {
    /// 0: lying down, motors damped.
    Passive,
    /// 1: standing (also shake-hand).
    Stand,
    /// 10: lying down, motors go free after a while.
    LieDownFree,
    /// 18: walking (also ZSL-1W crawl and climb).
    Move,
    /// 21: action state (tricks, attitude, two-leg stand).
    Action,
    /// 51: lying down, joints locked.
    LieDown,
    /// Any other value, kept raw.
    Unknown(u32),
}

impl ControlMode {
    /// The raw value.
    pub const fn raw(self) -> u32 {
        match self {
            Self::Passive => 0,
            Self::Stand => 1,
            Self::LieDownFree => 10,
            Self::Move => 18,
            Self::Action => 21,
            Self::LieDown => 51,
            Self::Unknown(raw) => raw,
        }
    }

    /// The mode of a raw value.
    pub const fn from_raw(raw: u32) -> Self {
        match raw {
            0 => Self::Passive,
            1 => Self::Stand,
            10 => Self::LieDownFree,
            18 => Self::Move,
            21 => Self::Action,
            51 => Self::LieDown,
            other => Self::Unknown(other),
        }
    }
}

/// Action codes of command 0x1C (spec §8.2).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Action {
    /// 0: none.
    None,
    /// 2: backflip (6 datagrams, then cleared).
    Backflip,
    /// 5: jump (6 datagrams).
    Jump,
    /// 6: front jump (6 datagrams).
    FrontJump,
    /// 7: two-leg stand (sticky).
    TwoLegStand,
    /// 11: shake hand (6 datagrams).
    ShakeHand,
    /// 16: ZSL-1W climb (sticky).
    Climb,
    /// 17: ZSL-1W crawl (sticky).
    Crawl,
    /// Any other value, kept raw.
    Unknown(u16),
}

impl Action {
    /// The raw value.
    pub const fn raw(self) -> u16 {
        match self {
            Self::None => 0,
            Self::Backflip => 2,
            Self::Jump => 5,
            Self::FrontJump => 6,
            Self::TwoLegStand => 7,
            Self::ShakeHand => 11,
            Self::Climb => 16,
            Self::Crawl => 17,
            Self::Unknown(raw) => raw,
        }
    }

    /// The action of a raw value.
    pub const fn from_raw(raw: u16) -> Self {
        match raw {
            0 => Self::None,
            2 => Self::Backflip,
            5 => Self::Jump,
            6 => Self::FrontJump,
            7 => Self::TwoLegStand,
            11 => Self::ShakeHand,
            16 => Self::Climb,
            17 => Self::Crawl,
            other => Self::Unknown(other),
        }
    }

    /// One-shot tricks the sender clears after 6 datagrams (2, 5, 6, 11).
    pub const fn is_one_shot(self) -> bool {
        matches!(self, Self::Backflip | Self::Jump | Self::FrontJump | Self::ShakeHand)
    }
}

/// Return codes of the HighLevel calls and error words of state 0x1F4 (spec §8.3).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum ReturnCode {
    /// 0: queued (not "the robot obeyed").
    Queued,
    /// 0x3007: state-machine switch failed.
    SwitchFailed,
    /// 0x3009: motor angle limit exceeded.
    AngleLimit,
    /// 0x3010: motor disabled.
    MotorDisabled,
    /// 0x3011: motor fault.
    MotorFault,
    /// 0x3012: motor data lost.
    MotorDataLost,
    /// 0x3013: speed command too large.
    SpeedTooLarge,
    /// Any other word, kept raw.
    Unknown(u32),
}

impl ReturnCode {
    /// The raw word.
    pub const fn raw(self) -> u32 {
        match self {
            Self::Queued => 0,
            Self::SwitchFailed => 0x3007,
            Self::AngleLimit => 0x3009,
            Self::MotorDisabled => 0x3010,
            Self::MotorFault => 0x3011,
            Self::MotorDataLost => 0x3012,
            Self::SpeedTooLarge => 0x3013,
            Self::Unknown(raw) => raw,
        }
    }

    /// The code of a raw word.
    pub const fn from_raw(raw: u32) -> Self {
        match raw {
            0 => Self::Queued,
            0x3007 => Self::SwitchFailed,
            0x3009 => Self::AngleLimit,
            0x3010 => Self::MotorDisabled,
            0x3011 => Self::MotorFault,
            0x3012 => Self::MotorDataLost,
            0x3013 => Self::SpeedTooLarge,
            other => Self::Unknown(other),
        }
    }
}
