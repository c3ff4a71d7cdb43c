//! A walking policy (`robowire_policy`) on a device opened by address (feature `policy`): which
//! addresses a policy can drive, and a run on the G1 or the Go2 an [`AnyDevice`] holds. The CLI's
//! `robowire policy run` and Python's `robowire.policy` both start here.

use std::sync::Arc;

use robowire_policy::control::StepReport;
use robowire_policy::{Ended, MsgType, OnnxPolicy, Phase, PolicyConfig, RunOptions, Running, StartError, start};
use robowire_tap::{RecordLinks, Tap};
use unitree::g1::G1;
use unitree::{Go2, LowLevel};

use crate::{AnyDevice, DeviceAddress, DeviceKind};

/// Why a policy cannot drive the device at an address. Nothing was opened.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum Refused {
    /// An HG robot's generic client.
    #[error("{0}: a policy drives a G1 as g1:IFACE (hg:/h1: robots are not supported yet)")]
    Hg(DeviceAddress),
    /// Not a Unitree robot.
    #[error("{0}: a policy drives a Unitree robot: g1:IFACE, go2:IFACE, sim:g1 or sim:go2 with --physics")]
    NotUnitree(DeviceAddress),
    /// A simulator without physics.
    #[error(
        "{0} is the kinematic simulator: its joints follow the commands and nothing walks; add --physics \
         (physics=True in Python; a build with the mujoco feature)"
    )]
    Kinematic(DeviceAddress),
    /// The config is for the other message family.
    #[error("msg_type: the config is for {config} robots, {address} speaks {device}")]
    MsgType {
        /// The device's address.
        address: DeviceAddress,
        /// The config's family.
        config: MsgType,
        /// The device's family.
        device: MsgType,
    },
}

/// The message family of the robot at `address`, or why a policy cannot drive it; `physics`:
/// whether a `sim:` address is opened with a physics body.
pub fn robot_of(address: &DeviceAddress, physics: bool) -> Result<MsgType, Refused> {
    let msg_type = match address {
        DeviceAddress::G1(_) | DeviceAddress::Sim(DeviceKind::G1) => MsgType::Hg,
        DeviceAddress::Go2(_) | DeviceAddress::Sim(DeviceKind::Go2) => MsgType::Go,
        DeviceAddress::Hg(_) => return Err(Refused::Hg(address.clone())),
        other => return Err(Refused::NotUnitree(other.clone())),
    };
    if address.is_simulated() && !physics {
        return Err(Refused::Kinematic(address.clone()));
    }
    Ok(msg_type)
}

/// [`robot_of`], and the config's `msg_type` against it.
pub fn check(config: &PolicyConfig, address: &DeviceAddress, physics: bool) -> Result<MsgType, Refused> {
    let device = robot_of(address, physics)?;
    if config.msg_type != device {
        return Err(Refused::MsgType { address: address.clone(), config: config.msg_type, device });
    }
    Ok(device)
}

/// The capture link of a policy's steps on `device`: `g1/policy` or `go2/policy`, beside the
/// device's own links.
pub fn policy_link(device: &AnyDevice, links: &RecordLinks) -> Tap {
    links.link(&format!("{}/policy", device.kind().name()), &robowire_policy::record::POLICY)
}

/// A policy running on the G1 or the Go2 of a device opened by address.
#[derive(Debug)]
pub enum DeviceRun {
    /// On a G1 (`g1:`, `sim:g1`).
    G1(Running<AnyDevice, G1>),
    /// On a Go2 (`go2:`, `sim:go2`).
    Go2(Running<AnyDevice, LowLevel<Go2>>),
}

/// Starts `policy` on the robot of `config.msg_type` that `device` holds, as [`start`] does
/// ([`StartError::NoBody`] when it holds none).
pub async fn start_on(
    device: Arc<AnyDevice>,
    config: &PolicyConfig,
    policy: OnnxPolicy,
    options: RunOptions,
) -> Result<DeviceRun, StartError> {
    Ok(match config.msg_type {
        MsgType::Hg => DeviceRun::G1(start(device, AnyDevice::g1, config, policy, options).await?),
        MsgType::Go => DeviceRun::Go2(start(device, AnyDevice::go2, config, policy, options).await?),
    })
}

impl DeviceRun {
    /// Damps the robot and ends the run at the next tick.
    pub fn stop(&self) {
        match self {
            Self::G1(run) => run.stop(),
            Self::Go2(run) => run.stop(),
        }
    }

    /// Where the sequence is.
    pub fn phase(&self) -> Phase {
        match self {
            Self::G1(run) => run.phase(),
            Self::Go2(run) => run.phase(),
        }
    }

    /// How late the ticks ran against their deadlines, µs.
    pub fn tick_lateness(&self) -> robowire_core::timing::LatenessSummary {
        match self {
            Self::G1(run) => run.tick_lateness(),
            Self::Go2(run) => run.tick_lateness(),
        }
    }

    /// The last policy step.
    pub fn last_step(&self) -> StepReport {
        match self {
            Self::G1(run) => run.last_step(),
            Self::Go2(run) => run.last_step(),
        }
    }

    /// How the run ended, once it has (any executor).
    pub async fn ended(&self) -> Ended {
        match self {
            Self::G1(run) => run.ended().await,
            Self::Go2(run) => run.ended().await,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn only_unitree_robots_with_a_body_are_driven() {
        let at = |a: &str| a.parse::<DeviceAddress>().unwrap();
        assert_eq!(robot_of(&at("g1:eth0"), false), Ok(MsgType::Hg));
        assert_eq!(robot_of(&at("go2:eth0"), false), Ok(MsgType::Go));
        assert_eq!(robot_of(&at("sim:g1"), true), Ok(MsgType::Hg));
        assert_eq!(robot_of(&at("sim:go2"), false), Err(Refused::Kinematic(at("sim:go2"))));
        assert_eq!(robot_of(&at("hg:eth0"), false), Err(Refused::Hg(at("hg:eth0"))));
        assert_eq!(robot_of(&at("sim:kmc"), true), Err(Refused::NotUnitree(at("sim:kmc"))));
        let line = robot_of(&at("sim:g1"), false).unwrap_err().to_string();
        assert!(line.starts_with("sim:g1 is the kinematic simulator") && line.contains("--physics"), "{line}");
    }
}
