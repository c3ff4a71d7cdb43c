//! Pseudo-terminals: the simulators' stand-in for a serial cable.
//!
//! The simulator owns the master side; the client opens [`Pty::slave_path`] like any serial
//! device (`/dev/pts/N`). The slave is put in raw mode (no echo, no CR/LF translation) so bytes
//! pass unchanged, and the simulator keeps one slave descriptor open so the master stays usable
//! while no client is attached. Dropping the [`Pty`] hangs the line up: the client's reads fail,
//! as with an unplugged USB adapter.
//!
//! I/O on the master is blocking with timeouts (`poll(2)`), for a simulator thread.

use std::io;
use std::os::fd::{AsFd, OwnedFd};
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

use rustix::event::{PollFd, PollFlags, Timespec, poll};
use rustix::fs::{Mode, OFlags};
use rustix::pty::OpenptFlags;
use rustix::termios::{OptionalActions, tcgetattr, tcsetattr};

/// A pseudo-terminal pair; the master side is ours.
#[derive(Debug)]
pub struct Pty {
    master: OwnedFd,
    slave_path: PathBuf,
    /// Keeps the slave open (and raw) while no client is attached.
    _slave: OwnedFd,
}

impl Pty {
    /// Opens a new pair.
    pub fn open() -> io::Result<Self> {
        let master = rustix::pty::openpt(OpenptFlags::RDWR | OpenptFlags::NOCTTY | OpenptFlags::CLOEXEC)?;
        rustix::pty::grantpt(&master)?;
        rustix::pty::unlockpt(&master)?;
        let name = rustix::pty::ptsname(&master, Vec::new())?;
        let slave_path = PathBuf::from(name.to_str().map_err(|e| io::Error::new(io::ErrorKind::InvalidData, e))?);
        let slave = rustix::fs::open(
            &slave_path,
            OFlags::RDWR | OFlags::NOCTTY | OFlags::CLOEXEC | OFlags::NONBLOCK,
            Mode::empty(),
        )?;
        let mut termios = tcgetattr(&slave)?;
        termios.make_raw();
        tcsetattr(&slave, OptionalActions::Now, &termios)?;
        let flags = rustix::fs::fcntl_getfl(&master)?;
        rustix::fs::fcntl_setfl(&master, flags | OFlags::NONBLOCK)?;
        Ok(Self { master, slave_path, _slave: slave })
    }

    /// The device path a client opens, e.g. `/dev/pts/3`.
    pub fn slave_path(&self) -> &Path {
        &self.slave_path
    }

    /// Waits up to `timeout` for `flags` on the master; `true` when ready.
    fn wait(&self, flags: PollFlags, timeout: Duration) -> io::Result<bool> {
        let timeout = Timespec::try_from(timeout).unwrap_or(Timespec { tv_sec: i64::MAX, tv_nsec: 0 });
        let mut fds = [PollFd::new(&self.master, flags)];
        match poll(&mut fds, Some(&timeout)) {
            Ok(n) => Ok(n > 0),
            Err(rustix::io::Errno::INTR) => Ok(false),
            Err(e) => Err(e.into()),
        }
    }

    /// Reads what the client wrote, waiting up to `timeout` for the first byte; `Ok(0)` on timeout.
    pub fn read_timeout(&self, buf: &mut [u8], timeout: Duration) -> io::Result<usize> {
        if !self.wait(PollFlags::IN, timeout)? {
            return Ok(0);
        }
        match rustix::io::read(self.master.as_fd(), buf) {
            Ok(n) => Ok(n),
            Err(rustix::io::Errno::AGAIN | rustix::io::Errno::INTR) => Ok(0),
            Err(e) => Err(e.into()),
        }
    }

    /// Writes all of `bytes` for the client to read, waiting up to `timeout` in all for space
    /// (a client that does not read fills the line's buffer).
    pub fn write_all(&self, mut bytes: &[u8], timeout: Duration) -> io::Result<()> {
        let deadline = Instant::now() + timeout;
        while !bytes.is_empty() {
            let left = deadline.saturating_duration_since(Instant::now());
            if left.is_zero() {
                return Err(io::ErrorKind::TimedOut.into());
            }
            if !self.wait(PollFlags::OUT, left)? {
                continue;
            }
            match rustix::io::write(self.master.as_fd(), bytes) {
                Ok(0) => return Err(io::ErrorKind::WriteZero.into()),
                Ok(n) => bytes = &bytes[n..],
                Err(rustix::io::Errno::AGAIN | rustix::io::Errno::INTR) => {}
                Err(e) => return Err(e.into()),
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::io::{Read, Write};

    #[test]
    fn bytes_pass_unchanged_both_ways() {
        let pty = Pty::open().unwrap();
        let mut client = std::fs::OpenOptions::new().read(true).write(true).open(pty.slave_path()).unwrap();
        // Bytes a cooked tty would mangle: CR, LF, ^C, ^D, XON/XOFF, DEL.
        let all: Vec<u8> = (0..=255).collect();
        client.write_all(&all).unwrap();
        let mut got = Vec::new();
        let mut buf = [0u8; 512];
        while got.len() < all.len() {
            let n = pty.read_timeout(&mut buf, Duration::from_secs(5)).unwrap();
            assert!(n > 0, "timed out after {} bytes", got.len());
            got.extend_from_slice(&buf[..n]);
        }
        assert_eq!(got, all);
        pty.write_all(&all, Duration::from_secs(5)).unwrap();
        let mut back = vec![0u8; all.len()];
        client.read_exact(&mut back).unwrap();
        assert_eq!(back, all);
        // Nothing echoed back to the master.
        assert_eq!(pty.read_timeout(&mut buf, Duration::from_millis(20)).unwrap(), 0);
    }
}
