//! Links registered with one recording: each link's name and description, by the number its
//! taps stamp on their frames, and the ring those taps fill. Nothing here writes a file: a
//! recorder (`robowire-record`) drains the ring and reads the registry.

use std::sync::{Arc, Mutex};

use robowire_core::json::LinkDescription;

use crate::{Tap, TapRing};

/// Every link's name and description, by link number.
pub type LinkRegistry = Arc<Mutex<Vec<(String, &'static dyn LinkDescription)>>>;

/// Registers links with a recording: each [`link`](Self::link) a tap into the recording's ring
/// under the next link number. Clones register with the same recording; taps handed out after
/// it finished drop their frames and count them.
#[derive(Debug, Clone)]
pub struct RecordLinks {
    ring: TapRing,
    links: LinkRegistry,
    /// Put before each link's name (`kmc0/`), or empty.
    prefix: String,
}

impl RecordLinks {
    /// Links registered into `links`, their frames tapped into `ring` (a recorder's).
    pub fn new(ring: TapRing, links: LinkRegistry) -> Self {
        Self { ring, links, prefix: String::new() }
    }

    /// A tap for the link `name` (`zsl1/high_level`), whose frames `description` describes.
    pub fn link(&self, name: &str, description: &'static dyn LinkDescription) -> Tap {
        let mut links = lock(&self.links);
        links.push((format!("{}{}", self.prefix, name.trim_matches('/')), description));
        self.ring.tap(u16::try_from(links.len() - 1).unwrap_or(u16::MAX))
    }

    /// A handle that registers links under `prefix` (`kmc0`: `kmc0/kmc/serial`), for two
    /// devices whose links have the same names.
    pub fn under(&self, prefix: &str) -> RecordLinks {
        let prefix = format!("{}{}/", self.prefix, prefix.trim_matches('/'));
        RecordLinks { prefix, ..self.clone() }
    }
}

/// Two handles are equal when they register with the same recording.
impl PartialEq for RecordLinks {
    fn eq(&self, other: &Self) -> bool {
        Arc::ptr_eq(&self.links, &other.links)
    }
}

impl Eq for RecordLinks {}

/// The registry, whatever a panicking holder left in it (names are only ever pushed).
fn lock(links: &LinkRegistry) -> std::sync::MutexGuard<'_, Vec<(String, &'static dyn LinkDescription)>> {
    links.lock().unwrap_or_else(std::sync::PoisonError::into_inner)
}
