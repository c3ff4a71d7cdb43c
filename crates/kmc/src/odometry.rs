//! Planar odometry from the chassis's speed reports and its commanded curvature (the KMC reports
//! only its speed): x, y, heading integrated on caller time. The [`Driver`](crate::Driver) keeps
//! one in its [`ChassisState`](crate::ChassisState).

/// Pose in the `odom` frame: x, y (m), heading (rad), and the last velocities.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct PlanarOdometry {
    /// x, m.
    pub x_m: f64,
    /// y, m.
    pub y_m: f64,
    /// Heading, rad, in (-π, π].
    pub heading_rad: f64,
    /// Forward speed, m/s.
    pub speed_mps: f64,
    /// Yaw rate, rad/s.
    pub yaw_rate_radps: f64,
    last_s: Option<f64>,
}

impl PlanarOdometry {
    /// A speed report at `t_s` (seconds on any monotonic clock) while steering `curvature_per_m`:
    /// the pose advances by the previous speed over the interval (midpoint heading).
    pub fn on_speed(&mut self, t_s: f64, speed_mps: f64, curvature_per_m: f64) {
        if let Some(last) = self.last_s {
            let dt = (t_s - last).clamp(0.0, 1.0);
            let dtheta = self.yaw_rate_radps * dt;
            let mid = self.heading_rad + dtheta / 2.0;
            self.x_m += self.speed_mps * dt * mid.cos();
            self.y_m += self.speed_mps * dt * mid.sin();
            self.heading_rad = wrap(self.heading_rad + dtheta);
        }
        self.last_s = Some(t_s);
        self.speed_mps = speed_mps;
        self.yaw_rate_radps = speed_mps * curvature_per_m;
    }
}

fn wrap(a: f64) -> f64 {
    use std::f64::consts::{PI, TAU};
    let w = a.rem_euclid(TAU);
    if w > PI { w - TAU } else { w }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn straight_then_a_quarter_circle() {
        let mut odom = PlanarOdometry::default();
        for i in 0..=100 {
            odom.on_speed(f64::from(i) * 0.01, 1.0, 0.0);
        }
        assert!((odom.x_m - 1.0).abs() < 1e-9 && odom.y_m.abs() < 1e-12);
        // Radius 1 m at 1 m/s: a quarter turn in π/2 s.
        let start = 1.0;
        let steps = 10_000;
        let dt = std::f64::consts::FRAC_PI_2 / f64::from(steps);
        for i in 0..=steps {
            odom.on_speed(start + f64::from(i) * dt, 1.0, 1.0);
        }
        assert!((odom.heading_rad - std::f64::consts::FRAC_PI_2).abs() < 1e-3, "{odom:?}");
        assert!((odom.x_m - 2.0).abs() < 1e-3 && (odom.y_m - 1.0).abs() < 1e-3, "{odom:?}");
    }
}
