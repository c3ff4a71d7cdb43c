//! [`G1`]: the Unitree G1 humanoid's low-level interface (`crate::LowLevel<Hg>`: the 500 Hz
//! `rt/lowcmd` stream, `rt/lowstate`, motion_switcher) with the G1's rules, its `rt/arm_sdk`
//! stream, and its locomotion and arm action services.

use std::sync::atomic::Ordering;
use std::sync::{Arc, Mutex};
use std::time::Duration;

use crate::trajectory::Motion;
use crate::{Device, Following, Hg, JointCommand, LowLevel, LowLevelStats};
use robowire_core::timing::LatenessSummary;
use robowire_dds::qos::Qos;
use robowire_dds::{StatsHandle, TopicStats};
use robowire_rt::device::Receiving;
use robowire_rt::runner::{Runner, RunnerOptions, Waker};
use unitree_proto::api::{g1_arm, g1_loco};
use unitree_proto::bms::HgBmsState;
use unitree_proto::g1::{self, ARM_SDK_JOINTS, ARM_SDK_TOPIC, G1Variant, JOINTS, ModePr, slot};
use unitree_proto::hg::HgMotorCmd;
use unitree_proto::robot::{CommandError, Robot};
use unitree_proto::{HgLowCmd, HgLowState};

use crate::g1::arm_job::{ArmSdkJob, ArmShared};
use crate::g1::battery::BatteryReader;
use crate::g1::{ArmActions, Battery, G1Error, G1Options, Loco};
use unitree_proto::g1::arm_stream::ArmSdkStream;

/// The joints of `rt/arm_sdk`, in [`ARM_SDK_JOINTS`] order: both arms (slots 15..29), then the
/// waist (12, 13, 14).
pub const ARM_JOINTS: usize = ARM_SDK_JOINTS.len();

/// What the client did and saw.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct G1Stats {
    /// `rt/lowcmd`, `rt/lowstate`, the LowCmd stream, the watchdog.
    pub low_level: LowLevelStats,
    /// `rt/arm_sdk` writes.
    pub arm_sdk: TopicStats,
    /// `rt/arm_sdk` frames the arm stream sent.
    pub arm_sdk_sent: u64,
    /// Times the arm command went stale and its weight was ramped out.
    pub arm_sdk_command_timeouts: u64,
    /// Arm stream ticks skipped because its thread was more than a period late.
    pub arm_sdk_missed_ticks: u64,
    /// Arm frames the middleware did not take (send window full, or an error): dropped, counted.
    pub arm_sdk_write_drops: u64,
    /// The weight of the last arm frame, 0..=1.
    pub arm_sdk_weight: f32,
    /// Send lateness of the arm stream, µs.
    pub arm_sdk_send_lateness: LatenessSummary,
    /// `rt/lf/bmsstate` samples (decode errors counted apart).
    pub bmsstate: TopicStats,
}

/// A Unitree G1 over DDS, on robowire's one device shape ([`Device`]: the latest
/// [`HgLowState`] with its age, connection events, stats, close). No runtime needed; the async
/// calls run on any executor.
///
/// - Nothing is sent on `rt/lowcmd` before the robot's first LowState: its `mode_machine` is
///   copied into every command (the robot ignores a LowCmd without it), and a command before it
///   is [`CommandError::NoModeMachine`]. Every command is checked by
///   [`unitree_proto::g1::check_low_cmd`] against the robot's `mode_machine` and the
///   [variant](Self::variant) before it is latched; the latched command streams at 500 Hz and
///   becomes damping (with the same `mode_machine`) 100 ms after the last one.
/// - `rt/arm_sdk` streams at 50 Hz from the first [`set_arm_joints`](Self::set_arm_joints): its
///   weight ramped toward [`set_arm_weight`](Self::set_arm_weight)'s target (0.5/s by default),
///   ramped to 0 when no arm command came for `arm_sdk.command_timeout` (500 ms), idle at weight
///   0 (see [`unitree_proto::g1::arm_stream`]).
/// - Closing (or dropping): the arm weight ramps to 0 first (at most 2 s from weight 1, one
///   frame of weight 0 last), then the LowCmd stream's damping burst (if anything was sent),
///   then both threads end.
pub struct G1 {
    options: G1Options,
    arm_stream: Option<Runner<ArmSdkJob>>,
    arm_waker: Waker,
    arm_shared: Arc<ArmShared>,
    arm_sdk: StatsHandle,
    /// The last arm command set (caller side only; the stream reads `arm_shared`).
    arm_targets: Mutex<Option<HgLowCmd>>,
    loco: Loco,
    arm: ArmActions,
    battery: BatteryReader,
    /// Dropped after the arm stream ended.
    low: LowLevel<Hg>,
}

impl std::fmt::Debug for G1 {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("G1").field("options", &self.options).finish_non_exhaustive()
    }
}

impl G1 {
    /// Joins the domain on the interface; starts the receive thread, the idle LowCmd stream and
    /// the idle `rt/arm_sdk` stream; makes the `sport` (locomotion) and `arm` service clients.
    pub fn open(options: G1Options) -> Result<Self, G1Error> {
        options.validate()?;
        let low = LowLevel::<Hg>::open(options.low_level.clone())?;
        // Reliable like Unitree's, but the arm stream's writes never wait.
        let mut writer = low.participant().writer::<HgLowCmd>(ARM_SDK_TOPIC, Qos::STREAM_WRITER)?;
        writer.set_tap(options.arm_sdk_tap.clone());
        let arm_sdk = writer.stats_handle();
        let arm_shared = Arc::new(ArmShared::default());
        let job = ArmSdkJob::new(ArmSdkStream::new(options.arm_sdk), writer, arm_shared.clone());
        let arm_stream = Runner::spawn(RunnerOptions::placed("g1-arm-sdk", options.low_level.placement), job)?;
        let arm_waker = arm_stream.waker();
        let loco = Loco::new(low.service(g1_loco::SERVICE)?);
        let arm = ArmActions::new(low.service(g1_arm::SERVICE)?);
        let battery = BatteryReader::spawn(low.participant(), low.receiving().runtime())?;
        Ok(Self {
            options,
            arm_stream: Some(arm_stream),
            arm_waker,
            arm_shared,
            arm_sdk,
            arm_targets: Mutex::new(None),
            loco,
            arm,
            battery,
            low,
        })
    }

    /// Releases the robot's controller as Unitree's G1 low-level example does, through
    /// motion_switcher alone (no sport StandDown: the G1's `sport` is its locomotion service):
    /// CheckMode; while a mode is reported, ReleaseMode, CheckMode again; at most
    /// [`crate::services::RELEASE_ATTEMPTS`] ReleaseModes, then [`crate::UnitreeError::NotReleased`].
    /// Returns the ReleaseMode calls it took. Afterwards the locomotion service refuses with
    /// [`G1Error::LocoStateUnavailable`] until [`select_mode`](Self::select_mode).
    pub async fn release(&self) -> Result<u32, G1Error> {
        Ok(self.low.release_mode().await?)
    }

    /// The mode owning the motors as CheckMode reports it (empty: released).
    pub async fn mode(&self) -> Result<String, G1Error> {
        Ok(self.low.sport_mode().await?)
    }

    /// SelectMode `name` (a name [`mode`](Self::mode) reported before the release): the robot's
    /// controller takes the motors back (it ignores LowCmds from then on) and the locomotion
    /// service answers again.
    pub async fn select_mode(&self, name: &str) -> Result<(), G1Error> {
        Ok(self.low.select_mode(name).await?)
    }

    /// The robot's `mode_machine`, from its latest LowState (`None` before the first).
    pub fn mode_machine(&self) -> Option<u8> {
        self.low.latest().map(|s| s.state.mode_machine)
    }

    /// Which G1 this is: the option if set; otherwise what the LowState's `mode_machine` names
    /// ([`G1Variant::of_mode_machine`]), and [`G1Variant::Dof29`] for a value not in Unitree's
    /// table (0 from a simulator included: its commands are checked as for a 29-dof G1). `None`
    /// without the option before the first LowState.
    pub fn variant(&self) -> Option<G1Variant> {
        self.mode_machine().map(|m| self.options.variant_of(m)).or(self.options.variant)
    }

    /// The robot's `mode_machine` and variant, or [`CommandError::NoModeMachine`].
    fn machine(&self) -> Result<(u8, G1Variant), CommandError> {
        let mode_machine = self.mode_machine().ok_or(CommandError::NoModeMachine)?;
        Ok((mode_machine, self.options.variant_of(mode_machine)))
    }

    /// Latches `command` for `rt/lowcmd` if [`unitree_proto::g1::check_low_cmd`] allows it for
    /// the robot's `mode_machine` and variant: streamed from the next tick on. On error nothing
    /// changes and nothing is sent.
    pub fn set_command(&self, command: HgLowCmd) -> Result<(), G1Error> {
        g1::check_low_cmd(&command, self.mode_machine(), self.variant().unwrap_or(G1Variant::Dof29))?;
        Ok(self.low.set_command(command)?)
    }

    /// Latches a command for the 29 joint slots (position rad, velocity rad/s, gains, torque
    /// N·m; slot order of [`unitree_proto::g1::JOINT_NAMES`]): PR mode, `mode` 1 on every joint
    /// the variant drives, the robot's `mode_machine`. A slot the variant does not drive must be
    /// left at `JointCommand::default()` ([`CommandError::UndrivenMotor`] otherwise).
    pub fn set_joints(&self, joints: &[JointCommand; JOINTS]) -> Result<(), G1Error> {
        let (mode_machine, variant) = self.machine()?;
        let mut command = HgLowCmd::default();
        command.mode_pr = ModePr::Pr as u8;
        command.mode_machine = mode_machine;
        for (slot, (m, j)) in command.motor_cmd.iter_mut().zip(joints).enumerate() {
            if variant.drives(slot) {
                *m = HgMotorCmd::servo(j.q_rad, j.dq_radps, j.kp, j.kd, j.tau_nm);
            } else if *j != JointCommand::default() {
                return Err(CommandError::UndrivenMotor { motor: slot }.into());
            }
        }
        self.set_command(command)
    }

    /// Hands `motion` to the `rt/lowcmd` stream, which steps it on its own grid and holds its
    /// final command ([`LowLevel::follow`]: no loop on the caller's side; await
    /// [`Following::wait`]). Its commands carry the robot's `mode_machine`, as
    /// [`unitree_proto::g1::hold`] makes them; each is checked by
    /// [`unitree_proto::g1::check_low_cmd`] for the robot's `mode_machine` and variant as they
    /// are now: the first and the last steps here (a refusal changes nothing and sends nothing),
    /// every step again on the stream (a refused one ends the motion in damping).
    /// [`set_command`](Self::set_command), [`set_joints`](Self::set_joints),
    /// [`hold`](Self::hold) or another `follow` replace it; [`damp`](Self::damp) ends it.
    /// [`CommandError::NoModeMachine`] before the first LowState.
    pub fn follow(&self, motion: impl Motion<HgLowCmd> + Send + 'static) -> Result<Following, G1Error> {
        let (mode_machine, variant) = self.machine()?;
        Ok(self.low.follow(G1Rules { motion, mode_machine, variant })?)
    }

    /// Holds `q_rad` (by slot, rad) with the gains of Unitree's G1 low-level example
    /// ([`unitree_proto::g1::DEFAULT_GAINS`]) on every joint the variant drives.
    pub fn hold(&self, q_rad: &[f32; JOINTS]) -> Result<(), G1Error> {
        let (mode_machine, variant) = self.machine()?;
        self.set_command(g1::hold(q_rad, mode_machine, variant))
    }

    /// Damping from the next tick on (kp 0, the stream's damping kd, no targets, on the joints of
    /// the last command), until the next command; with the robot's `mode_machine` even before any
    /// command was sent (damping keeps the last command's: a damping command for the robot's
    /// joints and `mode_machine` is latched first). [`CommandError::NoModeMachine`] before the
    /// first LowState.
    pub fn damp(&self) -> Result<(), G1Error> {
        let (mode_machine, variant) = self.machine()?;
        if self.low.latched().is_none_or(|c| c.mode_machine != mode_machine) {
            let joints = g1::hold(&[0.0; JOINTS], mode_machine, variant);
            self.set_command(Hg::damping(&joints, self.options.low_level.stream.damping_kd))?;
        }
        self.low.damp();
        Ok(())
    }

    /// Joint positions of the latest state, rad, by slot.
    pub fn joint_positions(&self) -> Option<[f32; JOINTS]> {
        self.latest().map(|s| std::array::from_fn(|i| s.state.motor_state[i].q.get()))
    }

    /// Waits up to `timeout` for a LowState that satisfies `accept` (the latest counts). Any
    /// executor.
    pub async fn wait_state(
        &self,
        timeout: Duration,
        accept: impl Fn(&HgLowState) -> bool + Send + Sync + 'static,
    ) -> Option<HgLowState> {
        self.low.wait_state(timeout, accept).await
    }

    /// Sets the `rt/arm_sdk` targets of the arm and waist joints (in [`ARM_SDK_JOINTS`] order:
    /// slots 15..29, then 12, 13, 14; position rad, velocity rad/s, gains, torque N·m), keeping
    /// the target weight; refreshes the arm command (it goes stale without a refresh within
    /// `arm_sdk.command_timeout`). As Unitree's arm examples: `mode` 0 (the controller reads
    /// targets and gains); the robot's `mode_machine`. A joint the variant does not drive must be
    /// `JointCommand::default()`. Checked by [`unitree_proto::g1::check_arm_sdk`]; refused before
    /// the first LowState. The stream starts (at weight 0) with the first call.
    pub fn set_arm_joints(&self, joints: &[JointCommand; ARM_JOINTS]) -> Result<(), G1Error> {
        let (mode_machine, variant) = self.machine()?;
        let mut targets = robowire_rt::lock(&self.arm_targets);
        let weight = targets.map_or(0.0, |c| c.motor_cmd[slot::ARM_SDK_WEIGHT].q.get());
        let mut command = HgLowCmd::default();
        command.mode_machine = mode_machine;
        for (&slot, j) in ARM_SDK_JOINTS.iter().zip(joints) {
            if variant.drives(slot) {
                let mut m = HgMotorCmd::servo(j.q_rad, j.dq_radps, j.kp, j.kd, j.tau_nm);
                m.mode = 0;
                command.motor_cmd[slot] = m;
            } else if *j != JointCommand::default() {
                return Err(CommandError::UndrivenMotor { motor: slot }.into());
            }
        }
        command.motor_cmd[slot::ARM_SDK_WEIGHT].q = weight.into();
        self.latch_arm(&mut targets, command, variant)
    }

    /// Where the `rt/arm_sdk` weight goes (0: the robot's controller alone, 1: the arm targets
    /// alone), moved there at `arm_sdk.weight_rate_per_s`; refreshes the arm command. `target`
    /// outside 0..=1 or not finite is [`CommandError::ArmSdkWeight`]; before any
    /// [`set_arm_joints`](Self::set_arm_joints), [`G1Error::NoArmTargets`].
    pub fn set_arm_weight(&self, target: f32) -> Result<(), G1Error> {
        if !(target.is_finite() && (0.0..=1.0).contains(&target)) {
            return Err(CommandError::ArmSdkWeight { value: target }.into());
        }
        let (_, variant) = self.machine()?;
        let mut targets = robowire_rt::lock(&self.arm_targets);
        let mut command = targets.ok_or(G1Error::NoArmTargets)?;
        command.motor_cmd[slot::ARM_SDK_WEIGHT].q = target.into();
        self.latch_arm(&mut targets, command, variant)
    }

    /// Checks `command` and hands it to the arm stream.
    fn latch_arm(&self, targets: &mut Option<HgLowCmd>, command: HgLowCmd, variant: G1Variant) -> Result<(), G1Error> {
        g1::check_arm_sdk(&command, variant)?;
        *targets = Some(command);
        self.arm_shared.commands.write(robowire_rt::now(), &command);
        self.arm_waker.wake();
        Ok(())
    }

    /// The weight of the last `rt/arm_sdk` frame sent, 0..=1.
    pub fn arm_weight(&self) -> f32 {
        f32::from_bits(self.arm_shared.weight.load(Ordering::Relaxed))
    }

    /// The robot's latest battery state (`rt/lf/bmsstate`; `None` before the first).
    pub fn battery(&self) -> Option<HgBmsState> {
        self.battery.battery.latest()
    }

    /// A handle on the latest battery state, for readers that outlive a borrow of the client.
    pub fn battery_handle(&self) -> Battery {
        self.battery.battery.clone()
    }

    /// The locomotion service (`sport`).
    pub fn loco(&self) -> &Loco {
        &self.loco
    }

    /// The arm action service (`arm`).
    pub fn arm(&self) -> &ArmActions {
        &self.arm
    }

    /// The low-level client underneath (its participant, its other services).
    pub fn low_level(&self) -> &LowLevel<Hg> {
        &self.low
    }

    /// The options in force.
    pub fn options(&self) -> &G1Options {
        &self.options
    }

    /// The arm weight ramped to 0, the LowCmd damping burst, then closed. Dropping does the same.
    pub fn close(self) {
        drop(self);
    }
}

/// A motion checked by the G1's rules at each step, for the robot it was handed to.
struct G1Rules<M> {
    motion: M,
    mode_machine: u8,
    variant: G1Variant,
}

impl<M: Motion<HgLowCmd>> Motion<HgLowCmd> for G1Rules<M> {
    fn command_at(&self, elapsed: Duration) -> Result<HgLowCmd, CommandError> {
        let command = self.motion.command_at(elapsed)?;
        g1::check_low_cmd(&command, Some(self.mode_machine), self.variant)?;
        Ok(command)
    }

    fn duration(&self) -> Duration {
        self.motion.duration()
    }
}

impl Device for G1 {
    type State = HgLowState;
    type Stats = G1Stats;
    type Error = std::convert::Infallible;

    fn receiving(&self) -> &Receiving<HgLowState> {
        self.low.receiving()
    }

    /// Counters and timing of both streams.
    fn stats(&self) -> G1Stats {
        let a = &self.arm_shared;
        G1Stats {
            low_level: self.low.stats(),
            arm_sdk: self.arm_sdk.get(),
            arm_sdk_sent: a.sent.get(),
            arm_sdk_command_timeouts: a.command_timeouts.get(),
            arm_sdk_missed_ticks: a.missed_ticks.get(),
            arm_sdk_write_drops: a.write_drops.get(),
            arm_sdk_weight: self.arm_weight(),
            arm_sdk_send_lateness: a.lateness.summary(),
            bmsstate: self.battery.stats.get(),
        }
    }

    fn close(self) -> Result<(), std::convert::Infallible> {
        drop(self);
        Ok(())
    }
}

impl Drop for G1 {
    fn drop(&mut self) {
        // Velocities asked without waiting end with zero (its answer awaited 0.5 s at most).
        self.loco.stop_asked(self.options.low_level.service_timeout.min(Duration::from_millis(500)));
        self.battery.task.abort();
        if let Some(arm_stream) = self.arm_stream.take() {
            // The arm stream ramps its weight to 0 (bounded: see `arm_stream`) and ends by itself.
            self.arm_shared.closing.store(true, Ordering::Release);
            self.arm_waker.wake();
            let _ = arm_stream.join();
        }
    }
}
