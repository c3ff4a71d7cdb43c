//! The KMC chassis checks: pure functions of a [`KmcObservation`].

use std::ops::RangeInclusive;
use std::path::PathBuf;

use crate::check::Check;

/// The battery voltages taken as healthy: a 6S pack, 3.5–4.25 V a cell.
pub const BATTERY_VOLTS: RangeInclusive<f32> = 21.0..=25.5;
/// The share of skipped bytes above which the line is noisy.
pub const NOISE_SHARE: f64 = 0.05;

/// Why the port could not be opened.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum OpenFailure {
    /// No such file.
    Missing,
    /// Not allowed: the port's group (by name where known) and mode bits.
    Denied {
        /// The group owning the port.
        group: Option<String>,
        /// Its permission bits.
        mode: u32,
    },
    /// Another error.
    Other(String),
}

/// What the port showed (`diagnose` reads it with a serial link).
#[derive(Debug, Clone, PartialEq)]
pub struct KmcObservation {
    /// The port.
    pub path: PathBuf,
    /// Whether it opened.
    pub open: Result<(), OpenFailure>,
    /// How long it was read, seconds.
    pub seconds: f64,
    /// Requests sent (speed and battery).
    pub requests: u64,
    /// Frames that decoded.
    pub frames: u64,
    /// Bytes read.
    pub bytes_read: u64,
    /// Bytes the decoder skipped (noise, broken frames).
    pub skipped_bytes: u64,
    /// The battery voltage last reported.
    pub battery_volts: Option<f32>,
}

/// The KMC checks, in order; after a port that does not open, no other.
pub fn checks(seen: &KmcObservation) -> Vec<Check> {
    let path = seen.path.display();
    match &seen.open {
        Err(OpenFailure::Missing) => {
            return vec![Check::fail(
                "serial port",
                format!("{path} does not exist"),
                "plug in the chassis' USB-serial adapter and name its port (ls /dev/ttyUSB* /dev/ttyACM* /dev/serial/by-id/)",
            )];
        }
        Err(OpenFailure::Denied { group, mode }) => {
            let group = group.clone().unwrap_or_else(|| "the port's group".into());
            return vec![Check::fail(
                "serial port",
                format!("{path}: permission denied (group {group}, mode {mode:o})"),
                format!("sudo usermod -aG {group} $USER, then log in again"),
            )];
        }
        Err(OpenFailure::Other(why)) => {
            return vec![Check::fail(
                "serial port",
                format!("{path}: {why}"),
                "check the adapter (dmesg shows why it failed)",
            )];
        }
        Ok(()) => {}
    }
    let mut out = vec![Check::pass("serial port", format!("{path} opens"))];
    out.push(if seen.frames > 0 {
        Check::pass(
            "KMC frames",
            format!("{} frames decoded for {} requests in {:.1} s", seen.frames, seen.requests, seen.seconds),
        )
    } else {
        Check::fail(
            "KMC frames",
            format!(
                "no frame decoded for {} requests in {:.1} s ({} bytes read)",
                seen.requests, seen.seconds, seen.bytes_read
            ),
            "check that the chassis is on and cabled TX to RX, at 115200 baud 8N1 with RTS/CTS",
        )
    });
    let share = if seen.bytes_read == 0 { 0.0 } else { seen.skipped_bytes as f64 / seen.bytes_read as f64 };
    let saw = format!("{:.1}% of {} bytes skipped", 100.0 * share, seen.bytes_read);
    out.push(if share > NOISE_SHARE {
        Check::fail(
            "line noise",
            saw,
            "a wrong baud rate or flow control reads as noise: the chassis speaks 115200 8N1 with RTS/CTS; else check the cable and its ground",
        )
    } else {
        Check::pass("line noise", saw)
    });
    out.push(match seen.battery_volts {
        Some(v) if BATTERY_VOLTS.contains(&v) => Check::pass("battery", format!("{v:.1} V")),
        Some(v) => Check::fail(
            "battery",
            format!("{v:.1} V, outside {:.1}–{:.1} V", BATTERY_VOLTS.start(), BATTERY_VOLTS.end()),
            if v < *BATTERY_VOLTS.start() { "charge the battery" } else { "check the battery pack and its charger" },
        ),
        None => Check::unknown("battery", "no battery voltage reported"),
    });
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::check::Verdict;

    fn seen() -> KmcObservation {
        KmcObservation {
            path: "/dev/ttyUSB0".into(),
            open: Ok(()),
            seconds: 2.0,
            requests: 40,
            frames: 40,
            bytes_read: 400,
            skipped_bytes: 0,
            battery_volts: Some(25.2),
        }
    }

    fn failed(seen: &KmcObservation) -> Vec<Check> {
        checks(seen).into_iter().filter(|c| c.verdict == Verdict::Fail).collect()
    }

    #[test]
    fn a_healthy_chassis_passes() {
        assert!(failed(&seen()).is_empty());
    }

    #[test]
    fn a_missing_or_forbidden_port_says_what_to_do() {
        let missing = KmcObservation { open: Err(OpenFailure::Missing), ..seen() };
        assert_eq!(checks(&missing).len(), 1);
        let denied =
            KmcObservation { open: Err(OpenFailure::Denied { group: Some("dialout".into()), mode: 0o660 }), ..seen() };
        let failure = &failed(&denied)[0];
        assert_eq!(failure.saw, "/dev/ttyUSB0: permission denied (group dialout, mode 660)");
        assert_eq!(failure.fix.as_deref(), Some("sudo usermod -aG dialout $USER, then log in again"));
    }

    #[test]
    fn noise_silence_and_a_flat_battery_fail() {
        let noisy = KmcObservation { bytes_read: 1000, skipped_bytes: 600, ..seen() };
        assert_eq!(failed(&noisy)[0].saw, "60.0% of 1000 bytes skipped");
        let silent = KmcObservation { frames: 0, bytes_read: 0, battery_volts: None, ..seen() };
        assert_eq!(failed(&silent)[0].name, "KMC frames");
        let flat = KmcObservation { battery_volts: Some(19.0), ..seen() };
        assert_eq!(failed(&flat)[0].fix.as_deref(), Some("charge the battery"));
    }
}
