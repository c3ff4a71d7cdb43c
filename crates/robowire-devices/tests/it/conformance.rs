//! One conformance suite for every `sim:` kind: each property of the one device shape
//! written once, over `robowire_devices::{open, AnyDevice, OpenOptions}`, and checked on every
//! simulator. Each (kind, property) pair is a test named `conformance::<kind>::<property>`
//! (`cargo test --test it conformance::zsl1w::` runs one kind, `::silence` one property); DDS
//! kinds run where loopback carries multicast (`robowire_dds::netns`).
//!
//! The properties: a first state arrives and observes something ([`first_state`]); a silent
//! simulator is `Disconnected`, then `Connected` again when it speaks ([`silence`]); `close`
//! frees what the client held ([`close_frees`]); dropping a commanded device leaves a stop or
//! damping as its last word ([`drop_is_safe`]); the counters never block ([`stats_never_block`]);
//! a recording taps every link the kind declares ([`record_taps_every_link`]).
//!
//! What differs by kind sits in four functions at the end, each one `match` over the simulator:
//! its fault switch ([`set_silent`]), what it takes for every link to carry a frame
//! ([`exercise_links`]), how it is commanded ([`commander`]), and what its client held ([`held`]).

use std::future::Future;
use std::net::{SocketAddr, UdpSocket};
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::time::Duration;

use robowire_dds::netns::with_loopback_multicast;
use robowire_devices::{AnyDevice, Connection, DeviceAddress, DeviceKind, Observation, OpenOptions, Simulator, open};
use robowire_fixtures::wait::{one_at_a_time, runtime_two_workers, until_async};
use robowire_sim::g1::G1Fault;
use robowire_sim::go2::Go2Fault;
use robowire_sim::kmc::Fault as KmcFault;
use robowire_sim::zsl1::Zsl1Fault;
use robowire_tap::{Direction, LinkRegistry, RecordLinks, TapRing, TappedFrame};
use serde_json::Value;
use tokio::sync::watch;

/// Generous: a condition not reached within this is a failure, not slowness.
const WAIT: Duration = Duration::from_secs(20);
/// How long a silent device may stay silent in [`silence`] (the spline monitor keeps its own
/// 100 ms).
const STATE_TIMEOUT: Duration = Duration::from_millis(250);
/// Answers the KMC chassis swallows to fall silent: its fault is a count, after which it answers
/// again by itself; at its ~70 answers a second (speed at 50 Hz, the polls), about 3 s.
const SILENT_ANSWERS: u32 = 200;
/// Forward speed a drivable kind is driven at, m/s (inside every kind's band).
const FORWARD_MPS: f32 = 0.3;

/// Runs `property` on `kind`, one test at a time (two simulators and their streams would make
/// each other late on two cores), DDS kinds where loopback carries multicast.
fn check<F: Future<Output = ()>>(kind: DeviceKind, property: fn(DeviceKind) -> F) {
    let _turn = one_at_a_time();
    let run = move || runtime_two_workers().block_on(property(kind));
    if DeviceAddress::Sim(kind).uses_dds() { with_loopback_multicast(run) } else { run() }
}

/// `sim:<kind>`, opened.
fn open_sim(kind: DeviceKind, options: &OpenOptions) -> AnyDevice {
    let address = DeviceAddress::Sim(kind);
    open(&address, options).unwrap_or_else(|e| panic!("{address}: {}", robowire_devices::error_chain(&e)))
}

/// Waits until the connection is `want`.
async fn connection(events: &mut watch::Receiver<Connection>, want: Connection) {
    let seen = tokio::time::timeout(WAIT, events.wait_for(|c| *c == want)).await;
    assert!(seen.is_ok_and(|r| r.is_ok()), "not {want:?} within {WAIT:?}");
}

/// A first state arrives; it observes something; the device reports itself connected.
async fn first_state(kind: DeviceKind) {
    let device = open_sim(kind, &OpenOptions::default());
    assert_eq!(device.kind(), kind);
    assert!(device.wait_state(WAIT).await, "a first state");
    let seen = device.observe().expect("an observation once a state arrived");
    assert_ne!(seen, Observation::default(), "the state observes something");
    assert!(device.status_line().is_some() && device.status_json().is_some(), "a status once a state arrived");
    connection(&mut device.connection_events(), Connection::Connected).await;
    device.close().unwrap();
}

/// Silenced by its own fault switch, the simulator is `Disconnected` after the state timeout;
/// speaking again, it is `Connected` and its states flow.
async fn silence(kind: DeviceKind) {
    let device = open_sim(kind, &OpenOptions { state_timeout: Some(STATE_TIMEOUT), ..OpenOptions::default() });
    assert!(device.wait_state(WAIT).await, "a first state");
    let mut events = device.connection_events();
    connection(&mut events, Connection::Connected).await;
    set_silent(&device, true);
    connection(&mut events, Connection::Disconnected).await;
    set_silent(&device, false);
    connection(&mut events, Connection::Connected).await;
    let mut changes = device.state_changes();
    let fresh = tokio::time::timeout(WAIT, changes.changed()).await;
    assert!(fresh.is_ok_and(|open| open), "states again");
    device.close().unwrap();
}

/// After `close`, what the client held (a serial line, a UDP port, a DDS participant's domain,
/// a shared-memory object) serves again: a client of the still running simulator by its real
/// address gets states, or the port binds and the simulator's states reach it.
async fn close_frees(kind: DeviceKind) {
    let device = open_sim(kind, &OpenOptions::default());
    assert!(device.wait_state(WAIT).await, "a first state");
    let held = held(&device);
    let (closed, simulator) = device.close_keeping_simulator();
    closed.unwrap();
    let _simulator = simulator.expect("a sim: device has its simulator");
    match held {
        Held::Address(address) => {
            let again = open(&address, &OpenOptions::default()).unwrap();
            assert!(again.wait_state(WAIT).await, "{address}: states after the first client closed");
            again.close().unwrap();
        }
        Held::Socket { local, simulator } => {
            let socket = UdpSocket::bind(local).unwrap_or_else(|e| panic!("{local} after close: {e}"));
            socket.set_read_timeout(Some(WAIT)).unwrap();
            let mut datagram = [0; 2048];
            let (_, from) = socket.recv_from(&mut datagram).expect("a state on the freed port");
            assert_eq!(from, simulator, "from the simulator");
        }
    }
}

/// Dropped after being commanded, a device's last command on its links commands no motion (the
/// KMC's and the ZSL-1's stop bursts, a Unitree's damping); a monitor sends nothing, on drop
/// neither.
async fn drop_is_safe(kind: DeviceKind) {
    let mut recording = Recording::new();
    let device = open_sim(kind, &OpenOptions { record: Some(recording.links()), ..OpenOptions::default() });
    assert!(device.wait_state(WAIT).await, "a first state");
    let commanded = match commander(&device) {
        Some(mut step) => {
            until_async(WAIT, "the simulator following the command", || {
                recording.take();
                step()
            })
            .await;
            true
        }
        None => false,
    };
    drop(device);
    recording.take();
    let sent: Vec<Value> =
        recording.frames.iter().filter(|f| f.direction == Direction::Sent).map(|f| recording.read(f)).collect();
    if !commanded {
        assert!(sent.is_empty(), "sent by a device that commands nothing: {sent:?}");
        return;
    }
    let commands: Vec<Vec<f64>> = sent.iter().map(command_fields).filter(|c| !c.is_empty()).collect();
    assert!(commands.iter().any(|c| moves(c)), "the command went out on the recorded links");
    let last = commands.last().expect("commands sent");
    assert!(!moves(last), "the last word commands no motion: {last:?}");
}

/// `stats_line` returns while the stream runs, called over and over from another thread; the
/// states keep coming meanwhile.
async fn stats_never_block(kind: DeviceKind) {
    let device = Arc::new(open_sim(kind, &OpenOptions::default()));
    assert!(device.wait_state(WAIT).await, "a first state");
    let (stop, lines) = (Arc::new(AtomicBool::new(false)), Arc::new(AtomicU64::new(0)));
    let reader = std::thread::spawn({
        let (device, stop, lines) = (device.clone(), stop.clone(), lines.clone());
        move || {
            while !stop.load(Ordering::Relaxed) {
                assert!(!device.stats_line().is_empty());
                lines.fetch_add(1, Ordering::Relaxed);
            }
        }
    });
    let mut observations = device.observations();
    for n in 0..100 {
        let next = tokio::time::timeout(WAIT, observations.next()).await;
        assert!(next.is_ok_and(|o| o.is_some()), "state {n} while the counters are read");
    }
    until_async(WAIT, "1000 stats lines", || lines.load(Ordering::Relaxed) >= 1000).await;
    stop.store(true, Ordering::Relaxed);
    reader.join().unwrap();
    Arc::into_inner(device).expect("the reader's handle is gone").close().unwrap();
}

/// Opened with a recorder, the device declares its links; once used, every one carries frames,
/// and every frame reads by its link's description.
async fn record_taps_every_link(kind: DeviceKind) {
    let mut recording = Recording::new();
    let device = open_sim(kind, &OpenOptions { record: Some(recording.links()), ..OpenOptions::default() });
    let names = recording.names();
    assert!(!names.is_empty(), "no link declared");
    assert!(device.wait_state(WAIT).await, "a first state");
    exercise_links(&device).await;
    let mut carried = vec![false; names.len()];
    until_async(WAIT, &format!("a frame on every declared link, {names:?}"), || {
        for new in recording.take() {
            carried[usize::from(recording.frames[new].link)] = true;
        }
        carried.iter().all(|&c| c)
    })
    .await;
    device.close().unwrap();
    recording.take();
    for frame in &recording.frames {
        recording.read(frame);
    }
    assert_eq!(recording.ring.counters().oversize(), 0, "every frame fits a slot");
}

/// A recording as a recorder holds one: the ring the taps fill, the links registered, and the
/// frames taken from the ring so far.
struct Recording {
    ring: TapRing,
    links: LinkRegistry,
    frames: Vec<Frame>,
}

/// A recorded frame.
struct Frame {
    link: u16,
    direction: Direction,
    bytes: Vec<u8>,
}

impl Recording {
    fn new() -> Self {
        Self { ring: TapRing::with_slots(4096), links: LinkRegistry::default(), frames: Vec::new() }
    }

    fn links(&self) -> RecordLinks {
        RecordLinks::new(self.ring.clone(), self.links.clone())
    }

    fn names(&self) -> Vec<String> {
        self.links.lock().unwrap().iter().map(|(name, _)| name.clone()).collect()
    }

    /// Takes the frames in the ring now (no more: the taps keep filling it) into
    /// [`frames`](Self::frames); where they went there.
    fn take(&mut self) -> std::ops::Range<usize> {
        let start = self.frames.len();
        for _ in 0..self.ring.waiting() {
            let taken = |f: &TappedFrame| Frame { link: f.link, direction: f.direction, bytes: f.bytes().to_vec() };
            self.frames.extend(self.ring.pop(taken));
        }
        start..self.frames.len()
    }

    /// `frame` as JSON, by its link's description; a failure names the link.
    fn read(&self, frame: &Frame) -> Value {
        let (name, description) = self.links.lock().unwrap()[usize::from(frame.link)].clone();
        let read = description.decode(frame.direction, &frame.bytes);
        read.unwrap_or_else(|e| panic!("{name}: a {:?} frame that does not read: {e}", frame.direction)).value
    }
}

/// What a frame commands: every field named in m/s or rad/s (a velocity, as the descriptions
/// name units) and every motor's `kp`, anywhere in it; none in a frame that commands nothing.
fn command_fields(frame: &Value) -> Vec<f64> {
    let mut fields = Vec::new();
    let mut stack = vec![frame];
    while let Some(value) = stack.pop() {
        match value {
            Value::Object(map) => {
                for (key, value) in map {
                    match value.as_f64() {
                        Some(x) if key.ends_with("_mps") || key.ends_with("_radps") || key == "kp" => fields.push(x),
                        _ => stack.push(value),
                    }
                }
            }
            Value::Array(values) => stack.extend(values),
            _ => {}
        }
    }
    fields
}

/// Whether a command's fields ask for motion or stiffness.
fn moves(fields: &[f64]) -> bool {
    fields.iter().any(|&x| x != 0.0)
}

/// The simulator behind a `sim:` device.
fn simulator(device: &AnyDevice) -> &Simulator {
    device.simulator().expect("a sim: device has its simulator")
}

/// Its own fault switch: no state at all while `silent`. The chassis's is a count of answers it
/// swallows ([`SILENT_ANSWERS`]); it answers again by itself.
fn set_silent(device: &AnyDevice, silent: bool) {
    match simulator(device) {
        Simulator::Kmc(sim) if silent => sim.inject(KmcFault::DropResponses { count: SILENT_ANSWERS }),
        Simulator::Kmc(_) => {}
        Simulator::Zsl1(sim) if silent => sim.inject(Zsl1Fault::Silence),
        Simulator::Zsl1(sim) => sim.clear_faults(),
        Simulator::Go2(sim) if silent => sim.inject(Go2Fault::Silence),
        Simulator::Go2(sim) => sim.clear_faults(),
        Simulator::G1(sim) if silent => sim.inject(G1Fault::Silence),
        Simulator::G1(sim) => sim.clear_faults(),
        Simulator::Spline(sim) => sim.pause(silent),
        other => panic!("a simulator this suite does not know: {other:?}"),
    }
}

/// What makes every declared link carry a frame where states alone do not: line noise for
/// the chassis's skipped bytes, a service call for a Unitree's `api`, an arm command at weight 0
/// (the robot's controller alone) for the G1's `arm_sdk`.
async fn exercise_links(device: &AnyDevice) {
    match simulator(device) {
        Simulator::Kmc(sim) => sim.inject(KmcFault::Garbage { bytes: 16 }),
        Simulator::Go2(_) => {
            device.go2().unwrap().sport_mode().await.unwrap();
        }
        Simulator::G1(_) => {
            let g1 = device.g1().unwrap();
            g1.mode().await.unwrap();
            g1.set_arm_joints(&[unitree::g1::JointCommand::default(); unitree::g1::ARM_JOINTS]).unwrap();
        }
        _ => {}
    }
}

/// One step of commanding the device in its own way: the command (re)sent, and whether its
/// simulator follows. A drivable kind is driven forward (standing up first where it stands; the
/// command kept until the drop), a Unitree holds its pose (the G1's velocity goes to its own
/// controller: `tests/g1.rs`); a spline monitor commands nothing (`None`).
fn commander(device: &AnyDevice) -> Option<Box<dyn FnMut() -> bool + '_>> {
    let sim = simulator(device);
    if device.can_drive() && !matches!(sim, Simulator::G1(_)) {
        device.set_drive_timeout(WAIT).unwrap();
        if device.services().contains(&"stand_up") {
            device.call("stand_up").unwrap();
        }
        return Some(Box::new(move || {
            // Refused while it gets up: asked again until the simulator moves.
            let _ = device.drive(FORWARD_MPS, 0.0, 0.0);
            match sim {
                Simulator::Kmc(sim) => sim.state().commanded_velocity_mps > 0.0,
                Simulator::Zsl1(sim) => sim.snapshot().robot.velocity_mps()[0] > 0.0,
                other => panic!("a drivable simulator this suite does not know: {other:?}"),
            }
        }));
    }
    match sim {
        Simulator::Go2(sim) => {
            let go2 = device.go2().unwrap();
            Some(Box::new(move || {
                let q = go2.joint_positions().expect("a state");
                go2.set_joints(&q.map(|q| unitree::JointCommand::hold(q, 20.0, 0.5))).unwrap();
                let seen = sim.snapshot().lowcmd;
                seen.accepted + seen.ignored_sport_mode > 0
            }))
        }
        Simulator::G1(sim) => {
            let g1 = device.g1().unwrap();
            Some(Box::new(move || {
                g1.hold(&g1.joint_positions().expect("a state")).unwrap();
                let seen = sim.snapshot().lowcmd;
                seen.accepted + seen.ignored_mode > 0
            }))
        }
        _ => None,
    }
}

/// What a client held, to be used again once it closed.
enum Held {
    /// Opened by this address, the same resource reaches the simulator (a pty, a domain on an
    /// interface, a shared-memory object).
    Address(DeviceAddress),
    /// The client's UDP port, to which the simulator sends its states.
    Socket { local: SocketAddr, simulator: SocketAddr },
}

/// What the device's client holds.
fn held(device: &AnyDevice) -> Held {
    // Where `sim:go2` and `sim:g1` run without `OpenOptions::sim_interface`.
    let interface = || "lo".to_owned();
    match simulator(device) {
        Simulator::Kmc(sim) => Held::Address(DeviceAddress::Kmc(sim.path())),
        Simulator::Zsl1(sim) => {
            Held::Socket { local: device.zsl().unwrap().local_addr(), simulator: sim.high_level_addr() }
        }
        Simulator::Go2(_) => Held::Address(DeviceAddress::Go2(interface())),
        Simulator::G1(_) => Held::Address(DeviceAddress::G1(interface())),
        Simulator::Spline(sim) => Held::Address(DeviceAddress::Spline(sim.config().spline_name.clone())),
        other => panic!("a simulator this suite does not know: {other:?}"),
    }
}

/// One test per property on a kind: `<kind>::<property>`.
macro_rules! properties {
    ($kind:expr; $($property:ident),+) => {
        $(
            #[test]
            fn $property() {
                super::check($kind, super::$property);
            }
        )+
    };
}

/// Every property on the kind `$kind`, in the module `$name`.
macro_rules! kind {
    ($name:ident: $kind:expr) => {
        mod $name {
            use robowire_devices::DeviceKind;
            properties!($kind;
                first_state, silence, close_frees, drop_is_safe, stats_never_block, record_taps_every_link);
        }
    };
}

kind!(kmc: DeviceKind::Kmc);
kind!(zsl1: DeviceKind::Zsl1);
kind!(zsl1w: DeviceKind::Zsl1w);
kind!(go2: DeviceKind::Go2);
kind!(g1: DeviceKind::G1);
kind!(spline: DeviceKind::Spline);
