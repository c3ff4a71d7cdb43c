//! [`Placement`]: where a stream thread runs (priority, CPU, memory lock), with one validation
//! that every device's options share.

use crate::RtError;

/// Where a device's stream thread runs. Embedded in every facade's options; checked once by
/// [`validate`](Self::validate) before anything starts, applied by the runner when the thread
/// starts.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct Placement {
    /// `SCHED_FIFO` priority 1..=99; `None` keeps normal scheduling.
    pub realtime_priority: Option<u8>,
    /// Pin the thread to this CPU; `None` does not pin.
    pub cpu: Option<usize>,
    /// Lock the process's memory (`mlockall(MCL_CURRENT | MCL_FUTURE)`) when the thread starts, so
    /// that no page fault delays a deadline. Process-wide.
    pub lock_memory: bool,
}

impl Placement {
    /// `SCHED_FIFO` at `priority`, pinned to `cpu` if given.
    pub fn realtime(priority: u8, cpu: Option<usize>) -> Self {
        Self { realtime_priority: Some(priority), cpu, lock_memory: false }
    }

    /// Refuses what cannot work before a thread is started: a priority outside 1..=99, a CPU
    /// index beyond what the system can name.
    pub fn validate(&self) -> Result<(), RtError> {
        if let Some(priority) = self.realtime_priority
            && !(1..=99).contains(&priority)
        {
            return Err(RtError::RealtimePriority { priority, reason: "SCHED_FIFO priorities are 1..=99".into() });
        }
        if let Some(cpu) = self.cpu
            && cpu >= crate::thread::MAX_CPU
        {
            let source = std::io::Error::new(std::io::ErrorKind::InvalidInput, "CPU index beyond CPU_SETSIZE");
            return Err(RtError::CpuAffinity { cpu, source });
        }
        Ok(())
    }

    /// Applies the placement to the calling thread: memory lock, CPU, priority, then a fine timer
    /// slack.
    pub(crate) fn apply(&self) -> Result<(), RtError> {
        self.validate()?;
        if self.lock_memory {
            crate::lock_memory()?;
        }
        if let Some(cpu) = self.cpu {
            crate::pin_current_thread(cpu)?;
        }
        if let Some(priority) = self.realtime_priority {
            crate::set_realtime_priority(priority)?;
        }
        crate::set_fine_timer_slack();
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn out_of_range_settings_are_refused_before_anything_starts() {
        assert!(Placement::default().validate().is_ok());
        assert!(Placement::realtime(80, Some(0)).validate().is_ok());
        assert!(matches!(Placement::realtime(0, None).validate(), Err(RtError::RealtimePriority { priority: 0, .. })));
        assert!(matches!(Placement::realtime(100, None).validate(), Err(RtError::RealtimePriority { .. })));
        let far = Placement { cpu: Some(1 << 20), ..Placement::default() };
        assert!(matches!(far.validate(), Err(RtError::CpuAffinity { cpu: 1_048_576, .. })));
    }
}
