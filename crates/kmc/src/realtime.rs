//! `realtime_priority` and `cpu_affinity` for the driver thread (Linux).

use crate::KmcError;

/// Pins the calling thread to `cpu`.
#[cfg(target_os = "linux")]
pub(crate) fn pin_current_thread(cpu: usize) -> Result<(), KmcError> {
    use rustix::thread::{CpuSet, sched_setaffinity};
    if cpu >= CpuSet::MAX_CPU {
        let source = std::io::Error::new(std::io::ErrorKind::InvalidInput, "CPU index beyond CPU_SETSIZE");
        return Err(KmcError::CpuAffinity { cpu, source });
    }
    let mut set = CpuSet::new();
    set.set(cpu);
    sched_setaffinity(None, &set).map_err(|e| KmcError::CpuAffinity { cpu, source: e.into() })
}

/// Runs the calling thread under `SCHED_FIFO` at `priority` (1..=99).
#[cfg(target_os = "linux")]
pub(crate) fn set_realtime_priority(priority: u8) -> Result<(), KmcError> {
    use thread_priority::{
        RealtimeThreadSchedulePolicy, ThreadPriority, ThreadPriorityValue, ThreadSchedulePolicy,
        set_thread_priority_and_policy, thread_native_id,
    };
    let error = |reason: String| KmcError::RealtimePriority { priority, reason };
    let value = ThreadPriorityValue::try_from(priority).map_err(|e| error(e.to_string()))?;
    set_thread_priority_and_policy(
        thread_native_id(),
        ThreadPriority::Crossplatform(value),
        ThreadSchedulePolicy::Realtime(RealtimeThreadSchedulePolicy::Fifo),
    )
    .map_err(|e| error(format!("{e:?}")))
}

#[cfg(not(target_os = "linux"))]
pub(crate) fn pin_current_thread(cpu: usize) -> Result<(), KmcError> {
    let source = std::io::Error::new(std::io::ErrorKind::Unsupported, "CPU pinning is implemented on Linux only");
    Err(KmcError::CpuAffinity { cpu, source })
}

#[cfg(not(target_os = "linux"))]
pub(crate) fn set_realtime_priority(priority: u8) -> Result<(), KmcError> {
    Err(KmcError::RealtimePriority { priority, reason: "implemented on Linux only".into() })
}
