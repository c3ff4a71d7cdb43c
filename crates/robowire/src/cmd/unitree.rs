//! What `robowire go2` and `robowire g1` share: where the robot is, how long to wait for its
//! first LowState, the recording and the runtime; a move followed by the LowCmd stream, then held;
//! how long damping is sent before exiting.

use std::process::ExitCode;
use std::time::Duration;

use clap::Args;
use robowire_record::RecordLinks;
use unitree::{Connection, Device, Following, LowLevelOptions};

use crate::cmd::dds_args::DdsArgs;
use crate::cmd::seconds;

/// Damping sent before exiting, after a move and by `damp`.
pub(crate) const DAMP_FOR: Duration = Duration::from_millis(500);

/// A Unitree robot on DDS: where, how long to wait for it, what to record.
#[derive(Debug, Args)]
pub(crate) struct RobotArgs {
    #[command(flatten)]
    pub(crate) dds: DdsArgs,
    /// Seconds to wait for the robot's first LowState.
    #[arg(long, default_value_t = 5.0)]
    connect_timeout_s: f64,
    #[command(flatten)]
    record: crate::cmd::record::RecordArgs,
}

impl RobotArgs {
    /// Runs `body` on a two-thread runtime with the low-level options (domain, interface), the
    /// recorder's links with `--record` (the facade's options name their links), and the connect
    /// timeout; then closes the capture, whatever `body` returned.
    pub(crate) fn run<F>(
        &self,
        name: &str,
        body: impl FnOnce(LowLevelOptions, Option<RecordLinks>, Duration) -> F,
    ) -> anyhow::Result<ExitCode>
    where
        F: Future<Output = anyhow::Result<ExitCode>>,
    {
        let connect = seconds("--connect-timeout-s", self.connect_timeout_s)?;
        let runtime = tokio::runtime::Builder::new_multi_thread().worker_threads(2).enable_all().build()?;
        let taps = self.record.start(&format!("robowire {name}"))?;
        let options = LowLevelOptions { participant: self.dds.participant(), ..LowLevelOptions::default() };
        let code = runtime.block_on(body(options, taps.links(), connect));
        taps.finish()?;
        code
    }

    /// What to say when no LowState came within `connect`.
    pub(crate) fn silent(&self, connect: Duration) -> String {
        format!(
            "no rt/lowstate within {:.1} s on domain {} ({}): is the robot on, and is this the interface of its \
             network (192.168.123.x)?",
            connect.as_secs_f64(),
            self.dds.domain,
            self.dds.interface.as_deref().map_or("the default interface".into(), |i| format!("interface {i}"))
        )
    }
}

/// Waits for the motion the LowCmd stream follows to reach its end, then `hold` more while the
/// stream holds its final command; fails when the motion ends otherwise (a refused step, the
/// client closing) or when `rt/lowstate` stops (`during` says during what).
pub(crate) async fn follow_then_hold(
    robot: &impl Device,
    following: Following,
    hold: Duration,
    during: &str,
) -> anyhow::Result<()> {
    let mut connection = robot.connection_events();
    tokio::select! {
        done = async {
            following.wait().await?;
            tokio::time::sleep(hold).await;
            anyhow::Ok(())
        } => done,
        _ = connection.wait_for(|c| *c == Connection::Disconnected) => {
            anyhow::bail!("rt/lowstate stopped while {during}; damping")
        }
    }
}
