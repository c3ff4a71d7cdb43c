//! What reading a capture back knows: every link description, and the links' names across
//! devices' renames.

use robowire_record::LinkDescription;

/// Every link description the CLI knows, one list from each codec, and the bytes a serial link's
/// decoder skipped: what reading a capture back (`robowire replay`, `robowire decode --mcap`)
/// understands.
pub(crate) fn descriptions() -> Vec<&'static dyn LinkDescription> {
    [
        &zsl_proto::description::DESCRIPTIONS[..],
        &kmc_proto::description::DESCRIPTIONS,
        &unitree_proto::description::DESCRIPTIONS,
        &ros2_proto::description::DESCRIPTIONS,
        &[&robowire_core::json::SKIPPED_BYTES, &robowire_policy::record::POLICY],
    ]
    .concat()
}

/// What each codec plots of its links (`robowire plot`, the live page).
pub(crate) fn link_plots() -> Vec<&'static robowire_core::json::LinkPlots> {
    let lists: [&'static [robowire_core::json::LinkPlots]; 4] = [
        &kmc_proto::description::PLOTS,
        &zsl_proto::description::PLOTS,
        &unitree_proto::description::PLOTS,
        &robowire_policy::record::PLOTS,
    ];
    lists.into_iter().flatten().collect()
}

/// Devices whose links were recorded under another name: the ZSL-1's were `dog/…` before they
/// were `zsl1/…`. Such a capture still reads (kept for one release, as the `dog` command alias):
/// its links belong to the device's current name, and a link asked for under either name is
/// found.
const OLD_DEVICE_NAMES: [(&str, &str); 1] = [("dog", "zsl1")];

/// A device's current name (`dog`: `zsl1`; any other name: itself).
pub(crate) fn current_device(name: &str) -> &str {
    OLD_DEVICE_NAMES.iter().find(|(old, _)| *old == name).map_or(name, |(_, new)| new)
}

/// The device a link belongs to: the first part of its name, under the device's current name
/// (`zsl1/high_level` and an old capture's `dog/high_level`: `zsl1`).
pub(crate) fn device_of(link: &str) -> &str {
    current_device(link.split('/').next().unwrap_or_default())
}

/// Whether a capture's link `recorded` is the link `asked` for, under its current or old name
/// (`dog/high_level` is `zsl1/high_level`).
pub(crate) fn same_link(recorded: &str, asked: &str) -> bool {
    fn current(link: &str) -> (&str, &str) {
        let (device, rest) = link.split_once('/').unwrap_or((link, ""));
        (current_device(device), rest)
    }
    recorded == asked || current(recorded) == current(asked)
}

#[cfg(test)]
mod tests {
    #[test]
    fn every_protocol_is_described_once() {
        let mut names: Vec<_> = super::descriptions().iter().map(|d| d.protocol()).collect();
        let count = names.len();
        names.sort_unstable();
        names.dedup();
        assert_eq!(names.len(), count, "{names:?}");
        assert!(
            names.contains(&"zsl1.high_level")
                && names.contains(&"kmc.host")
                && names.contains(&"unitree_go.low_level")
                && names.contains(&"stream.skipped")
        );
    }

    #[test]
    fn the_zsl1_links_of_an_old_capture_read_under_the_new_name() {
        use super::{current_device, device_of, same_link};
        assert_eq!(
            [device_of("dog/high_level"), device_of("zsl1/high_level"), device_of("kmc/serial")],
            ["zsl1", "zsl1", "kmc"]
        );
        assert_eq!([current_device("dog"), current_device("zsl1"), current_device("go2")], ["zsl1", "zsl1", "go2"]);
        assert!(same_link("dog/high_level", "zsl1/high_level") && same_link("zsl1/low_level", "dog/low_level"));
        assert!(same_link("kmc/serial", "kmc/serial"));
        assert!(!same_link("dog/high_level", "zsl1/low_level") && !same_link("kmc/serial", "dog/serial"));
    }
}
