//! What the robot's body is doing, and how long the vendor's timed transitions take: what the
//! model decides and the body plays out.

use zsl_proto::udp::Action;

/// Standing up takes this long, s.
pub const STAND_UP_S: f32 = 1.2;
/// Lying down takes this long, s.
pub const LIE_DOWN_S: f32 = 1.0;
/// `jump()` takes this long, s.
pub const JUMP_S: f32 = 0.8;
/// `frontJump()` takes this long, s.
pub const FRONT_JUMP_S: f32 = 1.0;
/// `backflip()` takes this long, s.
pub const BACKFLIP_S: f32 = 1.5;
/// `shakeHand()` takes this long, s.
pub const SHAKE_HAND_S: f32 = 2.0;
/// What the body is doing (the mode says what was asked).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Activity {
    /// Lying, joints locked (mode 51) or free (10).
    Lying,
    /// Motors damped (mode 0).
    Passive,
    /// Getting up.
    StandingUp,
    /// Standing still or walking in place.
    Standing,
    /// Walking (mode 18); ZSL-1W crawling or climbing too.
    Walking,
    /// Lying down.
    LyingDown,
    /// A trick in progress.
    Trick(Action),
    /// Standing on the hind legs (sticky action 7).
    TwoLegStand,
    /// Attitude control in mode 21.
    Attitude,
    /// The twelve motors follow LowLevel commands.
    LowLevel,
}
