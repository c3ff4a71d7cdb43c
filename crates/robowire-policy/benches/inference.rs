//! Inference of a walking policy on tract, step by step, beside a plain matrix product of the
//! same number of weights in the same run (alternating sample by sample, so both see the same
//! state of the host): Unitree's G1 policy (`../shared/policies`, an LSTM 47 → 64, 64 → 32 → 12)
//! when it is there. Then the policy running on a G1 (the kinematic simulator, through the
//! `unitree::g1` facade, where loopback carries multicast): its ticks' lateness at 50 Hz, and the
//! facade's 500 Hz LowCmd stream's send lateness while it runs beside the same stream holding a
//! pose without it, in the same run. Writes p50/p99 to `$ROBOWIRE_BENCH_META_POLICY` for
//! `cargo xtask bench`.

use std::path::PathBuf;
use std::sync::Arc;
use std::time::{Duration, Instant};

use robowire_core::timing::LatenessSummary;
use robowire_dds::ParticipantOptions;
use robowire_policy::{OnnxPolicy, PolicyConfig, RunOptions};
use robowire_sim::g1::{G1Sim, G1SimConfig};
use unitree::Device;
use unitree::g1::{G1, G1Options};

/// The G1 policy's weights: LSTM 4·64·(47 + 64) + 2·4·64, then 64·32 + 32 and 32·12 + 12.
const G1_WEIGHTS: usize = 4 * 64 * (47 + 64) + 2 * 4 * 64 + 64 * 32 + 32 + 32 * 12 + 12;

fn percentiles(mut ns: Vec<u64>) -> (u64, u64) {
    ns.sort_unstable();
    let at = |p: f64| ns[((ns.len() - 1) as f64 * p).round() as usize];
    (at(0.50), at(0.99))
}

fn policies() -> Option<PathBuf> {
    let dir = std::env::var_os("ROBOWIRE_POLICIES")
        .map_or_else(|| PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../../shared/policies"), PathBuf::from);
    dir.join("g1_walk.yaml").is_file().then_some(dir)
}

/// Each phase of the running half: the ring of lateness samples holds 8.2 s of the 500 Hz stream,
/// so each phase's summary is its own.
const PHASE: Duration = Duration::from_secs(10);

/// Lateness as JSON (µs).
fn lateness_json(l: &LatenessSummary) -> String {
    format!("{{\"count\": {}, \"p50_us\": {}, \"p99_us\": {}, \"max_us\": {}}}", l.count, l.p50_us, l.p99_us, l.max_us)
}

/// The G1 policy on a kinematic simulated G1 through the facade: the stream holding a pose for
/// [`PHASE`] (its send lateness), then the policy for [`PHASE`] once it walks (its ticks' and the
/// stream's lateness). JSON.
fn running(config: &PolicyConfig) -> String {
    let runtime = tokio::runtime::Builder::new_multi_thread().worker_threads(2).enable_all().build().unwrap();
    runtime.block_on(async {
        let participant = ParticipantOptions::new(0, Some("lo"));
        let _sim = G1Sim::spawn(G1SimConfig { participant, ..G1SimConfig::default() }).expect("the G1 simulator");
        let g1 = Arc::new(G1::open(G1Options::on(Some("lo"), 0)).expect("the G1 client"));
        assert!(g1.wait_state(Duration::from_secs(10), |_| true).await.is_some(), "a LowState");
        g1.release().await.expect("released");
        g1.hold(&g1.joint_positions().expect("a state")).expect("holding");
        tokio::time::sleep(PHASE).await;
        let holding = g1.stats().low_level.send_lateness;
        let policy = OnnxPolicy::load(&config.policy_path, config.num_obs, config.num_actions).expect("the policy");
        let options = RunOptions { duration: Some(PHASE), release: false, ..RunOptions::default() };
        let run = robowire_policy::start(g1.clone(), |g1| Some(g1), config, policy, options).await.expect("a run");
        let ended = run.ended().await;
        let (ticks, walking) = (run.tick_lateness(), g1.stats().low_level.send_lateness);
        println!(
            "G1 policy running ({ended}): ticks late p50 {} µs p99 {} µs; LowCmd stream p99 {} µs (holding without it: {} µs)",
            ticks.p50_us, ticks.p99_us, walking.p99_us, holding.p99_us
        );
        format!(
            "{{\"ticks\": {}, \"stream_walking\": {}, \"stream_holding\": {}}}",
            lateness_json(&ticks),
            lateness_json(&walking),
            lateness_json(&holding)
        )
    })
}

fn main() {
    if std::env::args().any(|a| a == "--list") {
        return; // `cargo test --benches` lists; there is nothing to list
    }
    // Before anything: this program may run again in a user and network namespace.
    let loopback = robowire_dds::netns::for_this_process();
    let quick = std::env::var_os("ROBOWIRE_BENCH_QUICK").is_some();
    let samples = if quick { 2_000 } else { 10_000 };
    let Some(dir) = policies() else {
        println!("policy inference: skipped, no ../shared/policies/g1_walk.yaml (set ROBOWIRE_POLICIES)");
        return;
    };
    let config = PolicyConfig::load(&dir.join("g1_walk.yaml")).expect("Unitree's G1 deploy config");
    let mut g1 = OnnxPolicy::load(&config.policy_path, config.num_obs, config.num_actions).expect("the G1 policy");
    // The same number of weights as one matrix: 47 × n.
    let columns = G1_WEIGHTS.div_ceil(config.num_obs);
    let matmul =
        robowire_policy::tiny::matmul(config.num_obs as i64, columns as i64, vec![0.01; config.num_obs * columns]);
    let mut plain = OnnxPolicy::load(&matmul.write(), config.num_obs, columns).expect("the matrix product");
    let obs: Vec<f32> = (0..config.num_obs).map(|i| (i as f32 * 0.37).sin() * 0.5).collect();
    let (mut policy_ns, mut plain_ns) = (Vec::with_capacity(samples), Vec::with_capacity(samples));
    for _ in 0..samples {
        let started = Instant::now();
        std::hint::black_box(g1.step(std::hint::black_box(&obs)).expect("a step"));
        policy_ns.push(started.elapsed().as_nanos() as u64);
        let started = Instant::now();
        std::hint::black_box(plain.step(std::hint::black_box(&obs)).expect("a step"));
        plain_ns.push(started.elapsed().as_nanos() as u64);
    }
    let (policy, plain) = (percentiles(policy_ns), percentiles(plain_ns));
    println!(
        "G1 policy step: p50 {:.1} µs, p99 {:.1} µs; matrix 1×{} · {}×{columns}: p50 {:.1} µs, p99 {:.1} µs",
        policy.0 as f64 / 1e3,
        policy.1 as f64 / 1e3,
        config.num_obs,
        config.num_obs,
        plain.0 as f64 / 1e3,
        plain.1 as f64 / 1e3,
    );
    let running = match loopback.run(|| running(&config)) {
        Ok(meta) => meta,
        Err(e) => {
            println!("G1 policy running: skipped, no multicast on loopback ({e})");
            "null".into()
        }
    };
    if let Some(path) = std::env::var_os("ROBOWIRE_BENCH_META_POLICY") {
        let meta = format!(
            "{{\"g1\": {{\"p50_ns\": {}, \"p99_ns\": {}}}, \"matmul\": {{\"p50_ns\": {}, \"p99_ns\": {}, \"rows\": {}, \"columns\": {columns}}}, \"running\": {running}}}\n",
            policy.0, policy.1, plain.0, plain.1, config.num_obs
        );
        std::fs::write(path, meta).expect("writing the bench metadata");
    }
}
