//! robowire-dds against CycloneDDS itself: the `cyclonedds` Python binding with Unitree's IDL
//! classes and CRC (`tests/cyclone_peer/peer.py`), each scenario in a private network of its own
//! (`robowire_dds::netns`), on two CycloneDDS versions:
//!
//! - `cyclonedds_0_10_2`: PyPI's `cyclonedds==0.10.2` (Unitree's pin) in CPython 3.10
//!   (`robowire_fixtures::peers::unitree_python`); its wheel's own libddsc names itself 0.11.0;
//! - `cyclonedds_11`: PyPI's `cyclonedds==11.0.1` in CPython 3.12 or 3.13
//!   (`robowire_fixtures::peers::cyclonedds11_python`), libddsc 11.0.1.
//!
//! Scenarios: discovery both ways with each side's participant USER_DATA; Go2 LowCmd/LowState best
//! effort and reliable both ways, CRCs checked on both sides; a fragmented HG LowState (2092
//! bytes, above Cyclone's 1344-byte fragments) reliable both ways; both reliable exchanges again
//! with one UDP datagram in five dropped (nftables); transient-local late joiners
//! both ways; an incompatible reliability reported by Cyclone and not matched by robowire; the
//! peer leaving (cleanly, then killed) and a new peer process after it.

use std::io::{BufRead, BufReader, Read, Write};
use std::path::{Path, PathBuf};
use std::process::{Child, ChildStdin, Command, Stdio};
use std::sync::mpsc::{Receiver, RecvTimeoutError};
use std::time::{Duration, Instant};

use robowire_core::cdr::CdrType;
use robowire_dds::netns::with_loopback_multicast;
use robowire_dds::qos::Qos;
use robowire_dds::{Participant, ParticipantOptions, Reader, Writer};
use robowire_fixtures::wait::{runtime, until};
use serde_json::{Value, json};
use unitree_proto::{HgLowState, LowCmd, LowState, Message};

/// Any one step's bound (discovery, a burst, an exit).
const WAIT: Duration = Duration::from_secs(30);
/// CycloneDDS's default participant lease (what forgets a killed peer).
const CYCLONE_LEASE: Duration = Duration::from_secs(10);
/// Samples in a burst.
const COUNT: u32 = 200;
/// HG LowStates in the fragmented burst.
const FRAGMENTED: u32 = 20;
/// Samples kept for a transient-local late joiner.
const KEPT: u32 = 5;
/// The peer's participant USER_DATA.
const PEER_USER_DATA: &[u8] = b"cyclone=peer;";
/// Ours, as a ROS 2 participant's.
const OUR_USER_DATA: &[u8] = b"enclave=/;";
/// DDS's RELIABILITY_QOS_POLICY_ID.
const RELIABILITY_QOS_POLICY_ID: u64 = 11;

fn hex(bytes: &[u8]) -> String {
    bytes.iter().map(|b| format!("{b:02x}")).collect()
}

fn options() -> ParticipantOptions {
    ParticipantOptions::new(0, Some("lo"))
}

/// The reader's next sample within `within`.
fn recv<T: CdrType + 'static>(
    rt: &tokio::runtime::Runtime,
    reader: &mut Reader<T>,
    within: Duration,
) -> Option<(T, [u8; 16])> {
    rt.block_on(async { tokio::time::timeout(within, reader.recv()).await }).ok().map(|s| {
        let s = s.expect("a sample");
        (s.value, s.writer)
    })
}

/// `peer.py` running: its JSON lines as they come, its stdin for the words it waits for.
struct Peer {
    child: Child,
    stdin: Option<ChildStdin>,
    lines: Receiver<String>,
    seen: Vec<String>,
}

impl Peer {
    fn start(python: &Path, args: &[&str]) -> Self {
        let script = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/cyclone_peer/peer.py");
        let mut child = Command::new(python)
            .arg(&script)
            .args(args)
            .stdin(Stdio::piped())
            .stdout(Stdio::piped())
            .stderr(Stdio::piped())
            .spawn()
            .expect("running the Python peer");
        let stdout = child.stdout.take().unwrap();
        let (tx, lines) = std::sync::mpsc::channel();
        std::thread::spawn(move || {
            for line in BufReader::new(stdout).lines().map_while(Result::ok) {
                let _ = tx.send(line);
            }
        });
        Self { stdin: child.stdin.take(), child, lines, seen: Vec::new() }
    }

    /// What went wrong, with the peer's output so far.
    fn failure(&mut self, why: &str) -> String {
        let _ = self.child.kill();
        let status = self.child.wait().ok();
        let mut stderr = String::new();
        if let Some(mut e) = self.child.stderr.take() {
            let _ = e.read_to_string(&mut stderr);
        }
        format!("{why}; peer {status:?}\nstdout: {:#?}\nstderr: {stderr}", self.seen)
    }

    /// The next line with `"event": event` (panics on an "error" line, an exit, or after `within`).
    fn expect_within(&mut self, event: &str, within: Duration) -> Value {
        let deadline = Instant::now() + within;
        loop {
            let left = deadline.saturating_duration_since(Instant::now());
            match self.lines.recv_timeout(left) {
                Ok(line) => {
                    self.seen.push(line.clone());
                    let value: Value = match serde_json::from_str(&line) {
                        Ok(v) => v,
                        Err(_) => continue,
                    };
                    if value["event"] == event {
                        return value;
                    }
                    if value["event"] == "error" {
                        let failure = self.failure(&format!("the peer failed waiting for {event:?}"));
                        panic!("{failure}");
                    }
                }
                Err(RecvTimeoutError::Timeout) => {
                    let failure = self.failure(&format!("no {event:?} from the peer within {within:?}"));
                    panic!("{failure}");
                }
                Err(RecvTimeoutError::Disconnected) => {
                    let failure = self.failure(&format!("the peer ended before {event:?}"));
                    panic!("{failure}");
                }
            }
        }
    }

    fn expect(&mut self, event: &str) -> Value {
        self.expect_within(event, WAIT)
    }

    /// The line with `"event": event` if one has come.
    fn poll(&mut self, event: &str) -> Option<Value> {
        while let Ok(line) = self.lines.try_recv() {
            self.seen.push(line.clone());
            if let Ok(value) = serde_json::from_str::<Value>(&line)
                && value["event"] == event
            {
                return Some(value);
            }
        }
        None
    }

    fn say(&mut self, word: &str) {
        let stdin = self.stdin.as_mut().expect("the peer's stdin");
        writeln!(stdin, "{word}").expect("writing to the peer");
        stdin.flush().unwrap();
    }

    /// Says "quit" and waits for a clean exit.
    fn finish(mut self) {
        if let Some(mut stdin) = self.stdin.take() {
            let _ = writeln!(stdin, "quit");
        }
        let began = Instant::now();
        loop {
            match self.child.try_wait().unwrap() {
                Some(status) if status.success() => return,
                Some(status) => {
                    let failure = self.failure(&format!("the peer exited {status}"));
                    panic!("{failure}");
                }
                None if began.elapsed() > WAIT => {
                    let failure = self.failure("the peer did not exit");
                    panic!("{failure}");
                }
                None => std::thread::sleep(Duration::from_millis(10)),
            }
        }
    }
}

impl Drop for Peer {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

/// A GUID the peer printed (hex) as wire-order bytes.
fn guid_of(value: &Value) -> [u8; 16] {
    let text = value.as_str().unwrap_or_else(|| panic!("a GUID: {value}"));
    let bytes: Vec<u8> = (0..text.len()).step_by(2).map(|i| u8::from_str_radix(&text[i..i + 2], 16).unwrap()).collect();
    bytes.try_into().unwrap_or_else(|_| panic!("16 bytes: {text}"))
}

fn tags(value: &Value) -> Vec<u32> {
    value.as_array().unwrap().iter().map(|t| u32::try_from(t.as_u64().unwrap()).unwrap()).collect()
}

fn strictly_increasing_within(tags: &[u32], count: u32) -> bool {
    tags.windows(2).all(|w| w[0] < w[1]) && tags.iter().all(|t| (1..=count).contains(t))
}

fn go2_lowcmd(tag: u32) -> LowCmd {
    let mut cmd = LowCmd::default();
    cmd.head = [0xFE, 0xEF];
    cmd.reserve = tag.into();
    cmd.motor_cmd[0].mode = 1;
    cmd.motor_cmd[0].q = (0.001 * tag as f32).into();
    cmd
}

fn go2_lowstate(tick: u32) -> LowState {
    let mut state = LowState::default();
    state.head = [0xFE, 0xEF];
    state.tick = tick.into();
    state.motor_state[0].q = (0.001 * tick as f32).into();
    state
}

fn hg_lowstate(tick: u32) -> HgLowState {
    let mut state = HgLowState::default();
    state.tick = tick.into();
    state.mode_machine = 5;
    for (i, motor) in state.motor_state.iter_mut().enumerate() {
        motor.q = (0.001 * tick as f32 + i as f32).into();
    }
    state
}

// ---------------------------------------------------------------------------------------------
// 1. Discovery both ways, with USER_DATA.

fn discovery(python: &Path) {
    with_loopback_multicast(|| {
        let ours = Participant::new(ParticipantOptions { user_data: OUR_USER_DATA.to_vec(), ..options() }).unwrap();
        let writer = ours.writer::<LowCmd>(LowCmd::TOPIC, Qos::WRITER).unwrap();
        let reader = ours.reader::<LowState>(LowState::TOPIC, Qos::READER).unwrap();
        let mut peer = Peer::start(python, &["discovery"]);
        let ready = peer.expect("ready");
        eprintln!("peer: cyclonedds {} on {}", ready["cyclonedds"], ready["libddsc"]);
        let (their_participant, their_writer, their_reader) =
            (guid_of(&ready["participant"]), guid_of(&ready["writer"]), guid_of(&ready["reader"]));

        // Cyclone's builtin topics show our participant with its USER_DATA, and our endpoints.
        let seen = peer.expect("discovered");
        assert_eq!(seen["participants"][hex(&ours.guid())], "enclave=/;", "DCPSParticipant's USER_DATA: {seen}");
        let listed = |table: &str, guid: [u8; 16], topic: &str, type_name: &str| {
            seen[table].as_array().unwrap().iter().any(|e| {
                e["guid"] == hex(&guid)
                    && e["participant"] == hex(&ours.guid())
                    && e["topic"] == topic
                    && e["type"] == type_name
            })
        };
        assert!(listed("publications", writer.guid(), LowCmd::TOPIC, LowCmd::DDS_TYPE_NAME), "DCPSPublication: {seen}");
        assert!(
            listed("subscriptions", reader.guid(), LowState::TOPIC, LowState::DDS_TYPE_NAME),
            "DCPSSubscription: {seen}"
        );

        // We see Cyclone's participant with its USER_DATA, and its endpoints.
        until(WAIT, "Cyclone's participant and endpoints discovered", || {
            let endpoints = ours.discovered_endpoints();
            let has = |guid: [u8; 16], is_writer: bool, topic: &str, type_name: &str| {
                endpoints
                    .iter()
                    .any(|e| e.guid == guid && e.writer == is_writer && e.topic == topic && e.type_name == type_name)
            };
            has(their_writer, true, LowState::TOPIC, LowState::DDS_TYPE_NAME)
                && has(their_reader, false, LowCmd::TOPIC, LowCmd::DDS_TYPE_NAME)
        });
        let them = ours.discovered_participants();
        let them = them.iter().find(|p| p.guid_prefix == their_participant[..12]).expect("Cyclone's participant");
        assert_eq!(them.user_data, PEER_USER_DATA, "Cyclone's USER_DATA");
        assert_eq!(them.vendor, ([1, 0x10], Some("Eclipse CycloneDDS")));
        assert!(them.unicast.iter().all(|a| a.ip().is_loopback()) && !them.unicast.is_empty(), "{:?}", them.unicast);
        assert_eq!(&their_writer[..12], &their_participant[..12]);
        // Compatible QoS (Cyclone's defaults: writer reliable, reader best effort): matched.
        until(WAIT, "matched both ways", || writer.reader_matched(their_reader) && reader.matched_writers() == 1);
        peer.finish();
    });
}

/// `nft` with `script` on stdin, in the calling thread's network namespace.
fn nft(script: &str) -> Result<(), String> {
    let mut nft = Command::new("nft")
        .args(["-f", "-"])
        .stdin(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .map_err(|e| format!("no nftables' nft ({e}): install Debian's nftables"))?;
    nft.stdin.take().unwrap().write_all(script.as_bytes()).map_err(|e| e.to_string())?;
    let out = nft.wait_with_output().map_err(|e| e.to_string())?;
    if out.status.success() {
        Ok(())
    } else {
        Err(format!("nft cannot filter in this private network: {}", String::from_utf8_lossy(&out.stderr).trim()))
    }
}

/// A filter on arriving packets in this private network, dropping nothing yet; the reason when
/// nftables cannot make one here.
fn loss_filter() -> Result<(), String> {
    nft("add table inet robowire_loss\nadd chain inet robowire_loss input { type filter hook input priority 0; }\n")
}

/// From now on, one UDP datagram in five that arrives in this private network is dropped
/// (nftables' random number per packet): every repair path of a reliable writer and reader
/// (HEARTBEAT, ACKNACK, NACK_FRAG, retransmissions, GAP) has work.
fn lossy() {
    nft("add rule inet robowire_loss input meta l4proto udp numgen random mod 5 0 counter drop").unwrap();
}

/// The datagrams [`lossy`]'s rule has dropped so far.
fn dropped() -> u64 {
    let out = Command::new("nft").args(["list", "chain", "inet", "robowire_loss", "input"]).output().unwrap();
    let listing = String::from_utf8_lossy(&out.stdout);
    let after = listing.split("counter packets ").nth(1).unwrap_or_else(|| panic!("no counter: {listing}"));
    after.split_whitespace().next().and_then(|n| n.parse().ok()).unwrap_or_else(|| panic!("{listing}"))
}

/// Whether a scenario `test` under loss can run here (else its skip line, or its failure under
/// `ROBOWIRE_INTEROP=1`).
fn loss_possible(test: &str) -> bool {
    match loss_filter() {
        Ok(()) => true,
        Err(reason) => {
            robowire_fixtures::interop::missing(test, reason).unwrap_or_else(|failure| panic!("{failure}"));
            false
        }
    }
}

// ---------------------------------------------------------------------------------------------
// 2 and 3. Streams both ways: Go2 best effort and reliable, HG LowState fragmented.

/// One direction's samples: robowire writes `Out` (tagged by `out`), Cyclone writes `In`
/// (tagged by `tag`), `count` each way after both sides have matched.
struct Exchange<Out: Message + CdrType + 'static, In: Message + CdrType + 'static> {
    scenario: &'static [&'static str],
    out_topic: &'static str,
    out: fn(u32) -> Out,
    in_topic: &'static str,
    tag: fn(&In) -> u32,
    count: u32,
    reliable: bool,
    /// Drop one UDP datagram in five once both sides have matched ([`lossy`]).
    loss: bool,
}

/// What each side received: (ours, the peer's summary).
fn exchange<Out: Message + CdrType + 'static, In: Message + CdrType + 'static>(
    python: &Path,
    x: &Exchange<Out, In>,
) -> (Vec<u32>, Value) {
    let rt = runtime();
    let ours = Participant::new(options()).unwrap();
    let depth = i32::try_from(x.count).unwrap() + 10;
    let qos = Qos { reliable: x.reliable, depth, ..Qos::WRITER };
    let writer: Writer<Out> = ours.writer(x.out_topic, qos).unwrap();
    let mut reader: Reader<In> = ours.reader(x.in_topic, qos).unwrap();
    let count = x.count.to_string();
    let mut args = x.scenario.to_vec();
    args.push(&count);
    let mut peer = Peer::start(python, &args);
    let matched = peer.expect("matched");
    let their_reader = guid_of(&matched["reader"]);
    until(WAIT, "our writer and reader matched to Cyclone's", || {
        writer.reader_matched(their_reader) && reader.matched_writers() == 1
    });
    if x.loss {
        lossy();
    }
    peer.say("go");
    for tag in 1..=x.count {
        writer.write((x.out)(tag)).unwrap();
        std::thread::sleep(Duration::from_millis(1));
    }
    let mut received = Vec::new();
    // Reliable: every sample, however long it takes; best effort: until a second of silence.
    let quiet = if x.reliable { WAIT } else { Duration::from_secs(1) };
    while received.len() < x.count as usize {
        match recv(&rt, &mut reader, quiet) {
            Some((sample, from)) => {
                assert_eq!(from, guid_of(&matched["writer"]), "from Cyclone's writer");
                received.push((x.tag)(&sample));
            }
            None => break,
        }
    }
    let summary = peer.expect("summary");
    if x.loss {
        let dropped = dropped();
        eprintln!("{dropped} datagrams dropped");
        assert!(dropped > 0, "the loss is real");
    }
    let stats = reader.stats();
    assert_eq!((stats.checksum_errors, stats.decode_errors), (0, 0), "every CRC Unitree's: {stats:?}");
    assert_eq!(summary["crc_bad"], 0, "every CRC ours, as Unitree's code computes it: {summary}");
    peer.finish();
    (received, summary)
}

fn go2_exchange(reliable: bool) -> Exchange<LowCmd, LowState> {
    Exchange {
        scenario: if reliable { &["stream", "reliable"] } else { &["stream", "best_effort"] },
        out_topic: LowCmd::TOPIC,
        out: go2_lowcmd,
        in_topic: LowState::TOPIC,
        tag: |s| s.tick.get(),
        count: COUNT,
        reliable,
        loss: false,
    }
}

fn go2_reliable(python: &Path) {
    go2_reliable_losing(python, false);
}

fn go2_reliable_under_loss(python: &Path) {
    go2_reliable_losing(python, true);
}

fn go2_reliable_losing(python: &Path, loss: bool) {
    let test = robowire_fixtures::interop::current_test();
    with_loopback_multicast(|| {
        if loss && !loss_possible(&test) {
            return;
        }
        let (ours, theirs) = exchange(python, &Exchange { loss, ..go2_exchange(true) });
        let every: Vec<u32> = (1..=COUNT).collect();
        assert_eq!(ours, every, "reliable: every LowState of Cyclone's, in order");
        assert_eq!(tags(&theirs["tags"]), every, "reliable: every LowCmd of ours, in order: {theirs}");
        assert_eq!(theirs["last_q0"].as_f64().unwrap() as f32, 0.001 * COUNT as f32);
    });
}

fn go2_best_effort(python: &Path) {
    with_loopback_multicast(|| {
        let (ours, theirs) = exchange(python, &go2_exchange(false));
        let theirs = tags(&theirs["tags"]);
        eprintln!("best effort: {} of {COUNT} LowStates here, {} of {COUNT} LowCmds there", ours.len(), theirs.len());
        assert!(!ours.is_empty() && strictly_increasing_within(&ours, COUNT), "{ours:?}");
        assert!(!theirs.is_empty() && strictly_increasing_within(&theirs, COUNT), "{theirs:?}");
    });
}

fn fragmented(python: &Path) {
    fragmented_losing(python, false);
}

fn fragmented_under_loss(python: &Path) {
    fragmented_losing(python, true);
}

fn fragmented_losing(python: &Path, loss: bool) {
    // Above CycloneDDS's and robowire's 1344-byte fragments: DATA_FRAG both ways.
    const { assert!(HgLowState::IMAGE_LEN + 4 > 1344) };
    let test = robowire_fixtures::interop::current_test();
    with_loopback_multicast(|| {
        if loss && !loss_possible(&test) {
            return;
        }
        let x = Exchange {
            scenario: &["fragments"],
            out_topic: "rt/lowstate_back",
            out: hg_lowstate,
            in_topic: HgLowState::TOPIC,
            tag: |s: &HgLowState| s.tick.get(),
            count: FRAGMENTED,
            reliable: true,
            loss,
        };
        let (ours, theirs) = exchange(python, &x);
        let every: Vec<u32> = (1..=FRAGMENTED).collect();
        assert_eq!(ours, every, "every HG LowState of Cyclone's, reassembled, CRC checked");
        assert_eq!(tags(&theirs["tags"]), every, "every HG LowState of ours, reassembled by Cyclone: {theirs}");
        assert_eq!(theirs["last_q0"].as_f64().unwrap() as f32, 0.001 * FRAGMENTED as f32);
    });
}

// ---------------------------------------------------------------------------------------------
// 4. Transient-local late joiners.

fn transient_local(python: &Path) {
    let kept = Qos { reliable: true, depth: KEPT as i32, transient_local: true, ..Qos::WRITER };
    with_loopback_multicast(|| {
        let rt = runtime();
        // Cyclone writes first; our reader joins late.
        let mut peer = Peer::start(python, &["late_writer", &KEPT.to_string()]);
        let written = peer.expect("written");
        let ours = Participant::new(options()).unwrap();
        let mut reader = ours.reader::<LowState>(LowState::TOPIC, kept).unwrap();
        let mut ticks = Vec::new();
        while ticks.len() < KEPT as usize {
            let (state, from) = recv(&rt, &mut reader, WAIT).expect("Cyclone's kept LowStates");
            assert_eq!(from, guid_of(&written["writer"]));
            ticks.push(state.tick.get());
        }
        assert_eq!(ticks, (1..=KEPT).collect::<Vec<_>>(), "the samples Cyclone kept, in order");
        assert_eq!(reader.stats().checksum_errors, 0);
        peer.finish();
        drop(reader);

        // We write first; Cyclone's reader joins late.
        let writer = ours.writer::<LowState>(LowState::TOPIC, kept).unwrap();
        for tick in 1..=KEPT {
            writer.write(go2_lowstate(tick)).unwrap();
        }
        let mut peer = Peer::start(python, &["late_reader", &KEPT.to_string()]);
        let summary = peer.expect("summary");
        assert_eq!(tags(&summary["ticks"]), (1..=KEPT).collect::<Vec<_>>(), "the samples we kept: {summary}");
        assert_eq!(summary["crc_bad"], 0);
        peer.finish();
    });
}

// ---------------------------------------------------------------------------------------------
// 5. Incompatible QoS.

fn incompatible_qos(python: &Path) {
    with_loopback_multicast(|| {
        let ours = Participant::new(options()).unwrap();
        // Best effort offered to Cyclone's reliable reader; reliable requested of Cyclone's best-effort writer.
        let writer = ours.writer::<LowCmd>(LowCmd::TOPIC, Qos { reliable: false, ..Qos::WRITER }).unwrap();
        let reader = ours.reader::<LowState>(LowState::TOPIC, Qos { reliable: true, ..Qos::READER }).unwrap();
        let mut peer = Peer::start(python, &["incompatible"]);
        let ready = peer.expect("ready");
        let (their_reader, their_writer) = (guid_of(&ready["reader"]), guid_of(&ready["writer"]));
        let report = peer.expect("incompatible");
        for side in ["requested", "offered"] {
            let statuses = report[side].as_array().unwrap();
            assert!(
                statuses.iter().all(|s| s[0].as_u64() >= Some(1) && s[1] == RELIABILITY_QOS_POLICY_ID),
                "Cyclone's {side}-incompatible-QoS status names RELIABILITY: {report}"
            );
        }
        assert_eq!((report["reader_matched"].as_u64(), report["writer_matched"].as_u64()), (Some(0), Some(0)));
        until(WAIT, "Cyclone's endpoints discovered", || {
            let endpoints = ours.discovered_endpoints();
            endpoints.iter().any(|e| e.guid == their_reader) && endpoints.iter().any(|e| e.guid == their_writer)
        });
        // robowire reports both pairs incompatible, at the discovery that would have matched them.
        until(WAIT, "robowire reports the incompatible pairs", || {
            !writer.incompatible_readers().is_empty() && !reader.incompatible_writers().is_empty()
        });
        for why in [writer.incompatible_readers(), reader.incompatible_writers()] {
            assert!(why.len() == 1 && why[0].reason.contains("reliab"), "{why:?}");
        }
        assert_eq!(writer.matched_readers(), 0, "our best-effort writer is not matched to a reliable reader");
        assert_eq!(reader.matched_writers(), 0, "our reliable reader is not matched to a best-effort writer");
        peer.finish();
    });
}

// ---------------------------------------------------------------------------------------------
// 6. The peer leaving and coming back.

/// Runs `peer.py heartbeat` until samples flow both ways; the peer's participant GUID.
fn flowing(
    python: &Path,
    rt: &tokio::runtime::Runtime,
    writer: &Writer<LowCmd>,
    reader: &mut Reader<LowState>,
) -> (Peer, [u8; 16]) {
    let mut peer = Peer::start(python, &["heartbeat"]);
    let ready = peer.expect("ready");
    let their_writer = guid_of(&ready["writer"]);
    let (mut here, mut there) = (false, false);
    let began = Instant::now();
    let mut tag = 0;
    while !(here && there) {
        assert!(began.elapsed() < WAIT, "samples both ways: here {here}, there {there}");
        tag += 1;
        writer.write(go2_lowcmd(tag)).unwrap();
        if let Some((_, from)) = recv(rt, reader, Duration::from_millis(10)) {
            here |= from == their_writer;
        }
        there |= peer.poll("receiving").is_some();
    }
    (peer, guid_of(&ready["participant"]))
}

fn forgotten(ours: &Participant, prefix: &[u8]) -> bool {
    !ours.discovered_participants().iter().any(|p| p.guid_prefix == prefix)
        && !ours.discovered_endpoints().iter().any(|e| e.guid[..12] == *prefix)
}

fn leave_and_return(python: &Path) {
    with_loopback_multicast(|| {
        let rt = runtime();
        let ours = Participant::new(options()).unwrap();
        let writer = ours.writer::<LowCmd>(LowCmd::TOPIC, Qos::WRITER).unwrap();
        let mut reader = ours.reader::<LowState>(LowState::TOPIC, Qos::READER).unwrap();

        // A peer that leaves cleanly is forgotten at once (its participant's dispose).
        let (first, first_guid) = flowing(python, &rt, &writer, &mut reader);
        first.finish();
        until(WAIT, "the departed peer forgotten", || forgotten(&ours, &first_guid[..12]));
        assert_eq!((writer.matched_readers(), reader.matched_writers()), (0, 0));

        // A new process: samples flow again.
        let (mut second, second_guid) = flowing(python, &rt, &writer, &mut reader);
        assert_ne!(second_guid, first_guid);
        assert_eq!((writer.matched_readers(), reader.matched_writers()), (1, 1));

        // A peer killed says nothing: forgotten when its lease runs out.
        second.child.kill().unwrap();
        let killed = Instant::now();
        until(WAIT, "the killed peer forgotten after its lease", || forgotten(&ours, &second_guid[..12]));
        let after = killed.elapsed();
        assert!(after >= CYCLONE_LEASE / 2, "forgotten after {after:?}: by its lease, not before");
        eprintln!("a killed CycloneDDS peer forgotten after {after:?} (its lease: {CYCLONE_LEASE:?})");
        assert_eq!((writer.matched_readers(), reader.matched_writers()), (0, 0));
        drop(second);
    });
}

// ---------------------------------------------------------------------------------------------

/// The environment of PyPI's `cyclonedds==0.10.2` (Unitree's pin), CPython 3.10.
fn cyclone_0_10_2() -> Option<PathBuf> {
    robowire_fixtures::interop::require(robowire_fixtures::peers::unitree_python())
}

/// The environment of PyPI's `cyclonedds==11.0.1`, CPython 3.12 or 3.13.
fn cyclone_11() -> Option<PathBuf> {
    robowire_fixtures::interop::require(robowire_fixtures::peers::cyclonedds11_python())
}

/// Each scenario on each CycloneDDS: `<version>::<scenario>`.
macro_rules! on_each_cyclonedds {
    ($($scenario:ident),* $(,)?) => {
        mod cyclonedds_0_10_2 {
            $(#[test]
            fn $scenario() {
                if let Some(python) = super::cyclone_0_10_2() {
                    super::$scenario(&python);
                }
            })*
        }
        mod cyclonedds_11 {
            $(#[test]
            fn $scenario() {
                if let Some(python) = super::cyclone_11() {
                    super::$scenario(&python);
                }
            })*
        }
    };
}

on_each_cyclonedds!(
    discovery,
    go2_best_effort,
    go2_reliable,
    go2_reliable_under_loss,
    fragmented,
    fragmented_under_loss,
    transient_local,
    incompatible_qos,
    leave_and_return
);

#[test]
fn the_scenarios_json_is_read() {
    assert_eq!(guid_of(&json!("000102030405060708090a0b0c0d0e0f")), std::array::from_fn(|i| i as u8));
    assert!(strictly_increasing_within(&[1, 3, 200], 200) && !strictly_increasing_within(&[2, 2], 200));
}
