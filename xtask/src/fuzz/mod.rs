//! `cargo xtask fuzz`: cargo-fuzz targets with seed corpora made from the golden fixtures.

use std::path::Path;
use std::process::Command;

use anyhow::{Context, bail};

use crate::golden::kmc::{kmc_fixture_path, load_kmc};
use crate::{hex_decode, workspace_root};

mod messages;

/// Named seed inputs for a corpus directory.
pub type Seeds = anyhow::Result<Vec<(String, Vec<u8>)>>;

/// A fuzz target, where its seeds come from, and the check it runs.
#[derive(Debug, Clone, Copy)]
pub struct Target {
    /// cargo-fuzz target name (`fuzz/fuzz_targets/<name>.rs`).
    pub name: &'static str,
    /// Its seed corpus, named for the corpus directory.
    pub seeds: fn() -> Seeds,
    /// The check it runs, for replay under `cargo test`.
    pub check: fn(&[u8]),
}

/// Every fuzz target.
pub const TARGETS: &[Target] = &[
    Target {
        name: "kmc_host_decoder",
        seeds: || kmc_seeds("chassis->host"),
        check: kmc_proto::stream_consistency::chassis_frame_stream,
    },
    Target {
        name: "kmc_device_decoder",
        seeds: || kmc_seeds("host->chassis"),
        check: kmc_proto::stream_consistency::host_frame_stream,
    },
    Target {
        name: "lowcmd_image_decode",
        seeds: || unitree_seeds("packed_hex"),
        check: unitree_proto::decode_roundtrip::image_decode,
    },
    Target {
        name: "lowcmd_cdr_decode",
        seeds: || unitree_seeds("cdr_hex"),
        check: unitree_proto::decode_roundtrip::cdr_decode,
    },
    Target { name: "zsl_datagram_decode", seeds: zsl1_seeds, check: zsl_proto::decode_roundtrip::datagram_decode },
    Target {
        name: "mcap_replay_read",
        seeds: capture_seeds,
        check: |bytes| robowire_record::fuzz_read(bytes, &zsl_proto::description::DESCRIPTIONS),
    },
    Target {
        name: "ros2_message_decode",
        seeds: || Ok(messages::ros2_seeds()),
        check: ros2_proto::decode_roundtrip::message_decode,
    },
    Target { name: "dds_sample_receive", seeds: dds_seeds, check: unitree::fuzz_receive },
    Target {
        name: "lowcmd_api_decode",
        seeds: || Ok(messages::api_seeds()),
        check: unitree_proto::decode_roundtrip::api_decode,
    },
    Target { name: "rtps_message_parse", seeds: rtps_seeds, check: rtps_proto::fuzzing::parse_all },
    Target { name: "rtps_participant", seeds: rtps_participant_seeds, check: rtps_proto::fuzzing::participant },
];

/// RTPS seeds: the six hostile datagrams (`robowire_fixtures::rtps::hostile_datagrams`), and one datagram of the
/// submessages a reliable exchange uses, written with the crate's own emitter.
fn rtps_seeds() -> Seeds {
    use rtps_proto::wire::{self, Submessage};
    use rtps_proto::{EntityId, GuidPrefix, ProtocolVersion, SequenceNumber, SequenceNumberSet, VendorId};

    let from = [1, 0x0f, 0, 0, 0, 0, 0, 1, 0, 0, 0, 1];
    let names = [
        "seed-data-frag-sample-size",
        "seed-heartbeat-range",
        "seed-gap-range",
        "seed-nack-frag-fragment-numbers",
        "seed-nack-frag-fragment-0",
        "seed-acknack-sequence-number-overflow",
    ];
    let mut seeds: Vec<(String, Vec<u8>)> = names
        .into_iter()
        .zip(robowire_fixtures::rtps::hostile_datagrams(from))
        .map(|(name, (_, datagram))| (name.to_string(), datagram))
        .collect();
    let (reader, writer) = ([0u8, 0, 3, 0xC7], [0u8, 0, 3, 0xC2]);

    // A writer's DATA with inline QoS, a HEARTBEAT, a reader's ACKNACK, a GAP.
    let mut qos = [0u8; 64];
    let mut params = wire::ParameterWriter::new(&mut qos);
    params.push(wire::pid::KEY_HASH, &[7; 16]).map_err(|e| anyhow::anyhow!("{e:?}"))?;
    params.push(wire::pid::STATUS_INFO, &[0, 0, 0, 1]).map_err(|e| anyhow::anyhow!("{e:?}"))?;
    let qos_len = params.finish().map_err(|e| anyhow::anyhow!("{e:?}"))?;
    let inline_qos = wire::ParameterList::little_endian(&qos[..qos_len]).map_err(|e| anyhow::anyhow!("{e}"))?;
    let (reader, writer) = (EntityId(reader), EntityId(writer));
    let mut set = SequenceNumberSet::new(SequenceNumber(2), 8).map_err(|e| anyhow::anyhow!("{e:?}"))?;
    set.insert(SequenceNumber(3));
    let submessages = [
        Submessage::InfoDst(wire::InfoDst { guid_prefix: GuidPrefix(from) }),
        Submessage::Data(wire::Data {
            reader_id: reader,
            writer_id: writer,
            writer_sn: SequenceNumber(1),
            inline_qos: Some(inline_qos),
            payload: wire::Payload::Data(&[0, 1, 0, 0, 1, 2, 3, 4]),
            non_standard_payload: false,
        }),
        Submessage::Heartbeat(wire::Heartbeat {
            reader_id: reader,
            writer_id: writer,
            first_sn: SequenceNumber(1),
            last_sn: SequenceNumber(3),
            count: 1,
            final_flag: false,
            liveliness_flag: false,
        }),
        Submessage::AckNack(wire::AckNack {
            reader_id: reader,
            writer_id: writer,
            reader_sn_state: set,
            count: 1,
            final_flag: true,
        }),
        Submessage::Gap(wire::Gap {
            reader_id: reader,
            writer_id: writer,
            gap_start: SequenceNumber(2),
            gap_list: SequenceNumberSet::new(SequenceNumber(3), 0).map_err(|e| anyhow::anyhow!("{e:?}"))?,
        }),
    ];
    let header =
        wire::Header { version: ProtocolVersion::V2_4, vendor: VendorId::ROBOWIRE, guid_prefix: GuidPrefix(from) };
    let mut buf = vec![0u8; 512];
    let mut message = wire::MessageWriter::new(&mut buf, &header).map_err(|e| anyhow::anyhow!("{e:?}"))?;
    for s in &submessages {
        message.push(s).map_err(|e| anyhow::anyhow!("{e:?}"))?;
    }
    let len = message.finish();
    buf.truncate(len);
    seeds.push(("seed-reliable-exchange".to_string(), buf));
    Ok(seeds)
}

/// Participant seeds (steps of `rtps_proto::fuzzing::Step`, after the peer's discovery): each
/// of the six hostile datagrams of [`rtps_seeds`] sent from the discovered peer, then polled and
/// timed out; all six in a row; a normal exchange (a local write acknowledged, a sample
/// received, a fragmented write nacked, a fragmented sample received) over a clock; and the
/// discovery datagrams replayed one by one (no automatic feed, endpoints created after it).
fn rtps_participant_seeds() -> Seeds {
    use rtps_proto::fuzzing::{PEER_PREFIX, ParticipantSetup, Step, encode_steps};

    let hostile: Vec<(String, Vec<u8>)> = rtps_seeds()?
        .into_iter()
        .take(6)
        .map(|(name, mut d)| {
            d[8..20].copy_from_slice(&PEER_PREFIX.0);
            (name, d)
        })
        .collect();
    let after = [Step::Poll, Step::Clock { ms: 1000 }, Step::Poll, Step::Clock { ms: 3000 }, Step::Poll];
    let mut seeds: Vec<(String, Vec<u8>)> = hostile
        .iter()
        .map(|(name, d)| {
            let mut steps = vec![Step::Poll, Step::Raw(d)];
            steps.extend(after);
            (name.replacen("seed-", "seed-hostile-", 1), encode_steps(0, &steps))
        })
        .collect();
    let mut all: Vec<Step<'_>> = hostile.iter().map(|(_, d)| Step::Raw(d)).collect();
    all.extend(after);
    seeds.push(("seed-hostile-all-six".to_string(), encode_steps(0, &all)));

    let words = [0u32; 8];
    let exchange = [
        Step::Poll,
        Step::Write { len: 8 },
        Step::Poll,
        Step::AckNack { wrap: 0, from: 0, to: 0, base: 2, bits: 0, words, count: 1, final_flag: true },
        Step::Data { wrap: 4, to: 0, from: 0, sn: 1, len: 8, flags: 0 },
        Step::Heartbeat { wrap: 0, to: 0, from: 0, first: 1, last: 2, count: 1, flags: 0 },
        Step::Poll,
        Step::Data { wrap: 0, to: 0, from: 0, sn: 2, len: 8, flags: 0 },
        Step::Write { len: 3000 },
        Step::Poll,
        Step::NackFrag { wrap: 0, from: 0, to: 0, sn: 2, base: 2, bits: 1, words: [1, 0, 0, 0, 0, 0, 0, 0], count: 1 },
        Step::AckNack {
            wrap: 0,
            from: 0,
            to: 0,
            base: 2,
            bits: 1,
            words: [1 << 31, 0, 0, 0, 0, 0, 0, 0],
            count: 2,
            final_flag: false,
        },
        Step::Clock { ms: 100 },
        Step::Poll,
        Step::DataFrag { wrap: 0, to: 0, from: 0, sn: 3, start: 1, count: 2, size: 1024, sample: 3000, len: 0 },
        Step::HeartbeatFrag { wrap: 0, to: 0, from: 0, sn: 3, last: 2, count: 1 },
        Step::Heartbeat { wrap: 0, to: 0, from: 0, first: 1, last: 3, count: 2, flags: 0 },
        Step::Poll,
        Step::DataFrag { wrap: 0, to: 0, from: 0, sn: 3, start: 3, count: 1, size: 1024, sample: 3000, len: 0 },
        Step::Gap { wrap: 0, to: 0, from: 0, start: 4, base: 6, bits: 0, words },
        Step::Poll,
        Step::Clock { ms: 3000 },
        Step::Poll,
        Step::Clock { ms: 10_000 },
        Step::Clock { ms: 10_000 },
        Step::Poll,
    ];
    seeds.push(("seed-exchange".to_string(), encode_steps(0, &exchange)));
    let setup = ParticipantSetup::new();
    let mut discovery: Vec<Step<'_>> =
        (0..setup.discovery.len()).map(|i| Step::Discovery { index: i as u8, patches: [(0, 0); 2] }).collect();
    discovery.extend([Step::Poll, Step::Write { len: 8 }, Step::Poll]);
    seeds.push(("seed-discovery-steps".to_string(), encode_steps(3, &discovery)));
    Ok(seeds)
}

/// DDS sample seeds: every golden CDR payload (Go2, selector 0 `LowCmd_`, 1 `LowState_`) as
/// sent, with its CRC broken, and with the big-endian header of its representation (`00 00`,
/// `00 06`: refused); then the HG and service payloads made with the codecs.
fn dds_seeds() -> Seeds {
    let mut seeds = Vec::new();
    for (name, input) in unitree_seeds("cdr_hex")? {
        let mut bad_crc = input.clone();
        *bad_crc.last_mut().context("empty payload")? ^= 0x5a;
        let mut big_endian = input.clone();
        big_endian[2] -= 1; // the identifier's second byte: 01 → 00 (CDR_BE), 07 → 06 (XCDR2_BE)
        seeds.extend([(format!("{name}-bad-crc"), bad_crc), (format!("{name}-big-endian"), big_endian), (name, input)]);
    }
    seeds.extend(messages::dds_seeds());
    Ok(seeds)
}

/// Which datagrams a capture seed keeps.
type Keep = fn(&[u8]) -> bool;

/// Capture seeds: recorded exchanges of the captured ZSL-1 datagrams (all of them both ways,
/// HighLevel only, LowLevel only) and an empty capture.
fn capture_seeds() -> Seeds {
    let datagrams = zsl1_seeds()?;
    let low_level = |d: &[u8]| matches!(d.len(), 248 | 272);
    // Which datagrams each seed keeps: all, HighLevel, LowLevel, none.
    let variants: [(&str, Keep); 4] = [
        ("seed-all", |_| true),
        ("seed-high-level", |d| !matches!(d.len(), 248 | 272)),
        ("seed-low-level", |d| matches!(d.len(), 248 | 272)),
        ("seed-empty", |_| false),
    ];
    variants
        .into_iter()
        .map(|(name, keep)| {
            let path = std::env::temp_dir().join(format!("robowire-fuzz-{name}-{}.mcap", std::process::id()));
            let recorder = robowire_record::Recorder::create(&path, "cargo xtask fuzz (seed)")?;
            let high = recorder.link("zsl1/high_level", &zsl_proto::description::HIGH_LEVEL);
            let low = recorder.link("zsl1/low_level", &zsl_proto::description::LOW_LEVEL);
            for (i, (_, bytes)) in datagrams.iter().enumerate().filter(|(_, (_, d))| keep(d)) {
                let tap = if low_level(bytes) { &low } else { &high };
                let direction =
                    if i % 2 == 0 { robowire_record::Direction::Sent } else { robowire_record::Direction::Received };
                tap.record(direction, bytes);
            }
            recorder.finish()?;
            let capture = std::fs::read(&path)?;
            let _ = std::fs::remove_file(&path);
            Ok((name.to_string(), capture))
        })
        .collect()
}

/// ZSL-1 seeds: every captured datagram.
fn zsl1_seeds() -> Seeds {
    let text = std::fs::read_to_string(crate::golden::zsl1::frames_path())?;
    let entries: Vec<serde_json::Value> = serde_json::from_str(&text)?;
    entries
        .iter()
        .enumerate()
        .map(|(i, e)| Ok((format!("seed-{i:02}"), hex_decode(e["hex"].as_str().context("hex")?)?)))
        .collect()
}

/// KMC seeds: each fixture frame of `direction` alone and all of them back to back, each with
/// chunk-size byte 0 (1-byte chunks) and 7 (8-byte chunks).
fn kmc_seeds(direction: &str) -> Seeds {
    let fixtures = load_kmc(&kmc_fixture_path())?;
    let mut streams: Vec<(String, Vec<u8>)> = fixtures
        .iter()
        .filter(|f| f.direction == direction)
        .map(|f| Ok((f.name.clone(), hex_decode(&f.hex)?)))
        .collect::<anyhow::Result<_>>()?;
    if streams.is_empty() {
        bail!("no KMC fixtures for {direction}");
    }
    let all = streams.iter().flat_map(|(_, bytes)| bytes.clone()).collect();
    streams.push(("all".into(), all));
    Ok(streams
        .into_iter()
        .flat_map(|(name, stream)| {
            [0u8, 7].map(|chunk| {
                let mut input = vec![chunk];
                input.extend_from_slice(&stream);
                (format!("seed-{name}-chunk{}", chunk + 1), input)
            })
        })
        .collect())
}

/// Unitree seeds: every vector's struct image (`packed_hex`) or CDR payload (`cdr_hex`), with
/// the selector byte of its message type (0 LowCmd, 1 LowState).
fn unitree_seeds(key: &str) -> Seeds {
    let vectors = crate::golden::unitree::load(&crate::golden::unitree::vectors_path())?;
    let mut seeds = Vec::new();
    for list in ["lowcmd", "lowstate", "cdr"] {
        for vector in vectors[list].as_array().into_iter().flatten() {
            let Some(hex) = vector[key].as_str() else { continue };
            let is_state =
                list == "lowstate" || vector["dds_type_name"].as_str().is_some_and(|t| t.ends_with("LowState_"));
            let mut input = vec![u8::from(is_state)];
            input.extend(hex_decode(hex)?);
            seeds.push((format!("seed-{}", vector["name"].as_str().unwrap_or("vector")), input));
        }
    }
    if seeds.is_empty() {
        bail!("no Unitree vectors with {key}");
    }
    Ok(seeds)
}

/// A target's seeds: those made from the fixtures, plus any input committed under
/// `fuzz/regressions/<target>/` (a crash the fuzzer found, kept once fixed). `cargo test`
/// replays all of them.
pub fn seeds_of(target: &Target) -> Seeds {
    let mut seeds = (target.seeds)()?;
    let dir = workspace_root().join("fuzz/regressions").join(target.name);
    if let Ok(entries) = std::fs::read_dir(&dir) {
        for entry in entries {
            let path = entry?.path();
            let name = format!("regression-{}", path.file_name().unwrap_or_default().to_string_lossy());
            seeds.push((name, std::fs::read(&path).with_context(|| format!("reading {}", path.display()))?));
        }
    }
    Ok(seeds)
}

fn has_nightly() -> bool {
    Command::new("cargo").args(["+nightly", "--version"]).output().is_ok_and(|o| o.status.success())
}

/// Writes the seeds, builds the targets once and runs each selected one for `seconds`, as many
/// at a time as the machine has cores (each run's output in `fuzz/logs/<target>.log`, shown when
/// it fails).
///
/// With a nightly toolchain the targets run under AddressSanitizer; with stable only, with
/// `-s none` (no sanitizer; the property checks still run).
pub fn run(only: Option<&str>, seconds: u64) -> anyhow::Result<()> {
    let root = workspace_root();
    let fuzz_dir = root.join("fuzz");
    let version = Command::new("cargo").args(["fuzz", "--version"]).output();
    if !version.is_ok_and(|o| o.status.success()) {
        bail!("cargo-fuzz is not installed: cargo install --locked cargo-fuzz");
    }
    let targets: Vec<&Target> = TARGETS.iter().filter(|t| only.is_none_or(|name| t.name == name)).collect();
    if targets.is_empty() {
        let names: Vec<_> = TARGETS.iter().map(|t| t.name).collect();
        bail!("unknown fuzz target {only:?}; targets: {}", names.join(", "));
    }
    let nightly = has_nightly() && std::env::var("ROBOWIRE_FUZZ_STABLE").is_err();
    let how = if nightly { "nightly, AddressSanitizer" } else { "stable, -s none" };
    let cargo_fuzz = |verb: &str| {
        let mut command = Command::new("cargo");
        if nightly {
            command.arg("+nightly");
        }
        command.args(["fuzz", verb]);
        if !nightly {
            command.args(["-s", "none"]);
        }
        command.current_dir(&root);
        command
    };
    let mut build = cargo_fuzz("build");
    if let Some(name) = only {
        build.arg(name);
    }
    let status = build.status().context("running cargo fuzz build")?;
    if !status.success() {
        bail!("cargo fuzz build failed ({status})");
    }
    let logs = fuzz_dir.join("logs");
    std::fs::create_dir_all(&logs)?;
    let at_once = std::thread::available_parallelism().map_or(1, usize::from);
    for batch in targets.chunks(at_once) {
        let mut running = Vec::with_capacity(batch.len());
        for target in batch {
            let corpus = fuzz_dir.join("corpus").join(target.name);
            std::fs::create_dir_all(&corpus)?;
            for (name, input) in seeds_of(target)? {
                std::fs::write(corpus.join(name), input)?;
            }
            let log_path = logs.join(format!("{}.log", target.name));
            let log = std::fs::File::create(&log_path)?;
            let mut command = cargo_fuzz("run");
            command.arg(target.name).arg(&corpus).arg("--").arg(format!("-max_total_time={seconds}"));
            command.stdout(log.try_clone()?).stderr(log);
            println!("fuzz {} for {seconds} s ({how})", target.name);
            running.push((target, log_path, command.spawn().context("running cargo fuzz")?));
        }
        // Every run of the batch is waited for, so that none outlives a failure.
        let mut failed = Vec::new();
        for (target, log_path, mut child) in running {
            let status = child.wait().context("waiting for cargo fuzz")?;
            let log = std::fs::read_to_string(&log_path).unwrap_or_default();
            if status.success() {
                let runs = log.lines().rev().find(|l| l.starts_with("Done ")).unwrap_or("done");
                println!("fuzz {}: {runs}", target.name);
                continue;
            }
            eprintln!("{}", failure_report(&log));
            failed.push(format!(
                "fuzz target {} failed ({status}); its log is {}, the input under {}; commit it to {} to replay it in cargo test",
                target.name,
                display(&log_path),
                display(&fuzz_dir.join("artifacts").join(target.name)),
                display(&fuzz_dir.join("regressions").join(target.name))
            ));
        }
        if !failed.is_empty() {
            bail!("{}", failed.join("\n"));
        }
    }
    Ok(())
}

/// What a failed run's log says of the failure: from the panic or the sanitizer's report on
/// (at most 80 lines), else its last 40 lines.
fn failure_report(log: &str) -> String {
    let lines: Vec<&str> = log.lines().collect();
    let start = lines.iter().position(|l| l.contains("panicked at") || l.starts_with("==") && l.contains("ERROR"));
    let shown = match start {
        Some(at) => &lines[at..lines.len().min(at + 80)],
        None => &lines[lines.len().saturating_sub(40)..],
    };
    shown.join("\n")
}

fn display(path: &Path) -> String {
    path.display().to_string()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The seed corpus, replayed through the checks the fuzz targets run.
    #[test]
    fn seed_corpus_replays() {
        for target in TARGETS {
            let seeds = seeds_of(target).unwrap();
            assert!(seeds.len() >= 4, "{}", target.name);
            for (_, input) in seeds {
                (target.check)(&input);
            }
        }
    }
}
