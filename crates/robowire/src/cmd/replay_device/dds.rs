//! A Go2 link's LowStates published on DDS `rt/lowstate` by `robowire_sim::replay::DdsReplay`,
//! byte for byte as recorded, from the first matched reader on; the client's LowCmds are counted.
//! The first line on stdout is the domain and interface, as `robowire sim go2` prints them.

use std::process::ExitCode;
use std::time::Duration;

use robowire_sim::replay::{DdsReplay, DdsTopic, Pace};
use unitree_proto::{LowCmd, LowState, Message};

use crate::cmd::dds_args::DdsArgs;

/// After the first reader matched, for its side to discover the writer (see
/// `DdsReplay::first_reader`).
const SETTLE: Duration = Duration::from_millis(500);
/// After the last LowState, for the middleware to send what it still holds.
const LINGER: Duration = Duration::from_millis(500);

/// Plays `payloads` (offsets from the first, DDS payloads) of `link` on `dds`.
pub(super) fn run(
    payloads: Vec<(Duration, Vec<u8>)>,
    link: &str,
    dds: &DdsArgs,
    pace: Pace,
) -> anyhow::Result<ExitCode> {
    let states = DdsTopic { name: LowState::TOPIC, type_name: LowState::DDS_TYPE_NAME };
    let commands = DdsTopic { name: LowCmd::TOPIC, type_name: LowCmd::DDS_TYPE_NAME };
    let runtime = tokio::runtime::Builder::new_multi_thread().worker_threads(2).enable_all().build()?;
    runtime.block_on(async {
        let robot = DdsReplay::open(dds.participant(), states, Some(commands), payloads)
            .map_err(|e| anyhow::Error::new(e).context(format!("link {link}")))?;
        let interface = dds.interface.as_deref().unwrap_or("the default interface");
        println!("go2 domain {} {interface}", dds.domain);
        eprintln!(
            "replay: {} LowStates of {link} on {} (domain {}, {interface}); waiting for a reader \
             (try: robowire go2 --domain {} watch)",
            robot.frames(),
            states.name,
            dds.domain,
            dds.domain
        );
        robot.first_reader(SETTLE).await;
        eprintln!("replay: {} reader(s) matched; playing", robot.matched_readers());
        let summary = robot.play(pace, LINGER).await?;
        eprintln!(
            "replay: published {} of {} LowStates; received {} LowCmds",
            summary.sent, summary.frames, summary.commands
        );
        Ok(ExitCode::SUCCESS)
    })
}
