//! [`DdsReplay`]: recorded DDS payloads published again, byte for byte, on a topic: body, CRC
//! and encapsulation header alike (XCDR1 or XCDR2, its option bytes kept). A payload that is not
//! CDR (shorter than its header, or another representation) is refused before anything is
//! published.

use std::time::Duration;

use robowire_core::cdr::CdrEncoding;
use robowire_dds::qos::Qos;
use robowire_dds::{Participant, ParticipantOptions, RawSample, Reader, Writer};

use super::{Pace, ReplayError, ReplaySummary};

/// How often [`DdsReplay::first_reader`] looks at the writer's matches.
const MATCH_POLL: Duration = Duration::from_millis(10);
/// The writer: reliable like Unitree's, never waiting, keeping the last samples for a reliable
/// reader to ask again for (best-effort readers, Unitree's, take what arrives).
const WRITER: Qos = Qos { depth: 1024, ..Qos::STREAM_WRITER };

/// A topic by its name and the DDS type name it is announced with.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct DdsTopic<'a> {
    /// `rt/lowstate`.
    pub name: &'a str,
    /// `unitree_go::msg::dds_::LowState_`.
    pub type_name: &'a str,
}

/// Recorded payloads (encapsulation header, CDR body) published as the device on a DDS topic,
/// from the first reader that matches; the client's commands on another topic are counted.
///
/// ```no_run
/// use std::time::Duration;
/// use robowire_dds::ParticipantOptions;
/// use robowire_sim::replay::{DdsReplay, DdsTopic, Pace};
///
/// # tokio::runtime::Builder::new_current_thread().enable_all().build()?.block_on(async {
/// let states = DdsTopic { name: "rt/lowstate", type_name: "unitree_go::msg::dds_::LowState_" };
/// let payloads = [(Duration::ZERO, vec![0, 1, 0, 0, 0xfe, 0xef /* … */])];
/// let device = DdsReplay::open(ParticipantOptions::new(0, Some("lo")), states, None, payloads)?;
/// device.first_reader(Duration::from_millis(500)).await;
/// let summary = device.play(Pace::Recorded { speed: 1.0 }, Duration::from_millis(200)).await?;
/// println!("{} of {} LowStates published", summary.sent, summary.frames);
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// # })?;
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
#[derive(Debug)]
pub struct DdsReplay {
    writer: Writer<RawSample>,
    commands: Option<Reader<RawSample>>,
    /// Offset from the first frame, payload (header and body).
    frames: Vec<(Duration, Vec<u8>)>,
    /// Dropped last: the writer and reader belong to it.
    _participant: Participant,
}

impl DdsReplay {
    /// Joins the domain, with a writer of `states` (reliable, never waiting) and,
    /// if given, a reader of `commands`, to publish `payloads` (each: its offset from the first,
    /// the payload as recorded, in the order to publish them). A payload whose encapsulation
    /// header is neither XCDR1 nor XCDR2 is refused, with its index.
    pub fn open(
        participant: ParticipantOptions,
        states: DdsTopic<'_>,
        commands: Option<DdsTopic<'_>>,
        payloads: impl IntoIterator<Item = (Duration, Vec<u8>)>,
    ) -> Result<Self, ReplayError> {
        let frames = payloads
            .into_iter()
            .enumerate()
            .map(|(index, (offset, payload))| {
                let header = payload.get(..4).and_then(|h| <[u8; 4]>::try_from(h).ok());
                if header.and_then(CdrEncoding::from_header).is_none() {
                    let found = payload.iter().take(4).copied().collect();
                    return Err(ReplayError::Encapsulation { index, found });
                }
                Ok((offset, payload))
            })
            .collect::<Result<Vec<_>, _>>()?;
        let participant = Participant::new(participant)?;
        let writer = participant.raw_writer(states.name, states.type_name, WRITER)?;
        let commands = commands
            .map(|c| participant.raw_reader(c.name, c.type_name, Qos { depth: 64, ..Qos::READER }))
            .transpose()?;
        Ok(Self { writer, commands, frames, _participant: participant })
    }

    /// Payloads to publish.
    pub fn frames(&self) -> usize {
        self.frames.len()
    }

    /// Readers of the states' topic matched so far.
    pub fn matched_readers(&self) -> usize {
        self.writer.matched_readers()
    }

    /// Waits until a reader of the states' topic has matched (the client is there), then
    /// `settle` more. A match is this side's discovery of the reader; the reader takes samples
    /// only once its own side has discovered the writer, which DDS does not report here: what is
    /// published before is lost to a best-effort reader (Unitree's). On one network that follows
    /// within milliseconds, so a settle of a few hundred ms keeps the first payloads.
    pub async fn first_reader(&self, settle: Duration) {
        while self.matched_readers() == 0 {
            tokio::time::sleep(MATCH_POLL).await;
        }
        tokio::time::sleep(settle).await;
    }

    /// Publishes every payload on robowire's runner at `pace`, counting the client's commands
    /// meanwhile, then stays `linger` on the domain (best-effort readers acknowledge nothing:
    /// the middleware sends what it still holds meanwhile).
    pub async fn play(self, pace: Pace, linger: Duration) -> Result<ReplaySummary, ReplayError> {
        let Self { writer, mut commands, frames, _participant: participant } = self;
        let count = frames.len();
        let send = move |payload: &[u8]| writer.try_write_payload(payload).is_ok();
        let runner = super::spawn_playback(frames, pace, send)?;
        let mut done = tokio::task::spawn_blocking(move || runner.join());
        let mut received = 0u64;
        // The job (and its writer) stays until the participant leaves.
        let played = loop {
            tokio::select! {
                played = &mut done => break played.ok().flatten().ok_or(ReplayError::Lost)?,
                Some(()) = next_command(&mut commands) => received += 1,
            }
        };
        let lingering = tokio::time::sleep(linger);
        tokio::pin!(lingering);
        loop {
            tokio::select! {
                () = &mut lingering => break,
                Some(()) = next_command(&mut commands) => received += 1,
            }
        }
        let sent = played.sent;
        drop((played, participant));
        Ok(ReplaySummary { frames: count, sent, commands: received, invalid: 0, client: None })
    }
}

/// The client's next command, if a reader listens for them (else never).
async fn next_command(reader: &mut Option<Reader<RawSample>>) -> Option<()> {
    match reader {
        Some(reader) => reader.recv().await.ok().map(drop),
        None => std::future::pending().await,
    }
}
