//! [`LowLevel`]: a Unitree robot's low-level interface over DDS, as Unitree's low-level
//! examples use it, with robowire's safety: validated commands, damping when the command goes
//! stale, a watchdog on the state.

use std::sync::atomic::Ordering;
use std::sync::{Arc, Mutex};
use std::time::Duration;

use robowire_core::schedule::Watchdog;
use robowire_core::timing::LatenessSummary;
use robowire_dds::qos::Qos;
use robowire_dds::{Participant, StatsHandle, TopicStats};
use robowire_rt::Time;
use robowire_rt::device::{Device, Receiving};
use robowire_rt::runner::{Runner, RunnerOptions, Waker};
use unitree_proto::go2::MotorCmd;
use unitree_proto::robot::{Go2, Robot};
use unitree_proto::stream::{CommandStream, Motion, MotionState};
use unitree_proto::{LowCmd, Message};

use crate::following::Following;
use crate::receive::{StateReceiver, TickCounters, Ticks};
use crate::services::{ServiceHandle, Services};
use crate::stream::{Handed, MotionStatus, StreamJob, StreamShared};
use crate::{LowLevelOptions, UnitreeError};

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

/// What the client did and saw.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct LowLevelStats {
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
    /// LowCmds the middleware did not take (its send window full, or an error): dropped, counted.
    pub write_drops: u64,
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

/// A Unitree robot's low-level interface (`R`: [`Go2`] or [`Hg`](crate::Hg)): the LowCmd stream
/// on a thread of its own, `rt/lowstate` and the robot's services on a receive thread. No runtime
/// needed. Closing (or dropping) ends both after a burst of damping commands, if anything was
/// ever sent.
///
/// Nothing is sent until the first [`set_command`](Self::set_command) (or
/// [`follow`](Self::follow), [`damp`](Self::damp)); from then on the latched command goes out
/// every 2 ms on absolute deadlines, replaced by damping (kp 0, a small kd, no targets) once it
/// is older than the command timeout (100 ms), never by the last target. A motion
/// ([`follow`](Self::follow)) is stepped by the stream itself, on its own deadlines.
///
/// ```no_run
/// # async fn demo() -> Result<(), unitree::UnitreeError> {
/// use std::time::Duration;
/// use unitree::trajectory::JointTrajectory;
/// use unitree::{LowLevel, LowLevelOptions};
/// let robot = LowLevel::<unitree::Go2>::open(LowLevelOptions::on(Some("eth0"), 0))?;
/// let lying = robot.wait_state(Duration::from_secs(3), |_| true).await.expect("rt/lowstate");
/// robot.release_sport_mode().await?; // the robot lies down, its sport mode lets go
/// let from = std::array::from_fn(|i| lying.motor_state[i].q.get());
/// // Stepped every 2 ms by the stream; the stand pose held after 2 s.
/// robot.follow(JointTrajectory::stand_up(from, Duration::from_secs(2)))?.wait().await?;
/// robot.close(); // damping, then closed
/// # Ok(()) }
/// ```
pub struct LowLevel<R: Robot = Go2> {
    options: LowLevelOptions,
    shared: Arc<StreamShared<R>>,
    /// The stamp of the last input handed to the stream (command, motion, damping): callers
    /// take turns, the stream thread never takes it.
    last_input: Mutex<u64>,
    stream: Option<Runner<StreamJob<R>>>,
    waker: Waker,
    ticks: Arc<TickCounters>,
    lowcmd: StatsHandle,
    lowstate: StatsHandle,
    services: Arc<Services>,
    participant: Arc<Participant>,
    /// Dropped last: the receive thread ends after the stream's damping went out.
    receiving: Receiving<R::State>,
}

impl<R: Robot> std::fmt::Debug for LowLevel<R> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("LowLevel").field("robot", &R::NAME).field("options", &self.options).finish_non_exhaustive()
    }
}

/// What the receive thread opens and hands to the client.
struct Opened<R: Robot> {
    participant: Arc<Participant>,
    writer: robowire_dds::Writer<R::Cmd>,
    lowstate: StatsHandle,
    services: Arc<Services>,
}

impl<R: Robot> LowLevel<R>
where
    R::State: Send + Sync,
{
    /// Joins the domain on the interface, starts the receive thread and the (idle) stream.
    pub fn open(options: LowLevelOptions) -> Result<Self, UnitreeError> {
        options.validate()?;
        let now = robowire_rt::now();
        let first = now + options.state_timeout.max(crate::options::FIRST_STATE_TIMEOUT);
        let watchdog = Watchdog::waiting_until(first, options.state_timeout);
        let ticks = Arc::new(TickCounters::default());
        let name = R::NAME.to_ascii_lowercase();
        let (receiving, opened) = Receiving::spawn(&format!("{name}-receive"), watchdog, {
            let (participant_options, service_timeout, ticks) =
                (options.participant.clone(), options.service_timeout, ticks.clone());
            let (low_level_tap, services_tap) = (options.low_level_tap.clone(), options.services_tap.clone());
            move || async move {
                let participant = Arc::new(Participant::new(participant_options)?);
                // Reliable like Unitree's, but the stream thread's writes never wait.
                let mut writer = participant.writer::<R::Cmd>(R::Cmd::TOPIC, Qos::STREAM_WRITER)?;
                let mut reader = participant.reader::<R::State>(R::State::TOPIC, Qos::READER)?;
                writer.set_tap(low_level_tap.clone());
                reader.set_tap(low_level_tap);
                let lowstate = reader.stats_handle();
                // Their answers are read by tasks of this thread's runtime.
                let services = Arc::new(Services::new(&participant, service_timeout, services_tap.as_ref())?);
                let link = StateReceiver::<R> { reader, ticks: Ticks::default(), counters: ticks };
                Ok::<_, UnitreeError>((link, Opened::<R> { participant, writer, lowstate, services }))
            }
        })?;
        let Opened { participant, writer, lowstate, services } = opened;
        let lowcmd = writer.stats_handle();
        let shared = Arc::new(StreamShared::default());
        let job = StreamJob::new(CommandStream::new(now, options.stream), writer, shared.clone());
        let stream = Runner::spawn(RunnerOptions::placed(format!("{name}-lowcmd"), options.placement), job)?;
        let waker = stream.waker();
        Ok(Self {
            options,
            shared,
            last_input: Mutex::new(0),
            stream: Some(stream),
            waker,
            ticks,
            lowcmd,
            lowstate,
            services,
            participant,
            receiving,
        })
    }

    /// Runs `call` on the receive thread's runtime (where the services' answers arrive) and waits
    /// for its outcome, on any executor.
    async fn on_device<T, F>(&self, call: impl FnOnce(Arc<Services>) -> F + Send + 'static) -> Result<T, UnitreeError>
    where
        T: Send + 'static,
        F: Future<Output = Result<T, UnitreeError>> + Send + 'static,
    {
        let services = self.services.clone();
        crate::services::on_runtime(self.receiving.runtime(), async move { call(services).await }).await
    }

    /// Releases the sport mode the way Unitree's low-level example does: CheckMode; while a
    /// mode owns the motors, sport StandDown, motion_switcher ReleaseMode, CheckMode again.
    /// Returns the ReleaseMode calls it took (0 if nothing owned the motors). A service that does
    /// not answer within the service timeout, or answers an error, is an error. Any executor.
    pub async fn release_sport_mode(&self) -> Result<u32, UnitreeError> {
        self.on_device(|services| async move { services.release(true).await }).await
    }

    /// Releases the mode owning the motors the way Unitree's G1 and H1 low-level examples do,
    /// through `motion_switcher` alone: CheckMode; while a mode owns the motors, ReleaseMode,
    /// CheckMode again (at most [`RELEASE_ATTEMPTS`](crate::services::RELEASE_ATTEMPTS)
    /// ReleaseModes, then [`UnitreeError::NotReleased`]). Returns the ReleaseMode calls it took (0 if
    /// nothing owned the motors). Errors as [`release_sport_mode`](Self::release_sport_mode). Any
    /// executor.
    pub async fn release_mode(&self) -> Result<u32, UnitreeError> {
        self.on_device(|services| async move { services.release(false).await }).await
    }

    /// motion_switcher SelectMode `name`: the robot's controller of that name (a name CheckMode
    /// reported before the release) owns the motors again and ignores LowCmds. Any executor.
    pub async fn select_mode(&self, name: &str) -> Result<(), UnitreeError> {
        let name = name.to_owned();
        self.on_device(|services| async move { services.select_mode(&name).await }).await
    }

    /// A client of the robot's service `service` on this client's participant, called from any
    /// executor (its calls run on the receive thread), with the service timeout and the services
    /// tap of the options.
    pub fn service(&self, service: &'static str) -> Result<ServiceHandle, UnitreeError> {
        let (runtime, timeout) = (self.receiving.runtime(), self.options.service_timeout);
        Ok(ServiceHandle::new(&self.participant, service, runtime, timeout, self.options.services_tap.clone())?)
    }

    /// The client's DDS participant, for writers and readers of the robot's other topics.
    pub fn participant(&self) -> &Arc<Participant> {
        &self.participant
    }

    /// The latest command latched by [`set_command`](Self::set_command) (`None` before the first).
    pub fn latched(&self) -> Option<R::Cmd> {
        self.shared.commands.read().map(|(_, command)| command)
    }

    /// The sport mode owning the motors (empty: none), as CheckMode reports it. Any executor.
    pub async fn sport_mode(&self) -> Result<String, UnitreeError> {
        self.on_device(|services| async move { services.sport_mode().await }).await
    }

    /// Latches `command` if the robot's rules allow it (NaN, infinities, gains, torques, the
    /// Go2's joint limits): streamed from the next tick on, replacing a motion being followed.
    /// On error nothing changes.
    pub fn set_command(&self, command: R::Cmd) -> Result<(), UnitreeError> {
        R::check(&command)?;
        self.hand_over(|at| {
            self.shared.commands.write(at, &command);
        });
        Ok(())
    }

    /// Hands `motion` to the LowCmd stream, which steps it on its own grid: at each of its
    /// deadlines it sends `motion.command_at(elapsed)`, `elapsed` the time from the motion's
    /// first tick to this one (0, one period, two, …, as the stream's clock has it), up to
    /// `motion.duration()`; from then on it holds that last command, never stale (it is the
    /// stream's own), until the next [`set_command`](Self::set_command) or `follow` (which
    /// replace it) or [`damp`](Self::damp) (which ends it). [`close`](Self::close) and drop damp
    /// as always. No loop on the caller's side: await [`Following::wait`].
    ///
    /// The robot's rules: the first and the last steps are checked here, and a refusal returns
    /// the error with nothing changed and nothing sent (for a move between two poses at fixed
    /// gains, as [`JointTrajectory`](crate::trajectory::JointTrajectory), that covers every
    /// step); the stream checks every step again, and a step refused there ends the motion in
    /// damping ([`MotionState::Refused`]), without a panic. The motion is boxed here; the stream
    /// thread neither allocates nor frees (a replaced motion is dropped by a later call).
    pub fn follow(&self, motion: impl Motion<R::Cmd> + Send + 'static) -> Result<Following, UnitreeError> {
        for elapsed in [Duration::ZERO, motion.duration()] {
            R::check(&motion.command_at(elapsed)?)?;
        }
        // Motions the stream let go, dropped here rather than on its thread.
        while self.shared.retired.pop().is_some() {}
        let status = Arc::new(MotionStatus::default());
        let handed = Handed { motion: Box::new(motion), status: status.clone() };
        // A motion handed over before and not taken yet is overtaken by this one.
        if let Some((_, overtaken)) = self.hand_over(|at| self.shared.motions.force_push((at, handed))) {
            overtaken.status.publish(MotionState::Replaced, None);
        }
        let (runtime, period) = (self.receiving.runtime().clone(), self.options.stream.period);
        Ok(Following { status, runtime, period })
    }

    /// Damping from the next tick on, until the next command or motion; ends a motion being
    /// followed.
    pub fn damp(&self) {
        self.hand_over(|at| self.shared.damp_at.store(at.as_nanos(), Ordering::Release));
    }

    /// Hands an input over, stamped after every earlier one, and wakes the stream.
    fn hand_over<T>(&self, publish: impl FnOnce(Time) -> T) -> T {
        let published = {
            let mut last = robowire_rt::lock(&self.last_input);
            *last = robowire_rt::now().as_nanos().max(*last + 1);
            publish(Time::from_nanos(*last))
        };
        self.waker.wake();
        published
    }

    /// Waits up to `timeout` for a state that satisfies `accept` (the latest counts). Any
    /// executor.
    pub async fn wait_state(
        &self,
        timeout: Duration,
        accept: impl Fn(&R::State) -> bool + Send + Sync + 'static,
    ) -> Option<R::State> {
        self.receiving.wait_for(timeout, accept).await.map(|s| s.state)
    }

    /// The options in force.
    pub fn options(&self) -> &LowLevelOptions {
        &self.options
    }

    /// Damping (if anything was sent), then both threads end and the participant leaves.
    /// Dropping the client does the same.
    pub fn close(self) {
        drop(self);
    }
}

impl<R: Robot> Device for LowLevel<R>
where
    R::State: Send + Sync,
{
    type State = R::State;
    type Stats = LowLevelStats;
    type Error = std::convert::Infallible;

    fn receiving(&self) -> &Receiving<R::State> {
        &self.receiving
    }

    /// Counters and timing.
    fn stats(&self) -> LowLevelStats {
        let s = &self.shared;
        let feed = self.receiving.stats();
        LowLevelStats {
            lowcmd: self.lowcmd.get(),
            lowstate: self.lowstate.get(),
            commands_sent: s.sent.get(),
            damping_sent: s.damping.get(),
            command_timeouts: s.command_timeouts.get(),
            missed_ticks: s.missed_ticks.get(),
            write_drops: s.write_errors.get(),
            lost_by_tick: self.ticks.lost_by_tick.get(),
            late_by_tick: self.ticks.late_by_tick.get(),
            disconnects: feed.disconnects,
            reconnects: feed.reconnects,
            send_lateness: s.lateness.summary(),
            state_gap: feed.state_gap,
        }
    }

    fn close(self) -> Result<(), std::convert::Infallible> {
        drop(self);
        Ok(())
    }
}

impl LowLevel<Go2> {
    /// Latches a command for the 12 joints (motor order FR, FL, RR, RL × hip, thigh, calf); the
    /// other 8 slots hold nothing.
    pub fn set_joints(&self, joints: &[JointCommand; 12]) -> Result<(), UnitreeError> {
        self.set_command(go2_command(joints))
    }

    /// Joint positions of the latest state, rad, motor order.
    pub fn joint_positions(&self) -> Option<[f32; 12]> {
        self.latest().map(|s| std::array::from_fn(|i| s.state.motor_state[i].q.get()))
    }
}

/// The Go2's command for its 12 joints (motor order); the other 8 slots hold nothing.
pub(crate) fn go2_command(joints: &[JointCommand; 12]) -> LowCmd {
    let mut cmd = LowCmd::default();
    for (m, j) in cmd.motor_cmd.iter_mut().zip(joints) {
        *m = MotorCmd::servo(j.q_rad, j.dq_radps, j.kp, j.kd, j.tau_nm);
    }
    cmd
}

impl<R: Robot> Drop for LowLevel<R> {
    fn drop(&mut self) {
        if let Some(stream) = self.stream.take()
            && let Some(job) = stream.stop()
        {
            // Whatever was streaming, the robot's last word from this client is damping.
            if self.shared.sent.get() > 0 {
                job.write_closing_damping(job.damping_kd());
            }
            job.close_motions();
        }
    }
}
