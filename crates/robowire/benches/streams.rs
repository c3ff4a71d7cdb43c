//! Send lateness of every periodic stream, each beside a bare C-like loop measured in the same
//! run: a thread that `clock_nanosleep`s to absolute deadlines at the same rate, with the same
//! (normal) priority and the same 1 ns timer slack as robowire's runner threads. Also the
//! ZSL-1 command interval as the simulated dog receives it, and the runner's spin measured at
//! several lengths (lateness and CPU) to show why `DEFAULT_SPIN` is what it is.
//!
//! Run by `cargo xtask bench` (figures to `ROBOWIRE_BENCH_META_STREAMS`); each stream runs
//! alone, 10 s (2 s with `ROBOWIRE_BENCH_QUICK`), nothing pinned.

use std::time::{Duration, Instant};

use kmc::{Device, Driver, DriverOptions};
use robowire_core::schedule::{Periodic, Time};
use robowire_core::timing::{LatenessRing, LatenessSummary};
use robowire_rt::runner::{DEFAULT_SPIN, Job, Runner, RunnerOptions};
use robowire_rt::stats::micros;
use robowire_sim::kmc::{ChassisSim, ChassisSimConfig};
use robowire_sim::spline::{SplineSim, SplineSimConfig};
use robowire_sim::zsl1::{Zsl1Sim, Zsl1SimConfig};
use serde_json::{Value, json};
use zsl::udp::{ClientOptions, HighLevel, LowLevel};

/// Samples kept per measurement: 10 s at 1 kHz.
const SAMPLES: usize = 16384;

fn summary(s: &LatenessSummary) -> Value {
    json!({"count": s.count, "p50_us": s.p50_us, "p99_us": s.p99_us, "max_us": s.max_us})
}

/// The baseline: a bare thread sleeping with `clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME)`
/// to each deadline of a `period` grid for `seconds`.
fn bare_loop(period: Duration, seconds: f64) -> LatenessSummary {
    std::thread::spawn(move || {
        robowire_rt::set_fine_timer_slack();
        let mut ring: Box<LatenessRing<SAMPLES>> = Box::new(LatenessRing::new());
        let start = robowire_rt::now();
        let end = start + Duration::from_secs_f64(seconds);
        let mut next = start + period;
        while next < end {
            let ns = next.as_nanos();
            let at =
                rustix::time::Timespec { tv_sec: (ns / 1_000_000_000) as i64, tv_nsec: (ns % 1_000_000_000) as i64 };
            let _ = rustix::thread::clock_nanosleep_absolute(rustix::thread::ClockId::Monotonic, &at);
            ring.record(micros(robowire_rt::now().saturating_duration_since(next)));
            next = next + period;
        }
        ring.summary()
    })
    .join()
    .expect("the baseline loop")
}

/// A runner job that does nothing on a `period` grid until `end`: the runner's own precision,
/// and the CPU its spin costs.
struct Idle {
    grid: Periodic,
    end: Time,
    ring: Box<LatenessRing<SAMPLES>>,
    cpu: Duration,
}

impl Job for Idle {
    fn next_run(&mut self) -> Option<Time> {
        if self.grid.deadline() < self.end {
            return Some(self.grid.deadline());
        }
        let t = rustix::time::clock_gettime(rustix::time::ClockId::ThreadCPUTime);
        self.cpu = Duration::new(t.tv_sec as u64, t.tv_nsec as u32);
        None
    }

    fn run(&mut self, now: Time) {
        if let Some(tick) = self.grid.poll(now) {
            self.ring.record(micros(tick.lateness));
        }
    }
}

/// The runner with `spin` on a `period` grid for `seconds`: lateness and CPU share of one core.
fn runner_loop(period: Duration, seconds: f64, spin: Duration) -> (LatenessSummary, f64) {
    let start = robowire_rt::now();
    let job = Idle {
        grid: Periodic::new(start + period, period),
        end: start + Duration::from_secs_f64(seconds),
        ring: Box::new(LatenessRing::new()),
        cpu: Duration::ZERO,
    };
    let done = Runner::spawn(RunnerOptions { spin, ..RunnerOptions::named("bench-idle") }, job)
        .expect("runner")
        .join()
        .expect("the idle job");
    (done.ring.summary(), done.cpu.as_secs_f64() / seconds)
}

/// The KMC Driver's 100 Hz `0xA5` stream against the chassis simulator on a pty.
fn kmc_stream(seconds: f64) -> LatenessSummary {
    let sim = ChassisSim::spawn(ChassisSimConfig::default()).expect("chassis simulator");
    let options = DriverOptions { command_timeout: Duration::from_secs(3600), ..DriverOptions::default() };
    let driver = Driver::open(sim.path(), options).expect("driver");
    driver.set_command(0.3, 0.0).expect("command");
    let end = Instant::now() + Duration::from_secs_f64(seconds);
    while Instant::now() < end {
        for _frame in driver.messages_until(Instant::now() + Duration::from_millis(50)) {}
    }
    let lateness = driver.stats().control_lateness;
    driver.close().expect("driver stop");
    lateness
}

fn runtime() -> tokio::runtime::Runtime {
    tokio::runtime::Builder::new_multi_thread().worker_threads(1).enable_all().build().expect("runtime")
}

/// The ZSL-1 HighLevel client's idle 500 Hz stream against the dog simulator: the client's
/// send lateness, the simulator's state-stream lateness, the interval at the dog.
fn zsl_high_level(seconds: f64) -> (LatenessSummary, LatenessSummary, LatenessSummary) {
    let sim = Zsl1Sim::spawn(Zsl1SimConfig::loopback()).expect("dog simulator");
    let dog = sim.high_level_addr();
    runtime().block_on(async {
        let options = ClientOptions { dog, ..ClientOptions::high_level([127, 0, 0, 1].into(), 0, dog.ip()) };
        let client = HighLevel::open(options).expect("HighLevel client");
        tokio::time::sleep(Duration::from_secs_f64(seconds)).await;
        let snapshot = sim.snapshot();
        (client.stats().stream_lateness, snapshot.state_lateness, snapshot.high_level.command_jitter)
    })
}

/// The ZSL-1 LowLevel client's idle 500 Hz stream against the dog simulator.
fn zsl_low_level(seconds: f64) -> LatenessSummary {
    let sim = Zsl1Sim::spawn(Zsl1SimConfig::loopback()).expect("dog simulator");
    let dog = sim.low_level_addr();
    runtime().block_on(async {
        let options = ClientOptions { dog, ..ClientOptions::low_level([127, 0, 0, 1].into(), 0, dog.ip()) };
        let client = LowLevel::open(options).expect("LowLevel client");
        tokio::time::sleep(Duration::from_secs_f64(seconds)).await;
        client.stats().stream_lateness
    })
}

/// The spline daemon simulator's 1 kHz loop.
fn spline_daemon(seconds: f64) -> LatenessSummary {
    let sim = SplineSim::spawn(SplineSimConfig::private("bench-streams")).expect("spline simulator");
    std::thread::sleep(Duration::from_secs_f64(seconds));
    sim.stats().lateness
}

fn main() {
    // `cargo bench` passes harness arguments (`--bench`, criterion's options): not ours.
    let quick = std::env::var_os("ROBOWIRE_BENCH_QUICK").is_some();
    let seconds = if quick { 2.0 } else { 10.0 };
    let ms = Duration::from_millis;
    let mut streams = Vec::new();
    let mut stream = |name: &str, period: Duration, measure: &dyn Fn() -> LatenessSummary| {
        let bare = bare_loop(period, seconds);
        let lateness = measure();
        println!(
            "{name}: p50 {} p99 {} max {} µs; bare loop p50 {} p99 {} max {} µs",
            lateness.p50_us, lateness.p99_us, lateness.max_us, bare.p50_us, bare.p99_us, bare.max_us
        );
        streams.push(json!({
            "name": name,
            "period_us": period.as_micros() as u64,
            "lateness": summary(&lateness),
            "bare_loop": summary(&bare),
        }));
    };
    stream("KMC Driver 0xA5 stream (100 Hz)", ms(10), &|| kmc_stream(seconds));
    let high = std::cell::Cell::new(None);
    stream("ZSL-1 HighLevel command stream (500 Hz)", ms(2), &|| {
        let (client, state, at_dog) = zsl_high_level(seconds);
        high.set(Some((state, at_dog)));
        client
    });
    let (dog_state, at_dog) = high.take().expect("the HighLevel run");
    stream("dog simulator state stream (500 Hz)", ms(2), &|| dog_state);
    stream("ZSL-1 LowLevel command stream (500 Hz)", ms(2), &|| zsl_low_level(seconds));
    stream("spline daemon simulator (1 kHz)", ms(1), &|| spline_daemon(seconds));

    // The spin: lateness and CPU of the runner alone at 500 Hz, at several lengths.
    let spin_seconds = seconds / 2.0;
    let bare = bare_loop(ms(2), spin_seconds);
    let spins: Vec<Value> = [0, 30, 60, 100, 150]
        .map(|us| {
            let spin = Duration::from_micros(us);
            let (lateness, cpu) = runner_loop(ms(2), spin_seconds, spin);
            println!("runner spin {us} µs: p50 {} p99 {} µs, CPU {:.1} %", lateness.p50_us, lateness.p99_us, cpu * 100.0);
            json!({"spin_us": us, "default": spin == DEFAULT_SPIN, "lateness": summary(&lateness), "cpu_percent": cpu * 100.0})
        })
        .into();
    let meta = json!({
        "seconds": seconds,
        "streams": streams,
        "zsl_interval_at_dog": summary(&at_dog),
        "spin": {"seconds": spin_seconds, "bare_loop": summary(&bare), "runs": spins},
    });
    println!("{meta}");
    if let Ok(path) = std::env::var("ROBOWIRE_BENCH_META_STREAMS") {
        std::fs::write(path, meta.to_string()).expect("writing the bench metadata");
    }
}
