//! `geometry_msgs`: vectors, poses, twists, transforms (m, rad, m/s, rad/s).

use crate::builtin::Header;

ros_struct! {
    /// `geometry_msgs/Vector3`.
    #[derive(Default, Copy)]
    pub struct Vector3 {
        /// x.
        pub x: f64,
        /// y.
        pub y: f64,
        /// z.
        pub z: f64,
    }
}

ros_struct! {
    /// `geometry_msgs/Point`, m.
    #[derive(Default, Copy)]
    pub struct Point {
        /// x, m.
        pub x: f64,
        /// y, m.
        pub y: f64,
        /// z, m.
        pub z: f64,
    }
}

ros_struct! {
    /// `geometry_msgs/Quaternion` (x, y, z, w); the default is the identity.
    #[derive(Copy)]
    pub struct Quaternion {
        /// x.
        pub x: f64,
        /// y.
        pub y: f64,
        /// z.
        pub z: f64,
        /// w.
        pub w: f64,
    }
}

impl Default for Quaternion {
    fn default() -> Self {
        Self { x: 0.0, y: 0.0, z: 0.0, w: 1.0 }
    }
}

impl Quaternion {
    /// The rotation by roll, pitch, yaw (rad, applied yaw, then pitch, then roll: ROS's RPY).
    pub fn from_rpy(roll: f64, pitch: f64, yaw: f64) -> Self {
        let (sr, cr) = libm_sin_cos(roll / 2.0);
        let (sp, cp) = libm_sin_cos(pitch / 2.0);
        let (sy, cy) = libm_sin_cos(yaw / 2.0);
        Self {
            x: sr * cp * cy - cr * sp * sy,
            y: cr * sp * cy + sr * cp * sy,
            z: cr * cp * sy - sr * sp * cy,
            w: cr * cp * cy + sr * sp * sy,
        }
    }
}

/// sin and cos without std (a short Taylor series after range reduction: |error| < 1e-12).
fn libm_sin_cos(x: f64) -> (f64, f64) {
    use core::f64::consts::{PI, TAU};
    let mut a = x % TAU;
    if a > PI {
        a -= TAU;
    } else if a < -PI {
        a += TAU;
    }
    let (mut sin, mut cos, mut term_s, mut term_c) = (0.0, 0.0, a, 1.0);
    for n in 0..12 {
        sin += term_s;
        cos += term_c;
        let k = f64::from(2 * n + 2);
        term_s *= -a * a / (k * (k + 1.0));
        term_c *= -a * a / ((k - 1.0) * k);
    }
    (sin, cos)
}

ros_struct! {
    /// `geometry_msgs/Pose`.
    #[derive(Default, Copy)]
    pub struct Pose {
        /// Position, m.
        pub position: Point,
        /// Orientation.
        pub orientation: Quaternion,
    }
}

ros_struct! {
    /// `geometry_msgs/PoseWithCovariance`: the covariance row-major over (x, y, z, roll, pitch, yaw).
    #[derive(Copy)]
    pub struct PoseWithCovariance {
        /// The pose.
        pub pose: Pose,
        /// 6×6 covariance, row-major.
        pub covariance: [f64; 36],
    }
}

ros_struct! {
    /// `geometry_msgs/Twist`: linear m/s, angular rad/s.
    #[derive(Default, Copy)]
    pub struct Twist {
        /// Linear velocity, m/s.
        pub linear: Vector3,
        /// Angular velocity, rad/s.
        pub angular: Vector3,
    }
}

ros_struct! {
    /// `geometry_msgs/TwistWithCovariance`.
    #[derive(Copy)]
    pub struct TwistWithCovariance {
        /// The twist.
        pub twist: Twist,
        /// 6×6 covariance, row-major.
        pub covariance: [f64; 36],
    }
}

impl Default for PoseWithCovariance {
    fn default() -> Self {
        Self { pose: Pose::default(), covariance: [0.0; 36] }
    }
}

impl Default for TwistWithCovariance {
    fn default() -> Self {
        Self { twist: Twist::default(), covariance: [0.0; 36] }
    }
}

ros_struct! {
    /// `geometry_msgs/Transform`.
    #[derive(Default, Copy)]
    pub struct Transform {
        /// Translation, m.
        pub translation: Vector3,
        /// Rotation.
        pub rotation: Quaternion,
    }
}

ros_struct! {
    /// `geometry_msgs/TransformStamped`: `header.frame_id` → `child_frame_id`.
    #[derive(Default)]
    pub struct TransformStamped {
        /// Time and parent frame.
        pub header: Header,
        /// Child frame.
        pub child_frame_id: alloc::string::String,
        /// The child frame's pose in the parent frame.
        pub transform: Transform,
    }
}

ros_message! {
    Twist => "geometry_msgs::msg::dds_::Twist_";
    TransformStamped => "geometry_msgs::msg::dds_::TransformStamped_";
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rpy_to_quaternion_matches_known_rotations() {
        let q = Quaternion::from_rpy(0.0, 0.0, core::f64::consts::FRAC_PI_2);
        let h = core::f64::consts::FRAC_1_SQRT_2;
        assert!((q.z - h).abs() < 1e-12 && (q.w - h).abs() < 1e-12 && q.x.abs() < 1e-12 && q.y.abs() < 1e-12);
        let q = Quaternion::from_rpy(0.3, -0.2, 2.5);
        assert!(((q.x * q.x + q.y * q.y + q.z * q.z + q.w * q.w) - 1.0).abs() < 1e-12);
        let (s, c) = libm_sin_cos(7.0);
        assert!((s - 0.6569865987187891).abs() < 1e-12 && (c - 0.7539022543433046).abs() < 1e-12);
    }
}
