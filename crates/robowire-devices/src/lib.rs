#![doc = include_str!("../README.md")]
#![forbid(unsafe_code)]
// A build without any device kind opens nothing: what serves the kinds is unused there.
#![cfg_attr(
    not(any(feature = "kmc", feature = "zsl1", feature = "unitree")),
    allow(dead_code, unused_variables, unreachable_code)
)]

mod address;
mod error;
mod facade;
mod kinds;
mod observation;
#[cfg(feature = "policy")]
pub mod policy;
#[cfg(feature = "sim")]
mod sim;

use std::net::{IpAddr, Ipv4Addr, SocketAddr};
use std::path::PathBuf;
use std::time::Duration;

pub use address::{ADDRESS_EXAMPLES, AddressError, DeviceAddress, DeviceKind};
pub use error::{DeviceError, error_chain};
pub use facade::{Describe, Observations, StateChanges};
#[cfg(feature = "kmc")]
pub use kinds::kmc::kmc_taps;
#[cfg(feature = "zsl1")]
pub use kinds::spline::{SPLINE_IMU_LINK, SPLINE_LINK};
#[cfg(feature = "zsl1")]
pub use kinds::zsl1::state_line as zsl_state_line;
pub use observation::{BatteryReading, ImuReading, JointReadings, MotorReport, Observation, Odometry, Passthrough};
pub use robowire_rt::device::Connection;
#[cfg(feature = "sim")]
pub use sim::Simulator;

use facade::Facade;
use robowire_tap::RecordLinks;
use serde_json::Value;
use tokio::sync::watch;

/// The ZSL-1's default `target_port`: where the robot sends its state (`sdk_config.yaml`).
const ZSL_LOCAL_PORT: u16 = 43988;

/// How [`open`] reaches a device, beyond its address.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct OpenOptions {
    /// DDS domain of `go2:`, `hg:`, `g1:`, `sim:go2` and `sim:g1` (Unitree's robots: 0).
    pub domain: u16,
    /// Network interface of `sim:go2`'s and `sim:g1`'s simulator and client (`None`: `lo`).
    pub sim_interface: Option<String>,
    /// Local address of `zsl1:`/`zsl1w:` clients: where the robot sends its state (its
    /// `target_ip`/`target_port`, port 43988 by default).
    pub zsl_local: SocketAddr,
    /// `kmc:` polls the battery (1 Hz) and the motors' all-state (10 Hz).
    pub kmc_polls: bool,
    /// A device silent this long is `Disconnected` (`kmc:`, `zsl1:`, `zsl1w:`, `go2:`, `hg:`,
    /// `g1:` and their simulators); `None`: each device's default (KMC 500 ms, ZSL-1 the vendor's
    /// 3 s watchdog, Go2/HG/G1 100 ms).
    pub state_timeout: Option<Duration>,
    /// Record the device's links with this recorder (`None`: not recorded), named after the
    /// device: `kmc/serial` (and `kmc/serial_skipped`, the line noise), `zsl1/high_level`,
    /// `go2/low_level` and `go2/api`, `hg/low_level` and `hg/api`, `g1/low_level` and `g1/api`
    /// (described by `unitree_proto::description::HG_LOW_LEVEL` and `API_CLIENT`), `spline/spline` (the states a
    /// monitor takes from `/spline_shm`).
    pub record: Option<RecordLinks>,
    /// The body of `sim:go2`'s and `sim:g1`'s simulator: `None`, its kinematic joints; `Some`,
    /// MuJoCo physics, as `robowire sim go2|g1 --physics` runs it (a build with the `mujoco`
    /// feature). Physics asked of any other address is [`DeviceError::NoPhysics`], and of a
    /// build without the feature [`DeviceError::PhysicsNotBuilt`]: never the kinematic body.
    pub sim_physics: Option<SimPhysics>,
}

/// MuJoCo physics behind a simulated robot's body (`sim:go2`, `sim:g1`): the robot stands, sinks
/// and falls under its motors' torques instead of following them joint by joint.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct SimPhysics {
    /// A user's MJCF file (a scene with a floor and the robot, e.g. unitree_mujoco's or MuJoCo
    /// Menagerie's `scene.xml`), its joints found by the motors' names; `None`: robowire's own
    /// model of the robot.
    pub model: Option<PathBuf>,
    /// The base held where it starts by a stiff spring (as on Unitree's elastic band), or free on
    /// the floor; `None`: as `robowire sim` has it, a Go2 free (lying on its floor) and a G1
    /// hanging (its balance controller is not simulated); a walking G1 free.
    pub hanging: Option<bool>,
    /// The robot's own locomotion is this walking policy (a deploy config, its ONNX model beside
    /// it), walked by the robot's sport/loco service as `robowire sim go2|g1 --walk` has it (a
    /// build with the `walk` feature, else [`DeviceError::Unsupported`]).
    pub walk: Option<PathBuf>,
}

impl Default for OpenOptions {
    fn default() -> Self {
        Self {
            domain: 0,
            sim_interface: None,
            zsl_local: SocketAddr::new(IpAddr::V4(Ipv4Addr::UNSPECIFIED), ZSL_LOCAL_PORT),
            kmc_polls: true,
            state_timeout: None,
            record: None,
            sim_physics: None,
        }
    }
}

/// A device opened by address, in the one shape every app drives: state, connection, status, a
/// neutral [`Observation`], drive, services, close. Typed access to the facade underneath for
/// what is the device's own ([`kmc`](Self::kmc), [`zsl`](Self::zsl), [`go2`](Self::go2),
/// [`hg`](Self::hg), [`g1`](Self::g1)). Dropping it does the device's safe thing and closes it (then stops its
/// simulator, if any).
pub struct AnyDevice {
    address: DeviceAddress,
    facade: Box<dyn Facade>,
    /// The simulator's walking policy, stopped before the simulator.
    #[cfg(feature = "walk")]
    walker: Option<robowire_policy::onboard::Walker>,
    /// Dropped after the facade: the client says its last word to a live simulator.
    #[cfg(feature = "sim")]
    simulator: Option<Simulator>,
}

impl std::fmt::Debug for AnyDevice {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("AnyDevice").field("address", &self.address).finish_non_exhaustive()
    }
}

/// Opens the device at `address`: its client, and for `sim:` addresses its simulator first.
/// DDS devices on one machine need multicast on loopback (see `robowire-dds`).
///
/// ```
/// use robowire_devices::{DeviceAddress, open, OpenOptions};
/// let address: DeviceAddress = "kmc:/dev/robowire-no-such-port".parse()?;
/// let error = open(&address, &OpenOptions::default()).unwrap_err();
/// assert!(format!("{error:#}").contains("KMC chassis"));
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
pub fn open(address: &DeviceAddress, options: &OpenOptions) -> Result<AnyDevice, DeviceError> {
    physics_possible(address, options)?;
    let facade = match address {
        DeviceAddress::Sim(kind) => return open_simulated(address, *kind, options),
        _ => kinds::open(address, options)?,
    };
    Ok(AnyDevice {
        address: address.clone(),
        facade,
        #[cfg(feature = "walk")]
        walker: None,
        #[cfg(feature = "sim")]
        simulator: None,
    })
}

/// Physics only where there is a simulated body, and only in a build with MuJoCo (which builds
/// the simulators and the Unitree kinds with it); checked before anything starts.
fn physics_possible(address: &DeviceAddress, options: &OpenOptions) -> Result<(), DeviceError> {
    if options.sim_physics.is_none() {
        return Ok(());
    }
    if !matches!(address, DeviceAddress::Sim(DeviceKind::Go2 | DeviceKind::G1)) {
        return Err(DeviceError::NoPhysics { address: address.clone() });
    }
    if !cfg!(feature = "mujoco") {
        return Err(DeviceError::PhysicsNotBuilt { address: address.clone() });
    }
    if options.sim_physics.as_ref().is_some_and(|p| p.walk.is_some()) && !cfg!(feature = "walk") {
        return Err(DeviceError::Unsupported {
            what: "a walking policy in the simulator (robowire-devices' `walk` feature)",
        });
    }
    Ok(())
}

#[cfg(feature = "sim")]
fn open_simulated(address: &DeviceAddress, kind: DeviceKind, options: &OpenOptions) -> Result<AnyDevice, DeviceError> {
    let (simulator, facade) = sim::open(address, kind, options)?;
    Ok(AnyDevice {
        address: address.clone(),
        facade,
        #[cfg(feature = "walk")]
        walker: sim::walker(address, &simulator, options)?,
        simulator: Some(simulator),
    })
}

#[cfg(not(feature = "sim"))]
fn open_simulated(address: &DeviceAddress, _: DeviceKind, _: &OpenOptions) -> Result<AnyDevice, DeviceError> {
    Err(DeviceError::NoSimulators { address: address.clone() })
}

impl AnyDevice {
    fn facade(&self) -> &dyn Facade {
        self.facade.as_ref()
    }

    /// The address it was opened by.
    pub fn address(&self) -> &DeviceAddress {
        &self.address
    }

    /// What kind of device it is.
    pub fn kind(&self) -> DeviceKind {
        self.address.kind()
    }

    /// The connection as the device's watchdog sees it.
    pub fn connection(&self) -> Connection {
        *self.facade().connection_events().borrow()
    }

    /// Connection events: `Waiting` → `Connected` → `Disconnected` → `Connected` ….
    pub fn connection_events(&self) -> watch::Receiver<Connection> {
        self.facade().connection_events()
    }

    /// Wakes at every new state.
    pub fn state_changes(&self) -> StateChanges {
        self.facade().changes()
    }

    /// How long ago the latest state arrived (`None` before the first).
    pub fn state_age(&self) -> Option<Duration> {
        self.facade().age()
    }

    /// Waits up to `timeout` for a first state (needs a tokio runtime with its timer);
    /// whether one arrived.
    pub async fn wait_state(&self, timeout: Duration) -> bool {
        let mut changes = self.state_changes();
        if self.state_age().is_some() {
            return true;
        }
        tokio::time::timeout(timeout, async {
            while self.state_age().is_none() {
                if !changes.changed().await {
                    return false;
                }
            }
            true
        })
        .await
        .unwrap_or(false)
    }

    /// The latest state as JSON: the fields of the device's own status command
    /// (`robowire zsl1 status --json`, `robowire go2 status --json`).
    pub fn status_json(&self) -> Option<Value> {
        self.facade().status_json()
    }

    /// The latest state as a few lines of text.
    pub fn status_text(&self) -> Option<String> {
        self.facade().status_text()
    }

    /// The latest state as one line, with its age.
    pub fn status_line(&self) -> Option<String> {
        self.facade().status_line()
    }

    /// The client's counters as one line.
    pub fn stats_line(&self) -> String {
        self.facade().stats_line()
    }

    /// The latest state, device-neutral (`None` before the first).
    pub fn observe(&self) -> Option<Observation> {
        self.facade().observe()
    }

    /// Every state from now on, in order, device-neutral (a bridge publishes each).
    pub fn observations(&self) -> Observations {
        self.facade().observations()
    }

    /// Whether it is driven by a velocity ([`drive`](Self::drive)).
    pub fn can_drive(&self) -> bool {
        self.facade().can_drive()
    }

    /// Drives a mobile base: forward m/s, left m/s, yaw rate rad/s, checked by the device's own
    /// rules before anything is sent.
    pub fn drive(&self, vx_mps: f32, vy_mps: f32, yaw_rate_radps: f32) -> Result<(), DeviceError> {
        self.facade().drive(vx_mps, vy_mps, yaw_rate_radps)
    }

    /// Stops a commanded motion (zero velocity where the device is driven by one).
    pub fn stop_motion(&self) -> Result<(), DeviceError> {
        self.facade().stop_motion()
    }

    /// A drive command not refreshed within `timeout` stops the device (where it has such a
    /// timeout: the KMC chassis; a ZSL-1 keeps its command until its watchdog).
    pub fn set_drive_timeout(&self, timeout: Duration) -> Result<(), DeviceError> {
        self.facade().set_drive_timeout(timeout)
    }

    /// Its named actions (`stand_up`, `lie_down`, `passive` on a ZSL-1).
    pub fn services(&self) -> &'static [&'static str] {
        self.facade().services()
    }

    /// Runs the named action; what the device said.
    pub fn call(&self, service: &str) -> Result<String, DeviceError> {
        self.facade().call(service)
    }

    #[cfg(feature = "kmc")]
    /// The KMC driver, if this is a chassis.
    pub fn kmc(&self) -> Option<&::kmc::Driver> {
        self.facade().as_any().downcast_ref()
    }

    #[cfg(feature = "zsl1")]
    /// The ZSL-1 HighLevel client, if this is a ZSL-1 or ZSL-1W.
    pub fn zsl(&self) -> Option<&::zsl::udp::HighLevel> {
        self.facade().as_any().downcast_ref()
    }

    #[cfg(feature = "unitree")]
    /// The Go2 low-level client, if this is a Go2.
    pub fn go2(&self) -> Option<&unitree::LowLevel<unitree::Go2>> {
        self.facade().as_any().downcast_ref()
    }

    #[cfg(feature = "unitree")]
    /// The HG low-level client, if this is an HG robot opened as `hg:`.
    pub fn hg(&self) -> Option<&unitree::LowLevel<unitree::Hg>> {
        self.facade().as_any().downcast_ref()
    }

    #[cfg(feature = "unitree")]
    /// The G1 client, if this is a G1 (`g1:`, `sim:g1`).
    pub fn g1(&self) -> Option<&unitree::g1::G1> {
        self.facade().as_any().downcast_ref()
    }

    #[cfg(feature = "walk")]
    /// The walking policy of a simulator asked to walk ([`SimPhysics::walk`]).
    pub fn walker(&self) -> Option<&robowire_policy::onboard::Walker> {
        self.walker.as_ref()
    }

    #[cfg(feature = "zsl1")]
    /// The spline monitor, if this is a spline daemon.
    pub fn spline(&self) -> Option<&::zsl::spline::SplineMonitor> {
        self.facade().as_any().downcast_ref()
    }

    /// The simulator behind a `sim:` address.
    #[cfg(feature = "sim")]
    pub fn simulator(&self) -> Option<&Simulator> {
        self.simulator.as_ref()
    }

    /// As [`close`](Self::close), but hands the simulator back still running, for a look at what
    /// the device sent last (a stop burst, a damping command).
    #[cfg(feature = "sim")]
    pub fn close_keeping_simulator(self) -> (Result<(), DeviceError>, Option<Simulator>) {
        (self.facade.close(), self.simulator)
    }

    /// Does the device's safe thing (stop burst, stop, damping) and closes it; then stops its
    /// simulator. When this returns, its port or socket can be opened again.
    pub fn close(self) -> Result<(), DeviceError> {
        // The facade first; the simulator (dropped at the end of this scope) hears its last word.
        self.facade.close()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Opens `address` with physics: the error.
    fn with_physics(address: &str) -> DeviceError {
        let options = OpenOptions { sim_physics: Some(SimPhysics::default()), ..OpenOptions::default() };
        open(&address.parse().unwrap(), &options).expect_err(address)
    }

    #[test]
    fn physics_is_for_sim_go2_and_sim_g1_only() {
        for address in ["sim:kmc", "sim:zsl1", "sim:spline", "go2:lo", "g1:lo", "kmc:/dev/robowire-no-such-port"] {
            let error = with_physics(address);
            assert!(matches!(&error, DeviceError::NoPhysics { address: a } if a.to_string() == address), "{error:?}");
            assert!(error.to_string().contains("MuJoCo simulates the bodies of sim:go2 and sim:g1 only"), "{error}");
        }
    }

    #[cfg(not(feature = "mujoco"))]
    #[test]
    fn physics_in_a_build_without_mujoco_says_how_to_build_it() {
        for address in ["sim:go2", "sim:g1"] {
            let error = with_physics(address);
            assert!(matches!(&error, DeviceError::PhysicsNotBuilt { address: a } if a.to_string() == address));
            let text = error.to_string();
            assert!(text.contains("without physics") && text.contains("`mujoco` feature"), "{text}");
            assert!(text.contains("MUJOCO_DYNAMIC_LINK_DIR") && text.contains("LD_LIBRARY_PATH"), "{text}");
        }
    }
}
