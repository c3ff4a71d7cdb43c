//! Pseudo-terminals: the simulators' stand-in for a serial cable, and the device end of the
//! serial transport.
//!
//! A device (a simulator) owns the master side; the host opens [`Pty::slave_path`] like any
//! serial device (`/dev/pts/N`), with [`SerialLink`](crate::SerialLink). The slave is put in raw mode (no echo, no CR/LF translation) so bytes
//! pass unchanged, and the simulator keeps one slave descriptor open so the master stays usable
//! while no client is attached. Dropping the [`Pty`] hangs the line up: the client's reads fail,
//! as with an unplugged USB adapter.
//!
//! I/O on the master is blocking with timeouts (`poll(2)`), for a simulator thread.
//! [`PtyDevice`] puts a [`StreamDecoder`] on it, the same way [`SerialLink`](crate::SerialLink)
//! does on the host side: whole frames in, whole frames out, counters, hang-up and re-plug.

use std::io;
use std::os::fd::{AsFd, OwnedFd};
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

use rustix::event::{PollFd, PollFlags, Timespec, poll};
use rustix::fs::{Mode, OFlags};
use rustix::pty::OpenptFlags;
use rustix::termios::{OptionalActions, tcgetattr, tcsetattr};

use robowire_core::{FrameBuffer, StreamDecoder};

use crate::{LinkCounters, RX_BUFFER_LEN, SerialTaps};

/// A pseudo-terminal pair; the master side is ours.
#[derive(Debug)]
pub struct Pty {
    master: OwnedFd,
    slave_path: PathBuf,
    /// Keeps the slave open (and raw) while no client is attached.
    slave: OwnedFd,
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
        Ok(Self { master, slave_path, slave })
    }

    /// The device path a client opens, e.g. `/dev/pts/3`.
    pub fn slave_path(&self) -> &Path {
        &self.slave_path
    }

    /// Bytes written for the client that it has not read yet (the line's input queue), so that
    /// a device can wait for the client to catch up before hanging up.
    pub fn unread(&self) -> io::Result<u64> {
        Ok(rustix::io::ioctl_fionread(&self.slave)?)
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

/// The device end of a serial line: a [`Pty`] whose master side is decoded with `D`, for a
/// device simulator. The host opens [`path`](Self::path) with a [`SerialLink`](crate::SerialLink).
///
/// With a `link` path, a symlink there always points at the current pseudo-terminal, so that a
/// host can reopen the same path after a [`hang_up`](Self::hang_up) and
/// [`plug_in`](Self::plug_in), as with a stable `/dev/serial/by-id/…` name.
#[derive(Debug)]
pub struct PtyDevice<D: StreamDecoder> {
    /// `None` while hung up: dropping the master is what hangs the line up.
    pty: Option<Pty>,
    slave_path: PathBuf,
    link: Option<PathBuf>,
    new_decoder: fn() -> D,
    rx: FrameBuffer<D, RX_BUFFER_LEN>,
    counters: LinkCounters,
    buf: [u8; 512],
    taps: SerialTaps,
}

impl<D: StreamDecoder> PtyDevice<D> {
    /// Opens a pseudo-terminal (and points `link` at it, if given); each line gets a fresh
    /// decoder from `new_decoder`.
    pub fn open(new_decoder: fn() -> D, link: Option<PathBuf>) -> io::Result<Self> {
        let pty = Pty::open()?;
        if let Some(link) = &link {
            point_link(link, pty.slave_path())?;
        }
        Ok(Self {
            slave_path: pty.slave_path().to_path_buf(),
            pty: Some(pty),
            link,
            new_decoder,
            rx: FrameBuffer::new(new_decoder()),
            counters: LinkCounters::default(),
            buf: [0; 512],
            taps: SerialTaps::default(),
        })
    }

    /// Hands the frames decoded (received) and the bytes the decoder skipped to `taps` from now
    /// on, as [`SerialLink::set_taps`](crate::SerialLink::set_taps) does on the host side; what
    /// the device writes is its own to record ([`SerialTaps::sent`]), as it alone knows where its
    /// frames start.
    pub fn set_taps(&mut self, taps: SerialTaps) {
        self.taps = taps;
    }

    /// The path a host opens: the symlink if configured, else the pseudo-terminal.
    pub fn path(&self) -> &Path {
        self.link.as_deref().unwrap_or(&self.slave_path)
    }

    /// The current pseudo-terminal's device path.
    pub fn pty_path(&self) -> &Path {
        &self.slave_path
    }

    /// Whether the line is plugged in (not hung up).
    pub fn is_plugged_in(&self) -> bool {
        self.pty.is_some()
    }

    /// Waits up to `timeout` for bytes from the host, then hands every frame they complete to
    /// `on_frame`; returns the number of bytes read (0 on timeout, while hung up, or while no
    /// host has the line open). Never blocks longer than `timeout`.
    pub fn receive(&mut self, timeout: Duration, mut on_frame: impl FnMut(D::Frame)) -> io::Result<usize> {
        let Some(pty) = &self.pty else {
            std::thread::sleep(timeout);
            return Ok(0);
        };
        let n = match pty.read_timeout(&mut self.buf, timeout) {
            Ok(n) => n,
            // EIO: no host has the slave open at the moment; wait for one.
            Err(e) if e.raw_os_error() == Some(rustix::io::Errno::IO.raw_os_error()) => {
                std::thread::sleep(timeout);
                0
            }
            Err(e) => return Err(e),
        };
        self.counters.bytes_read += n as u64;
        let taps = &self.taps;
        if taps.is_empty() {
            self.rx.push_all(&self.buf[..n], &mut on_frame);
        } else {
            self.rx.push_all_seen(&self.buf[..n], |c| taps.received(c), &mut on_frame);
        }
        Ok(n)
    }

    /// Writes bytes for the host to read (whole frames, noise), waiting up to `timeout` in all
    /// for room. An error while hung up.
    pub fn send(&mut self, bytes: &[u8], timeout: Duration) -> io::Result<()> {
        let pty =
            self.pty.as_ref().ok_or_else(|| io::Error::new(io::ErrorKind::NotConnected, "the line is hung up"))?;
        pty.write_all(bytes, timeout)?;
        self.counters.bytes_written += bytes.len() as u64;
        self.counters.frames_written += 1;
        Ok(())
    }

    /// Hangs the line up, like an unplugged adapter: the host's reads fail at once.
    pub fn hang_up(&mut self) {
        self.pty = None;
    }

    /// Plugs a new pseudo-terminal in (one opened with [`Pty::open`], possibly on another
    /// thread), points the symlink at it, and starts a fresh decoder. Counters carry on; the
    /// decoder's are those of the current line.
    pub fn plug_in(&mut self, pty: Pty) -> io::Result<()> {
        if let Some(link) = &self.link {
            point_link(link, pty.slave_path())?;
        }
        self.slave_path = pty.slave_path().to_path_buf();
        self.pty = Some(pty);
        self.rx = FrameBuffer::new((self.new_decoder)());
        self.counters.reopens += 1;
        Ok(())
    }

    /// Bytes, frames and the current line's decoder counters.
    pub fn counters(&self) -> LinkCounters {
        LinkCounters { decoder: self.rx.counters(), ..self.counters }
    }
}

impl<D: StreamDecoder> Drop for PtyDevice<D> {
    fn drop(&mut self) {
        if let Some(link) = &self.link {
            let _ = std::fs::remove_file(link);
        }
    }
}

/// Makes `link` a symlink to `target`, replacing what was there.
fn point_link(link: &Path, target: &Path) -> io::Result<()> {
    match std::fs::remove_file(link) {
        Ok(()) => {}
        Err(e) if e.kind() == io::ErrorKind::NotFound => {}
        Err(e) => return Err(e),
    }
    std::os::unix::fs::symlink(target, link)
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

    #[test]
    fn unread_counts_what_the_client_has_not_read_yet() {
        let pty = Pty::open().unwrap();
        let mut client = std::fs::OpenOptions::new().read(true).open(pty.slave_path()).unwrap();
        assert_eq!(pty.unread().unwrap(), 0);
        pty.write_all(&[1, 2, 3, 4, 5], Duration::from_secs(5)).unwrap();
        // The kernel moves the bytes to the client's side on its own time: waited for, bounded.
        let deadline = Instant::now() + Duration::from_secs(5);
        while pty.unread().unwrap() < 5 {
            assert!(Instant::now() < deadline, "the bytes never reached the client's side");
            std::thread::yield_now();
        }
        let mut two = [0u8; 2];
        client.read_exact(&mut two).unwrap();
        assert_eq!(pty.unread().unwrap(), 3);
        let mut rest = [0u8; 3];
        client.read_exact(&mut rest).unwrap();
        assert_eq!(pty.unread().unwrap(), 0);
    }
}
