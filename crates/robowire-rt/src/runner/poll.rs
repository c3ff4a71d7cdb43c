//! The wait of a polling runner ([`Runner::spawn_polling`](super::Runner::spawn_polling)):
//! `poll(2)` on the wake socket and the job's file descriptors until `spin` before the deadline,
//! then spinning on the clock with a non-blocking `poll(2)` each turn.

use std::os::fd::{AsFd, OwnedFd};
use std::os::unix::net::UnixDatagram;
use std::time::Duration;

use robowire_core::schedule::Time;
use rustix::event::{PollFd, PollFlags, Timespec, poll};
use rustix::io::Errno;

use super::{Control, Job};

/// Wake-ups drained from the wake socket per look: more stay for the next look.
const WAKE_DRAIN: usize = 16;

/// What a polling runner's thread waits on.
#[derive(Debug)]
pub(super) struct Readable {
    /// The thread's end of the wake socket pair.
    woken: UnixDatagram,
    /// The job's.
    fds: Vec<OwnedFd>,
}

impl Readable {
    pub(super) fn new(woken: UnixDatagram, fds: Vec<OwnedFd>) -> Self {
        Self { woken, fds }
    }

    /// The runner's loop with this wait.
    pub(super) fn run<J: Job>(&self, job: &mut J, control: &Control, spin: Duration) {
        let mut fds: Vec<PollFd<'_>> = std::iter::once(self.woken.as_fd())
            .chain(self.fds.iter().map(AsFd::as_fd))
            .map(|fd| PollFd::from_borrowed_fd(fd, PollFlags::IN))
            .collect();
        super::run(job, control, |deadline| self.wait_until(deadline, spin, control, &mut fds));
    }

    /// Returns at `deadline`, on a wake or a stop, or when one of the job's descriptors is
    /// readable. `fds[0]` is the wake socket.
    fn wait_until(&self, deadline: Time, spin: Duration, control: &Control, fds: &mut [PollFd<'_>]) {
        loop {
            let Some(left) = control.left_until(deadline) else { return };
            // Zero in the last `spin`: a look, then the next turn of the spin.
            let timeout = left.saturating_sub(spin);
            let Ok(timeout_spec) = Timespec::try_from(timeout) else {
                super::wait_until(deadline, spin, control);
                return;
            };
            match poll(fds, Some(&timeout_spec)) {
                Ok(0) => std::hint::spin_loop(),
                Ok(_) => {
                    if !fds[0].revents().is_empty() {
                        self.drain_wake();
                    }
                    if fds[1..].iter().any(|fd| !fd.revents().is_empty()) {
                        return;
                    }
                }
                Err(Errno::INTR) => {}
                // Not seen in practice (the set is fixed and small): keep the deadline.
                Err(_) => {
                    super::wait_until(deadline, spin, control);
                    return;
                }
            }
        }
    }

    fn drain_wake(&self) {
        let mut byte = [0u8; 1];
        for _ in 0..WAKE_DRAIN {
            if self.woken.recv(&mut byte).is_err() {
                return;
            }
        }
    }
}
