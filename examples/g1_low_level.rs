//! Unitree's G1 low-level example with robowire: release the robot's controller, move every joint
//! from where it is to 0 rad, swing the ankles (pitch and roll, as joints: PR mode), damp, and
//! give the motors back to the controller. Against a simulated 29-dof G1 on DDS by default (where
//! the loopback has no multicast: as root in a network namespace of its own, else run again in a
//! user + network namespace); `--interface eth0` for a robot on its 192.168.123.x network, hung
//! from its frame first (releasing the controller drops it).
//!
//! ```sh
//! cargo run --example g1_low_level
//! ```

use std::time::Duration;

use anyhow::{Context, ensure};
use clap::Parser;
use robowire_sim::g1::{G1Sim, G1SimConfig};
use unitree::g1::slot::{LEFT_ANKLE_PITCH, LEFT_ANKLE_ROLL, RIGHT_ANKLE_PITCH, RIGHT_ANKLE_ROLL};
use unitree::g1::{Device, G1, G1Options, G1Variant, JOINTS, ParticipantOptions, from_fn, hold};

/// The ankle swing's amplitudes, rad, at 1 Hz (Unitree's example: 30° pitch, 10° roll).
const PITCH_RAD: f32 = 30.0 * std::f32::consts::PI / 180.0;
const ROLL_RAD: f32 = 10.0 * std::f32::consts::PI / 180.0;

/// Unitree G1 low-level example.
#[derive(Debug, Parser)]
struct Args {
    /// The network interface of the robot's network; without it, a simulated G1 on loopback.
    #[arg(long)]
    interface: Option<String>,
    /// Seconds of each stage (to the zero posture, the ankle swing).
    #[arg(long, default_value_t = 3.0)]
    stage_s: f64,
}

fn main() -> anyhow::Result<()> {
    let args = Args::parse();
    ensure!(args.stage_s.is_finite() && args.stage_s >= 0.2, "--stage-s must be at least 0.2 s");
    match &args.interface {
        Some(interface) => run(&args, ParticipantOptions::new(0, Some(interface)), None),
        // Multicast on loopback: here, or in a user + network namespace this example runs again in.
        None => robowire_dds::netns::for_this_process()
            .run(|| simulated(&args))
            .context("a simulated G1 on loopback needs multicast on lo")?,
    }
}

fn simulated(args: &Args) -> anyhow::Result<()> {
    let lo = ParticipantOptions::new(0, Some("lo"));
    let sim = G1Sim::spawn(G1SimConfig { participant: lo.clone(), ..G1SimConfig::default() })
        .context("starting the simulated G1")?;
    println!("simulated 29-dof G1 on DDS, interface lo");
    run(args, lo, Some(&sim))
}

/// The two ankles' pitch and roll at `t_s` of the swing; every other joint at 0.
fn swing(t_s: f32) -> [f32; JOINTS] {
    let phase = (2.0 * std::f32::consts::PI * t_s).sin();
    let mut q = [0.0; JOINTS];
    q[LEFT_ANKLE_PITCH] = PITCH_RAD * phase;
    q[LEFT_ANKLE_ROLL] = ROLL_RAD * phase;
    q[RIGHT_ANKLE_PITCH] = PITCH_RAD * phase;
    q[RIGHT_ANKLE_ROLL] = -ROLL_RAD * phase;
    q
}

fn run(args: &Args, participant: ParticipantOptions, sim: Option<&G1Sim>) -> anyhow::Result<()> {
    let runtime = tokio::runtime::Builder::new_multi_thread().worker_threads(2).enable_all().build()?;
    runtime.block_on(async {
        let mut options = G1Options::default();
        options.low_level.participant = participant;
        let robot = G1::open(options)?;
        // The robot's `mode_machine` comes with its first LowState: nothing is sent before it.
        let first = robot.wait_state(Duration::from_secs(10), |_| true).await.context("no rt/lowstate")?;
        println!("G1: mode_machine {} ({:?})", first.mode_machine, robot.variant());
        let mode = robot.mode().await?;
        let calls = robot.release().await?;
        println!("controller {mode:?} released ({calls} ReleaseMode)");
        let stage = Duration::from_secs_f64(args.stage_s);

        // 1. Every joint from where it is to 0 rad, with Unitree's example gains, stepped by
        // robowire's LowCmd stream on its own 2 ms deadlines (each step checked by the G1's rules).
        let (mode_machine, variant) = (first.mode_machine, robot.variant().unwrap_or(G1Variant::Dof29));
        let from = robot.joint_positions().context("no state")?;
        let to_zero = from_fn(stage, move |elapsed| {
            let ratio = (elapsed.as_secs_f32() / stage.as_secs_f32()).min(1.0);
            hold(&from.map(|q| (1.0 - ratio) * q), mode_machine, variant)
        });
        robot.follow(to_zero)?.wait().await?;
        let largest = robot.joint_positions().context("no state")?.iter().fold(0.0f32, |m, q| m.max(q.abs()));
        println!("zero posture: largest |q| {largest:.3} rad");

        // 2. The ankles swing at 1 Hz, stepped by the stream; its left ankle pitch seen with each
        // LowState meanwhile.
        let swinging = from_fn(stage, move |elapsed| hold(&swing(elapsed.as_secs_f32()), mode_machine, variant));
        let end = robot.follow(swinging)?.wait();
        tokio::pin!(end);
        let mut states = robot.states();
        let mut pitch = (f32::INFINITY, f32::NEG_INFINITY);
        loop {
            tokio::select! {
                end = &mut end => break end?,
                changed = states.changed() => if changed.is_err() {
                    break (&mut end).await?;
                }
            }
            if let Some(q) = robot.joint_positions() {
                pitch = (pitch.0.min(q[LEFT_ANKLE_PITCH]), pitch.1.max(q[LEFT_ANKLE_PITCH]));
            }
        }
        println!("ankle swing: left ankle pitch {:+.3}..{:+.3} rad", pitch.0, pitch.1);

        robot.damp()?;
        tokio::time::sleep(Duration::from_millis(300)).await;
        robot.select_mode(&mode).await?;
        println!("damped; controller {mode:?} selected again");
        if let Some(sim) = sim {
            ensure!(largest < 0.05, "the simulated G1 did not reach the zero posture ({largest:.3} rad)");
            ensure!(pitch.1 - pitch.0 > PITCH_RAD, "the simulated G1's ankles did not swing: {pitch:?}");
            println!("simulator: {} LowCmds accepted", sim.snapshot().lowcmd.accepted);
        }
        robot.close();
        Ok(())
    })
}
