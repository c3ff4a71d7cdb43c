//! `robowire replay --as-device`: the device side of a capture played back to a live client over
//! the same transport, so that a session seen once on a robot can be replayed on a desk. The
//! link's protocol (from the capture's metadata) says which device and transport:
//!
//! - the ZSL-1's states on UDP (HighLevel on 43997, LowLevel on 43900 of `--bind`), [`udp`];
//! - the KMC chassis' frames on a pseudo-terminal, [`serial`];
//! - the Go2's `LowState_` payloads on DDS `rt/lowstate`, [`dds`];
//! - the spline daemon's states on shared memory, with the IMU records of the device's
//!   `zsl1.imu` link, [`shm`].
//!
//! `robowire_sim::replay::PLAYABLE` says which protocols have a device side and which frames the
//! device sent. This picks the device's frames out of the capture; `robowire_sim::replay` plays them.

mod dds;
mod serial;
mod shm;
mod udp;

use std::collections::BTreeMap;
use std::net::IpAddr;
use std::process::ExitCode;
use std::time::Duration;

use anyhow::bail;
use robowire_record::RecordedFrame;
use robowire_sim::replay::{Pace, Playable, Played, playable, playable_list};
use zsl_proto::description::IMU;

use crate::cmd::captures::same_link;

/// Where and how fast to play.
#[derive(Debug)]
pub(crate) struct Target<'a> {
    /// The link to play (default: the first with device frames).
    pub(crate) link: Option<&'a str>,
    /// The ZSL-1's address.
    pub(crate) bind: IpAddr,
    /// The Go2's domain and interface.
    pub(crate) dds: &'a crate::cmd::dds_args::DdsArgs,
    /// The spline daemon's objects: spline, IMU.
    pub(crate) shm: (&'a str, &'a str),
    /// The recorded pace scaled by this; `None`: as fast as possible.
    pub(crate) speed: Option<f64>,
}

/// Each link of the capture in order of its first frame: its protocol and frame count.
fn links(frames: &[RecordedFrame]) -> Vec<(&str, &'static str, usize)> {
    let mut counts: BTreeMap<&str, usize> = BTreeMap::new();
    let mut order = Vec::new();
    for frame in frames {
        let count = counts.entry(&frame.link).or_default();
        if *count == 0 {
            order.push((frame.link.as_str(), frame.protocol.protocol()));
        }
        *count += 1;
    }
    order.into_iter().map(|(link, protocol)| (link, protocol, counts[link])).collect()
}

/// The links found, for an error.
fn found(frames: &[RecordedFrame]) -> String {
    let links = links(frames);
    if links.is_empty() {
        return "the capture has no frames".into();
    }
    let list: Vec<String> = links.iter().map(|(l, p, n)| format!("{l} ({p}, {n} frames)")).collect();
    format!("the capture has {}", list.join(", "))
}

/// Whether `frame` is one its link's device sent, by the link's entry in `PLAYABLE`.
fn device_sent(playable: &Playable, frame: &RecordedFrame) -> bool {
    playable.device_sent(frame.direction, &frame.bytes)
}

/// The device frames of `link` (or of the first link that has any), with the link and what they
/// are played as.
fn pick<'f>(
    frames: &'f [RecordedFrame],
    link: Option<&str>,
) -> anyhow::Result<(String, Played, Vec<&'f RecordedFrame>)> {
    let device_frames = |link: &str, playable: &Playable| -> Vec<&RecordedFrame> {
        frames.iter().filter(|f| f.link == link && device_sent(playable, f)).collect()
    };
    let Some(link) = link else {
        // The link of the first device frame.
        let first =
            frames.iter().find_map(|f| playable(f.protocol.protocol()).filter(|p| device_sent(p, f)).map(|p| (f, p)));
        let Some((first, playable)) = first else {
            bail!("no device frames to play: {}; --as-device plays {}", found(frames), playable_list());
        };
        return Ok((first.link.clone(), playable.played, device_frames(&first.link, playable)));
    };
    // The link by its name in the capture, else under its old or new name (an old capture's
    // `dog/high_level` is `zsl1/high_level`).
    let recorded = frames.iter().find(|f| f.link == link).or_else(|| frames.iter().find(|f| same_link(&f.link, link)));
    let Some(recorded) = recorded else {
        bail!("no link {link:?}: {}", found(frames));
    };
    let (link, protocol) = (recorded.link.as_str(), recorded.protocol.protocol());
    let Some(playable) = playable(protocol) else {
        bail!("link {link} is {protocol}, which has no device side to play; --as-device plays {}", playable_list());
    };
    let picked = device_frames(link, playable);
    if picked.is_empty() {
        bail!("link {link} ({protocol}) has no device frames: {}", found(frames));
    }
    Ok((link.to_string(), playable.played, picked))
}

/// Plays the device frames of `target.link` (default: the first link that has any) on the
/// device's transport.
pub(crate) fn run(frames: &[RecordedFrame], target: &Target<'_>) -> anyhow::Result<ExitCode> {
    let (link, device, picked) = pick(frames, target.link)?;
    let first_ns = picked[0].unix_ns;
    let offset = |f: &RecordedFrame| (Duration::from_nanos(f.unix_ns.saturating_sub(first_ns)), f.bytes.clone());
    let offsets: Vec<(Duration, Vec<u8>)> = picked.iter().map(|f| offset(f)).collect();
    let pace = target.speed.map_or(Pace::Fast, |speed| Pace::Recorded { speed });
    match device {
        Played::Zsl1 => udp::run(offsets, picked[0].protocol.protocol(), &link, target.bind, pace),
        Played::Kmc => serial::run(offsets, &link, pace),
        Played::Go2 => dds::run(offsets, &link, target.dds, pace),
        Played::Spline => {
            // The device's IMU records (its `zsl1.imu` link beside), from the states' first on.
            let device = link.split('/').next().unwrap_or_default();
            let imu: Vec<(Duration, Vec<u8>)> = frames
                .iter()
                .filter(|f| f.protocol.protocol() == IMU.name && f.link.split('/').next() == Some(device))
                .filter(|f| f.unix_ns >= first_ns)
                .map(offset)
                .collect();
            shm::run(offsets, imu, &link, target.shm, pace)
        }
        other => bail!("no player for {other:?} in this build"),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use kmc_proto::description::{CHASSIS, HOST};
    use robowire_record::Direction;
    use unitree_proto::description::GO2_LOW_LEVEL;
    use unitree_proto::{CdrEncoding, LowCmd, LowState, Message};
    use zsl_proto::description::HIGH_LEVEL;

    fn frame(
        link: &str,
        protocol: &'static dyn robowire_record::LinkDescription,
        direction: Direction,
        bytes: Vec<u8>,
    ) -> RecordedFrame {
        RecordedFrame { link: link.into(), direction, protocol, unix_ns: 0, bytes }
    }

    fn payload<M: Message>() -> Vec<u8> {
        let mut payload = vec![0u8; M::cdr_len(CdrEncoding::Xcdr1)];
        M::default().encode_cdr(CdrEncoding::Xcdr1, &mut payload).unwrap();
        payload
    }

    #[test]
    fn the_device_frames_follow_from_the_recording_end_and_the_direction() {
        let speed = vec![0xb3, 0, 0, 0, 0];
        let frames = [
            // A simulator's capture: the chassis sent, the Go2 sent its LowStates.
            frame("kmc/chassis", &CHASSIS, Direction::Received, vec![0xb3]),
            frame("kmc/chassis", &CHASSIS, Direction::Sent, speed.clone()),
            frame("go2/low_level", &GO2_LOW_LEVEL, Direction::Received, payload::<LowCmd>()),
            frame("go2/low_level", &GO2_LOW_LEVEL, Direction::Sent, payload::<LowState>()),
            // A host's capture: it received the chassis' frames.
            frame("kmc/serial", &HOST, Direction::Sent, vec![0xb3]),
            frame("kmc/serial", &HOST, Direction::Received, speed.clone()),
        ];
        let picked =
            |link| pick(&frames, link).map(|(l, d, f)| (l, d, f.iter().map(|f| f.direction).collect::<Vec<_>>()));
        assert_eq!(picked(None).unwrap(), ("kmc/chassis".into(), Played::Kmc, vec![Direction::Sent]));
        assert_eq!(picked(Some("kmc/serial")).unwrap(), ("kmc/serial".into(), Played::Kmc, vec![Direction::Received]));
        assert_eq!(
            picked(Some("go2/low_level")).unwrap(),
            ("go2/low_level".into(), Played::Go2, vec![Direction::Sent])
        );
    }

    #[test]
    fn a_link_of_an_old_capture_is_found_under_its_new_name() {
        // An older capture recorded the ZSL-1's links as `dog/…`.
        let state = robowire_sim::zsl1::Zsl1Model::new(zsl_proto::udp::Model::Zsl1).high_level_state().encode();
        let command = zsl_proto::udp::HighLevelCommand::stand_up().encode(zsl_proto::udp::Model::Zsl1);
        let frames = [
            frame("dog/high_level", &HIGH_LEVEL, Direction::Sent, command.to_vec()),
            frame("dog/high_level", &HIGH_LEVEL, Direction::Received, state.to_vec()),
        ];
        for asked in ["zsl1/high_level", "dog/high_level"] {
            let (link, device, picked) = pick(&frames, Some(asked)).unwrap();
            assert_eq!((link.as_str(), device, picked.len()), ("dog/high_level", Played::Zsl1, 1), "{asked}");
            assert_eq!(picked[0].direction, Direction::Received);
        }
        let error = pick(&frames, Some("zsl1/low_level")).unwrap_err().to_string();
        assert!(error.contains("no link \"zsl1/low_level\"") && error.contains("dog/high_level"), "{error}");
    }
}
