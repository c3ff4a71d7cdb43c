//! [`LowLevel`]: a Unitree robot's low-level interface over DDS, as Unitree's low-level
//! examples use it, with robowire's safety: validated commands, damping when the command goes
//! stale, a watchdog on the state.

use std::sync::Arc;
use std::sync::atomic::Ordering;
use std::time::{Duration, Instant};

use lowcmd_proto::api::{motion_switcher, sport, status};
use lowcmd_proto::go2::MotorCmd;
use lowcmd_proto::robot::{Go2, Robot};
use lowcmd_proto::stream::CommandStream;
use lowcmd_proto::{LowCmd, Message};
use robowire_core::schedule::{Connection, Watchdog};
use robowire_core::timing::LatenessSummary;
use robowire_dds::qos::Qos;
use robowire_dds::rpc::RpcClient;
use robowire_dds::{Participant, Reader, StatsHandle, TopicStats};
use robowire_rt::Time;
use robowire_rt::runner::{Runner, Waker};
use robowire_rt::stats::{Counter, SharedLateness, micros};
use tokio::sync::watch;
use tokio::task::JoinHandle;

use crate::stream::{StreamJob, StreamShared};
use crate::{Go2Error, LowLevelOptions};

/// One joint's command: position target, velocity target, gains, feed-forward torque.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct JointCommand {
    /// Position target, rad.
    pub q_rad: f32,
    /// Velocity target, rad/s.
    pub dq_radps: f32,
    /// Position gain, N·m/rad.
    pub kp: f32,
    /// Velocity gain, N·m·s/rad.
    pub kd: f32,
    /// Feed-forward torque, N·m.
    pub tau_nm: f32,
}

impl JointCommand {
    /// Hold `q_rad` with gains `kp`, `kd`.
    pub fn hold(q_rad: f32, kp: f32, kd: f32) -> Self {
        Self { q_rad, kp, kd, ..Self::default() }
    }
}

/// The latest state and how old it is.
#[derive(Debug, Clone, PartialEq)]
pub struct StateSnapshot<S> {
    /// The state (its CRC was verified).
    pub state: S,
    /// Time since it arrived.
    pub age: Duration,
}

/// What the client did and saw.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Go2Stats {
    /// `rt/lowcmd` writes.
    pub lowcmd: TopicStats,
    /// `rt/lowstate` samples (decode and CRC errors counted apart).
    pub lowstate: TopicStats,
    /// LowCmds the stream sent (fresh and damping).
    pub commands_sent: u64,
    /// Of those, damping.
    pub damping_sent: u64,
    /// Times a command went stale and damping took over.
    pub command_timeouts: u64,
    /// Stream ticks skipped because the thread was more than a period late.
    pub missed_ticks: u64,
    /// LowStates missing by their `tick` (gaps beyond the usual step).
    pub lost_by_tick: u64,
    /// LowStates whose `tick` was not after the previous one's.
    pub late_by_tick: u64,
    /// Watchdog timeouts.
    pub disconnects: u64,
    /// Returns to `Connected` after a timeout.
    pub reconnects: u64,
    /// Send lateness of the LowCmd stream, µs.
    pub send_lateness: LatenessSummary,
    /// Time between LowStates, µs.
    pub state_gap: LatenessSummary,
}

/// The receive side's state, shared with the user's threads.
struct StateShared<S> {
    latest: watch::Sender<Option<(Instant, S)>>,
    connection: watch::Sender<Connection>,
    lost_by_tick: Counter,
    late_by_tick: Counter,
    disconnects: Counter,
    reconnects: Counter,
    gaps: SharedLateness<1024>,
}

/// A Unitree robot's low-level interface (`R`: [`Go2`] or [`Hg`](crate::Hg)). Needs a tokio
/// runtime for its receive task; the LowCmd stream runs on its own thread. Both stop on drop,
/// after a burst of damping commands.
///
/// Nothing is sent until the first [`set_command`](Self::set_command) (or
/// [`damp`](Self::damp)); from then on the latched command goes out every 2 ms on absolute
/// deadlines, replaced by damping (kp 0, a small kd, no targets) once it is older than the
/// command timeout (100 ms), never by the last target.
///
/// ```no_run
/// # async fn demo() -> Result<(), go2::Go2Error> {
/// use go2::{JointCommand, LowLevel, LowLevelOptions, STAND_POSE_RAD};
/// let robot = LowLevel::<go2::Go2>::connect(LowLevelOptions::on(Some("eth0"), 0)).await?;
/// robot.release_sport_mode().await?; // the robot lies down, its sport mode lets go
/// let stand: [JointCommand; 12] = std::array::from_fn(|i| JointCommand::hold(STAND_POSE_RAD[i % 3], 60.0, 5.0));
/// for _ in 0..1000 {
///     robot.set_joints(&stand)?;
///     tokio::time::sleep(std::time::Duration::from_millis(2)).await;
/// }
/// robot.damp();
/// # Ok(()) }
/// ```
pub struct LowLevel<R: Robot = Go2> {
    options: LowLevelOptions,
    shared: Arc<StreamShared<R>>,
    state: Arc<StateShared<R::State>>,
    stream: Option<Runner<StreamJob<R>>>,
    waker: Waker,
    receive: JoinHandle<()>,
    lowcmd: StatsHandle,
    lowstate: StatsHandle,
    switcher: RpcClient,
    sport: RpcClient,
    _participant: Arc<Participant>,
}

impl<R: Robot> std::fmt::Debug for LowLevel<R> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("LowLevel").field("robot", &R::NAME).field("options", &self.options).finish_non_exhaustive()
    }
}

impl<R: Robot> LowLevel<R> {
    /// Joins the domain on the interface, starts the receive task and the (idle) stream.
    pub async fn connect(options: LowLevelOptions) -> Result<Self, Go2Error> {
        options.validate()?;
        let participant = Arc::new(Participant::new(options.participant.clone())?);
        let writer = participant.writer::<R::Cmd>(R::Cmd::TOPIC, Qos::WRITER)?;
        let reader = participant.reader::<R::State>(R::State::TOPIC, Qos::READER)?;
        let (lowcmd, lowstate) = (writer.stats_handle(), reader.stats_handle());
        let switcher = RpcClient::new(&participant, motion_switcher::SERVICE)?;
        let sport = RpcClient::new(&participant, sport::SERVICE)?;
        let shared = Arc::new(StreamShared::default());
        let state = Arc::new(StateShared {
            latest: watch::Sender::new(None),
            connection: watch::Sender::new(Connection::Waiting),
            lost_by_tick: Counter::default(),
            late_by_tick: Counter::default(),
            disconnects: Counter::default(),
            reconnects: Counter::default(),
            gaps: SharedLateness::new(),
        });
        let now = robowire_rt::now();
        let job = StreamJob::new(CommandStream::new(now, options.stream), writer, shared.clone());
        let stream = Runner::spawn(options.runner_options(), job)?;
        let waker = stream.waker();
        let first = now + options.state_timeout.max(crate::options::FIRST_STATE_TIMEOUT);
        let watchdog = Watchdog::waiting_until(first, options.state_timeout);
        let receive = tokio::spawn(receive::<R>(reader, state.clone(), watchdog));
        Ok(Self {
            options,
            shared,
            state,
            stream: Some(stream),
            waker,
            receive,
            lowcmd,
            lowstate,
            switcher,
            sport,
            _participant: participant,
        })
    }

    /// Releases the sport mode the way Unitree's low-level example does: CheckMode; while a
    /// mode owns the motors, sport StandDown, motion_switcher ReleaseMode, CheckMode again.
    /// Returns the ReleaseMode calls it took (0 if nothing owned the motors). A service that does
    /// not answer within the service timeout, or answers an error, is an error.
    pub async fn release_sport_mode(&self) -> Result<u32, Go2Error> {
        const MAX_ATTEMPTS: u32 = 10;
        let timeout = self.options.service_timeout;
        let mut attempts = 0;
        loop {
            let answer = self.switcher.call(motion_switcher::CHECK_MODE, "{}", timeout).await?;
            check_code(motion_switcher::SERVICE, motion_switcher::CHECK_MODE, answer.code)?;
            let unexpected = || Go2Error::Unexpected { service: motion_switcher::SERVICE, data: answer.data.clone() };
            let mode = motion_switcher::mode_name(&answer.data).ok_or_else(unexpected)?;
            if mode.is_empty() {
                return Ok(attempts);
            }
            if attempts == MAX_ATTEMPTS {
                return Err(Go2Error::NotReleased { mode: mode.into(), attempts });
            }
            let down = self.sport.call(sport::STAND_DOWN, "{}", timeout).await?;
            check_code(sport::SERVICE, sport::STAND_DOWN, down.code)?;
            let release = self.switcher.call(motion_switcher::RELEASE_MODE, "{}", timeout).await?;
            check_code(motion_switcher::SERVICE, motion_switcher::RELEASE_MODE, release.code)?;
            attempts += 1;
        }
    }

    /// The sport mode owning the motors (empty: none), as CheckMode reports it.
    pub async fn sport_mode(&self) -> Result<String, Go2Error> {
        let answer = self.switcher.call(motion_switcher::CHECK_MODE, "{}", self.options.service_timeout).await?;
        check_code(motion_switcher::SERVICE, motion_switcher::CHECK_MODE, answer.code)?;
        motion_switcher::mode_name(&answer.data)
            .map(str::to_owned)
            .ok_or(Go2Error::Unexpected { service: motion_switcher::SERVICE, data: answer.data })
    }

    /// Latches `command` if the robot's rules allow it (NaN, infinities, gains, torques, the
    /// Go2's joint limits): streamed from the next tick on. On error nothing changes.
    pub fn set_command(&self, command: R::Cmd) -> Result<(), Go2Error> {
        R::check(&command)?;
        self.shared.commands.write(robowire_rt::now(), &command);
        self.waker.wake();
        Ok(())
    }

    /// Damping from the next tick on, until the next command.
    pub fn damp(&self) {
        self.shared.damp_at.store(robowire_rt::now().as_nanos(), Ordering::Release);
        self.waker.wake();
    }

    /// The latest state and its age (`None` before the first).
    pub fn state(&self) -> Option<StateSnapshot<R::State>> {
        self.state.latest.borrow().as_ref().map(|(at, state)| StateSnapshot { state: *state, age: at.elapsed() })
    }

    /// Waits up to `timeout` for a state that satisfies `accept`.
    pub async fn wait_state(&self, timeout: Duration, accept: impl Fn(&R::State) -> bool) -> Option<R::State> {
        let mut rx = self.state.latest.subscribe();
        let wait = rx.wait_for(|s| s.as_ref().is_some_and(|(_, s)| accept(s)));
        match tokio::time::timeout(timeout, wait).await {
            Ok(Ok(state)) => state.as_ref().map(|(_, s)| *s),
            _ => None,
        }
    }

    /// The connection as the watchdog sees it.
    pub fn connection(&self) -> Connection {
        *self.state.connection.borrow()
    }

    /// Connection events: `Waiting` → `Connected` → `Disconnected` → `Connected` ….
    pub fn connection_events(&self) -> watch::Receiver<Connection> {
        self.state.connection.subscribe()
    }

    /// Counters and timing.
    pub fn stats(&self) -> Go2Stats {
        let (s, st) = (&self.shared, &self.state);
        Go2Stats {
            lowcmd: self.lowcmd.get(),
            lowstate: self.lowstate.get(),
            commands_sent: s.sent.get(),
            damping_sent: s.damping.get(),
            command_timeouts: s.command_timeouts.get(),
            missed_ticks: s.missed_ticks.get(),
            lost_by_tick: st.lost_by_tick.get(),
            late_by_tick: st.late_by_tick.get(),
            disconnects: st.disconnects.get(),
            reconnects: st.reconnects.get(),
            send_lateness: s.lateness.summary(),
            state_gap: st.gaps.summary(),
        }
    }

    /// The options in force.
    pub fn options(&self) -> &LowLevelOptions {
        &self.options
    }
}

impl LowLevel<Go2> {
    /// Latches a command for the 12 joints (motor order FR, FL, RR, RL × hip, thigh, calf); the
    /// other 8 slots hold nothing.
    pub fn set_joints(&self, joints: &[JointCommand; 12]) -> Result<(), Go2Error> {
        let mut cmd = LowCmd::default();
        for (m, j) in cmd.motor_cmd.iter_mut().zip(joints) {
            *m = MotorCmd::servo(j.q_rad, j.dq_radps, j.kp, j.kd, j.tau_nm);
        }
        self.set_command(cmd)
    }

    /// Joint positions of the latest state, rad, motor order.
    pub fn joint_positions(&self) -> Option<[f32; 12]> {
        self.state().map(|s| std::array::from_fn(|i| s.state.motor_state[i].q.get()))
    }
}

impl<R: Robot> Drop for LowLevel<R> {
    fn drop(&mut self) {
        self.receive.abort();
        if let Some(stream) = self.stream.take()
            && let Some(job) = stream.stop()
        {
            // Whatever was streaming, the robot's last word from this client is damping.
            if self.shared.sent.get() > 0 {
                job.write_closing_damping(job.damping_kd());
            }
        }
    }
}

fn check_code(service: &'static str, api_id: i64, code: i32) -> Result<(), Go2Error> {
    if code == status::OK { Ok(()) } else { Err(Go2Error::Refused { service, api_id, code }) }
}

/// Tick bookkeeping: the usual step is the smallest positive one seen.
#[derive(Default)]
struct Ticks {
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

fn tokio_instant(at: Time) -> tokio::time::Instant {
    tokio::time::Instant::now() + at.saturating_duration_since(robowire_rt::now())
}

/// Receives states, runs the watchdog, keeps the latest.
async fn receive<R: Robot>(mut reader: Reader<R::State>, state: Arc<StateShared<R::State>>, mut watchdog: Watchdog) {
    let mut ticks = Ticks::default();
    let mut last: Option<Time> = None;
    loop {
        let expires = watchdog.poll_timeout();
        let timeout = async {
            match expires {
                Some(at) => tokio::time::sleep_until(tokio_instant(at)).await,
                None => std::future::pending().await,
            }
        };
        tokio::select! {
            sample = reader.recv() => {
                let Ok(sample) = sample else { return };
                let now = robowire_rt::now();
                if let Some(previous) = last.replace(now) {
                    state.gaps.record(micros(now.saturating_duration_since(previous)));
                }
                let (lost, late) = ticks.on(R::tick(&sample.value));
                state.lost_by_tick.add(lost);
                state.late_by_tick.add(late);
                // The connection first: whoever wakes on the state sees it connected.
                if watchdog.feed(now).is_some() {
                    state.reconnects.set(watchdog.counters().reconnects);
                    state.connection.send_replace(watchdog.connection());
                }
                state.latest.send_replace(Some((Instant::now(), sample.value)));
            }
            () = timeout => {
                if watchdog.poll_event(robowire_rt::now()).is_some() {
                    state.disconnects.set(watchdog.counters().disconnects);
                    state.connection.send_replace(Connection::Disconnected);
                }
            }
        }
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
