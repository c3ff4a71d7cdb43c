//! Counters and lateness summaries as Python dicts.

use pyo3::prelude::*;
use pyo3::types::PyDict;
use robowire_core::timing::LatenessSummary;
use robowire_dds::TopicStats;
use unitree::LowLevelStats;

/// `{"count", "p50_us", "p99_us", "max_us"}`.
pub(crate) fn lateness<'py>(py: Python<'py>, summary: &LatenessSummary) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    d.set_item("count", summary.count)?;
    d.set_item("p50_us", summary.p50_us)?;
    d.set_item("p99_us", summary.p99_us)?;
    d.set_item("max_us", summary.max_us)?;
    Ok(d)
}

/// A dict from `name => value` pairs.
macro_rules! dict {
    ($py:expr, { $($key:literal => $value:expr),* $(,)? }) => {{
        let d = pyo3::types::PyDict::new($py);
        $(d.set_item($key, $value)?;)*
        d
    }};
}

pub(crate) use dict;

/// A DDS topic's counters.
pub(crate) fn topic<'py>(py: Python<'py>, t: &TopicStats) -> PyResult<Bound<'py, PyDict>> {
    Ok(dict!(py, {
        "samples" => t.samples,
        "write_errors" => t.write_errors,
        "decode_errors" => t.decode_errors,
        "checksum_errors" => t.checksum_errors,
    }))
}

/// A low-level client's stats as a dict: topics, commands sent, damping, timeouts, lost states,
/// timing (µs).
pub(crate) fn low_level_stats<'py>(py: Python<'py>, s: &LowLevelStats) -> PyResult<Bound<'py, PyDict>> {
    Ok(dict!(py, {
        "lowcmd" => topic(py, &s.lowcmd)?,
        "lowstate" => topic(py, &s.lowstate)?,
        "commands_sent" => s.commands_sent,
        "damping_sent" => s.damping_sent,
        "command_timeouts" => s.command_timeouts,
        "missed_ticks" => s.missed_ticks,
        "write_drops" => s.write_drops,
        "lost_by_tick" => s.lost_by_tick,
        "late_by_tick" => s.late_by_tick,
        "disconnects" => s.disconnects,
        "reconnects" => s.reconnects,
        "send_lateness_us" => lateness(py, &s.send_lateness)?,
        "state_gap_us" => lateness(py, &s.state_gap)?,
    }))
}
