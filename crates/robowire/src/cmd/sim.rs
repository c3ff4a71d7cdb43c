//! `robowire sim …`: a simulator alone, until Ctrl-C.

use std::path::PathBuf;
use std::process::ExitCode;
use std::time::Duration;

use anyhow::Context;
use clap::{Args, Subcommand};
use robowire_sim::kmc::{ChassisSim, ChassisSimConfig};

#[derive(Debug, Subcommand)]
pub(crate) enum SimCommand {
    /// A KMC chassis on a pseudo-terminal; prints the device path to open.
    Kmc(KmcSimArgs),
    /// The ZSL-1 spline daemon: a 1 kHz loop on /spline_shm and /imu_shm with a PD joint model.
    Spline(SplineSimArgs),
    /// A ZSL-1 / ZSL-1W on UDP: HighLevel on 43997, LowLevel on 43900, state at 500 Hz.
    // `dog`: its old name, kept for one release.
    #[command(alias = "dog")]
    Zsl1(Zsl1SimArgs),
    /// A Unitree Go2 on DDS (rt/lowcmd, rt/lowstate at 500 Hz, motion_switcher and sport), booted
    /// with its sport mode owning the motors, as Unitree's software expects; --physics: its body
    /// in MuJoCo (a build with the `mujoco` feature).
    Go2(Go2SimArgs),
    /// A Unitree G1 humanoid on DDS (rt/lowcmd, rt/arm_sdk, rt/lowstate at 500 Hz,
    /// motion_switcher, the loco service `sport` and `arm`), booted standing under its own
    /// controller, as Unitree's software expects; --physics: its body in MuJoCo, hanging.
    G1(G1SimArgs),
}

/// The G1's joint count.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
enum Dof {
    /// 29 joints.
    #[value(name = "29")]
    Dof29,
    /// 23 joints.
    #[value(name = "23")]
    Dof23,
}

impl Dof {
    fn variant(self) -> unitree_proto::g1::G1Variant {
        match self {
            Self::Dof29 => unitree_proto::g1::G1Variant::Dof29,
            Self::Dof23 => unitree_proto::g1::G1Variant::Dof23,
        }
    }
}

#[derive(Debug, Args)]
pub(crate) struct G1SimArgs {
    #[command(flatten)]
    dds: crate::cmd::dds_args::DdsArgs,
    /// Joints: 29 (waist roll and pitch, 3-joint wrists) or 23 (neither; the same 29 slots).
    #[arg(long, value_enum, default_value = "29")]
    dof: Dof,
    /// The mode_machine the robot reports and its LowCmds must carry (default: the variant's,
    /// 5 for 29 joints, 4 for 23).
    #[arg(long)]
    mode_machine: Option<u8>,
    /// Print the simulator's state every this many seconds (0: never).
    #[arg(long, default_value_t = 1.0)]
    report_every_s: f64,
    #[command(flatten)]
    record: crate::cmd::record::RecordArgs,
    #[command(flatten)]
    body: crate::cmd::sim_body::BodyArgs,
    /// With --physics: the G1 on the floor, its pelvis held there as on Unitree's elastic band
    /// until a LowCmd stream has driven every leg joint with stiffness for 3.5 s, then let go
    /// (default: hanging where it starts, for good; the G1's balance controller is not
    /// simulated).
    #[arg(long, requires = "physics")]
    free_base: bool,
}

#[derive(Debug, Args)]
pub(crate) struct Go2SimArgs {
    #[command(flatten)]
    dds: crate::cmd::dds_args::DdsArgs,
    #[command(flatten)]
    body: crate::cmd::sim_body::BodyArgs,
    /// Print the simulator's state every this many seconds (0: never).
    #[arg(long, default_value_t = 1.0)]
    report_every_s: f64,
    #[command(flatten)]
    record: crate::cmd::record::RecordArgs,
}

#[derive(Debug, Args)]
pub(crate) struct Zsl1SimArgs {
    /// Address to listen on (both ports).
    #[arg(long, default_value = "127.0.0.1")]
    bind: std::net::IpAddr,
    /// Send state here instead of to the address the commands come from.
    #[arg(long)]
    client: Option<std::net::SocketAddr>,
    /// Robot model.
    #[arg(long, value_enum, default_value = "zsl-1")]
    model: crate::cmd::zsl1::ModelArg,
    /// HighLevel port (0: any free port).
    #[arg(long, default_value_t = zsl_proto::udp::HIGH_LEVEL_PORT)]
    high_level_port: u16,
    /// LowLevel port (0: any free port).
    #[arg(long, default_value_t = zsl_proto::udp::LOW_LEVEL_PORT)]
    low_level_port: u16,
    /// Print the simulator's state every this many seconds (0: never).
    #[arg(long, default_value_t = 1.0)]
    report_every_s: f64,
    #[command(flatten)]
    record: crate::cmd::record::RecordArgs,
}

#[derive(Debug, Args)]
pub(crate) struct SplineSimArgs {
    /// Spline object name.
    #[arg(long, default_value = zsl_proto::shm::SPLINE_SHM_NAME)]
    name: String,
    /// IMU object name.
    #[arg(long, default_value = zsl_proto::shm::IMU_SHM_NAME)]
    imu_name: String,
    /// Permission bits of the objects (octal), applied after creation regardless of the umask.
    #[arg(long, default_value = "660", value_parser = parse_octal)]
    mode: u32,
    /// Print the simulator's counters every this many seconds (0: never).
    #[arg(long, default_value_t = 1.0)]
    report_every_s: f64,
    /// Record the daemon's side of /spline_shm (commands taken, states published) and the IMU
    /// records it publishes.
    #[command(flatten)]
    record: crate::cmd::record::RecordArgs,
}

fn parse_octal(text: &str) -> Result<u32, String> {
    u32::from_str_radix(text, 8).ok().filter(|m| *m <= 0o777).ok_or_else(|| format!("{text:?} is no octal mode"))
}

#[derive(Debug, Args)]
pub(crate) struct KmcSimArgs {
    /// Also make a symlink here to the pty (a stable path, e.g. /tmp/kmc0).
    #[arg(long)]
    link: Option<PathBuf>,
    /// Stop the wheels when no 0xA5 arrived for this long, ms (0 disables).
    #[arg(long, default_value_t = 1000)]
    watchdog_ms: u64,
    /// Print the simulator's counters every this many seconds (0: never).
    #[arg(long, default_value_t = 1.0)]
    report_every_s: f64,
    /// Record the chassis's side of the line (host frames decoded, responses sent, bytes
    /// skipped).
    #[command(flatten)]
    record: crate::cmd::record::RecordArgs,
}

pub(crate) fn run(command: SimCommand) -> anyhow::Result<ExitCode> {
    match command {
        SimCommand::Kmc(args) => run_kmc(&args),
        SimCommand::Spline(args) => run_spline(&args),
        SimCommand::Zsl1(args) => run_zsl1(&args),
        SimCommand::Go2(args) => run_go2(&args),
        SimCommand::G1(args) => run_g1(&args),
    }
}

fn run_spline(args: &SplineSimArgs) -> anyhow::Result<ExitCode> {
    use zsl_proto::description::{IMU, SPLINE_DAEMON};
    let taps = args.record.start("robowire sim spline")?;
    let config = robowire_sim::spline::SplineSimConfig {
        spline_name: args.name.clone(),
        imu_name: args.imu_name.clone(),
        create: robowire_shm::CreateOptions { mode: args.mode, unlink_on_drop: true },
        tap: taps.link(robowire_devices::SPLINE_LINK, &SPLINE_DAEMON),
        imu_tap: taps.link(robowire_devices::SPLINE_IMU_LINK, &IMU),
        ..Default::default()
    };
    let sim = robowire_sim::spline::SplineSim::spawn(config).context("starting the spline daemon simulator")?;
    println!("{} {}", args.name, args.imu_name);
    eprintln!(
        "spline daemon simulator on {} and {} (mode {:o}), 1 kHz. Try: robowire shm status --name {} --imu-name {}. Ctrl-C stops and removes the objects.",
        args.name, args.imu_name, args.mode, args.name, args.imu_name
    );
    crate::cmd::sim_loop::until_ctrl_c(args.report_every_s, || {
        let s = sim.stats();
        eprintln!(
            "cycles {} missed {} | lateness p50 {} µs p99 {} µs max {} µs | commands fresh {} repeated {} cleared {} rejected {}",
            s.cycles,
            s.missed_cycles,
            s.lateness.p50_us,
            s.lateness.p99_us,
            s.lateness.max_us,
            s.daemon.fresh,
            s.daemon.repeated,
            s.daemon.cleared,
            s.daemon.rejected
        );
    })?;
    drop(sim);
    taps.finish()?;
    Ok(ExitCode::SUCCESS)
}

fn run_kmc(args: &KmcSimArgs) -> anyhow::Result<ExitCode> {
    let taps = args.record.start("robowire sim kmc")?;
    let config = ChassisSimConfig {
        link: args.link.clone(),
        command_watchdog: (args.watchdog_ms > 0).then(|| Duration::from_millis(args.watchdog_ms)),
        taps: taps
            .links()
            .map(|l| robowire_devices::kmc_taps(&l, &kmc_proto::description::CHASSIS))
            .unwrap_or_default(),
        ..ChassisSimConfig::default()
    };
    let sim = ChassisSim::spawn(config).context("starting the chassis simulator")?;
    // The first line is the path, alone, for scripts: `port=$(robowire sim kmc | head -1)`.
    println!("{}", sim.path().display());
    eprintln!(
        "KMC chassis simulator on {} (pty {}). Try: robowire kmc --port {} drive --velocity 0.5 --yaw-rate 0.2. Ctrl-C stops.",
        sim.path().display(),
        sim.pty_path().display(),
        sim.path().display()
    );
    crate::cmd::sim_loop::until_ctrl_c(args.report_every_s, || {
        let (s, st) = (sim.stats(), sim.state());
        eprintln!(
            "cmd {:+.2} m/s {:+.2} 1/m | speed {:+.3} m/s | battery {:.2} V | rx: control {} speed-req {} af-read {} af-write {} | sent {} | skipped {} rejected {}",
            st.commanded_velocity_mps,
            st.commanded_curvature_per_m,
            st.speed_mps,
            st.battery_volts,
            s.control_frames,
            s.speed_requests,
            s.af_reads,
            s.af_writes,
            s.responses_sent,
            s.decoder.skipped_bytes,
            s.decoder.rejected_candidates
        );
    })?;
    drop(sim);
    taps.finish()?;
    Ok(ExitCode::SUCCESS)
}

fn run_zsl1(args: &Zsl1SimArgs) -> anyhow::Result<ExitCode> {
    use robowire_sim::zsl1::{Zsl1Sim, Zsl1SimConfig};
    use zsl_proto::description::{HIGH_LEVEL, LOW_LEVEL};
    let taps = args.record.start("robowire sim zsl1")?;
    let config = Zsl1SimConfig {
        bind: args.bind,
        high_level_port: args.high_level_port,
        low_level_port: args.low_level_port,
        client: args.client,
        model: args.model.into(),
        high_level_tap: taps.link("zsl1/high_level", &HIGH_LEVEL),
        low_level_tap: taps.link("zsl1/low_level", &LOW_LEVEL),
        ..Zsl1SimConfig::default()
    };
    let sim = Zsl1Sim::spawn(config).context("starting the ZSL-1 simulator")?;
    // The first line is the two addresses, alone, for scripts.
    println!("{} {}", sim.high_level_addr(), sim.low_level_addr());
    eprintln!(
        "{} simulator: HighLevel on {}, LowLevel on {}, state at 500 Hz to {}. Try: robowire zsl1 --dog-ip {} stand. Ctrl-C stops.",
        if args.model == crate::cmd::zsl1::ModelArg::Zsl1W { "ZSL-1W" } else { "ZSL-1" },
        sim.high_level_addr(),
        sim.low_level_addr(),
        args.client.map_or("the address commands come from".to_string(), |c| c.to_string()),
        args.bind
    );
    crate::cmd::sim_loop::until_ctrl_c(args.report_every_s, || {
        let s = sim.snapshot();
        let [x, y, z] = s.robot.position_m();
        eprintln!(
            "mode {:>2} {:?} | pos {x:+.2} {y:+.2} {z:+.2} m yaw {:+.2} rad | battery {:.1} % | HL cmds {} invalid {} states {} | LL cmds {} invalid {} states {}",
            s.robot.mode().raw(),
            s.robot.activity(),
            s.robot.yaw_rad(),
            s.robot.battery_percent(),
            s.high_level.commands,
            s.high_level.invalid,
            s.high_level.states_sent,
            s.low_level.commands,
            s.low_level.invalid,
            s.low_level.states_sent
        );
    })?;
    drop(sim); // its links (and taps) closed before the capture is
    taps.finish()?;
    Ok(ExitCode::SUCCESS)
}

/// Joint positions as a report shows them (`+0.00 -1.30 …`).
fn joints(q_rad: &[f32]) -> String {
    q_rad.iter().map(|q| format!("{q:+.2}")).collect::<Vec<_>>().join(" ")
}

/// The Go2 simulator's periodic report line.
use crate::cmd::sim_body::physics_report;

fn go2_report(s: &robowire_sim::go2::Go2Snapshot) -> String {
    format!(
        "sport mode {:?} | q {} | lowcmd accepted {} ignored {} bad CRC {} bad head {} | lowstate {} | requests {}",
        s.sport_mode,
        joints(&s.joints_rad),
        s.lowcmd.accepted,
        s.lowcmd.ignored_sport_mode,
        s.lowcmd.bad_crc,
        s.lowcmd.bad_head,
        s.lowstate.samples,
        s.requests
    )
}

/// The G1 simulator's LowCmd counters as its report lines say them.
fn g1_lowcmd(c: &robowire_sim::g1::G1LowCmdCounters) -> String {
    format!(
        "lowcmd accepted {} ignored {} bad CRC {} bad mode_machine {} disabled motors {}",
        c.accepted, c.ignored_mode, c.bad_crc, c.bad_mode_machine, c.disabled_motors
    )
}

/// The G1 simulator's periodic report line.
fn g1_report(s: &robowire_sim::g1::G1Snapshot) -> String {
    format!(
        "mode {:?} fsm {} | q {} | {} | arm_sdk accepted {} weight {:.2} | lowstate {} | requests {}",
        s.mode,
        s.fsm_id,
        joints(&s.joints_rad),
        g1_lowcmd(&s.lowcmd),
        s.arm_sdk.accepted,
        s.arm_sdk.weight,
        s.stream.lowstate.samples,
        s.stream.requests
    )
}

fn run_go2(args: &Go2SimArgs) -> anyhow::Result<ExitCode> {
    use robowire_sim::go2::{Go2Sim, Go2SimConfig};
    #[cfg_attr(not(feature = "mujoco"), allow(unused_variables))]
    let physics = args.body.physics(false)?;
    let taps = args.record.start("robowire sim go2")?;
    let config = Go2SimConfig {
        participant: args.dds.participant(),
        low_level_tap: taps.link("go2/low_level", &unitree_proto::description::GO2_LOW_LEVEL),
        services_tap: taps.link("go2/api", &unitree_proto::description::API_SERVER),
        clock: args.body.clock(),
        onboard_gait: args.body.walks(),
        #[cfg(feature = "mujoco")]
        physics,
        ..Go2SimConfig::default()
    };
    let sim = Go2Sim::spawn(config).context("starting the Go2 simulator")?;
    let walker = args.body.start_walker::<unitree_proto::robot::Go2>(|| sim.onboard())?;
    let interface = args.dds.interface.as_deref().unwrap_or("the default interface");
    // The first line, alone, for scripts.
    println!("go2 domain {} {interface}", args.dds.domain);
    eprintln!(
        "Go2 simulator ({}) on DDS domain {} ({interface}): rt/lowstate at 500 Hz, rt/lowcmd, motion_switcher and \
         sport. Try: robowire go2 --domain {} status. Ctrl-C stops.",
        args.body.describe(),
        args.dds.domain,
        args.dds.domain
    );
    let last = std::cell::Cell::new((0.0, 0.0));
    let base = || sim.snapshot().base;
    crate::cmd::sim_loop::until_ctrl_c_with_log(
        args.report_every_s,
        || logs(sim.take_log(), walker.as_ref()),
        || {
            let s = sim.snapshot();
            go2_report(&s) + &physics_report(s.base, s.sim_time_s, s.wall_time_s, &last)
        },
        taps.events().map(|events| crate::cmd::sim_loop::LiveBody { events, device: "go2", base: &base }),
    )?;
    let s = sim.snapshot();
    println!(
        "lowcmd accepted {} ignored {} bad CRC {} bad head {}; final q {:?}",
        s.lowcmd.accepted, s.lowcmd.ignored_sport_mode, s.lowcmd.bad_crc, s.lowcmd.bad_head, s.joints_rad
    );
    drop(walker);
    drop(sim);
    taps.finish()?;
    Ok(ExitCode::SUCCESS)
}

/// The simulator's log lines and the walker's.
fn logs(mut lines: Vec<String>, walker: Option<&robowire_policy::onboard::Walker>) -> Vec<String> {
    lines.extend(walker.into_iter().flat_map(robowire_policy::onboard::Walker::take_log));
    lines
}

fn run_g1(args: &G1SimArgs) -> anyhow::Result<ExitCode> {
    use robowire_sim::g1::{G1Sim, G1SimConfig};
    use unitree_proto::g1::G1Variant;
    let variant = args.dof.variant();
    let dof = variant.joint_count();
    let mode_machine = args.mode_machine.unwrap_or(variant.mode_machine());
    match G1Variant::of_mode_machine(mode_machine) {
        None => eprintln!(
            "warning: mode_machine {mode_machine} is no G1 in Unitree's table (4: 23 joints, 5: 29 joints, …); \
             clients that copy it from rt/lowstate still work"
        ),
        Some(named) if named != variant => {
            eprintln!("warning: mode_machine {mode_machine} names a {named:?} G1, not the {dof}-joint one simulated")
        }
        Some(_) => {}
    }
    #[cfg_attr(not(feature = "mujoco"), allow(unused_variables))]
    // A walking G1 stands on the floor.
    let physics = args.body.physics(!(args.free_base || args.body.walks()))?;
    let taps = args.record.start("robowire sim g1")?;
    let config = G1SimConfig {
        participant: args.dds.participant(),
        mode_machine,
        low_level_tap: taps.link("g1/low_level", &unitree_proto::description::HG_LOW_LEVEL),
        services_tap: taps.link("g1/api", &unitree_proto::description::API_SERVER),
        clock: args.body.clock(),
        onboard_gait: args.body.walks(),
        #[cfg(feature = "mujoco")]
        physics,
        ..G1SimConfig::new(variant)
    };
    let sim = G1Sim::spawn(config).context("starting the G1 simulator")?;
    let walker = args.body.start_walker::<unitree_proto::robot::Hg>(|| sim.onboard())?;
    let interface = args.dds.interface.as_deref().unwrap_or("the default interface");
    // The first line, alone, for scripts.
    println!("g1 domain {} {interface} dof {dof} mode_machine {mode_machine}", args.dds.domain);
    eprintln!(
        "G1 simulator ({dof} joints, {}) on DDS domain {} ({interface}): rt/lowstate at 500 Hz, rt/lowcmd, \
         rt/arm_sdk, motion_switcher, sport (loco) and arm. Try: robowire g1 --domain {} zero. Ctrl-C stops.",
        args.body.describe(),
        args.dds.domain,
        args.dds.domain
    );
    let last = std::cell::Cell::new((0.0, 0.0));
    let base = || sim.snapshot().base;
    crate::cmd::sim_loop::until_ctrl_c_with_log(
        args.report_every_s,
        || logs(sim.take_log(), walker.as_ref()),
        || {
            let s = sim.snapshot();
            g1_report(&s) + &physics_report(s.base, s.stream.sim_time_s, s.stream.wall_time_s, &last)
        },
        taps.events().map(|events| crate::cmd::sim_loop::LiveBody { events, device: "g1", base: &base }),
    )?;
    let s = sim.snapshot();
    println!(
        "{}; arm_sdk accepted {} ignored {} unsealed {} weight {:.2}; final q {:?}",
        g1_lowcmd(&s.lowcmd),
        s.arm_sdk.accepted,
        s.arm_sdk.ignored_released,
        s.arm_sdk.unsealed,
        s.arm_sdk.weight,
        s.joints_rad
    );
    drop(walker);
    drop(sim);
    taps.finish()?;
    Ok(ExitCode::SUCCESS)
}
