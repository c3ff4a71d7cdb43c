//! [`G1Options`]: the low-level client's options, the variant, the `rt/arm_sdk` stream.

use std::time::Duration;

use crate::{LowLevelOptions, UnitreeError};
use robowire_tap::{RecordLinks, Tap};
use unitree_proto::g1::G1Variant;

use crate::g1::G1Error;
use unitree_proto::g1::arm_stream::{ARM_SDK_WEIGHT_RATE_MAX_PER_S, ArmSdkConfig};

/// How a [`G1`](crate::g1::G1) client is set up.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct G1Options {
    /// Domain, interface, the 500 Hz `rt/lowcmd` stream, the state watchdog, service timeout,
    /// taps: as for any Unitree robot. Its placement places both stream threads (`rt/lowcmd` and
    /// `rt/arm_sdk`).
    pub low_level: LowLevelOptions,
    /// Which G1 this is, whatever its LowState's `mode_machine` says (`None`: from
    /// `mode_machine`, see [`G1::variant`](crate::g1::G1::variant)).
    pub variant: Option<G1Variant>,
    /// The `rt/arm_sdk` stream: 20 ms period, 500 ms command timeout, weight rate 0.5/s.
    pub arm_sdk: ArmSdkConfig,
    /// Where each `rt/arm_sdk` frame written goes, as its payload (a link of its own, described
    /// by `unitree_proto::description::HG_LOW_LEVEL`: HG LowCmds sent).
    pub arm_sdk_tap: Option<Tap>,
}

impl G1Options {
    /// Recorded with `links` when given: the HG low level as `g1/low_level`, the services as
    /// `g1/api`, `rt/arm_sdk` as `g1/arm_sdk` (all described by `unitree_proto::description`).
    pub fn recorded(self, links: Option<&RecordLinks>) -> Self {
        let Some(links) = links else { return self };
        let hg = &unitree_proto::description::HG_LOW_LEVEL;
        Self {
            low_level: self.low_level.recorded(Some(links), "g1", hg),
            arm_sdk_tap: Some(links.link("g1/arm_sdk", hg)),
            ..self
        }
    }

    /// Domain `domain` on interface `interface` (`None`: the library chooses); everything else
    /// the defaults.
    pub fn on(interface: Option<&str>, domain: u16) -> Self {
        Self { low_level: LowLevelOptions::on(interface, domain), ..Self::default() }
    }

    /// The variant of a robot whose LowState says `mode_machine`: the option if set; otherwise
    /// what `mode_machine` names ([`G1Variant::of_mode_machine`]), and [`G1Variant::Dof29`] for a
    /// value not in Unitree's table (0, a simulator's, included).
    pub fn variant_of(&self, mode_machine: u8) -> G1Variant {
        self.variant.or(G1Variant::of_mode_machine(mode_machine)).unwrap_or(G1Variant::Dof29)
    }

    /// The `rt/arm_sdk` options: period 1 ms..=1 s, command timeout at least a period, weight
    /// rate finite in (0, 5] per second. (The low-level options, placement included, are checked
    /// by [`crate::LowLevel::open`].)
    pub(crate) fn validate(&self) -> Result<(), G1Error> {
        let bad = |name: &'static str, reason: String| Err(G1Error::LowLevel(UnitreeError::Option { name, reason }));
        let a = &self.arm_sdk;
        if a.period < Duration::from_millis(1) || a.period > Duration::from_secs(1) {
            return bad("arm_sdk.period", format!("{:?} is outside 1 ms..=1 s", a.period));
        }
        if a.command_timeout < a.period {
            return bad("arm_sdk.command_timeout", format!("{:?} is shorter than the period", a.command_timeout));
        }
        let rate = a.weight_rate_per_s;
        if !(rate.is_finite() && rate > 0.0 && rate <= ARM_SDK_WEIGHT_RATE_MAX_PER_S) {
            return bad("arm_sdk.weight_rate_per_s", format!("{rate} is outside (0, {ARM_SDK_WEIGHT_RATE_MAX_PER_S}]"));
        }
        Ok(())
    }
}
