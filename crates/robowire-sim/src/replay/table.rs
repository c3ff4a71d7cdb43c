//! Which recorded links have a device side to play, keyed by the link's protocol: the device the
//! frames are played as, and which of a link's frames that device sent.

use robowire_core::Direction;
use robowire_core::json::LinkProtocol;

/// The device side a recorded link is played as, and the player that plays it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[non_exhaustive]
pub enum Played {
    /// The ZSL-1's states on UDP ([`super::DatagramReplay`]).
    #[cfg(feature = "zsl")]
    Zsl1,
    /// The spline daemon's states on shared memory, with the IMU records of the device's
    /// `zsl1.imu` link ([`super::SplineReplay`]).
    #[cfg(feature = "zsl")]
    Spline,
    /// The KMC chassis' frames on a pseudo-terminal ([`super::SerialReplay`]).
    #[cfg(feature = "kmc")]
    Kmc,
    /// The Go2's `LowState_` payloads on DDS `rt/lowstate` ([`super::DdsReplay`]).
    #[cfg(feature = "go2")]
    Go2,
}

/// A protocol whose links have a device side to play.
#[derive(Debug)]
pub struct Playable {
    /// The links' protocol.
    pub protocol: &'static LinkProtocol,
    /// What its device frames are played as.
    pub played: Played,
    /// Which frames the device sent, in words, for errors.
    pub frames: &'static str,
    /// Whether a frame of the link, recorded in `direction`, is one the device sent.
    device_sent: fn(Direction, &[u8]) -> bool,
}

impl Playable {
    /// Whether a frame of a link of this protocol, recorded in `direction`, is one the device sent.
    pub fn device_sent(&self, direction: Direction, frame: &[u8]) -> bool {
        (self.device_sent)(direction, frame)
    }
}

/// Every protocol with a device side to play, in this build's features.
pub static PLAYABLE: &[Playable] = &[
    #[cfg(feature = "zsl")]
    Playable {
        protocol: &zsl_proto::description::HIGH_LEVEL,
        played: Played::Zsl1,
        frames: "its states",
        device_sent: zsl1_state,
    },
    #[cfg(feature = "zsl")]
    Playable {
        protocol: &zsl_proto::description::LOW_LEVEL,
        played: Played::Zsl1,
        frames: "its states",
        device_sent: zsl1_state,
    },
    // The daemon's states: what the controller received, what the daemon sent.
    #[cfg(feature = "zsl")]
    Playable {
        protocol: &zsl_proto::description::SPLINE_CLIENT,
        played: Played::Spline,
        frames: "received",
        device_sent: received,
    },
    #[cfg(feature = "zsl")]
    Playable {
        protocol: &zsl_proto::description::SPLINE_DAEMON,
        played: Played::Spline,
        frames: "sent",
        device_sent: sent,
    },
    // The chassis' frames: what the host received, what the chassis sent.
    #[cfg(feature = "kmc")]
    Playable {
        protocol: &kmc_proto::description::HOST,
        played: Played::Kmc,
        frames: "received",
        device_sent: received,
    },
    #[cfg(feature = "kmc")]
    Playable { protocol: &kmc_proto::description::CHASSIS, played: Played::Kmc, frames: "sent", device_sent: sent },
    #[cfg(feature = "go2")]
    Playable {
        protocol: &unitree_proto::description::GO2_LOW_LEVEL,
        played: Played::Go2,
        frames: "LowStates",
        device_sent: go2_low_state,
    },
];

/// The entry for links of `protocol`, if they have a device side to play.
pub fn playable(protocol: &str) -> Option<&'static Playable> {
    PLAYABLE.iter().find(|p| p.protocol.name == protocol)
}

/// What can be played, for an error: `zsl1.high_level (its states), kmc.host (received), …`.
pub fn playable_list() -> String {
    let list: Vec<String> = PLAYABLE.iter().map(|p| format!("{} ({})", p.protocol.name, p.frames)).collect();
    list.join(", ")
}

#[cfg(any(feature = "zsl", feature = "kmc"))]
fn received(direction: Direction, _: &[u8]) -> bool {
    direction == Direction::Received
}

#[cfg(any(feature = "zsl", feature = "kmc"))]
fn sent(direction: Direction, _: &[u8]) -> bool {
    direction == Direction::Sent
}

/// A HighLevel or LowLevel state datagram, whichever side recorded it.
#[cfg(feature = "zsl")]
fn zsl1_state(_: Direction, frame: &[u8]) -> bool {
    use zsl_proto::udp::AnyDatagram;
    matches!(AnyDatagram::decode(frame), Ok(AnyDatagram::HighLevelState(_) | AnyDatagram::LowLevelState(_)))
}

/// A `LowState_` by its length in the encoding its header names, as the link's description tells
/// `LowCmd_` and `LowState_` apart (whatever its CRC), whichever side recorded it.
#[cfg(feature = "go2")]
fn go2_low_state(_: Direction, frame: &[u8]) -> bool {
    use unitree_proto::{CdrEncoding, LowState, Message};
    frame
        .get(..4)
        .and_then(|header| CdrEncoding::from_header(header.try_into().ok()?))
        .is_some_and(|encoding| frame.len() == LowState::cdr_len(encoding))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_protocol_is_listed_once() {
        for (i, p) in PLAYABLE.iter().enumerate() {
            assert!(PLAYABLE[..i].iter().all(|q| q.protocol.name != p.protocol.name), "{} twice", p.protocol.name);
            assert_eq!(playable(p.protocol.name).map(|q| q.played), Some(p.played));
        }
        assert!(playable("ros2.rt_lowcmd").is_none());
    }

    #[cfg(feature = "kmc")]
    #[test]
    fn the_chassis_frames_are_what_the_host_received_or_the_chassis_sent() {
        let host = playable(kmc_proto::description::HOST.name).unwrap();
        let chassis = playable(kmc_proto::description::CHASSIS.name).unwrap();
        assert!(host.device_sent(Direction::Received, &[]) && !host.device_sent(Direction::Sent, &[]));
        assert!(chassis.device_sent(Direction::Sent, &[]) && !chassis.device_sent(Direction::Received, &[]));
    }

    #[cfg(feature = "go2")]
    #[test]
    fn a_go2_link_plays_its_low_states_not_its_commands() {
        use unitree_proto::{CdrEncoding, LowCmd, LowState, Message};
        let go2 = playable(unitree_proto::description::GO2_LOW_LEVEL.name).unwrap();
        let cdr = |encode: &dyn Fn(&mut [u8]) -> usize| {
            let mut out = [0u8; 4096];
            let n = encode(&mut out);
            out[..n].to_vec()
        };
        let state = cdr(&|out| LowState::default().encode_cdr(CdrEncoding::Xcdr1, out).unwrap());
        let cmd = cdr(&|out| LowCmd::default().encode_cdr(CdrEncoding::Xcdr1, out).unwrap());
        assert!(go2.device_sent(Direction::Received, &state));
        assert!(!go2.device_sent(Direction::Sent, &cmd));
        assert!(!go2.device_sent(Direction::Received, &state[..3]));
    }
}
