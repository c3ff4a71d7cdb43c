//! A participant table filled by forged announcements (`Limits::participants` SPDP datagrams with
//! made-up GUID prefixes and an infinite lease, as a flood of bit-flipped captures makes them)
//! does not shut a real newcomer out: the participant heard from least recently makes room.

use std::net::SocketAddr;
use std::time::Duration;

use rtps_proto::discovery::Qos;
use rtps_proto::participant::{Destination, Event, LostReason, Participant};
use rtps_proto::{GuidPrefix, Limits, Time};

use crate::pair;

#[test]
fn forged_announcements_that_fill_the_participant_table_do_not_shut_out_a_newcomer() {
    let start = Time::from_nanos(1_000_000_000);
    let mut ours = Participant::new(pair::config_at([1; 12], 7410), start);
    let reader = ours.create_reader(start, "rt/lowstate", "T", Qos::default()).unwrap();
    let limit = Limits::default().participants;
    let mut buf = vec![0u8; 65_536];
    let from: SocketAddr = "127.0.0.1:7400".parse().unwrap();
    for n in 0..limit {
        let mut forged = pair::config_at([0xF0, n as u8, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11], 9000);
        forged.lease_duration = Duration::from_secs(u64::from(u32::MAX));
        let mut forger = Participant::new(forged, start);
        let t = forger.poll_transmit(start, &mut buf).expect("its SPDP announcement");
        ours.handle_datagram(start, from, Destination::Multicast, &buf[..t.len]);
    }
    assert_eq!(ours.remote_participants().count(), limit, "the table is full");
    while ours.poll_event().is_some() {}

    // A second later (every forged lease still running) a real participant comes.
    let now = start + Duration::from_secs(1);
    let mut newcomer = Participant::new(pair::config_at([3; 12], 7430), now);
    let w = newcomer.create_writer(now, "rt/lowstate", "T", Qos::default()).unwrap();
    pair::exchange(now, &mut ours, &mut newcomer);
    assert!(ours.remote_participants().any(|p| p.guid_prefix == GuidPrefix([3; 12])), "the newcomer is known");
    assert_eq!(ours.remote_participants().count(), limit, "one forged participant made room");
    assert_eq!(ours.counters().participants_at_limit, 1);
    let t = newcomer.write(now, w, &[0, 1, 0, 0, 7, 7, 7, 7], &Default::default(), &mut buf).unwrap();
    ours.handle_datagram(now, from, Destination::Unicast, &buf[..t.transmit.expect("matched").len]);
    let events: Vec<Event> = std::iter::from_fn(|| ours.poll_event()).collect();
    let displaced = events
        .iter()
        .filter(
            |e| matches!(e, Event::ParticipantLost { reason: LostReason::Displaced, prefix } if prefix.0[0] == 0xF0),
        )
        .count();
    assert_eq!(displaced, 1, "{events:?}");
    let samples: Vec<_> = events
        .into_iter()
        .filter_map(|e| match e {
            Event::Sample(s) if s.info.reader == reader => Some(s.payload),
            _ => None,
        })
        .collect();
    assert_eq!(samples, vec![vec![0, 1, 0, 0, 7, 7, 7, 7]]);
}
