//! The spline daemon simulator from the consumer end of the shared-memory transport: the
//! handshake and the versioned IMU record, as `zsl-proto` lays them out and `robowire-shm`
//! implements them, without the `zsl` facade.

use std::time::{Duration, Instant};

use robowire_shm::{MappedRegion, SharedRegion};
use robowire_sim::spline::{SplineSim, SplineSimConfig};
use zsl_proto::shm::{
    ConsumerIndex, IMU_RECORD, JointControl, JointIndex, Leg, NAV_IMU_LEN, NavImuSample, SPLINE_COMMAND,
    SPLINE_DATA_LEN, SplineCommandBlock, SplineStateBlock,
};
use zsl_proto::zerocopy::{FromZeros, IntoBytes};

use crate::hammer;

/// Polls `take` until it gives a block, for at most 20 s (generous: a failure, not slowness).
fn fresh_state(region: &MappedRegion, consumer: ConsumerIndex) -> SplineStateBlock {
    let mut state = SplineStateBlock::new_zeroed();
    let deadline = Instant::now() + Duration::from_secs(20);
    while !region.take(&consumer.state(), state.legs.as_mut_bytes()).unwrap() {
        assert!(Instant::now() < deadline, "the daemon publishes no state");
        std::thread::sleep(Duration::from_micros(100));
    }
    state
}

#[test]
fn the_daemon_takes_commands_and_publishes_state_and_imu() {
    let sim = SplineSim::spawn(SplineSimConfig::private("sim-test")).unwrap();
    let region = MappedRegion::open(&sim.config().spline_name, SPLINE_DATA_LEN).unwrap();

    // Both consumers get the same fresh state, each through its own flag.
    let control = fresh_state(&region, ConsumerIndex::Control);
    let other = fresh_state(&region, ConsumerIndex::Other);
    assert!(control.joint(Leg::FrontRight, JointIndex::Knee).p.get() < -2.0, "lying");
    assert!(other.joint(Leg::FrontRight, JointIndex::Knee).p.get() < -2.0);

    // A command with a PD target on every joint, published with the handshake.
    let mut command = SplineCommandBlock::default();
    for leg in Leg::ALL {
        for joint in [JointIndex::Abad, JointIndex::Hip, JointIndex::Knee] {
            *command.joint_mut(leg, joint) = JointControl::new(-1.0, 0.0, 60.0, 2.0, 0.0);
        }
    }
    let before = sim.stats().daemon.fresh;
    let deadline = Instant::now() + Duration::from_secs(20);
    let mut knee = 0.0;
    while Instant::now() < deadline {
        region.publish(&[SPLINE_COMMAND], command.normalized().legs.as_bytes()).unwrap();
        knee = fresh_state(&region, ConsumerIndex::Control).joint(Leg::RearLeft, JointIndex::Knee).p.get();
        if (knee + 1.0).abs() < 0.05 {
            break;
        }
    }
    assert!((knee + 1.0).abs() < 0.05, "the knee followed the command: {knee} rad");
    assert!(sim.stats().daemon.fresh > before, "commands taken as fresh");

    let imu = MappedRegion::open(&sim.config().imu_name, NAV_IMU_LEN).unwrap();
    let mut sample = NavImuSample::new_zeroed();
    let read = imu.read_versioned(&IMU_RECORD, sample.as_mut_bytes(), 16).unwrap();
    assert!(read.version > 0, "the timestamp is the version");
    assert_eq!(sample.acc[2].get(), 9.81);
}

#[test]
fn the_loop_keeps_its_cycles_while_the_api_is_hammered() {
    let sim = SplineSim::spawn(SplineSimConfig::private("sim-hammer")).unwrap();
    let api = || {
        let _ = (sim.stats(), sim.state());
        // Requests that change nothing, through the same hand-over as any other.
        sim.pause(false);
        sim.inject_fault(Leg::FrontLeft, JointIndex::Knee, 0);
    };
    let before = sim.stats();
    let after = hammer::while_hammering(api, || {
        let deadline = Instant::now() + Duration::from_secs(20);
        loop {
            let now = sim.stats();
            if now.cycles >= before.cycles + 1000 {
                return now;
            }
            assert!(Instant::now() < deadline, "the loop stalled: {now:?}");
            std::thread::sleep(Duration::from_millis(1));
        }
    });
    let (ran, missed) = (after.cycles - before.cycles, after.missed_cycles - before.missed_cycles);
    assert!(missed < ran / 2, "{missed} cycles skipped while {ran} ran");
    assert!(after.daemon.states_published - before.daemon.states_published >= ran, "a state every cycle");
}
