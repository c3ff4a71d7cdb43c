//! The KMC probe: the port opened read-write, then speed and battery requests (they move
//! nothing) every 100 ms and what comes back decoded.

use std::os::unix::fs::MetadataExt;
use std::path::Path;
use std::time::Duration;

use kmc_proto::{AfFrame, ChassisFrame, ChassisFrameDecoder, HostFrame};
use robowire_serial::{SerialLink, SerialPortOptions};

use crate::kmc::{KmcObservation, OpenFailure};

/// How often the requests go out.
const REQUEST_PERIOD: Duration = Duration::from_millis(100);

/// Why `path` does not open read-write, if it does not.
fn open_failure(path: &Path) -> Option<OpenFailure> {
    let error = std::fs::OpenOptions::new().read(true).write(true).open(path).err()?;
    Some(match error.kind() {
        std::io::ErrorKind::NotFound => OpenFailure::Missing,
        std::io::ErrorKind::PermissionDenied => {
            let meta = std::fs::metadata(path).ok();
            OpenFailure::Denied {
                group: meta.as_ref().and_then(|m| group_name(m.gid())),
                mode: meta.map_or(0, |m| m.mode() & 0o777),
            }
        }
        _ => OpenFailure::Other(error.to_string()),
    })
}

/// The name of group `gid` in `/etc/group`.
fn group_name(gid: u32) -> Option<String> {
    let groups = std::fs::read_to_string("/etc/group").ok()?;
    groups.lines().find_map(|line| {
        let mut fields = line.split(':');
        let name = fields.next()?;
        (fields.nth(1)?.parse::<u32>().ok()? == gid).then(|| name.to_owned())
    })
}

/// What the chassis on `path` answers within `timeout`.
pub(crate) fn read(path: &Path, timeout: Duration) -> KmcObservation {
    let mut seen = KmcObservation {
        path: path.to_owned(),
        open: Ok(()),
        seconds: timeout.as_secs_f64(),
        requests: 0,
        frames: 0,
        bytes_read: 0,
        skipped_bytes: 0,
        battery_volts: None,
    };
    if let Some(failure) = open_failure(path) {
        seen.open = Err(failure);
        return seen;
    }
    let runtime = match tokio::runtime::Builder::new_current_thread().enable_all().build() {
        Ok(runtime) => runtime,
        Err(e) => {
            seen.open = Err(OpenFailure::Other(format!("no runtime: {e}")));
            return seen;
        }
    };
    runtime.block_on(async {
        let mut link = match SerialLink::open(path, &SerialPortOptions::default(), ChassisFrameDecoder::new()) {
            Ok(link) => link,
            Err(e) => {
                seen.open = Err(OpenFailure::Other(robowire_devices::error_chain(&e)));
                return;
            }
        };
        let mut requests = [[0u8; 8]; 2];
        let lens = [
            HostFrame::VehicleSpeedRequest.emit(&mut requests[0]).unwrap_or(0),
            HostFrame::Af(AfFrame::battery_read(0)).emit(&mut requests[1]).unwrap_or(0),
        ];
        let deadline = tokio::time::Instant::now() + timeout;
        let mut next = tokio::time::Instant::now();
        while tokio::time::Instant::now() < deadline {
            if tokio::time::Instant::now() >= next {
                for (request, len) in requests.iter().zip(lens) {
                    if link.send(&request[..len]).await.is_ok() {
                        seen.requests += 1;
                    }
                }
                next += REQUEST_PERIOD;
            }
            match tokio::time::timeout_at(next.min(deadline), link.recv()).await {
                Ok(Ok(frame)) => {
                    seen.frames += 1;
                    if let ChassisFrame::BatteryVoltage(battery) = frame {
                        seen.battery_volts = Some(battery.volts);
                    }
                }
                Ok(Err(_)) => break,
                Err(_) => {}
            }
        }
        let counters = link.counters();
        (seen.bytes_read, seen.skipped_bytes) = (counters.bytes_read, counters.decoder.skipped_bytes);
    });
    seen
}
