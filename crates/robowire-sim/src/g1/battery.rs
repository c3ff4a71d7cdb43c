//! The G1's battery on `rt/lf/bmsstate` (HG `BmsState_`, no CRC), once a second beside
//! `rt/lowstate`, as the robot publishes it: a 13-cell pack, its state of charge falling by
//! [`DRAIN_PERCENT_PER_MIN`] from [`FULL_SOC_PERCENT`] at a constant draw of [`CURRENT_MA`].

use std::time::Duration;

use robowire_dds::Writer;
use unitree_proto::bms::HgBmsState;

/// How often the battery state goes out.
pub const PERIOD: Duration = Duration::from_secs(1);
/// The charge at boot, %.
pub const FULL_SOC_PERCENT: u8 = 90;
/// How fast the charge falls, % per minute (a G1 walks about 2 hours on a charge).
pub const DRAIN_PERCENT_PER_MIN: f32 = 0.75;
/// The current drawn, mA (negative: discharging).
pub const CURRENT_MA: i32 = -4_000;
/// Cells in the pack.
pub const CELLS: usize = 13;

/// The battery `elapsed` after boot: soc, each cell's voltage (3.6 V empty … 4.15 V full), the
/// pack voltage, current, health, temperatures.
pub fn battery_state(elapsed: Duration) -> HgBmsState {
    let drained = DRAIN_PERCENT_PER_MIN * elapsed.as_secs_f32() / 60.0;
    let soc = (f32::from(FULL_SOC_PERCENT) - drained).clamp(0.0, 100.0);
    let cell_mv = (3_600.0 + 5.5 * soc) as u16;
    let mut state = HgBmsState::default();
    state.soc = soc.round() as u8;
    state.soh = 98;
    state.current = CURRENT_MA.into();
    state.cell_vol[..CELLS].fill(cell_mv.into());
    state.bmsvoltage[0] = (u32::from(cell_mv) * CELLS as u32).into();
    state.temperature[..4].fill(31.into());
    state.cycle = 12.into();
    state
}

/// Publishes [`battery_state`] every [`PERIOD`] until dropped (a full send window drops one).
pub(super) async fn publish(writer: Writer<HgBmsState>) {
    let boot = tokio::time::Instant::now();
    let mut every = tokio::time::interval(PERIOD);
    loop {
        every.tick().await;
        let _ = writer.try_write(battery_state(boot.elapsed()));
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_13_cell_pack_draining_slowly() {
        let boot = battery_state(Duration::ZERO);
        assert_eq!(
            (boot.soc, boot.current.get(), boot.cell_vol[12].get(), boot.cell_vol[13].get()),
            (90, -4000, 4095, 0)
        );
        assert_eq!(boot.bmsvoltage[0].get(), 13 * 4095);
        let later = battery_state(Duration::from_secs(40 * 60));
        assert_eq!(later.soc, 60);
        assert!(later.cell_vol[0].get() < boot.cell_vol[0].get());
        assert_eq!(battery_state(Duration::from_secs(10 * 3600)).soc, 0, "never below empty");
    }
}
