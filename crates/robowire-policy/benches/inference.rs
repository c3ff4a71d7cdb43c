//! Inference of a walking policy on tract, step by step, beside a plain matrix product of the
//! same number of weights in the same run (alternating sample by sample, so both see the same
//! state of the host): Unitree's G1 policy (`../shared/policies`, an LSTM 47 → 64, 64 → 32 → 12)
//! when it is there. Writes p50/p99 to `$ROBOWIRE_BENCH_META_POLICY` for `cargo xtask bench`.

use std::path::PathBuf;
use std::time::Instant;

use robowire_policy::{OnnxPolicy, PolicyConfig};

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

fn main() {
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
    if let Some(path) = std::env::var_os("ROBOWIRE_BENCH_META_POLICY") {
        let meta = format!(
            "{{\"g1\": {{\"p50_ns\": {}, \"p99_ns\": {}}}, \"matmul\": {{\"p50_ns\": {}, \"p99_ns\": {}, \"rows\": {}, \"columns\": {columns}}}}}\n",
            policy.0, policy.1, plain.0, plain.1, config.num_obs
        );
        std::fs::write(path, meta).expect("writing the bench metadata");
    }
}
