//! The body behind `robowire sim go2|g1` and behind `sim:go2`/`sim:g1` opened by address
//! (`robowire status|watch`, `robowire ros2 --device`): the kinematic joint model or MuJoCo
//! physics (`--physics [--model MJCF]`, in a build with the `mujoco` feature), and how a
//! simulator's time runs (`--speed X`), and the robot's own locomotion (`--walk CONFIG`).

use std::path::PathBuf;

use anyhow::Context;
use clap::Args;

/// The simulated robot's body: its kinematic joints or MuJoCo physics.
#[derive(Debug, Args)]
pub(crate) struct PhysicsArgs {
    /// Simulate the body in MuJoCo (a build with the `mujoco` feature): the robot stands, sinks
    /// and falls under its motors' torques instead of following them joint by joint.
    #[arg(long)]
    physics: bool,
    /// With --physics: the MJCF to load instead of robowire's own model (a scene with a floor
    /// and the robot, e.g. unitree_mujoco's or MuJoCo Menagerie's scene.xml); its joints are
    /// found by the motors' names (FR_hip_joint, …, left_hip_pitch_joint, …).
    #[arg(long, value_name = "MJCF", requires = "physics")]
    model: Option<PathBuf>,
    /// With --physics: the robot's own locomotion is this walking policy (unitree_rl_gym's deploy
    /// config, its ONNX model beside it): the Go2's sport StandUp/BalanceStand/Move and the
    /// G1's loco Start/SetVelocity (Unitree's SportClient.Move, LocoClient.Move) make it stand and
    /// walk, StopMove asks zero velocity, Damp stops it. The G1 starts free on the floor.
    #[arg(long, value_name = "CONFIG.yaml", requires = "physics")]
    walk: Option<PathBuf>,
}

/// The body of a `sim:go2` or `sim:g1` opened by address (`robowire status|watch`,
/// `robowire ros2 --device`); physics asked of any other address is an error.
#[derive(Debug, Args)]
pub(crate) struct SimPhysicsArgs {
    #[command(flatten)]
    body: PhysicsArgs,
    /// With --physics: the base free on the floor (sim:g1 otherwise hangs by its pelvis, as in
    /// `robowire sim g1`; sim:go2 is free either way).
    #[arg(long, requires = "physics")]
    free_base: bool,
}

impl SimPhysicsArgs {
    /// Whether `--physics` was given.
    pub(crate) fn physics(&self) -> bool {
        self.body.physics
    }

    /// The base free on the floor, whatever `--free-base` said.
    pub(crate) fn free_the_base(&mut self) {
        self.free_base = true;
    }

    /// What `robowire_devices::open` is asked for: `None`, the kinematic body.
    pub(crate) fn options(&self) -> Option<robowire_devices::SimPhysics> {
        self.body.physics.then(|| robowire_devices::SimPhysics {
            model: self.body.model.clone(),
            hanging: self.free_base.then_some(false),
            walk: self.body.walk.clone(),
        })
    }
}

/// How the simulated robot's body and time run.
#[derive(Debug, Args)]
pub(crate) struct BodyArgs {
    #[command(flatten)]
    body: PhysicsArgs,
    /// Simulated seconds per wall second (0 < X <= 100).
    #[arg(long, value_name = "X", default_value_t = 1.0)]
    speed: f32,
}

impl BodyArgs {
    /// The clock the simulator runs on.
    pub(crate) fn clock(&self) -> robowire_sim::go2::SimClock {
        robowire_sim::go2::SimClock::RealTime { speed: self.speed }
    }

    /// Whether `--walk` was given.
    pub(crate) fn walks(&self) -> bool {
        self.body.walk.is_some()
    }

    /// Starts `--walk`'s policy on the simulator's onboard port (`None` without `--walk`).
    pub(crate) fn start_walker<R: robowire_policy::onboard::OnboardRobot>(
        &self,
        port: impl FnOnce() -> Option<robowire_sim::go2::Onboard<R::State, R::Cmd>>,
    ) -> anyhow::Result<Option<robowire_policy::onboard::Walker>> {
        let Some(path) = &self.body.walk else { return Ok(None) };
        anyhow::ensure!(self.speed == 1.0, "--walk runs the policy in real time: --speed must be 1");
        let config = robowire_policy::PolicyConfig::load(path).map_err(anyhow::Error::msg)?;
        let port = port().context("the simulator has no onboard port")?;
        let walker = robowire_policy::onboard::Walker::start::<R>(port, config)
            .with_context(|| format!("--walk {}", path.display()))?;
        Ok(Some(walker))
    }

    /// What the startup line says of the body.
    pub(crate) fn describe(&self) -> String {
        let body = match (&self.body.physics, &self.body.model) {
            (false, _) => "kinematic joints".to_string(),
            (true, None) => "MuJoCo physics, robowire's model".to_string(),
            (true, Some(model)) => format!("MuJoCo physics, {}", model.display()),
        };
        let body = match &self.body.walk {
            Some(config) => format!("{body}, walking under {}", config.display()),
            None => body,
        };
        if self.speed == 1.0 { body } else { format!("{body}, {}× real time", self.speed) }
    }

    /// The physics options (`hanging`: the base held), or `None` for the kinematic body.
    #[cfg(feature = "mujoco")]
    pub(crate) fn physics(&self, hanging: bool) -> anyhow::Result<Option<robowire_sim::physics::PhysicsOptions>> {
        Ok(self.body.physics.then(|| robowire_sim::physics::PhysicsOptions { model: self.body.model.clone(), hanging }))
    }

    /// Refuses `--physics` in a build without MuJoCo.
    #[cfg(not(feature = "mujoco"))]
    pub(crate) fn physics(&self, _hanging: bool) -> anyhow::Result<Option<()>> {
        anyhow::ensure!(
            !self.body.physics,
            "this robowire was built without physics: build it with `cargo build --release -p robowire --features \
             mujoco`, MUJOCO_DYNAMIC_LINK_DIR naming a directory with MuJoCo 3.17.0's libmujoco.so (the PyPI wheel \
             mujoco==3.17.0 ships it), and run it with that directory on LD_LIBRARY_PATH"
        );
        Ok(None)
    }
}

/// What a report line adds for a simulator whose body is physics: the base's height and the
/// real-time factor since the last report (`last`: the previous (sim, wall) times, updated).
pub(crate) fn physics_report(
    base: Option<robowire_sim::go2::BasePose>,
    sim_time_s: f64,
    wall_time_s: f64,
    last: &std::cell::Cell<(f64, f64)>,
) -> String {
    let (sim0, wall0) = last.replace((sim_time_s, wall_time_s));
    let rtf = if wall_time_s > wall0 { (sim_time_s - sim0) / (wall_time_s - wall0) } else { 0.0 };
    match base {
        Some(b) => format!(
            " | base z {:.3} m roll {:.2} pitch {:.2} | sim {sim_time_s:.1} s, real-time factor {rtf:.2}",
            b.position_m[2], b.rpy_rad[0], b.rpy_rad[1]
        ),
        None => format!(" | sim {sim_time_s:.1} s, real-time factor {rtf:.2}"),
    }
}
