//! Bad input at every DDS port. 100 000 datagrams from a seeded PRNG: garbage, near-valid RTPS (a
//! valid header, then submessages with random fields and lying lengths) and real discovery
//! packets with bits flipped, sent as fast as the socket takes them to every UDP port a simulated
//! Go2 (`robowire sim go2`) or `robowire ros2`'s participant has bound and to domain 0's multicast
//! groups. Half the near-valid datagrams carry a captured GUID prefix: the program's own (which it
//! drops) or that of this test's participant, which the program has discovered and serves when
//! the flood begins. Afterwards the Go2 still publishes
//! `rt/lowstate` and stands up for a new client; the bridge still publishes `odom` and obeys
//! `cmd_vel`; each ends successfully on Ctrl-C and said nothing of a panic.
//!
//! Both programs run robowire's own RTPS core, `rtps-proto`. The six datagrams that broke
//! rustdds 0.15.1, robowire's DDS before it (see `datagrams::rustdds_0_15_1_trusts`: one made a
//! participant allocate gigabytes, loop for minutes or panic on its event-loop thread), are still
//! drawn: the default flood redraws them, as it did for rustdds; one test floods with them drawn
//! in, and one sends each alone as each participant. What `rtps-proto` does with each (checked
//! without sockets in `crates/rtps-proto/tests/hostile.rs`):
//!
//! - the NACK_FRAG naming fragments past 2^32, the NACK_FRAG naming fragment 0 and the ACKNACK
//!   whose set reaches past `i64::MAX`: refused by the wire layer, counted by kind
//!   (`FragmentNumberSet`, `FragmentNumberZero`, `SequenceNumberSet` in `Counters::wire`);
//! - the DATA_FRAG of a 4 GiB sample: from a matched writer, refused before anything is allocated
//!   (`Limits::reassembly_bytes`, counted in the reader's `refused_fragments`); from the SPDP
//!   writer, as here, taken by no reader (SPDP is never reassembled; `unmatched_source`);
//! - the HEARTBEAT of 2^40 samples and the GAP up to 2^40: taken, and bounded by arithmetic: the
//!   ACKNACK that answers asks for at most 256 numbers, a GAP marks at most its 256 bits, a reader
//!   holds at most its depth of early samples.
//!
//! The bit-flipped announcements make up a few hundred participants per flood: the first
//! `Limits::participants` fill the table and each later one displaces the participant heard from
//! least recently (`LostReason::Displaced`), so a new client is served at once after the flood.
//!
//! Memory: the flooded programs run under an address-space limit ([`MEMORY_LIMIT_KB`]), so that
//! an unbounded table fails the test instead of exhausting the machine's memory. Each program's
//! resident memory (`VmRSS`) is read before the flood, its peak (`VmHWM`) reset, and both are
//! read after the flood and after the checks: the peak may exceed the resident memory before the
//! flood by at most [`growth_bound_kib`], what `rtps_proto::Limits::default()` lets the flood make
//! the participant keep (about 27 MiB, 16 of them two SEDP readers' reassemblies). The programs do
//! not show their participant's counters; this test's participant, the same core, takes domain
//! 0's multicast share of the flood and prints what it refused, by kind.
//!
//! Forged discovery packets name random locators, which the participants then send to: each test
//! runs only in a network namespace of its own (`robowire_dds::netns`), where they lead nowhere.

use std::collections::{BTreeMap, BTreeSet};
use std::io::{BufRead, BufReader, Read};
use std::net::{Ipv4Addr, SocketAddrV4, UdpSocket};
use std::process::{Child, Command, Stdio};
use std::sync::mpsc::{self, Receiver, Sender};
use std::time::{Duration, Instant};

use robowire_dds::netns::with_loopback_multicast;
use robowire_dds::qos::Qos;
use robowire_dds::{Participant, ParticipantOptions};
use ros2_proto::geometry::{Twist, Vector3};
use ros2_proto::nav::Odometry;
use unitree::trajectory::JointTrajectory;
use unitree::{Device, Go2, LowLevel, LowLevelOptions, LowState};
use unitree_proto::Message;

/// The flood's PRNG seed: a failure replays the same datagrams.
const SEED: u64 = 0x0F10_0D5E_ED00_2026;
/// Datagrams per flood.
const DATAGRAMS: usize = 100_000;
/// Generous: a condition not reached within this is a failure, not slowness.
const WAIT: Duration = Duration::from_secs(30);
/// Address space of a flooded program, KiB: about ten times what it maps when idle.
const MEMORY_LIMIT_KB: u64 = 4 << 20;
/// Domain 0's multicast ports (RTPS default port mapping: PB 7400, d0 0, d2 1).
const SPDP_MULTICAST_PORT: u16 = 7400;
const USER_MULTICAST_PORT: u16 = 7401;
/// Participant 0's metatraffic and user unicast ports (d1 10, d3 11).
const PARTICIPANT_0_PORTS: [u16; 2] = [7410, 7411];

mod datagrams;
use datagrams::{
    GROUP, Rng, SPDP_WRITER, bit_flipped, near_valid_rtps, one_datagram_each, rustdds_0_15_1_trusts, submessages,
};
use robowire_fixtures::wait::runtime_two_workers;

/// What a flood sent.
#[derive(Debug, Default)]
struct FloodReport {
    garbage: u64,
    near_valid: u64,
    bit_flipped: u64,
    bytes: u64,
    /// The longest datagram sent, bytes.
    largest: usize,
    /// Datagrams drawn again because rustdds 0.15.1 trusts a field of theirs, by field.
    redrawn: BTreeMap<&'static str, u64>,
    /// Sends the socket refused, by error.
    refused: BTreeMap<String, u64>,
}

/// One datagram of the flood into `out`; which kind it is.
fn draw(rng: &mut Rng, captured: &[Vec<u8>], prefixes: &[[u8; 12]], out: &mut Vec<u8>) -> usize {
    out.clear();
    let kind = rng.below(3);
    match kind {
        0 => {
            let len = rng.below(1501);
            rng.fill(out, len);
        }
        1 => near_valid_rtps(rng, prefixes, out),
        _ => bit_flipped(rng, captured, out),
    }
    kind
}

/// Sends [`DATAGRAMS`] datagrams from `socket`, each to a random one of `targets`, as fast as the
/// socket takes them; those rustdds 0.15.1 would trust are drawn again unless `trusted_fields`.
fn flood(socket: &UdpSocket, targets: &[SocketAddrV4], captured: &[Vec<u8>], trusted_fields: bool) -> FloodReport {
    let prefixes: Vec<[u8; 12]> = captured.iter().filter_map(|d| d.get(8..20)?.try_into().ok()).collect();
    let mut rng = Rng(SEED);
    let mut report = FloodReport::default();
    let mut datagram = Vec::with_capacity(65_536);
    for _ in 0..DATAGRAMS {
        let mut kind = draw(&mut rng, captured, &prefixes, &mut datagram);
        while let Some(field) = rustdds_0_15_1_trusts(&datagram).filter(|_| !trusted_fields) {
            *report.redrawn.entry(field).or_default() += 1;
            kind = draw(&mut rng, captured, &prefixes, &mut datagram);
        }
        *[&mut report.garbage, &mut report.near_valid, &mut report.bit_flipped][kind] += 1;
        report.largest = report.largest.max(datagram.len());
        match socket.send_to(&datagram, rng.pick(targets)) {
            Ok(n) => report.bytes += n as u64,
            Err(e) => *report.refused.entry(e.kind().to_string()).or_default() += 1,
        }
    }
    report
}

/// A socket in domain 0's discovery group beside the participants' own (which share the port).
fn discovery_listener() -> UdpSocket {
    use rustix::net::{AddressFamily, SocketFlags, SocketType, bind, socket_with, sockopt};
    // Close-on-exec: a copy in the programs this test starts would take its share of what
    // arrives at the port (SO_REUSEPORT) and read none of it.
    let fd = socket_with(AddressFamily::INET, SocketType::DGRAM, SocketFlags::CLOEXEC, None).unwrap();
    sockopt::set_socket_reuseaddr(&fd, true).unwrap();
    sockopt::set_socket_reuseport(&fd, true).unwrap();
    bind(&fd, &SocketAddrV4::new(Ipv4Addr::UNSPECIFIED, SPDP_MULTICAST_PORT)).unwrap();
    let socket = UdpSocket::from(fd);
    socket.join_multicast_v4(&GROUP, &Ipv4Addr::LOCALHOST).unwrap();
    socket.set_read_timeout(Some(WAIT)).unwrap();
    socket
}

/// What the participant under test and one of this test's own sent to domain 0's discovery
/// group until each had announced itself (SPDP): announcements of participants and endpoints
/// (SEDP), heartbeats.
struct Discovery {
    datagrams: Vec<Vec<u8>>,
    /// The two GUID prefixes.
    prefixes: Vec<[u8; 12]>,
    /// This test's participant, still there: the flood speaks as it to the program, which knows
    /// it (its GUID prefix is in the captured datagrams).
    other: Participant,
    /// The unicast ports `other` bound, which the flood spares.
    other_ports: BTreeSet<u16>,
}

fn capture_discovery(listener: &UdpSocket) -> Discovery {
    let bound = bound_udp_ports();
    let other = participant();
    let other_ports = bound_udp_ports().difference(&bound).copied().collect();
    let (mut datagrams, mut announced) = (Vec::new(), BTreeSet::new());
    let mut buf = vec![0; 65_536];
    let start = Instant::now();
    while announced.len() < 2 {
        assert!(start.elapsed() < WAIT, "two participants' SPDP within {WAIT:?}: {announced:?}");
        let n = listener.recv(&mut buf).unwrap_or_else(|e| panic!("no discovery datagram within {WAIT:?}: {e}"));
        let datagram = &buf[..n];
        if submessages(datagram).any(|(kind, _, body)| kind == 0x15 && body.get(8..12) == Some(&SPDP_WRITER[..])) {
            announced.insert(<[u8; 12]>::try_from(&datagram[8..20]).unwrap());
        }
        if datagram.starts_with(b"RTPS") {
            datagrams.push(datagram.to_vec());
        }
    }
    Discovery { datagrams, prefixes: announced.into_iter().collect(), other, other_ports }
}

/// How many participants the flood speaks as (the GUID prefixes of `captured`) that the flooded
/// program takes datagrams from: all but its own.
fn spoofed(captured: &[Vec<u8>]) -> usize {
    let prefixes: BTreeSet<&[u8]> = captured.iter().filter_map(|d| d.get(8..20)).collect();
    prefixes.len().saturating_sub(1)
}

/// Prints what `participant`'s core refused (by kind), dropped and counted, and asserts that it
/// refused something: the flooded programs do not show their counters, this test's participant
/// (the same `rtps-proto` core) does.
fn print_counters(name: &str, participant: &Participant) {
    let c = participant.counters();
    let refused: Vec<_> = c.wire.iter().filter(|(_, n)| *n > 0).collect();
    println!(
        "{name}: {} datagrams, refused by the wire layer {refused:?}, discovery data refused {}, participants \
         at the limit {}, endpoints at the limit {}, not for it {}, from unmatched endpoints {}, other domain {}, \
         events at the limit {}",
        c.datagrams,
        c.discovery_errors,
        c.participants_at_limit,
        c.endpoints_at_limit,
        c.not_for_us,
        c.unmatched_source,
        c.other_domain,
        c.events_at_limit
    );
    assert!(c.wire.total() > 0, "{name} refused nothing: {c:?}");
}

/// A domain participant of this test's own, on `lo`.
fn participant() -> Participant {
    Participant::new(ParticipantOptions::new(0, Some("lo"))).unwrap()
}

/// The UDP ports bound in this network namespace.
fn bound_udp_ports() -> BTreeSet<u16> {
    let table = std::fs::read_to_string("/proc/thread-self/net/udp").unwrap();
    table
        .lines()
        .skip(1)
        .filter_map(|line| u16::from_str_radix(line.split_whitespace().nth(1)?.split(':').nth(1)?, 16).ok())
        .collect()
}

/// This namespace's UDP counters (`Udp:` of `/proc/net/snmp`: InDatagrams, RcvbufErrors, …).
fn udp_counters() -> BTreeMap<String, u64> {
    let snmp = std::fs::read_to_string("/proc/thread-self/net/snmp").unwrap();
    let mut udp = snmp.lines().filter(|l| l.starts_with("Udp:")).map(|l| l.split_whitespace().skip(1));
    let (names, values) = (udp.next().unwrap(), udp.next().unwrap());
    names.map(str::to_owned).zip(values.map(|v| v.parse().unwrap())).collect()
}

/// Floods every port bound in this namespace (but the flood's own and `spared`) and domain 0's two
/// multicast groups, after checking that participant 0's ports are among them. What it sent.
fn flood_every_port(captured: &[Vec<u8>], trusted_fields: bool, spared: &BTreeSet<u16>) -> FloodReport {
    let socket = UdpSocket::bind((Ipv4Addr::LOCALHOST, 0)).unwrap();
    let own = socket.local_addr().unwrap().port();
    let ports: Vec<u16> = bound_udp_ports().into_iter().filter(|p| *p != own && !spared.contains(p)).collect();
    assert!(
        [SPDP_MULTICAST_PORT].iter().chain(&PARTICIPANT_0_PORTS).all(|p| ports.contains(p)),
        "participant 0 of domain 0 listens on 7400, 7410, 7411: {ports:?}"
    );
    let mut targets: Vec<SocketAddrV4> = ports.iter().map(|p| SocketAddrV4::new(Ipv4Addr::LOCALHOST, *p)).collect();
    targets.extend([SPDP_MULTICAST_PORT, USER_MULTICAST_PORT].map(|p| SocketAddrV4::new(GROUP, p)));
    println!("seed {SEED:#x}; {} captured discovery datagrams; targets {targets:?}", captured.len());
    let before = udp_counters();
    let start = Instant::now();
    let report = flood(&socket, &targets, captured, trusted_fields);
    let after = udp_counters();
    let delta = |name: &str| after[name] - before[name];
    println!("flood sent in {:?}: {report:?}", start.elapsed());
    println!(
        "UDP in this namespace meanwhile (DDS traffic included): {} datagrams delivered, {} dropped on a full \
         receive buffer, {} to no port",
        delta("InDatagrams"),
        delta("RcvbufErrors"),
        delta("NoPorts")
    );
    report
}

/// `robowire ARGS` under the address-space limit [`MEMORY_LIMIT_KB`], what it printed kept.
struct Robowire {
    child: Child,
    /// Its lines from both pipes, as they come; `None` once a pipe closed.
    lines: Receiver<Option<String>>,
    /// What it printed so far, stdout and stderr interleaved.
    said: String,
}

impl Robowire {
    /// Starts it and waits (up to [`WAIT`]) for a line that contains `ready`.
    fn start(args: &[&str], ready: &str) -> Self {
        let mut child = Command::new("sh")
            .arg("-c")
            .arg(format!("ulimit -v {MEMORY_LIMIT_KB} && exec \"$0\" \"$@\""))
            .arg(env!("CARGO_BIN_EXE_robowire"))
            .args(args)
            .stdout(Stdio::piped())
            .stderr(Stdio::piped())
            .spawn()
            .unwrap();
        let (sender, lines) = mpsc::channel();
        forward_lines(child.stdout.take().unwrap(), sender.clone());
        forward_lines(child.stderr.take().unwrap(), sender);
        let mut robowire = Self { child, lines, said: String::new() };
        let start = Instant::now();
        loop {
            match robowire.lines.recv_timeout(WAIT.saturating_sub(start.elapsed())) {
                Ok(Some(line)) => {
                    robowire.said.push_str(&line);
                    robowire.said.push('\n');
                    if line.contains(ready) {
                        return robowire;
                    }
                }
                Ok(None) | Err(_) => panic!("robowire {args:?} never said {ready:?}: {}", robowire.output()),
            }
        }
    }

    /// What it printed so far.
    fn output(&mut self) -> &str {
        while let Ok(Some(line)) = self.lines.try_recv() {
            self.said.push_str(&line);
            self.said.push('\n');
        }
        &self.said
    }

    /// Its memory now; `None` once it ended.
    fn memory(&self) -> Option<Memory> {
        let status = std::fs::read_to_string(format!("/proc/{}/status", self.child.id())).ok()?;
        let kib = |name: &str| -> Option<u64> {
            let line = status.lines().find(|l| l.starts_with(name))?;
            line.split_whitespace().nth(1)?.parse().ok()
        };
        Some(Memory { rss_kib: kib("VmRSS:")?, peak_kib: kib("VmHWM:")?, mapped_kib: kib("VmSize:")? })
    }

    /// Its memory now, which must be there (it still runs).
    fn running_memory(&mut self) -> Memory {
        self.memory().unwrap_or_else(|| panic!("it ended: {}", self.output()))
    }

    /// Sets its resident peak (`VmHWM`) to what is resident now (`clear_refs` 5, Linux 4.0);
    /// whether it could.
    fn reset_peak(&self) -> bool {
        let reset = std::fs::write(format!("/proc/{}/clear_refs", self.child.id()), "5");
        if let Err(e) = &reset {
            println!("the peak resident memory could not be reset ({e}): the resident memory after counts");
        }
        reset.is_ok()
    }

    /// CPU time each of its threads used so far, busiest first: a thread that spins after the
    /// flood shows here.
    fn cpu_by_thread(&self) -> String {
        let ticks_per_s = rustix::param::clock_ticks_per_second() as f64;
        let tasks = std::fs::read_dir(format!("/proc/{}/task", self.child.id())).into_iter().flatten().flatten();
        let mut threads: Vec<(f64, String)> = tasks
            .filter_map(|task| {
                let stat = std::fs::read_to_string(task.path().join("stat")).ok()?;
                let (name, rest) = stat.split_once(" (")?.1.rsplit_once(") ")?;
                let fields: Vec<&str> = rest.split_whitespace().collect();
                // utime and stime: fields 14 and 15 of the line, 12 and 13 after the name.
                let ticks: u64 = fields.get(11)?.parse::<u64>().ok()? + fields.get(12)?.parse::<u64>().ok()?;
                Some((ticks as f64 / ticks_per_s, name.to_owned()))
            })
            .collect();
        threads.sort_by(|a, b| b.0.total_cmp(&a.0));
        threads.iter().take(6).map(|(s, name)| format!("{name} {s:.2} s")).collect::<Vec<_>>().join(", ")
    }

    /// Ctrl-C: it must close both pipes within [`WAIT`] and end successfully, having said nothing
    /// of a panic. What it printed.
    fn stop(mut self) -> String {
        rustix::process::kill_process(rustix::process::Pid::from_child(&self.child), rustix::process::Signal::INT)
            .unwrap();
        let start = Instant::now();
        let mut open_pipes = 2;
        while open_pipes > 0 {
            match self.lines.recv_timeout(WAIT.saturating_sub(start.elapsed())) {
                Ok(Some(line)) => {
                    self.said.push_str(&line);
                    self.said.push('\n');
                }
                Ok(None) => open_pipes -= 1,
                Err(_) => panic!("still running {WAIT:?} after Ctrl-C: {}", self.said),
            }
        }
        let status = self.child.wait().unwrap();
        let said = std::mem::take(&mut self.said);
        assert!(status.success(), "{status} after Ctrl-C\n{said}");
        assert!(!said.contains("panicked"), "{said}");
        said
    }
}

impl Drop for Robowire {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

/// A program's memory, from `/proc/PID/status`.
#[derive(Debug, Clone, Copy)]
struct Memory {
    /// Resident now (`VmRSS`), KiB.
    rss_kib: u64,
    /// Resident at its peak (`VmHWM`), KiB.
    peak_kib: u64,
    /// Mapped (`VmSize`), KiB.
    mapped_kib: u64,
}

impl std::fmt::Display for Memory {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "VmRSS {} KiB (VmHWM {} KiB), VmSize {} KiB", self.rss_kib, self.peak_kib, self.mapped_kib)
    }
}

/// Resident memory a program may gain that no table of its participant holds: stacks touched
/// deeper, the allocator's per-thread arenas and fragmentation, KiB.
const UNTABLED_KIB: usize = 2048;

/// How far a flooded program's resident memory may grow, KiB, with the terms it adds up: what
/// its participant's [`rtps_proto::Limits::default()`] lets the flood make it keep. `largest` is
/// the longest datagram the flood sent; no entry a datagram makes holds more of it than that.
/// `spoofed` is how many participants the flood speaks as, by their GUID prefixes in the
/// captured datagrams (the program drops datagrams that carry its own).
///
/// - Remote participants: forged SPDP announcements (a captured one with a bit flipped in its GUID
///   prefix) make new ones, at most `participants`, each a `ParticipantData` from one datagram.
/// - Remote endpoints of a spoofed participant (forged SEDP data): `endpoints_per_participant`,
///   each an `EndpointData` from one datagram.
/// - The two SEDP readers, matched with each spoofed participant's SEDP writers: samples held
///   until the ones before them come (`2 × local_endpoints`, the builtin readers' depth), each a
///   datagram's payload, and `reassemblies` fragmented samples of up to `reassembly_bytes`.
/// - Events not yet taken: `events`, each an `Event` and a datagram's payload.
/// - [`UNTABLED_KIB`].
///
/// The participants the flood makes up it speaks as only when the same bits flip again in a
/// captured SEDP datagram: their held samples are a datagram each, inside the slack.
fn growth_bound_kib(largest: usize, spoofed: usize) -> (usize, Vec<(&'static str, usize)>) {
    use rtps_proto::discovery::{EndpointData, ParticipantData};
    use rtps_proto::participant::Event;
    let l = rtps_proto::Limits::default();
    let entry = largest.min(l.parameter_list_bytes);
    let sedp_readers = 2;
    let terms = vec![
        ("participants", l.participants * (size_of::<ParticipantData>() + entry)),
        ("endpoints", spoofed * l.endpoints_per_participant * (size_of::<EndpointData>() + entry)),
        ("held SEDP samples", spoofed * sedp_readers * 2 * l.local_endpoints * entry),
        ("reassemblies", spoofed * sedp_readers * l.reassemblies * l.reassembly_bytes),
        ("events", l.events * (size_of::<Event>() + largest)),
        ("untabled", UNTABLED_KIB * 1024),
    ];
    let terms: Vec<_> = terms.into_iter().map(|(name, bytes)| (name, bytes.div_ceil(1024))).collect();
    (terms.iter().map(|(_, kib)| kib).sum(), terms)
}

/// Prints `program`'s memory before the flood, right after it, and after the checks, and asserts
/// that its resident peak from the flood on (with `peak_reset` at the flood's start; else the
/// larger of the two resident figures after) grew by no more than [`growth_bound_kib`].
fn assert_memory_bounded(
    program: &str,
    [before, flooded, after]: [Memory; 3],
    peak_reset: bool,
    report: &FloodReport,
    spoofed: usize,
) {
    let (bound, terms) = growth_bound_kib(report.largest, spoofed);
    let top = if peak_reset { after.peak_kib } else { flooded.rss_kib.max(after.rss_kib) };
    let grown = top.saturating_sub(before.rss_kib);
    println!(
        "{program} memory: {before} before the flood; {flooded} after it; {after} after the checks; \
         resident peak +{grown} KiB, bound {bound} KiB from rtps_proto::Limits::default() \
         (largest datagram {} B, {spoofed} spoofed participant(s)): {terms:?}",
        report.largest
    );
    assert!(grown <= bound as u64, "{program}'s resident peak grew by {grown} KiB, over {bound} KiB: {terms:?}");
}

/// Sends every line of `pipe` to `lines`, then `None`, on a thread.
fn forward_lines(pipe: impl Read + Send + 'static, lines: Sender<Option<String>>) {
    std::thread::spawn(move || {
        for line in BufReader::new(pipe).lines().map_while(Result::ok) {
            let _ = lines.send(Some(line));
        }
        let _ = lines.send(None);
    });
}

/// Runs `body` in a network namespace of its own with multicast on loopback; skips (one line)
/// where that would be the machine's own network (its `lo` carries multicast already).
fn in_private_network(body: impl FnOnce() + Send) {
    with_loopback_multicast(|| {
        let interfaces = robowire_udp::host_interfaces();
        if interfaces.iter().any(|(name, _)| name != "lo") {
            return robowire_fixtures::interop::skip(format!(
                "forged discovery packets make participants send to random addresses; this test runs only \
                 in a network namespace with nothing but lo, and this one has {interfaces:?}"
            ));
        }
        body();
    });
}

/// Whether a new reader of `rt/lowstate` on `participant` receives states whose tick goes on.
async fn lowstate_goes_on(participant: &Participant) -> Result<(), String> {
    let mut lowstate = participant.reader::<LowState>(LowState::TOPIC, Qos::READER).unwrap();
    let mut ticks = Vec::new();
    let start = Instant::now();
    while ticks.len() < 2 || ticks[ticks.len() - 1] <= ticks[0] {
        let Ok(sample) = tokio::time::timeout(WAIT.saturating_sub(start.elapsed()), lowstate.recv()).await else {
            return Err(format!("rt/lowstate did not go on within {WAIT:?}: ticks {ticks:?}"));
        };
        ticks.push(sample.map_err(|e| e.to_string())?.value.tick.get());
    }
    println!("rt/lowstate went on for a new reader within {:?}", start.elapsed());
    Ok(())
}

/// Floods `robowire sim go2`, then a new reader sees `rt/lowstate` go on and a new client stands
/// the robot up; the simulator ends cleanly.
fn flood_a_go2(trusted_fields: bool) {
    let listener = discovery_listener();
    let mut sim = Robowire::start(&["sim", "go2", "--interface", "lo", "--report-every-s", "0"], "go2 domain 0 lo");
    let discovery = capture_discovery(&listener);
    drop(listener);
    // The simulator serves this test's participant: it has matched the participant's builtin
    // endpoints, which the flood then speaks as.
    runtime_two_workers().block_on(lowstate_goes_on(&discovery.other)).unwrap();
    let before = sim.running_memory();
    let peak_reset = sim.reset_peak();
    let captured = &discovery.datagrams;
    let report = flood_every_port(captured, trusted_fields, &discovery.other_ports);
    let flooded = sim.running_memory();
    print_counters("this test's participant (domain 0's multicast share of the flood)", &discovery.other);

    runtime_two_workers().block_on(async {
        if let Err(stopped) = lowstate_goes_on(&participant()).await {
            let cpu = sim.cpu_by_thread();
            panic!("after the flood, {stopped}; the simulator's CPU by thread: {cpu}; it said {}", sim.output());
        }

        let robot = LowLevel::<Go2>::open(LowLevelOptions::on(Some("lo"), 0)).unwrap();
        let lying = robot.wait_state(WAIT, |_| true).await.expect("the client's first rt/lowstate");
        assert_eq!(robot.release_sport_mode().await.unwrap(), 1, "one ReleaseMode");
        let from = std::array::from_fn(|i| lying.motor_state[i].q.get());
        let stand = JointTrajectory::stand_up(from, Duration::from_millis(500));
        let (began, mut ticker) = (Instant::now(), tokio::time::interval(Duration::from_millis(2)));
        loop {
            ticker.tick().await;
            robot.set_joints(&stand.joints_at(began.elapsed())).unwrap();
            let q = robot.joint_positions().unwrap();
            if began.elapsed() >= stand.duration() && stand.largest_error_rad(&q) < 0.05 {
                break;
            }
            assert!(began.elapsed() < WAIT, "not standing within {WAIT:?}: {q:?}");
        }
        let s = robot.stats();
        assert_eq!((s.lowstate.checksum_errors, s.lowstate.decode_errors), (0, 0), "{s:?}");
        robot.close();
    });
    let after = sim.running_memory();
    assert_memory_bounded("simulator", [before, flooded, after], peak_reset, &report, spoofed(captured));
    let out = sim.stop();
    assert!(out.contains("ReleaseMode"), "{out}");
}

#[test]
fn the_default_flood_redraws_each_datagram_that_breaks_rustdds_0_15_1() {
    let datagrams = one_datagram_each([7; 12]);
    for (field, datagram) in &datagrams {
        assert_eq!(rustdds_0_15_1_trusts(datagram), Some(*field));
    }
    // The same HEARTBEAT announcing sequence numbers 1..=10, a GAP of 1000..1010.
    let (mut heartbeat, mut gap) = (datagrams[1].1.clone(), datagrams[2].1.clone());
    heartbeat[40..48].copy_from_slice(&[0, 0, 0, 0, 10, 0, 0, 0]);
    gap[40..48].copy_from_slice(&[0, 0, 0, 0, 0xF2, 3, 0, 0]);
    assert_eq!(rustdds_0_15_1_trusts(&heartbeat), None);
    assert_eq!(rustdds_0_15_1_trusts(&gap), None);
}

#[test]
fn a_flooded_go2_still_streams_lowstate_and_stands_up_for_a_client() {
    in_private_network(|| flood_a_go2(false));
}

#[test]
fn a_go2_flooded_with_what_rustdds_0_15_1_trusts_still_stands_up() {
    in_private_network(|| flood_a_go2(true));
}

#[test]
fn one_datagram_that_rustdds_0_15_1_trusts_does_not_silence_a_go2() {
    in_private_network(|| {
        let mut broken = Vec::new();
        for field in one_datagram_each([0; 12]).map(|(field, _)| field) {
            let listener = discovery_listener();
            let mut sim =
                Robowire::start(&["sim", "go2", "--interface", "lo", "--report-every-s", "0"], "go2 domain 0 lo");
            let discovery = capture_discovery(&listener);
            drop(listener);
            // Once the simulator serves this test's participant, it has matched its builtin
            // endpoints: the datagram then reaches their state, not "unmatched".
            runtime_two_workers()
                .block_on(lowstate_goes_on(&discovery.other))
                .expect("rt/lowstate before the datagram");
            let socket = UdpSocket::bind((Ipv4Addr::LOCALHOST, 0)).unwrap();
            // As each participant, to the simulator's metatraffic port (participant 0).
            for prefix in &discovery.prefixes {
                let (_, datagram) = one_datagram_each(*prefix).into_iter().find(|(f, _)| *f == field).unwrap();
                socket.send_to(&datagram, (Ipv4Addr::LOCALHOST, PARTICIPANT_0_PORTS[0])).unwrap();
            }
            let streaming = runtime_two_workers().block_on(lowstate_goes_on(&discovery.other));
            let memory = sim.memory().map_or("ended".into(), |m| m.to_string());
            println!("{field}: {streaming:?}; simulator {memory}");
            if let Err(stopped) = streaming {
                let said: Vec<String> = sim.output().lines().skip(1).take(3).map(str::to_owned).collect();
                broken.push((field, stopped, said));
            }
        }
        assert!(broken.is_empty(), "one datagram silenced the simulator: {broken:#?}");
    });
}

#[test]
fn a_flooded_ros2_bridge_still_publishes_odom_and_obeys_cmd_vel() {
    in_private_network(|| {
        let listener = discovery_listener();
        let args = ["ros2", "--device", "sim:kmc", "--arm", "--interface", "lo", "--json"];
        let mut bridge = Robowire::start(&args, "ros2: ready");
        let discovery = capture_discovery(&listener);
        drop(listener);
        // The bridge serves this test's participant (it has matched its builtin endpoints).
        runtime_two_workers().block_on(async {
            let mut odom = discovery.other.reader::<Odometry>(&ros2_proto::topic("", "odom"), Qos::READER).unwrap();
            tokio::time::timeout(WAIT, odom.recv()).await.expect("odom before the flood").unwrap();
        });
        let before = bridge.running_memory();
        let peak_reset = bridge.reset_peak();
        let captured = &discovery.datagrams;
        let report = flood_every_port(captured, false, &discovery.other_ports);
        let flooded = bridge.running_memory();
        print_counters("this test's participant (domain 0's multicast share of the flood)", &discovery.other);

        let driven = runtime_two_workers().block_on(async {
            let participant = participant();
            let mut odom = participant.reader::<Odometry>(&ros2_proto::topic("", "odom"), Qos::READER).unwrap();
            let cmd_vel = participant.writer::<Twist>(&ros2_proto::topic("", "cmd_vel"), Qos::ROS_DEFAULT).unwrap();
            let start = Instant::now();
            if tokio::time::timeout(WAIT, odom.recv()).await.is_err() {
                return Err(format!("no odom within {WAIT:?} after the flood"));
            }
            println!("odom for a new reader after the flood within {:?}", start.elapsed());
            let forward = Twist { linear: Vector3 { x: 0.5, y: 0.0, z: 0.0 }, angular: Vector3::default() };
            let start = Instant::now();
            loop {
                cmd_vel.write(forward).map_err(|e| e.to_string())?;
                // A twist every 20 ms (the deadman is 0.5 s), the odometry in between.
                if let Ok(sample) = tokio::time::timeout(Duration::from_millis(20), odom.recv()).await
                    && sample.map_err(|e| e.to_string())?.value.twist.twist.linear.x > 0.2
                {
                    return Ok(());
                }
                if start.elapsed() > WAIT {
                    return Err(format!("cmd_vel did not move the chassis within {WAIT:?}"));
                }
            }
        });
        if let Err(failed) = driven {
            let cpu = bridge.cpu_by_thread();
            panic!("{failed}; the bridge's CPU by thread: {cpu}; it said {}", bridge.output());
        }

        let after = bridge.running_memory();
        assert_memory_bounded("bridge", [before, flooded, after], peak_reset, &report, spoofed(captured));
        let out = bridge.stop();
        let report = out.lines().find(|line| line.starts_with('[')).unwrap_or_else(|| panic!("no JSON report: {out}"));
        let counters: serde_json::Value = serde_json::from_str(report).unwrap_or_else(|e| panic!("{e}: {out}"));
        let cmd_vel = &counters[0]["cmd_vel"];
        assert!(cmd_vel["applied"].as_u64().unwrap() > 0, "{counters}");
        assert_eq!(cmd_vel["invalid"], 0, "{counters}");
    });
}
