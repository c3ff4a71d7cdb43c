//! The receive side of the low-level client: `rt/lowstate` as robowire-rt's receive loop drives
//! it, with states lost or late counted by their `tick`.

use std::sync::Arc;

use robowire_dds::Reader;
use robowire_rt::Time;
use robowire_rt::device::{Receive, Received};
use robowire_rt::stats::Counter;
use unitree_proto::robot::Robot;

/// What the receive loop counts beyond the feed.
#[derive(Debug, Default)]
pub(crate) struct TickCounters {
    pub(crate) lost_by_tick: Counter,
    pub(crate) late_by_tick: Counter,
}

/// `rt/lowstate` as robowire-rt's receive loop drives it.
pub(crate) struct StateReceiver<R: Robot> {
    pub(crate) reader: Reader<R::State>,
    pub(crate) ticks: Ticks,
    pub(crate) counters: Arc<TickCounters>,
}

impl<R: Robot> Receive for StateReceiver<R>
where
    R::State: Send + Sync,
{
    type Item = R::State;
    type State = R::State;

    async fn receive(&mut self) -> Received<R::State> {
        match self.reader.recv().await {
            Ok(sample) => Received::Item(sample.value),
            Err(_) => Received::Closed,
        }
    }

    fn on_item(&mut self, _: Time, state: R::State) -> Option<R::State> {
        let (lost, late) = self.ticks.on(R::tick(&state));
        self.counters.lost_by_tick.add(lost);
        self.counters.late_by_tick.add(late);
        Some(state)
    }
}

/// Tick bookkeeping: the usual step is the smallest positive one seen.
#[derive(Default)]
pub(crate) struct Ticks {
    last: Option<u32>,
    step: Option<u32>,
}

impl Ticks {
    /// `(lost, late)` implied by `tick`.
    fn on(&mut self, tick: u32) -> (u64, u64) {
        let Some(last) = self.last.replace(tick) else { return (0, 0) };
        let delta = tick.wrapping_sub(last);
        if delta == 0 || delta > u32::MAX / 2 {
            return (0, 1);
        }
        let step = *self.step.get_or_insert(delta);
        self.step = Some(step.min(delta));
        let step = step.min(delta);
        (u64::from(delta / step).saturating_sub(1), 0)
    }
}

#[cfg(test)]
mod tests {
    use super::Ticks;

    #[test]
    fn ticks_count_gaps_and_reorders() {
        let mut t = Ticks::default();
        assert_eq!(t.on(10), (0, 0));
        assert_eq!(t.on(12), (0, 0));
        assert_eq!(t.on(14), (0, 0));
        assert_eq!(t.on(20), (2, 0), "16 and 18 missing");
        assert_eq!(t.on(20), (0, 1), "not after the previous");
        assert_eq!(t.on(22), (0, 0));
    }
}
