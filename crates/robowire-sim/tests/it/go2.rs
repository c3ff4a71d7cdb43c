//! The simulated Go2's state stream while its public API is called in a loop from another
//! thread, in a private network (`robowire_dds::netns`): `rt/lowstate` keeps its ticks.

use std::time::{Duration, Instant};

use robowire_dds::netns::with_loopback_multicast;
use robowire_dds::qos::Qos;
use robowire_dds::{Participant, ParticipantOptions};
use robowire_sim::go2::{Go2Fault, Go2Sim, Go2SimConfig};
use unitree_proto::{LowState, Message};

use crate::hammer;

/// Generous: a condition not reached within this is a failure, not slowness.
const WAIT: Duration = Duration::from_secs(20);

#[test]
fn the_state_stream_keeps_its_ticks_while_the_api_is_hammered() {
    with_loopback_multicast(|| {
        let lo = ParticipantOptions::new(0, Some("lo"));
        let sim = Go2Sim::spawn(Go2SimConfig { participant: lo.clone(), ..Go2SimConfig::default() }).unwrap();
        let us = Participant::new(lo).unwrap();
        let mut reader = us.reader::<LowState>(LowState::TOPIC, Qos::READER).unwrap();
        let runtime = tokio::runtime::Builder::new_current_thread().enable_all().build().unwrap();
        // The body's tick (ms) of the next state that arrives: it counts every slot of the
        // 2 ms grid, served or skipped.
        let mut next_tick = || {
            runtime.block_on(async {
                let sample = tokio::time::timeout(WAIT, reader.recv()).await.expect("a state in time").unwrap();
                u64::from(sample.value.tick.get())
            })
        };
        let first = next_tick();
        let ran_before = sim.snapshot().state_lateness.count;
        let api = || {
            let _ = (sim.snapshot(), sim.take_log());
            sim.inject(Go2Fault::MotorFault { motor: 11 });
            sim.clear_faults();
        };
        let (ran_after, last) = hammer::while_hammering(api, || {
            let start = Instant::now();
            loop {
                let ran = sim.snapshot().state_lateness.count;
                let tick = next_tick();
                if ran >= ran_before + 500 {
                    return (ran, tick);
                }
                assert!(start.elapsed() < WAIT, "the stream stalled after {} ticks", ran - ran_before);
            }
        });
        // The two ends are read a state apart at most: a small error, well inside the bound.
        let (ran, slots) = (ran_after - ran_before, (last - first) / 2);
        let skipped = slots.saturating_sub(ran);
        assert!(skipped < ran / 2, "{skipped} slots skipped while {ran} ticks ran");
        assert!(sim.snapshot().lowstate.samples >= ran, "a state written every tick");
    });
}
