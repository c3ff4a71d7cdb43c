//! robowire-dds against eProsima Fast DDS 2.9 (Debian's `libfastrtps-dev` 2.9.1, `fastddsgen`
//! 2.3): discovery both ways, Unitree's Go2 and HG messages in both directions, best effort and
//! reliable, a fragmented sample, a transient-local late joiner, an incompatible QoS, a peer that
//! leaves and comes back. Each test runs in a private network namespace
//! (`with_loopback_multicast`) on a domain of its own.
//!
//! The Fast DDS side is `tests/fastdds_peer/peer.cpp`, built here once into the cargo target directory
//! (`fastdds-peer/`, rebuilt when its sources change) with fastddsgen's type support of Unitree's
//! IDL (`fastdds_peer/unitree_{go,hg}.idl`). It computes Unitree's CRC in C++ over the C struct
//! image, independently of robowire, and prints one JSON line per event. A missing `fastddsgen`,
//! `cmake`, `g++` or `libfastrtps-dev` skips these tests with one line (fails under
//! `ROBOWIRE_INTEROP=1`): `apt-get install -y libfastrtps-dev fastddsgen cmake g++`.

use std::io::{BufRead, BufReader, Read};
use std::path::{Path, PathBuf};
use std::process::{Child, ChildStdin, Command, Stdio};
use std::sync::mpsc::{self, Receiver, RecvTimeoutError};
use std::sync::{Arc, Mutex, OnceLock};
use std::time::{Duration, Instant};

use robowire_core::cdr::CdrType;
use robowire_dds::netns::with_loopback_multicast;
use robowire_dds::qos::Qos;
use robowire_dds::{Participant, ParticipantOptions, Reader, Writer};
use robowire_fixtures::interop;
use robowire_fixtures::wait::{runtime, until};
use serde_json::Value;
use unitree_proto::hg::HG_MOTOR_COUNT;
use unitree_proto::{F32, HgLowState, I16, LowCmd, LowState, Message, MotorCmd, U16, U32};

/// How long anything may take to happen.
const WAIT: Duration = Duration::from_secs(20);

// ---------------------------------------------------------------------------------------------
// The peer: built once per target directory, under a file lock (tests run in parallel, and again
// in their user namespaces).

fn target_dir() -> PathBuf {
    std::env::var_os("CARGO_TARGET_DIR")
        .map_or_else(|| PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../target"), PathBuf::from)
}

const SOURCES: [&str; 4] = ["CMakeLists.txt", "peer.cpp", "unitree_go.idl", "unitree_hg.idl"];

/// Runs `program args` in `dir`; its output, or why it failed.
fn run(program: &str, args: &[&str], dir: &Path) -> Result<String, String> {
    let out = Command::new(program)
        .args(args)
        .current_dir(dir)
        .stdin(Stdio::null())
        .output()
        .map_err(|e| format!("`{program}` cannot run: {e}"))?;
    let text = format!("{}{}", String::from_utf8_lossy(&out.stdout), String::from_utf8_lossy(&out.stderr));
    if out.status.success() {
        Ok(text)
    } else {
        Err(format!("`{program} {}` failed ({}):\n{text}", args.join(" "), out.status))
    }
}

const INSTALL: &str = "install Fast DDS 2.9 with `apt-get install -y libfastrtps-dev fastddsgen cmake g++`";

/// The peer's executable, built when missing or when its sources changed. A missing tool or
/// library is an `Err` (the gate's reason); a peer that does not compile with them is a panic.
fn build_peer() -> Result<PathBuf, String> {
    let sources = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/fastdds_peer");
    let dir = target_dir().join("fastdds-peer");
    std::fs::create_dir_all(&dir).map_err(|e| format!("creating {}: {e}", dir.display()))?;
    let lock = std::fs::File::create(dir.join(".lock")).map_err(|e| e.to_string())?;
    lock.lock().map_err(|e| format!("locking {}: {e}", dir.display()))?;
    let mut stamp = Vec::new();
    for name in SOURCES {
        stamp.extend_from_slice(name.as_bytes());
        stamp.extend(std::fs::read(sources.join(name)).map_err(|e| format!("reading {name}: {e}"))?);
    }
    let (binary, stamp_file) = (dir.join("peer"), dir.join("sources.stamp"));
    if binary.exists() && std::fs::read(&stamp_file).is_ok_and(|s| s == stamp) {
        return Ok(binary);
    }
    for (tool, flag) in [("fastddsgen", "-version"), ("cmake", "--version"), ("g++", "--version")] {
        run(tool, &[flag], &dir).map_err(|e| format!("no {tool} ({e}): {INSTALL}"))?;
    }
    // fastddsgen's preprocessor writes `<idl>.cc` into its temporary directory: `/tmp` unless
    // told, where another user's run leaves files this user may not overwrite.
    let (generated, build, temporary) = (dir.join("gen"), dir.join("build"), dir.join("tmp"));
    for d in [&generated, &build, &temporary] {
        std::fs::create_dir_all(d).map_err(|e| e.to_string())?;
    }
    for idl in ["unitree_go.idl", "unitree_hg.idl"] {
        std::fs::copy(sources.join(idl), generated.join(idl)).map_err(|e| e.to_string())?;
    }
    let temporary = temporary.to_str().ok_or("a non-UTF-8 path")?;
    run("fastddsgen", &["-replace", "-t", temporary, "unitree_go.idl", "unitree_hg.idl"], &generated)
        .unwrap_or_else(|e| panic!("fastddsgen refuses the peer's IDL: {e}"));
    let source_dir = sources.to_str().ok_or("a non-UTF-8 path")?;
    let gen_dir = format!("-DGEN_DIR={}", generated.display());
    run("cmake", &["-S", source_dir, "-B", ".", &gen_dir, "-DCMAKE_BUILD_TYPE=Release"], &build)
        .map_err(|e| format!("Fast DDS's CMake packages (fastrtps, fastcdr) are missing: {INSTALL}\n{e}"))?;
    run("cmake", &["--build", ".", "-j2"], &build).unwrap_or_else(|e| panic!("the Fast DDS peer does not build: {e}"));
    std::fs::copy(build.join("peer"), &binary).map_err(|e| e.to_string())?;
    std::fs::write(&stamp_file, stamp).map_err(|e| e.to_string())?;
    Ok(binary)
}

/// The peer, or `None` after the gate's skip line (a panic under `ROBOWIRE_INTEROP=1`).
fn peer_binary() -> Option<PathBuf> {
    static BUILT: OnceLock<Result<PathBuf, String>> = OnceLock::new();
    interop::require(BUILT.get_or_init(build_peer).clone())
}

/// A running peer: its JSON lines as they come, its stderr kept for a failure's message. Killed
/// when dropped.
struct Peer {
    child: Child,
    stdin: Option<ChildStdin>,
    lines: Receiver<Value>,
    seen: Vec<Value>,
    taken: usize,
    stderr: Arc<Mutex<String>>,
    command: String,
}

impl Peer {
    fn start(binary: &Path, scenario: &str, args: &[String]) -> Self {
        let mut child = Command::new(binary)
            .arg(scenario)
            .args(args)
            .stdin(Stdio::piped())
            .stdout(Stdio::piped())
            .stderr(Stdio::piped())
            .spawn()
            .unwrap_or_else(|e| panic!("starting the Fast DDS peer: {e}"));
        let (tx, lines) = mpsc::channel();
        let stdout = child.stdout.take().unwrap();
        std::thread::spawn(move || {
            for line in BufReader::new(stdout).lines().map_while(Result::ok) {
                let value = serde_json::from_str(&line).unwrap_or(Value::String(line));
                if tx.send(value).is_err() {
                    break;
                }
            }
        });
        let stderr = Arc::new(Mutex::new(String::new()));
        let mut err = child.stderr.take().unwrap();
        std::thread::spawn({
            let stderr = stderr.clone();
            move || {
                let mut buf = [0u8; 4096];
                while let Ok(n @ 1..) = err.read(&mut buf) {
                    stderr.lock().unwrap().push_str(&String::from_utf8_lossy(&buf[..n]));
                }
            }
        });
        let stdin = child.stdin.take();
        let command = format!("peer {scenario} {}", args.join(" "));
        Self { child, stdin, lines, seen: Vec::new(), taken: 0, stderr, command }
    }

    /// What the peer said so far, for a failure's message.
    fn transcript(&self) -> String {
        let mut out = format!("`{}` printed:\n", self.command);
        for v in &self.seen {
            let line = v.to_string();
            out.push_str(&line[..line.len().min(400)]);
            out.push('\n');
        }
        out + "stderr: " + &self.stderr.lock().unwrap()
    }

    /// The next line within `timeout`; `None` when none came or the peer is gone.
    fn next(&mut self, timeout: Duration) -> Option<&Value> {
        match self.lines.recv_timeout(timeout) {
            Ok(v) => {
                self.seen.push(v);
                self.seen.last()
            }
            Err(RecvTimeoutError::Timeout | RecvTimeoutError::Disconnected) => None,
        }
    }

    /// The first line (said before or now) that `pred` accepts; panics after [`WAIT`].
    fn wait(&mut self, what: &str, pred: impl Fn(&Value) -> bool) -> Value {
        if let Some(v) = self.seen.iter().find(|v| pred(v)) {
            return v.clone();
        }
        let began = Instant::now();
        while began.elapsed() < WAIT {
            if let Some(v) = self.next(Duration::from_millis(50))
                && pred(v)
            {
                return v.clone();
            }
        }
        panic!("the Fast DDS peer never reported {what}; {}", self.transcript());
    }

    /// The event named `event`.
    fn event(&mut self, event: &str) -> Value {
        self.wait(event, |v| v["event"] == event)
    }

    /// The next received sample not yet taken, within `timeout`.
    fn next_sample(&mut self, timeout: Duration) -> Option<Value> {
        let began = Instant::now();
        loop {
            if let Some(i) = self.seen[self.taken..].iter().position(|v| v["event"] == "sample") {
                self.taken += i + 1;
                return Some(self.seen[self.taken - 1].clone());
            }
            self.taken = self.seen.len();
            let left = timeout.checked_sub(began.elapsed())?;
            self.next(left.min(Duration::from_millis(20)));
        }
    }

    /// The next `n` received samples; panics after [`WAIT`].
    fn samples(&mut self, n: usize) -> Vec<Value> {
        (0..n)
            .map(|i| {
                self.next_sample(WAIT)
                    .unwrap_or_else(|| panic!("the Fast DDS peer received {i} of {n} samples; {}", self.transcript()))
            })
            .collect()
    }

    /// Closes its standard input: it deletes its participant (Fast DDS announces that) and
    /// exits. Its summary.
    fn leave(&mut self) -> Value {
        drop(self.stdin.take());
        let began = Instant::now();
        while began.elapsed() < WAIT {
            if let Ok(Some(status)) = self.child.try_wait() {
                assert!(status.success(), "the Fast DDS peer exited with {status}; {}", self.transcript());
                while self.next(Duration::from_millis(100)).is_some() {}
                return self.event("summary");
            }
            self.next(Duration::from_millis(20));
        }
        panic!("the Fast DDS peer did not exit; {}", self.transcript());
    }
}

impl Drop for Peer {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

fn args(list: &[(&str, &dyn std::fmt::Display)]) -> Vec<String> {
    list.iter().map(|(k, v)| format!("{k}={v}")).collect()
}

// ---------------------------------------------------------------------------------------------
// Samples as a function of their index: the same as peer.cpp's `fill`.

fn f(v: f32) -> F32 {
    v.into()
}

fn fill_lowcmd(i: u32) -> LowCmd {
    let mut m = LowCmd::default();
    m.head = [0xFE, 0xEF];
    m.level_flag = 0xFF;
    m.sn = [i.into(), 7.into()];
    m.version = [1.into(), 2.into()];
    m.bandwidth = 0x3A.into();
    for (k, c) in m.motor_cmd.iter_mut().enumerate() {
        let k = k as u32;
        *c = MotorCmd::servo(0.25 * k as f32 + i as f32, -0.5 * k as f32, 20.0 + k as f32, 0.5, 0.125 * k as f32);
        c.mode = 1;
        c.reserve = [k.into(), 0.into(), 0.into()];
    }
    for (j, b) in m.wireless_remote.iter_mut().enumerate() {
        *b = j as u8;
    }
    for (j, b) in m.led.iter_mut().enumerate() {
        *b = 2 * j as u8;
    }
    m.fan = [1, 2];
    m.gpio = 3;
    m.reserve = i.into();
    m
}

fn fill_lowstate(i: u32) -> LowState {
    let mut m = LowState::default();
    m.head = [0xFE, 0xEF];
    m.level_flag = 0xFF;
    m.sn = [i.into(), 0.into()];
    m.version = [1.into(), 2.into()];
    let imu = &mut m.imu_state;
    imu.quaternion = [f(1.0), f(0.0), f(0.0), f(0.0)];
    imu.gyroscope = [f(0.5), f(-0.5), f(0.25)];
    imu.accelerometer = [f(0.0), f(0.0), f(9.75)];
    imu.rpy = [f(0.125), f(0.0), f(-0.125)];
    imu.temperature = 40;
    for (k, s) in m.motor_state.iter_mut().enumerate() {
        let k = k as u32;
        s.mode = 1;
        s.q = f(0.25 * k as f32 + i as f32);
        s.dq = f(0.5);
        s.tau_est = f(-0.25 * k as f32);
        s.q_raw = s.q;
        s.dq_raw = f(0.5);
        s.temperature = 30 + k as u8;
        s.lost = k.into();
    }
    let b = &mut m.bms_state;
    (b.version_high, b.version_low, b.status, b.soc) = (1, 2, 3, 88);
    b.current = (-1500).into();
    b.cycle = 12.into();
    b.bq_ntc = [25, 26];
    b.mcu_ntc = [30, 31];
    for (j, v) in b.cell_vol.iter_mut().enumerate() {
        *v = U16::new(3600 + j as u16);
    }
    m.foot_force = [10, 20, 30, 40].map(I16::new);
    m.foot_force_est = [-1, -2, -3, -4].map(I16::new);
    m.tick = (1000 + i).into();
    for (j, b) in m.wireless_remote.iter_mut().enumerate() {
        *b = 255 - j as u8;
    }
    m.bit_flag = 0x80;
    m.adc_reel = f(1.5);
    m.temperature_ntc1 = 200;
    m.temperature_ntc2 = 41;
    m.power_v = f(28.5);
    m.power_a = f(1.25);
    m.fan_frequency = [1000, 2000, 40000, 0].map(U16::new);
    m.reserve = i.into();
    m
}

fn fill_hg_lowstate(i: u32) -> HgLowState {
    let mut m = HgLowState::default();
    m.version = [3.into(), 4.into()];
    m.mode_pr = 0;
    m.mode_machine = 5;
    m.tick = (1000 + i).into();
    let imu = &mut m.imu_state;
    imu.quaternion = [f(1.0), f(0.0), f(0.0), f(0.0)];
    imu.gyroscope = [f(0.5), f(-0.5), f(0.25)];
    imu.accelerometer = [f(0.0), f(0.0), f(9.75)];
    imu.rpy = [f(0.125), f(0.0), f(-0.125)];
    imu.temperature = I16::new(-5);
    for (k, s) in m.motor_state.iter_mut().enumerate() {
        let k = k as u32;
        s.mode = 1;
        s.q = f(0.25 * k as f32 + i as f32);
        s.dq = f(0.5);
        s.tau_est = f(-0.25 * k as f32);
        s.temperature = [I16::new(30 + k as i16), I16::new(-(k as i16))];
        s.vol = f(24.5);
        s.sensor = [k.into(), (2 * k).into()];
        s.motorstate = (3 * k).into();
        s.reserve = [0.into(), 0.into(), 0.into(), i.into()];
    }
    for (j, b) in m.wireless_remote.iter_mut().enumerate() {
        *b = j as u8 + 1;
    }
    m.reserve = [i, 1, 2, 3].map(U32::new);
    m
}

// ---------------------------------------------------------------------------------------------
// Reading the peer's JSON.

fn floats(v: &Value) -> Vec<f32> {
    v.as_array().unwrap_or_else(|| panic!("not an array: {v}")).iter().map(|x| x.as_f64().unwrap() as f32).collect()
}

fn ints(v: &Value) -> Vec<i64> {
    v.as_array().unwrap_or_else(|| panic!("not an array: {v}")).iter().map(|x| x.as_i64().unwrap()).collect()
}

fn int(v: &Value) -> i64 {
    v.as_i64().unwrap_or_else(|| panic!("not an integer: {v}"))
}

/// A LowCmd as the peer printed it is `sent` (sealed by robowire's writer), field for field,
/// with the CRC robowire computed, which the peer's own computation over the struct image agrees
/// with.
fn assert_lowcmd(got: &Value, sent: &LowCmd) {
    let sent = sent.sealed();
    assert_eq!(got["type"], "go2_lowcmd");
    assert_eq!(ints(&got["head"]), [0xFE, 0xEF]);
    assert_eq!(int(&got["level_flag"]), 0xFF);
    assert_eq!(ints(&got["sn"]), sent.sn.map(|v| i64::from(v.get())));
    assert_eq!(ints(&got["version"]), sent.version.map(|v| i64::from(v.get())));
    assert_eq!(int(&got["bandwidth"]), i64::from(sent.bandwidth.get()));
    let motors = &sent.motor_cmd;
    assert_eq!(ints(&got["mode"]), motors.map(|m| i64::from(m.mode)));
    assert_eq!(floats(&got["q"]), motors.map(|m| m.q.get()));
    assert_eq!(floats(&got["dq"]), motors.map(|m| m.dq.get()));
    assert_eq!(floats(&got["tau"]), motors.map(|m| m.tau.get()));
    assert_eq!(floats(&got["kp"]), motors.map(|m| m.kp.get()));
    assert_eq!(floats(&got["kd"]), motors.map(|m| m.kd.get()));
    assert_eq!(ints(&got["wireless_remote"]), sent.wireless_remote.map(i64::from));
    assert_eq!(ints(&got["led"]), sent.led.map(i64::from));
    assert_eq!(ints(&got["fan"]), sent.fan.map(i64::from));
    assert_eq!(int(&got["gpio"]), i64::from(sent.gpio));
    assert_eq!(int(&got["reserve"]), i64::from(sent.reserve.get()));
    assert_eq!(int(&got["crc"]), i64::from(sent.crc.get()), "the CRC robowire sealed");
    assert_eq!(got["crc_ok"], true, "Fast DDS's side computes the same CRC over the struct image: {got}");
}

/// An HG LowState as the peer printed it is `sent`, with robowire's CRC, which the peer agrees
/// with.
fn assert_hg_lowstate(got: &Value, sent: &HgLowState) {
    let sent = sent.sealed();
    assert_eq!(got["type"], "hg_lowstate");
    assert_eq!(int(&got["tick"]), i64::from(sent.tick.get()));
    assert_eq!(int(&got["mode_machine"]), i64::from(sent.mode_machine));
    let motors = &sent.motor_state;
    assert_eq!(floats(&got["q"]), motors.map(|m| m.q.get()));
    assert_eq!(floats(&got["tau_est"]), motors.map(|m| m.tau_est.get()));
    assert_eq!(ints(&got["temperature"]), motors.map(|m| i64::from(m.temperature[0].get())));
    assert_eq!(ints(&got["wireless_remote"]), sent.wireless_remote.map(i64::from));
    assert_eq!(ints(&got["reserve"]), sent.reserve.map(|v| i64::from(v.get())));
    assert_eq!(int(&got["crc"]), i64::from(sent.crc.get()), "the CRC robowire sealed");
    assert_eq!(got["crc_ok"], true, "Fast DDS's side computes the same CRC over the struct image: {got}");
    assert_eq!(motors.len(), HG_MOTOR_COUNT);
}

// ---------------------------------------------------------------------------------------------
// robowire's side.

fn participant(domain: u16) -> Participant {
    Participant::new(ParticipantOptions::new(domain, Some("lo"))).unwrap()
}

/// The next sample of `reader` within `timeout`.
fn recv<T: CdrType + 'static>(rt: &tokio::runtime::Runtime, reader: &mut Reader<T>, timeout: Duration) -> Option<T> {
    rt.block_on(async { tokio::time::timeout(timeout, reader.recv()).await }).ok().map(|s| s.unwrap().value)
}

fn hex(bytes: &[u8]) -> String {
    bytes.iter().map(|b| format!("{b:02x}")).collect()
}

/// Whether `by` knows an endpoint of the participant whose GUID prefix is `prefix` (hex).
fn knows_endpoint(by: &Participant, prefix: &str, writer: bool, topic: &str, type_name: &str) -> bool {
    by.discovered_endpoints()
        .iter()
        .any(|e| hex(&e.guid[..12]) == prefix && e.writer == writer && e.topic == topic && e.type_name == type_name)
}

fn reliable_reader(depth: i32) -> Qos {
    Qos { reliable: true, depth, ..Qos::READER }
}

// ---------------------------------------------------------------------------------------------
// 1. Discovery.

/// Each side sees the other's endpoints: robowire lists the Fast DDS participant (its vendor)
/// with its writer of LowState_ and its reader of LowCmd_ under Unitree's names; Fast DDS
/// matches robowire's writer and reader, by their GUIDs.
#[test]
fn discovery_both_ways() {
    let Some(peer_bin) = peer_binary() else { return };
    with_loopback_multicast(|| {
        let domain = 1;
        let robowire = participant(domain);
        let commands = robowire.writer::<LowCmd>(LowCmd::TOPIC, Qos::WRITER).unwrap();
        let states = robowire.reader::<LowState>(LowState::TOPIC, Qos::READER).unwrap();
        let mut peer = Peer::start(&peer_bin, "discover", &args(&[("domain", &domain), ("seconds", &60)]));
        let prefix = peer.event("ready")["guid_prefix"].as_str().unwrap().to_owned();

        let reader_guid = hex(&states.guid());
        let writer_guid = hex(&commands.guid());
        peer.wait("a match of robowire's LowCmd_ writer", |v| {
            v["event"] == "subscription_matched" && v["current"] == 1 && v["writer"] == writer_guid.as_str()
        });
        peer.wait("a match of robowire's LowState_ reader", |v| {
            v["event"] == "publication_matched" && v["current"] == 1 && v["reader"] == reader_guid.as_str()
        });

        until(WAIT, "robowire discovers the Fast DDS endpoints", || {
            knows_endpoint(&robowire, &prefix, true, LowState::TOPIC, LowState::DDS_TYPE_NAME)
                && knows_endpoint(&robowire, &prefix, false, LowCmd::TOPIC, LowCmd::DDS_TYPE_NAME)
        });
        let fastdds = robowire.discovered_participants().into_iter().find(|p| hex(&p.guid_prefix) == prefix).unwrap();
        assert_eq!(fastdds.vendor, ([1, 0x0f], Some("eProsima Fast DDS")));
        assert!(!fastdds.unicast.is_empty(), "{fastdds:?}");
        until(WAIT, "robowire matches both", || commands.matched_readers() == 1 && states.matched_writers() == 1);
        let topics = robowire.discovered_topics();
        assert!(topics.iter().any(|t| t.name == LowState::TOPIC && t.writers == 1), "{topics:?}");
        assert!(topics.iter().any(|t| t.name == LowCmd::TOPIC && t.readers == 1), "{topics:?}");
        let summary = peer.leave();
        assert_eq!(
            (summary["offered_incompatible_qos"].as_i64(), summary["requested_incompatible_qos"].as_i64()),
            (Some(0), Some(0))
        );
    });
}

// ---------------------------------------------------------------------------------------------
// 2. Go2 LowCmd robowire → Fast DDS, LowState Fast DDS → robowire.

/// Best effort: robowire writes LowCmds until Fast DDS has three; each is what was sent, field
/// for field, CRC included.
#[test]
fn lowcmd_to_fastdds_best_effort() {
    let Some(peer_bin) = peer_binary() else { return };
    with_loopback_multicast(|| {
        let domain = 2;
        let robowire = participant(domain);
        let writer = robowire.writer::<LowCmd>(LowCmd::TOPIC, Qos { reliable: false, ..Qos::WRITER }).unwrap();
        let mut peer = Peer::start(
            &peer_bin,
            "sub",
            &args(&[("domain", &domain), ("type", &"go2_lowcmd"), ("reliability", &"besteffort"), ("depth", &8)]),
        );
        let mut got = Vec::new();
        let began = Instant::now();
        for tag in 0.. {
            assert!(began.elapsed() < WAIT, "Fast DDS received {} LowCmds; {}", got.len(), peer.transcript());
            writer.write(fill_lowcmd(tag)).unwrap();
            got.extend(peer.next_sample(Duration::from_millis(20)));
            if got.len() >= 3 {
                break;
            }
        }
        for sample in &got {
            let tag = u32::try_from(int(&sample["reserve"])).unwrap();
            assert_lowcmd(sample, &fill_lowcmd(tag));
        }
        assert_eq!(writer.stats().write_errors, 0);
    });
}

/// Reliable: once robowire's writer has matched Fast DDS's reader, 20 LowCmds written back to
/// back all arrive, in order (robowire repairs what Fast DDS did not take before it matched
/// robowire's writer).
#[test]
fn lowcmd_to_fastdds_reliable() {
    let Some(peer_bin) = peer_binary() else { return };
    with_loopback_multicast(|| {
        let domain = 3;
        let robowire = participant(domain);
        let writer = robowire.writer::<LowCmd>(LowCmd::TOPIC, Qos { depth: 20, ..Qos::WRITER }).unwrap();
        let mut peer = Peer::start(
            &peer_bin,
            "sub",
            &args(&[("domain", &domain), ("type", &"go2_lowcmd"), ("depth", &20), ("expect", &20)]),
        );
        until(WAIT, "robowire's writer matches Fast DDS's reader", || writer.matched_readers() == 1);
        for tag in 1..=20 {
            writer.write(fill_lowcmd(tag)).unwrap();
        }
        let got = peer.samples(20);
        for (sample, tag) in got.iter().zip(1..) {
            assert_lowcmd(sample, &fill_lowcmd(tag));
        }
        let rt = runtime();
        let acknowledged = rt.block_on(async { tokio::time::timeout(WAIT, writer.acknowledged()).await });
        assert!(acknowledged.is_ok_and(|r| r.unwrap()), "Fast DDS acknowledged every LowCmd");
        assert_eq!(int(&peer.event("summary")["received"]), 20);
    });
}

/// Best effort: Fast DDS writes LowStates with its own CRC; robowire's reader decodes them, the
/// CRC verified, equal to the same message sealed by robowire.
#[test]
fn lowstate_from_fastdds_best_effort() {
    let Some(peer_bin) = peer_binary() else { return };
    with_loopback_multicast(|| {
        let domain = 4;
        let rt = runtime();
        let robowire = participant(domain);
        let mut reader = robowire.reader::<LowState>(LowState::TOPIC, Qos::READER).unwrap();
        let mut peer = Peer::start(
            &peer_bin,
            "pub",
            &args(&[("domain", &domain), ("type", &"go2_lowstate"), ("reliability", &"besteffort"), ("count", &0)]),
        );
        for _ in 0..3 {
            let state = recv(&rt, &mut reader, WAIT).unwrap_or_else(|| panic!("no LowState; {}", peer.transcript()));
            assert_eq!(state, fill_lowstate(state.reserve.get()).sealed(), "field for field, Fast DDS's CRC");
        }
        let stats = reader.stats();
        assert_eq!((stats.checksum_errors, stats.decode_errors), (0, 0), "{stats:?}");
        peer.leave();
    });
}

/// Reliable: 20 LowStates Fast DDS writes once it has matched robowire's reader all arrive, in
/// order, with valid CRCs. Fast DDS writes them the moment it matches robowire's reader, often
/// before robowire has its writer's SEDP announcement: robowire drops those as from an unknown
/// writer and asks for them at Fast DDS's next periodic HEARTBEAT (every 3 s), so the peer stays
/// until the test is done. (robowire sends no pre-emptive ACKNACK when it matches a writer;
/// Fast DDS 2.9 would answer one, an ACKNACK with base 0, with a HEARTBEAT at once.)
#[test]
fn lowstate_from_fastdds_reliable() {
    let Some(peer_bin) = peer_binary() else { return };
    with_loopback_multicast(|| {
        let domain = 5;
        let rt = runtime();
        let robowire = participant(domain);
        let mut reader = robowire.reader::<LowState>(LowState::TOPIC, reliable_reader(20)).unwrap();
        let mut peer = Peer::start(
            &peer_bin,
            "pub",
            &args(&[
                ("domain", &domain),
                ("type", &"go2_lowstate"),
                ("depth", &20),
                ("count", &20),
                ("period_ms", &0),
                ("settle_ms", &0),
                ("linger_ms", &60_000),
            ]),
        );
        for tag in 0..20 {
            let state = recv(&rt, &mut reader, WAIT)
                .unwrap_or_else(|| panic!("LowState {tag} never came; {}", peer.transcript()));
            assert_eq!(state, fill_lowstate(tag).sealed(), "in order, field for field");
        }
        assert_eq!(reader.stats().checksum_errors, 0);
        assert_eq!(int(&peer.leave()["written"]), 20);
    });
}

// ---------------------------------------------------------------------------------------------
// 3. A fragmented sample both ways: the HG LowState_, 2092 bytes in XCDR1, is larger than Fast
// DDS's fragments (1296 bytes with a 1472-byte message) and robowire's.

#[test]
fn fragmented_hg_lowstate_to_fastdds_reliable() {
    let Some(peer_bin) = peer_binary() else { return };
    with_loopback_multicast(|| {
        let domain = 6;
        let robowire = participant(domain);
        let writer = robowire.writer::<HgLowState>(HgLowState::TOPIC, Qos { depth: 5, ..Qos::WRITER }).unwrap();
        let mut peer = Peer::start(
            &peer_bin,
            "sub",
            &args(&[("domain", &domain), ("type", &"hg_lowstate"), ("depth", &5), ("expect", &5)]),
        );
        until(WAIT, "robowire's writer matches Fast DDS's reader", || writer.matched_readers() == 1);
        for i in 0..5 {
            writer.write(fill_hg_lowstate(i)).unwrap();
        }
        for (sample, i) in peer.samples(5).iter().zip(0..) {
            assert_hg_lowstate(sample, &fill_hg_lowstate(i));
        }
    });
}

#[test]
fn fragmented_hg_lowstate_from_fastdds_reliable() {
    let Some(peer_bin) = peer_binary() else { return };
    with_loopback_multicast(|| {
        let domain = 7;
        let rt = runtime();
        let robowire = participant(domain);
        let mut reader = robowire.reader::<HgLowState>(HgLowState::TOPIC, reliable_reader(5)).unwrap();
        let mut peer = Peer::start(
            &peer_bin,
            "pub",
            &args(&[
                ("domain", &domain),
                ("type", &"hg_lowstate"),
                ("depth", &5),
                ("count", &5),
                ("period_ms", &0),
                ("settle_ms", &0),
                ("linger_ms", &60_000),
            ]),
        );
        for i in 0..5 {
            let state = recv(&rt, &mut reader, WAIT)
                .unwrap_or_else(|| panic!("HG LowState {i} never came; {}", peer.transcript()));
            assert_eq!(state, fill_hg_lowstate(i).sealed(), "in order, field for field, Fast DDS's CRC");
        }
        let stats = reader.stats();
        assert_eq!((stats.checksum_errors, stats.decode_errors), (0, 0), "{stats:?}");
        peer.leave();
    });
}

// ---------------------------------------------------------------------------------------------
// 4. Transient local: a late-joining reader gets what the writer kept.

/// Fast DDS writes 8 LowStates on a transient-local keep-last-5 writer with no reader; a robowire
/// reader that joins afterwards gets the last 5, in order (the first three are gone: a GAP).
#[test]
fn late_joining_robowire_reader_gets_fastdds_transient_local_history() {
    let Some(peer_bin) = peer_binary() else { return };
    with_loopback_multicast(|| {
        let domain = 8;
        let rt = runtime();
        let mut peer = Peer::start(
            &peer_bin,
            "pub",
            &args(&[
                ("domain", &domain),
                ("type", &"go2_lowstate"),
                ("durability", &"transient_local"),
                ("depth", &5),
                ("count", &8),
                ("period_ms", &0),
                ("wait_match_ms", &0),
                ("linger_ms", &60_000),
            ]),
        );
        peer.wait("its 8th write", |v| v["event"] == "written" && v["index"] == 7);
        let robowire = participant(domain);
        let mut reader =
            robowire.reader::<LowState>(LowState::TOPIC, Qos { transient_local: true, ..reliable_reader(5) }).unwrap();
        for tag in 3..8 {
            let state = recv(&rt, &mut reader, WAIT)
                .unwrap_or_else(|| panic!("kept LowState {tag} never came; {}", peer.transcript()));
            assert_eq!(state, fill_lowstate(tag).sealed());
        }
        assert!(recv(&rt, &mut reader, Duration::from_millis(500)).is_none(), "nothing more");
    });
}

/// robowire writes 8 LowCmds on a transient-local keep-last-5 writer with no reader; a Fast DDS
/// reader that joins afterwards gets the last 5, in order.
#[test]
fn late_joining_fastdds_reader_gets_robowire_transient_local_history() {
    let Some(peer_bin) = peer_binary() else { return };
    with_loopback_multicast(|| {
        let domain = 9;
        let robowire = participant(domain);
        let writer: Writer<LowCmd> =
            robowire.writer(LowCmd::TOPIC, Qos { transient_local: true, depth: 5, ..Qos::WRITER }).unwrap();
        for tag in 0..8 {
            writer.write(fill_lowcmd(tag)).unwrap();
        }
        let mut peer = Peer::start(
            &peer_bin,
            "sub",
            &args(&[
                ("domain", &domain),
                ("type", &"go2_lowcmd"),
                ("durability", &"transient_local"),
                ("depth", &5),
                ("expect", &5),
            ]),
        );
        for (sample, tag) in peer.samples(5).iter().zip(3..) {
            assert_lowcmd(sample, &fill_lowcmd(tag));
        }
        assert!(peer.next_sample(Duration::from_millis(500)).is_none(), "nothing more");
    });
}

// ---------------------------------------------------------------------------------------------
// 5. An incompatible QoS.

/// A best-effort Fast DDS writer and a reliable robowire reader do not match: robowire discovers
/// the writer but matches nothing and takes no sample; Fast DDS reports the incompatible
/// reliability (policy 11) on its writer.
#[test]
fn best_effort_fastdds_writer_and_reliable_robowire_reader_do_not_match() {
    let Some(peer_bin) = peer_binary() else { return };
    with_loopback_multicast(|| {
        let domain = 10;
        let rt = runtime();
        let robowire = participant(domain);
        let mut reader = robowire.reader::<LowState>(LowState::TOPIC, reliable_reader(5)).unwrap();
        let mut peer = Peer::start(
            &peer_bin,
            "pub",
            &args(&[
                ("domain", &domain),
                ("type", &"go2_lowstate"),
                ("reliability", &"besteffort"),
                ("count", &0),
                ("wait_match_ms", &0),
            ]),
        );
        let prefix = peer.event("ready")["guid_prefix"].as_str().unwrap().to_owned();
        let incompatible = peer.event("offered_incompatible_qos");
        assert_eq!(int(&incompatible["policy"]), 11, "RELIABILITY_QOS_POLICY_ID: {incompatible}");
        until(WAIT, "robowire discovers the Fast DDS writer", || {
            knows_endpoint(&robowire, &prefix, true, LowState::TOPIC, LowState::DDS_TYPE_NAME)
        });
        peer.wait("writes", |v| v["event"] == "written" && int(&v["index"]) >= 20);
        assert!(recv(&rt, &mut reader, Duration::from_secs(1)).is_none(), "a sample crossed a QoS mismatch");
        assert_eq!(reader.matched_writers(), 0);
        assert_eq!(reader.stats().samples, 0);
        // robowire says why, naming the writer.
        let why = reader.incompatible_writers();
        assert_eq!(why.len(), 1, "{why:?}");
        assert_eq!(&why[0].remote[..12], &hex_prefix(&prefix)[..], "{why:?}");
        assert!(why[0].reason.contains("reliab"), "{why:?}");
        let summary = peer.leave();
        assert_eq!(int(&summary["publication_matched"]), 0, "{summary}");
        assert!(int(&summary["offered_incompatible_qos"]) >= 1, "{summary}");
    });
}

// ---------------------------------------------------------------------------------------------
// 6. A peer that leaves and comes back.

/// Fast DDS leaves (deleting its participant): robowire forgets its participant and endpoints
/// long before its 20 s lease ends, so from the dispose. A new peer on the same topic: samples flow again,
/// from its writer.
#[test]
fn fastdds_leaves_and_comes_back() {
    let Some(peer_bin) = peer_binary() else { return };
    with_loopback_multicast(|| {
        let domain = 11;
        let rt = runtime();
        let robowire = participant(domain);
        let mut reader = robowire.reader::<LowState>(LowState::TOPIC, Qos::READER).unwrap();
        let publish = |start: u32| {
            args(&[
                ("domain", &domain),
                ("type", &"go2_lowstate"),
                ("count", &0),
                ("start", &start),
                ("period_ms", &10),
            ])
        };
        let mut first = Peer::start(&peer_bin, "pub", &publish(0));
        let prefix = first.event("ready")["guid_prefix"].as_str().unwrap().to_owned();
        let state = recv(&rt, &mut reader, WAIT).unwrap_or_else(|| panic!("no LowState; {}", first.transcript()));
        assert_eq!(state, fill_lowstate(state.reserve.get()).sealed());
        assert!(knows_endpoint(&robowire, &prefix, true, LowState::TOPIC, LowState::DDS_TYPE_NAME));

        first.leave();
        // Its dispose, not its 20 s lease: the bound tells the two apart.
        until(Duration::from_secs(10), "robowire forgets the Fast DDS peer that left", || {
            !robowire.discovered_participants().iter().any(|d| hex(&d.guid_prefix) == prefix)
                && !robowire.discovered_endpoints().iter().any(|e| hex(&e.guid[..12]) == prefix)
        });
        assert_eq!(reader.matched_writers(), 0);
        while recv(&rt, &mut reader, Duration::from_millis(100)).is_some() {}

        let mut second = Peer::start(&peer_bin, "pub", &publish(100));
        let again = second.event("ready")["guid_prefix"].as_str().unwrap().to_owned();
        assert_ne!(again, prefix);
        let state =
            recv(&rt, &mut reader, WAIT).unwrap_or_else(|| panic!("no LowState again; {}", second.transcript()));
        assert!(state.reserve.get() >= 100, "from the new peer: {}", state.reserve.get());
        assert_eq!(state, fill_lowstate(state.reserve.get()).sealed());
        assert_eq!(reader.matched_writers(), 1);
        assert_eq!(reader.stats().checksum_errors, 0);
        second.leave();
    });
}

/// A GUID prefix from its hex (as the peer prints it).
fn hex_prefix(hex: &str) -> Vec<u8> {
    (0..hex.len()).step_by(2).map(|i| u8::from_str_radix(&hex[i..i + 2], 16).unwrap()).collect()
}
