//! `sim:` addresses: the simulator first, then the same client a real device gets.

#[cfg(feature = "unitree")]
use robowire_sim::g1::{G1Sim, G1SimConfig};
#[cfg(feature = "unitree")]
use robowire_sim::go2::{Go2Sim, Go2SimConfig};
#[cfg(feature = "kmc")]
use robowire_sim::kmc::{ChassisSim, ChassisSimConfig};
#[cfg(feature = "zsl1")]
use robowire_sim::spline::{SplineSim, SplineSimConfig};
#[cfg(feature = "zsl1")]
use robowire_sim::zsl1::{Zsl1Sim, Zsl1SimConfig};

use crate::facade::Facade;
use crate::{DeviceAddress, DeviceError, DeviceKind, OpenOptions};

/// The simulator behind a `sim:` address, for what only a simulator does (faults, snapshots).
#[derive(Debug)]
#[non_exhaustive]
pub enum Simulator {
    #[cfg(feature = "kmc")]
    /// A KMC chassis on a pseudo-terminal.
    Kmc(ChassisSim),
    #[cfg(feature = "zsl1")]
    /// A ZSL-1 / ZSL-1W on loopback UDP.
    Zsl1(Zsl1Sim),
    #[cfg(feature = "unitree")]
    /// A Go2 on DDS.
    Go2(Go2Sim),
    #[cfg(feature = "unitree")]
    /// A G1 on DDS.
    G1(G1Sim),
    #[cfg(feature = "zsl1")]
    /// The spline daemon on private shared memory.
    Spline(SplineSim),
}

pub(crate) fn open(
    address: &DeviceAddress,
    kind: DeviceKind,
    options: &OpenOptions,
) -> Result<(Simulator, Box<dyn Facade>), DeviceError> {
    let failed =
        |source: Box<dyn std::error::Error + Send + Sync>| DeviceError::Simulator { address: address.clone(), source };
    Ok(match kind {
        #[cfg(feature = "kmc")]
        DeviceKind::Kmc => {
            let sim = ChassisSim::spawn(ChassisSimConfig::default()).map_err(|e| failed(e.into()))?;
            let driver = kmc::Driver::open(sim.path(), crate::kinds::kmc::driver_options(options))?;
            (Simulator::Kmc(sim), Box::new(driver))
        }
        #[cfg(feature = "zsl1")]
        DeviceKind::Zsl1 | DeviceKind::Zsl1w => {
            let model = if kind == DeviceKind::Zsl1w { zsl::udp::Model::Zsl1W } else { zsl::udp::Model::Zsl1 };
            let sim =
                Zsl1Sim::spawn(Zsl1SimConfig { model, ..Zsl1SimConfig::loopback() }).map_err(|e| failed(e.into()))?;
            let dog = sim.high_level_addr();
            let client = zsl::udp::ClientOptions {
                dog,
                ..zsl::udp::ClientOptions::high_level([127, 0, 0, 1].into(), 0, dog.ip())
            };
            let link = zsl::udp::HighLevel::open(crate::kinds::zsl1::client_options(client, model, options))?;
            (Simulator::Zsl1(sim), Box::new(link))
        }
        #[cfg(feature = "zsl1")]
        DeviceKind::Spline => {
            static NEXT: std::sync::atomic::AtomicU32 = std::sync::atomic::AtomicU32::new(0);
            let n = NEXT.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
            let tag = format!("devices-{}-{n}", std::process::id());
            let sim = SplineSim::spawn(SplineSimConfig::private(&tag)).map_err(|e| failed(e.into()))?;
            let monitor = zsl::spline::SplineMonitor::open(crate::kinds::spline::monitor_options(
                &sim.config().spline_name,
                options,
            ))?;
            (Simulator::Spline(sim), Box::new(monitor))
        }
        #[cfg(feature = "unitree")]
        DeviceKind::Go2 => {
            let interface = options.sim_interface.as_deref().unwrap_or("lo");
            let client = crate::kinds::unitree::low_level_options::<unitree::Go2>(Some(interface), options);
            let sim = Go2Sim::spawn(Go2SimConfig {
                participant: client.participant.clone(),
                onboard_gait: walks(options),
                #[cfg(feature = "mujoco")]
                physics: physics(options, false),
                ..Go2SimConfig::default()
            })
            .map_err(|e| failed(e.into()))?;
            let client = unitree::LowLevel::<unitree::Go2>::open(client)?;
            (Simulator::Go2(sim), Box::new(client))
        }
        #[cfg(feature = "unitree")]
        DeviceKind::G1 => {
            let interface = options.sim_interface.as_deref().unwrap_or("lo");
            let client = crate::kinds::g1::client_options(Some(interface), options);
            let participant = client.low_level.participant.clone();
            let sim = G1Sim::spawn(G1SimConfig {
                participant,
                onboard_gait: walks(options),
                #[cfg(feature = "mujoco")]
                physics: physics(options, true),
                ..G1SimConfig::default()
            })
            .map_err(|e| failed(e.into()))?;
            let client = unitree::g1::G1::open(client)?;
            (Simulator::G1(sim), Box::new(client))
        }
        // The HG family's generic client has no simulator of its own (`sim:g1` is the G1's).
        DeviceKind::Hg => {
            return Err(DeviceError::Unsupported { what: "a simulator of the HG client (sim:g1 is the G1's)" });
        }
        #[allow(unreachable_patterns)] // every kind built
        _ => return Err(crate::kinds::not_built(address)),
    })
}

/// Whether the simulator's own locomotion is a walking policy.
fn walks(options: &OpenOptions) -> bool {
    options.sim_physics.as_ref().is_some_and(|p| p.walk.is_some())
}

/// The walking policy of a simulator asked to walk ([`crate::SimPhysics::walk`]), started on its
/// onboard port.
#[cfg(feature = "walk")]
pub(crate) fn walker(
    address: &DeviceAddress,
    simulator: &Simulator,
    options: &OpenOptions,
) -> Result<Option<robowire_policy::onboard::Walker>, DeviceError> {
    use robowire_policy::onboard::Walker;
    use unitree_proto::robot::{Go2, Hg};
    let Some(path) = options.sim_physics.as_ref().and_then(|p| p.walk.as_ref()) else { return Ok(None) };
    let failed =
        |source: Box<dyn std::error::Error + Send + Sync>| DeviceError::Simulator { address: address.clone(), source };
    let config = robowire_policy::PolicyConfig::load(path).map_err(|e| failed(e.into()))?;
    let walker = match simulator {
        Simulator::Go2(sim) => sim.onboard().map(|port| Walker::start::<Go2>(port, config)),
        Simulator::G1(sim) => sim.onboard().map(|port| Walker::start::<Hg>(port, config)),
        #[allow(unreachable_patterns)] // only the Unitree simulators take physics
        _ => None,
    };
    walker.transpose().map_err(|e| failed(e.into()))
}

/// The simulator's physics (`hanging`: whether the robot hangs unless told), `None` for the
/// kinematic body. Physics reaches here only in a build with MuJoCo (`crate::physics_possible`).
#[cfg(feature = "mujoco")]
fn physics(options: &OpenOptions, hanging: bool) -> Option<robowire_sim::physics::PhysicsOptions> {
    let physics = options.sim_physics.as_ref()?;
    Some(robowire_sim::physics::PhysicsOptions {
        model: physics.model.clone(),
        hanging: physics.hanging.unwrap_or(hanging && physics.walk.is_none()),
    })
}
