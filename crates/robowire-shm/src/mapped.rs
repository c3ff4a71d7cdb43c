//! POSIX shared-memory objects (`shm_open`), mapped read-write and shared.

use std::io;
use std::os::fd::OwnedFd;

use memmap2::MmapOptions;
use rustix::fs::Mode;
use rustix::io::Errno;
use rustix::shm;

use crate::raw::RawRegion;

/// How a creator makes a shared-memory object.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct CreateOptions {
    /// Permission bits, applied with `fchmod` after creation so the umask cannot narrow them.
    /// Default `0o660`.
    pub mode: u32,
    /// Remove the object's name when the region is dropped. Default true.
    pub unlink_on_drop: bool,
}

impl Default for CreateOptions {
    fn default() -> Self {
        Self { mode: 0o660, unlink_on_drop: true }
    }
}

/// Who owns an object and who asked for it, for a permission error.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Ownership {
    /// The object's permission bits (`None` if they could not be read).
    pub mode: Option<u32>,
    /// The object's owner (`None` if unknown).
    pub owner_uid: Option<u32>,
    /// The object's group (`None` if unknown).
    pub owner_gid: Option<u32>,
    /// This process's effective user.
    pub uid: u32,
    /// This process's effective group.
    pub gid: u32,
}

impl std::fmt::Display for Ownership {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let or_unknown = |v: Option<u32>| v.map_or_else(|| "?".to_string(), |v| v.to_string());
        match self.mode {
            Some(mode) => write!(f, "mode {mode:04o}")?,
            None => f.write_str("mode ?")?,
        }
        write!(
            f,
            ", owner uid {} gid {}; this process runs as uid {} gid {}",
            or_unknown(self.owner_uid),
            or_unknown(self.owner_gid),
            self.uid,
            self.gid
        )
    }
}

/// Why a shared-memory object could not be opened or created.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum ShmError {
    /// No object of that name exists (its creator is not running).
    #[error("no shared-memory object {name} (is the process that creates it running?)")]
    NotFound {
        /// The object's name.
        name: String,
    },
    /// The object exists but this process may not open it (or, creating, may not take it over).
    #[error(
        "permission denied on shared-memory object {name} ({ownership}): run as its owner or in its group, \
         or have its creator grant the group read-write (mode 0660); robowire never widens permissions \
         from the client side"
    )]
    PermissionDenied {
        /// The object's name.
        name: String,
        /// The object's mode and owner, and this process's identity.
        ownership: Ownership,
    },
    /// The object is smaller than the layout it must hold.
    #[error("shared-memory object {name} is {size} bytes, {required} needed (another program's object of that name?)")]
    TooSmall {
        /// The object's name.
        name: String,
        /// Its size.
        size: u64,
        /// What the layout needs.
        required: usize,
    },
    /// Not a POSIX shared-memory name (`/name`, no further `/`).
    #[error("invalid shared-memory name {name:?}: it must be '/' followed by a name without '/'")]
    InvalidName {
        /// The name given.
        name: String,
    },
    /// Another system call failed.
    #[error("{operation} of shared-memory object {name} failed")]
    Io {
        /// The object's name.
        name: String,
        /// What was being done.
        operation: &'static str,
        /// The error.
        #[source]
        source: io::Error,
    },
}

fn check_name(name: &str) -> Result<(), ShmError> {
    let valid = name.len() > 1 && name.starts_with('/') && !name[1..].contains('/') && name.len() < 256;
    if valid { Ok(()) } else { Err(ShmError::InvalidName { name: name.to_string() }) }
}

/// The mode and owner of `/dev/shm/<name>` (where Linux keeps POSIX objects), and who we are.
fn ownership(name: &str) -> Ownership {
    let stat = rustix::fs::stat(format!("/dev/shm/{}", &name[1..])).ok();
    Ownership {
        mode: stat.as_ref().map(|s| s.st_mode & 0o7777),
        owner_uid: stat.as_ref().map(|s| s.st_uid),
        owner_gid: stat.as_ref().map(|s| s.st_gid),
        uid: rustix::process::geteuid().as_raw(),
        gid: rustix::process::getegid().as_raw(),
    }
}

fn error(name: &str, operation: &'static str, errno: Errno) -> ShmError {
    match errno {
        Errno::NOENT => ShmError::NotFound { name: name.to_string() },
        Errno::ACCESS | Errno::PERM => {
            ShmError::PermissionDenied { name: name.to_string(), ownership: ownership(name) }
        }
        other => ShmError::Io { name: name.to_string(), operation, source: other.into() },
    }
}

/// A POSIX shared-memory object (`shm_open`) mapped read-write and shared.
#[derive(Debug)]
pub struct MappedRegion {
    raw: RawRegion,
    name: String,
    unlink_on_drop: bool,
}

impl MappedRegion {
    /// Opens an existing object, read-write, never creating or resizing it. A missing object
    /// is [`ShmError::NotFound`], one this process may not open [`ShmError::PermissionDenied`],
    /// one smaller than `min_len` [`ShmError::TooSmall`]. The whole object is mapped.
    pub fn open(name: &str, min_len: usize) -> Result<Self, ShmError> {
        check_name(name)?;
        let fd = shm::open(name, shm::OFlags::RDWR, Mode::empty()).map_err(|e| error(name, "shm_open", e))?;
        let size = rustix::fs::fstat(&fd).map_err(|e| error(name, "fstat", e))?.st_size;
        let size = u64::try_from(size).unwrap_or(0);
        if size < min_len as u64 {
            return Err(ShmError::TooSmall { name: name.to_string(), size, required: min_len });
        }
        Self::map(name, fd, size as usize, false)
    }

    /// Creates (or takes over) the object with exactly `len` bytes, permissions from `options`
    /// applied explicitly, and maps it. Only a device's side (a daemon, a simulator) creates.
    pub fn create(name: &str, len: usize, options: &CreateOptions) -> Result<Self, ShmError> {
        check_name(name)?;
        let mode = Mode::from_bits_truncate(options.mode);
        let fd =
            shm::open(name, shm::OFlags::CREATE | shm::OFlags::RDWR, mode).map_err(|e| error(name, "shm_open", e))?;
        rustix::fs::fchmod(&fd, mode).map_err(|e| error(name, "fchmod", e))?;
        rustix::fs::ftruncate(&fd, len as u64).map_err(|e| error(name, "ftruncate", e))?;
        Self::map(name, fd, len, options.unlink_on_drop)
    }

    fn map(name: &str, fd: OwnedFd, len: usize, unlink_on_drop: bool) -> Result<Self, ShmError> {
        let file = std::fs::File::from(fd);
        let map = MmapOptions::new().len(len).map_raw(&file).map_err(|source| ShmError::Io {
            name: name.to_string(),
            operation: "mmap",
            source,
        })?;
        Ok(Self { raw: RawRegion::mapped(map), name: name.to_string(), unlink_on_drop })
    }

    /// The object's name.
    pub fn name(&self) -> &str {
        &self.name
    }

    /// Removes an object's name (`shm_unlink`); `Ok` if it did not exist.
    pub fn unlink(name: &str) -> Result<(), ShmError> {
        check_name(name)?;
        match shm::unlink(name) {
            Ok(()) | Err(Errno::NOENT) => Ok(()),
            Err(e) => Err(error(name, "shm_unlink", e)),
        }
    }

    pub(crate) fn raw(&self) -> &RawRegion {
        &self.raw
    }
}

impl Drop for MappedRegion {
    fn drop(&mut self) {
        if self.unlink_on_drop {
            let _ = Self::unlink(&self.name);
        }
    }
}
