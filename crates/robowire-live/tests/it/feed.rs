//! A live view fed with real frames: a Go2's low-level link (LowCmd sent, LowState received, as
//! CDR payloads with their encapsulation header) and a KMC chassis's serial link, at their rates,
//! by a thread until dropped.

use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Duration;

use robowire_core::Direction;
use robowire_live::{LiveOptions, LiveServer};
use unitree_proto::{CdrEncoding, LowCmd, LowState, Message};

/// A live view on a free port of 127.0.0.1, at `rate_hz`, with every codec's plots and the
/// Unitree robots' bodies.
pub(crate) fn live(rate_hz: f64) -> LiveServer {
    let plots = unitree_proto::description::PLOTS.iter().chain(&kmc_proto::description::PLOTS).collect();
    let robots = unitree_proto::kinematics::ROBOTS.to_vec();
    let options = LiveOptions { rate_hz, plots, robots, ..LiveOptions::default() };
    LiveServer::start("127.0.0.1:0".parse().unwrap(), options).unwrap()
}

/// The front right calf's position in every [`low_state`], rad.
pub(crate) const FR_CALF_RAD: f32 = -1.3;

/// A Go2 LowState, level, its front right calf at [`FR_CALF_RAD`], as XCDR1 with its header.
pub(crate) fn low_state(tick: u32) -> Vec<u8> {
    let mut state = LowState::default();
    state.imu_state.quaternion = [1.0, 0.0, 0.0, 0.0].map(Into::into);
    state.motor_state[2].q = FR_CALF_RAD.into();
    state.tick = tick.into();
    let mut payload = vec![0; 2048];
    let n = state.encode_cdr(CdrEncoding::Xcdr1, &mut payload).unwrap();
    payload.truncate(n);
    payload
}

fn low_cmd() -> Vec<u8> {
    let mut payload = vec![0; 2048];
    let n = LowCmd::default().encode_cdr(CdrEncoding::Xcdr1, &mut payload).unwrap();
    payload.truncate(n);
    payload
}

/// A thread tapping frames into `live` until dropped: the Go2 both ways every `period`, the KMC
/// chassis's speed answer every 10 periods, an event every 100.
pub(crate) struct Feed {
    stop: Arc<AtomicBool>,
    thread: Option<std::thread::JoinHandle<u64>>,
}

impl Feed {
    pub(crate) fn start(live: &LiveServer, period: Duration) -> Self {
        let go2 = live.links().link("go2/low_level", &unitree_proto::description::GO2_LOW_LEVEL);
        let kmc = live.links().link("kmc/serial", &kmc_proto::description::HOST);
        let events = live.events();
        let stop = Arc::new(AtomicBool::new(false));
        let stopping = stop.clone();
        let thread = std::thread::spawn(move || {
            let (cmd, speed) = (low_cmd(), kmc_speed_frame());
            let mut n = 0u64;
            while !stopping.load(Ordering::Relaxed) {
                go2.record(Direction::Sent, &cmd);
                go2.record(Direction::Received, &low_state(n as u32));
                if n.is_multiple_of(10) {
                    kmc.record(Direction::Received, &speed);
                }
                if n.is_multiple_of(100) {
                    events.log(robowire_live::Level::Info, "go2", &format!("{n} LowStates"));
                }
                n += 1;
                if !period.is_zero() {
                    std::thread::sleep(period);
                }
            }
            n
        });
        Self { stop, thread: Some(thread) }
    }

    /// Stops it; the Go2 frames it tapped each way.
    pub(crate) fn stop(mut self) -> u64 {
        self.stop.store(true, Ordering::Relaxed);
        self.thread.take().map_or(0, |t| t.join().unwrap())
    }
}

impl Drop for Feed {
    fn drop(&mut self) {
        self.stop.store(true, Ordering::Relaxed);
        if let Some(thread) = self.thread.take() {
            let _ = thread.join();
        }
    }
}

/// The chassis's answer to a speed request, as the host receives it.
fn kmc_speed_frame() -> Vec<u8> {
    use kmc_proto::description::HOST;
    use robowire_core::json::LinkDescription;
    let mut frame = vec![0; kmc_proto::VehicleSpeed::LEN];
    kmc_proto::VehicleSpeed { speed_mps: 0.5 }.emit(&mut frame).unwrap();
    assert!(HOST.decode(Direction::Received, &frame).is_ok(), "a frame the host decodes");
    frame
}
