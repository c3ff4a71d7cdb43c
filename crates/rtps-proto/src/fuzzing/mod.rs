//! The fuzz oracles (internal; the fuzz targets and the xtask's corpus replay call them):
//! [`parse_all`] for the wire layer, [`participant`] / [`participant_steps`] for a whole
//! [`Participant`] driven by a sequence of [`Step`]s.
//!
//! Each job in its own module: `parse` (the wire oracle), `participant` (the setup and the run of
//! a participant), `step` (the steps and their byte format), `datagram` (the datagrams templated
//! steps stand for), `world` (the prefixes, topic and caps they share).
//!
//! [`participant`]: fn@participant
//! [`Participant`]: crate::participant::Participant

mod datagram;
mod parse;
mod participant;
mod step;
mod world;

pub use parse::parse_all;
pub use participant::{ParticipantSetup, participant, participant_steps};
pub use step::{Step, encode_steps};
pub use world::{LOCAL_PREFIX, PEER_PREFIX, TOPIC, TYPE_NAME};

#[cfg(test)]
mod tests {
    use alloc::vec::Vec;

    use super::datagram::{Ids, templated_datagram};
    use super::participant::{address, fuzz_config};
    use super::world::T0;
    use super::*;
    use crate::EntityId;
    use crate::discovery::Qos;
    use crate::participant::{Destination, Participant};
    use crate::wire::Message;

    #[test]
    fn the_setup_discovers_and_matches_the_peer() {
        let setup = ParticipantSetup::new();
        assert!(!setup.discovery.is_empty());
        let mut p = Participant::new(fuzz_config(LOCAL_PREFIX), T0);
        let w = p.create_writer(T0, TOPIC, TYPE_NAME, Qos::default()).unwrap();
        let r = p.create_reader(T0, TOPIC, TYPE_NAME, Qos::default()).unwrap();
        for d in &setup.discovery {
            p.handle_datagram(T0, address(PEER_PREFIX), Destination::Unicast, d);
        }
        assert_eq!(p.matched_readers(w).count(), 1);
        assert_eq!(p.matched_writers(r).count(), 1);
    }

    #[test]
    fn steps_decode_as_encoded() {
        let steps = [
            Step::Raw(&[1, 2, 3]),
            Step::FromPeer(&[]),
            Step::Discovery { index: 3, patches: [(1, 2), (0, 0)] },
            Step::Data { wrap: 5, to: 0, from: 0, sn: 1, len: 8, flags: 1 },
            Step::DataFrag { wrap: 0, to: 0, from: 0, sn: 2, start: 1, count: 1, size: 1024, sample: 3000, len: 0 },
            Step::Heartbeat { wrap: 8, to: 0, from: 0, first: 1, last: 3, count: 1, flags: 0 },
            Step::HeartbeatFrag { wrap: 0, to: 0, from: 0, sn: 2, last: 2, count: 1 },
            Step::AckNack { wrap: 0, from: 0, to: 0, base: 1, bits: 8, words: [1; 8], count: 1, final_flag: true },
            Step::Gap { wrap: 0, to: 0, from: 0, start: 1, base: 2, bits: 0, words: [0; 8] },
            Step::NackFrag { wrap: 0, from: 0, to: 0, sn: 1, base: 1, bits: 3, words: [7; 8], count: 2 },
            Step::Clock { ms: 100 },
            Step::Poll,
            Step::Write { len: 3000 },
        ];
        let ids = Ids {
            writer: EntityId([0, 0, 1, 3]),
            reader: EntityId([0, 0, 2, 4]),
            peer_writer: EntityId([0, 0, 1, 3]),
            peer_reader: EntityId([0, 0, 2, 4]),
        };
        for step in &steps[3..10] {
            let (mut d, mut payload) = (Vec::new(), Vec::new());
            templated_datagram(&mut d, step, &ids, &mut payload);
            let m = Message::parse(&d).unwrap();
            assert!(m.submessages().all(|s| s.is_ok()), "{step:?}");
        }
        let bytes = encode_steps(0, &steps);
        let mut rest = &bytes[1..];
        let back: Vec<Step<'_>> = core::iter::from_fn(|| Step::decode(&mut rest)).collect();
        assert_eq!(back, steps);
        participant(&bytes);
    }
}
