//! `robowire policy run CONFIG.yaml --device ADDRESS`: a trained locomotion policy (ONNX, with
//! unitree_rl_gym's deploy config) on a G1 or a Go2, or on their physics simulators, through
//! `robowire_policy`.

use std::path::PathBuf;
use std::process::ExitCode;
use std::sync::Arc;
use std::time::Duration;

use anyhow::Context;
use clap::{Args, Subcommand};
use robowire_devices::policy::{DeviceRun, policy_link, start_on};
use robowire_devices::{AnyDevice, DeviceAddress};
use robowire_policy::control::{HOLD_S, STAND_S};
use robowire_policy::{CommandSlot, Ended, OnnxPolicy, Phase, PolicyConfig, RunOptions};

use crate::cmd::device::ReachArgs;

#[derive(Debug, Subcommand)]
pub(crate) enum PolicyCommand {
    /// Run a policy: wait for the robot's state, release its controller, move to the default
    /// pose in 2 s, hold it 1 s, then run the policy every control_dt until --duration or
    /// Ctrl-C. A stale state (100 ms), a tilt past max_tilt_rad, an action that is not finite or
    /// a command the robot's limits refuse damp the robot at once.
    Run(RunArgs),
}

#[derive(Debug, Args)]
pub(crate) struct RunArgs {
    /// The deploy config: unitree_rl_gym's deploy_real/configs/*.yaml, policy_path an ONNX file
    /// relative to it.
    config: PathBuf,
    /// The robot: g1:IFACE, go2:IFACE, or sim:g1 / sim:go2 with --physics (started here, its base
    /// free on the floor).
    #[arg(long)]
    device: DeviceAddress,
    /// The velocity asked: vx m/s, vy m/s, wz rad/s (clamped to the config's max_cmd).
    #[arg(long, value_name = "VX,VY,WZ", default_value = "0,0,0", value_parser = parse_command)]
    cmd: [f32; 3],
    /// Seconds the policy runs once it took over (default: until Ctrl-C).
    #[arg(long, value_name = "S")]
    duration: Option<f64>,
    /// Run the policy from the first tick: no move to the default pose, no hold.
    #[arg(long)]
    no_stand: bool,
    #[command(flatten)]
    reach: ReachArgs,
}

impl RunArgs {
    /// A simulator on DDS: it and the policy's client meet on loopback, which needs multicast.
    pub(crate) fn simulates_dds(&self) -> bool {
        self.device.is_simulated() && self.device.uses_dds()
    }
}

fn parse_command(text: &str) -> Result<[f32; 3], String> {
    let values: Vec<f32> = text
        .split(',')
        .map(|v| v.trim().parse::<f32>().map_err(|e| format!("{v:?}: {e}")))
        .collect::<Result<_, _>>()?;
    match <[f32; 3]>::try_from(values) {
        Ok(command) if command.iter().all(|v| v.is_finite()) => Ok(command),
        Ok(command) => Err(format!("{command:?}: every value must be finite")),
        Err(values) => Err(format!("three values VX,VY,WZ, found {}", values.len())),
    }
}

pub(crate) fn run(command: PolicyCommand, loopback: Option<robowire_dds::netns::Loopback>) -> anyhow::Result<ExitCode> {
    let PolicyCommand::Run(mut args) = command;
    let config = PolicyConfig::load(&args.config).map_err(anyhow::Error::msg)?;
    robowire_devices::policy::check(&config, &args.device, args.reach.body.physics()).map_err(anyhow::Error::msg)?;
    let duration = args.duration.map(|s| crate::cmd::seconds("--duration", s)).transpose()?;
    let policy =
        OnnxPolicy::load(&config.policy_path, config.num_obs, config.num_actions).map_err(anyhow::Error::msg)?;
    // A policy walks a simulated robot on the floor.
    args.reach.body.free_the_base();
    let mut options =
        RunOptions { command: CommandSlot::new(args.cmd), duration, stand: !args.no_stand, ..RunOptions::default() };
    let mut ended = None;
    let code = crate::cmd::device::on_loopback(loopback, || {
        args.reach.recording_with_links(&args.device, "robowire policy run", |device, links| async {
            options.tap = links.map(|links| policy_link(&device, &links));
            let device = Arc::new(device);
            ended = Some(walk(device.clone(), &config, policy, options).await?);
            Arc::try_unwrap(device).map_err(|_| anyhow::anyhow!("the policy's thread still holds the device"))
        })
    })?;
    Ok(match ended {
        Some(Ended::Duration | Ended::Stopped) => code,
        _ => ExitCode::FAILURE,
    })
}

/// Runs the policy on the robot `device` holds until it ends or Ctrl-C, a line each second.
async fn walk(
    device: Arc<AnyDevice>,
    config: &PolicyConfig,
    policy: OnnxPolicy,
    options: RunOptions,
) -> anyhow::Result<Ended> {
    let command = options.command.get();
    let running = start_on(device, config, policy, options).await.context("starting the policy")?;
    eprintln!(
        "policy {} every {} ms: standing {STAND_S} s, holding {HOLD_S} s, then walking at ({}, {}, {})",
        config.policy_path.display(),
        (config.control_dt * 1e3).round(),
        command[0],
        command[1],
        command[2],
    );
    let ended = until_ended(&running).await;
    let late = running.tick_lateness();
    drop(running);
    eprintln!("ended: {ended}; the robot was damped");
    eprintln!(
        "policy ticks: {} late p50 {} µs, p99 {} µs, max {} µs",
        late.count, late.p50_us, late.p99_us, late.max_us
    );
    Ok(ended)
}

async fn until_ended(running: &DeviceRun) -> Ended {
    let ended = running.ended();
    tokio::pin!(ended);
    let ctrl_c = tokio::signal::ctrl_c();
    tokio::pin!(ctrl_c);
    let mut every = tokio::time::interval(Duration::from_secs(1));
    loop {
        tokio::select! {
            end = &mut ended => return end,
            _ = &mut ctrl_c => running.stop(),
            _ = every.tick() => {
                let step = running.last_step();
                match running.phase() {
                    Phase::Walking => eprintln!(
                        "walking: step {}, command ({:.2}, {:.2}, {:.2}), inference {} µs",
                        step.step, step.command[0], step.command[1], step.command[2], step.inference.as_micros()
                    ),
                    phase => eprintln!("{phase:?}"),
                }
            }
        }
    }
}
