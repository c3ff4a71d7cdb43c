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
    /// A second recording every link is also registered with ([`and`](Self::and)).
    also: Option<Box<RecordLinks>>,
}

impl RecordLinks {
    /// Links registered into `links`, their frames tapped into `ring` (a recorder's).
    pub fn new(ring: TapRing, links: LinkRegistry) -> Self {
        Self { ring, links, prefix: String::new(), also: None }
    }

    /// These links registered with `other` too (a capture and a live view): each tap copies its
    /// frames into both rings.
    pub fn and(self, other: RecordLinks) -> RecordLinks {
        let also = match self.also {
            Some(also) => also.and(other),
            None => other,
        };
        RecordLinks { also: Some(Box::new(also)), ..self }
    }

    /// Either or both of two recordings' links.
    pub fn either(a: Option<RecordLinks>, b: Option<RecordLinks>) -> Option<RecordLinks> {
        match (a, b) {
            (Some(a), Some(b)) => Some(a.and(b)),
            (a, b) => a.or(b),
        }
    }

    /// A tap for the link `name` (`zsl1/high_level`), whose frames `description` describes.
    pub fn link(&self, name: &str, description: &'static dyn LinkDescription) -> Tap {
        let tap = {
            let mut links = lock(&self.links);
            links.push((format!("{}{}", self.prefix, name.trim_matches('/')), description));
            self.ring.tap(u16::try_from(links.len() - 1).unwrap_or(u16::MAX))
        };
        match &self.also {
            Some(also) => tap.and(also.link(name, description)),
            None => tap,
        }
    }

    /// A handle that registers links under `prefix` (`kmc0`: `kmc0/kmc/serial`), for two
    /// devices whose links have the same names.
    pub fn under(&self, prefix: &str) -> RecordLinks {
        let also = self.also.as_ref().map(|also| Box::new(also.under(prefix)));
        let prefix = format!("{}{}/", self.prefix, prefix.trim_matches('/'));
        RecordLinks { prefix, also, ..self.clone() }
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::Direction;

    fn names(links: &LinkRegistry) -> Vec<String> {
        lock(links).iter().map(|(name, _)| name.clone()).collect()
    }

    #[test]
    fn links_of_two_recordings_are_registered_with_both_under_their_prefix() {
        let (capture, live) = (TapRing::with_slots(8), TapRing::with_slots(8));
        let (capture_names, live_names) = (LinkRegistry::default(), LinkRegistry::default());
        // The live view already knows a link: link numbers differ between the two.
        live_names.lock().unwrap().push(("other".into(), &robowire_core::json::SKIPPED_BYTES));
        let links = RecordLinks::either(
            Some(RecordLinks::new(capture.clone(), capture_names.clone())),
            Some(RecordLinks::new(live.clone(), live_names.clone())),
        )
        .unwrap();
        let tap = links.under("kmc0").link("/kmc/serial", &robowire_core::json::SKIPPED_BYTES);
        tap.record(Direction::Sent, &[7]);
        assert_eq!(names(&capture_names), ["kmc0/kmc/serial"]);
        assert_eq!(names(&live_names), ["other", "kmc0/kmc/serial"]);
        assert_eq!(capture.pop(|f| f.link), Some(0));
        assert_eq!(live.pop(|f| f.link), Some(1));
        assert!(RecordLinks::either(None, None).is_none());
    }
}
