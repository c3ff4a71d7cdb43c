//! [`Battery`]: the robot's latest `rt/lf/bmsstate` (HG `BmsState_`), read by a task on the
//! low-level client's receive runtime and handed over through a seqlock, so that no reader ever
//! waits on the receive thread nor the other way round.

use std::sync::Arc;

use robowire_dds::qos::Qos;
use robowire_dds::{Participant, StatsHandle};
use robowire_rt::Latest;
use unitree_proto::bms::{BMS_TOPIC, HgBmsState};

use crate::g1::G1Error;

/// The latest `rt/lf/bmsstate` the robot published (a cheap handle: clones share it).
#[derive(Debug, Clone)]
pub struct Battery(Arc<Latest<HgBmsState>>);

impl Battery {
    /// The latest battery state (`None` before the first).
    pub fn latest(&self) -> Option<HgBmsState> {
        self.0.read().map(|(_, state)| state)
    }
}

/// The reader of `rt/lf/bmsstate`: its task ends when `runtime` shuts down or when aborted.
pub(crate) struct BatteryReader {
    pub(crate) battery: Battery,
    pub(crate) stats: StatsHandle,
    pub(crate) task: tokio::task::JoinHandle<()>,
}

impl BatteryReader {
    /// Subscribes on `participant`; the samples are taken by a task on `runtime`.
    pub(crate) fn spawn(participant: &Participant, runtime: &tokio::runtime::Handle) -> Result<Self, G1Error> {
        let mut reader = participant.reader::<HgBmsState>(BMS_TOPIC, Qos::READER)?;
        let stats = reader.stats_handle();
        let battery = Battery(Arc::new(Latest::new()));
        let latest = battery.0.clone();
        let task = runtime.spawn(async move {
            while let Ok(sample) = reader.recv().await {
                latest.write(robowire_rt::now(), &sample.value);
            }
        });
        Ok(Self { battery, stats, task })
    }
}
