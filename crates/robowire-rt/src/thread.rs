//! Placing a thread: CPU affinity and `SCHED_FIFO` priority (Linux).

use std::io;

/// Why a thread could not be placed as asked.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum RtError {
    /// `cpu` could not be applied.
    #[error("cannot pin the thread to CPU {cpu}")]
    CpuAffinity {
        /// The requested CPU index.
        cpu: usize,
        /// What the system said.
        #[source]
        source: io::Error,
    },
    /// A thread could not be started.
    #[error("cannot start thread {name}")]
    Thread {
        /// The thread's name.
        name: String,
        /// What the system said.
        #[source]
        source: io::Error,
    },
    /// The socket pair that wakes a polling runner's thread could not be made.
    #[error("cannot make the wake-up socket of thread {name}")]
    Wake {
        /// The thread's name.
        name: String,
        /// What the system said.
        #[source]
        source: io::Error,
    },
    /// `mlockall` failed.
    #[error("cannot lock the process's memory (needs CAP_IPC_LOCK or a memlock limit)")]
    LockMemory(#[source] io::Error),
    /// `priority` could not be applied.
    #[error(
        "cannot run the thread at SCHED_FIFO priority {priority}: {reason} (needs CAP_SYS_NICE or an \
         rtprio limit; leave the priority unset for normal scheduling)"
    )]
    RealtimePriority {
        /// The requested priority.
        priority: u8,
        /// What the system said.
        reason: String,
    },
}

/// CPU indices a thread can be pinned to are below this (`CPU_SETSIZE`).
#[cfg(target_os = "linux")]
pub(crate) const MAX_CPU: usize = rustix::thread::CpuSet::MAX_CPU;
/// CPU indices a thread can be pinned to are below this.
#[cfg(not(target_os = "linux"))]
pub(crate) const MAX_CPU: usize = 1024;

/// Pins the calling thread to `cpu`.
#[cfg(target_os = "linux")]
pub fn pin_current_thread(cpu: usize) -> Result<(), RtError> {
    use rustix::thread::{CpuSet, sched_setaffinity};
    if cpu >= MAX_CPU {
        let source = io::Error::new(io::ErrorKind::InvalidInput, "CPU index beyond CPU_SETSIZE");
        return Err(RtError::CpuAffinity { cpu, source });
    }
    let mut set = CpuSet::new();
    set.set(cpu);
    sched_setaffinity(None, &set).map_err(|e| RtError::CpuAffinity { cpu, source: e.into() })
}

/// Runs the calling thread under `SCHED_FIFO` at `priority` (1..=99).
#[cfg(target_os = "linux")]
pub fn set_realtime_priority(priority: u8) -> Result<(), RtError> {
    use thread_priority::{
        RealtimeThreadSchedulePolicy, ThreadPriority, ThreadPriorityValue, ThreadSchedulePolicy,
        set_thread_priority_and_policy, thread_native_id,
    };
    let error = |reason: String| RtError::RealtimePriority { priority, reason };
    if !(1..=99).contains(&priority) {
        return Err(error("SCHED_FIFO priorities are 1..=99".into()));
    }
    let value = ThreadPriorityValue::try_from(priority).map_err(|e| error(e.to_string()))?;
    set_thread_priority_and_policy(
        thread_native_id(),
        ThreadPriority::Crossplatform(value),
        ThreadSchedulePolicy::Realtime(RealtimeThreadSchedulePolicy::Fifo),
    )
    .map_err(|e| error(format!("{e:?}")))
}

/// Locks the process's current and future memory (`mlockall(MCL_CURRENT | MCL_FUTURE)`).
#[cfg(target_os = "linux")]
pub fn lock_memory() -> Result<(), RtError> {
    use rustix::mm::{MlockAllFlags, mlockall};
    mlockall(MlockAllFlags::CURRENT | MlockAllFlags::FUTURE).map_err(|e| RtError::LockMemory(e.into()))
}

/// Sets the calling thread's timer slack to 1 ns (Linux's default is 50 µs), so that a timed
/// sleep ends within the kernel's wake-up latency of its target. Best effort: without it, waits
/// only end later.
#[cfg(target_os = "linux")]
pub fn set_fine_timer_slack() {
    let _ = rustix::thread::set_current_timer_slack(std::num::NonZeroU64::new(1));
}

/// Locks the process's memory (Linux only).
#[cfg(not(target_os = "linux"))]
pub fn lock_memory() -> Result<(), RtError> {
    Err(RtError::LockMemory(io::Error::new(io::ErrorKind::Unsupported, "implemented on Linux only")))
}

/// Fine timer slack (Linux only; elsewhere nothing).
#[cfg(not(target_os = "linux"))]
pub fn set_fine_timer_slack() {}

/// Pins the calling thread to `cpu` (Linux only).
#[cfg(not(target_os = "linux"))]
pub fn pin_current_thread(cpu: usize) -> Result<(), RtError> {
    let source = io::Error::new(io::ErrorKind::Unsupported, "CPU pinning is implemented on Linux only");
    Err(RtError::CpuAffinity { cpu, source })
}

/// Runs the calling thread under `SCHED_FIFO` (Linux only).
#[cfg(not(target_os = "linux"))]
pub fn set_realtime_priority(priority: u8) -> Result<(), RtError> {
    Err(RtError::RealtimePriority { priority, reason: "implemented on Linux only".into() })
}
