//! The G1 variants as Python names them: `"29dof"`, `"23dof"`, `"29dof_waist_locked"`,
//! `"dual_arm"`, or by joint count.

use pyo3::prelude::*;
use unitree::g1::G1Variant;

use crate::errors::{Kind, error};

/// The G1 variants by their Python name and joint count (Unitree's names: "27-dof" is the
/// 29-dof body with its waist locked, "14-dof" the dual-arm G1).
const VARIANTS: [(&str, u8, G1Variant); 4] = [
    ("29dof", 29, G1Variant::Dof29),
    ("23dof", 23, G1Variant::Dof23),
    ("29dof_waist_locked", 27, G1Variant::Dof29WaistLocked),
    ("dual_arm", 14, G1Variant::DualArm),
];

/// The Python name of `variant`.
pub(crate) fn variant_name(variant: G1Variant) -> &'static str {
    VARIANTS.iter().find(|(_, _, v)| *v == variant).map_or("29dof", |(name, _, _)| name)
}

/// The variant named `name`, or `ArgumentError`.
pub(crate) fn variant_named(name: &str) -> PyResult<G1Variant> {
    VARIANTS.iter().find(|(n, _, _)| *n == name).map(|(_, _, v)| *v).ok_or_else(|| {
        let names: Vec<_> = VARIANTS.iter().map(|(n, _, _)| format!("{n:?}")).collect();
        error(Kind::Argument, format!("variant = {name:?}: one of {}", names.join(", ")))
    })
}

/// The variant with `dof` joints, or `ArgumentError`.
pub(crate) fn variant_of_dof(dof: u8) -> PyResult<G1Variant> {
    VARIANTS
        .iter()
        .find(|(_, d, _)| *d == dof)
        .map(|(_, _, v)| *v)
        .ok_or_else(|| error(Kind::Argument, format!("dof = {dof}: 29, 27 (waist locked), 23 or 14 (dual arm)")))
}
