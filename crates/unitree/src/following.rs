//! [`Following`]: a motion the LowCmd stream steps, seen from the caller.

use std::future::Future;
use std::sync::Arc;
use std::time::Duration;

use robowire_rt::Time;
use unitree_proto::stream::MotionState;

use crate::UnitreeError;
use crate::stream::MotionStatus;

/// A motion the LowCmd stream follows ([`LowLevel::follow`](crate::LowLevel::follow)): where it is, and a wait for its
/// end. Cheap to clone; dropping it changes nothing (the stream goes on following).
#[derive(Debug, Clone)]
pub struct Following {
    pub(crate) status: Arc<MotionStatus>,
    pub(crate) runtime: tokio::runtime::Handle,
    pub(crate) period: Duration,
}

impl Following {
    /// Where the motion is (after the client closed: [`MotionState::Damped`] unless it had
    /// reached its end).
    pub fn state(&self) -> MotionState {
        self.status.state()
    }

    /// When its first step was due, on the monotonic clock (`robowire_rt::now`; `None` before
    /// it went out). Its step at `elapsed` was due at `began + elapsed`.
    pub fn began(&self) -> Option<Time> {
        self.status.began()
    }

    /// Whether the stream is done stepping it: its end reached (its final command held), or it
    /// ended before.
    pub fn is_done(&self) -> bool {
        !matches!(self.state(), MotionState::Pending | MotionState::Moving { .. }) || self.status.is_closed()
    }

    /// Waits until its last step went out (`Ok`: the stream holds its final command from then
    /// on), or until it ended before: [`UnitreeError::MotionEnded`] (replaced, damped, a step
    /// refused), [`UnitreeError::Closed`] (the client closed). Any executor: the wait runs on the
    /// client's receive thread, which looks every stream period. The future borrows nothing.
    pub fn wait(&self) -> impl Future<Output = Result<(), UnitreeError>> + Send + 'static {
        let this = self.clone();
        async move {
            if let Some(end) = this.end() {
                return end;
            }
            let runtime = this.runtime.clone();
            crate::services::on_runtime(&runtime, async move {
                loop {
                    if let Some(end) = this.end() {
                        return end;
                    }
                    tokio::time::sleep(this.period).await;
                }
            })
            .await
        }
    }

    fn end(&self) -> Option<Result<(), UnitreeError>> {
        match self.state() {
            MotionState::Reached => Some(Ok(())),
            _ if self.status.is_closed() => Some(Err(UnitreeError::Closed)),
            MotionState::Pending | MotionState::Moving { .. } => None,
            ended => Some(Err(UnitreeError::MotionEnded(ended))),
        }
    }
}
