//! A robot's bodies as a tree of frames, each placed in its parent's frame and turned by its
//! hinge: what a viewer needs to draw a robot from its joints' positions (a
//! `robot_state_publisher`'s table). Codecs declare their robots' tables; the poses need `std`.
//!
//! ```
//! # #[cfg(feature = "std")] {
//! use robowire_core::kinematics::{Body, Hinge, Pose};
//!
//! // A calf 0.2 m below its thigh, turned about +y: at a quarter turn its foot points backward.
//! let calf = Body {
//!     name: "calf",
//!     parent: "thigh",
//!     origin_m: [0.0, 0.0, -0.2],
//!     rotation: Pose::IDENTITY.rotation,
//!     hinge: Some(Hinge { motor: 2, axis: [0.0, 1.0, 0.0] }),
//! };
//! let foot = Pose { translation_m: [0.0, 0.0, -0.2], ..Pose::IDENTITY };
//! let at = calf.pose(Some(core::f64::consts::FRAC_PI_2)).then(&foot);
//! assert!((at.translation_m[0] + 0.2).abs() < 1e-12 && (at.translation_m[2] + 0.2).abs() < 1e-12);
//! # }
//! ```

/// A robot's frames and where its joints' positions are in its state.
#[derive(Debug, Clone, Copy)]
pub struct Kinematics {
    /// The robot (`go2`): links whose device is so named are drawn with this table.
    pub robot: &'static str,
    /// The state message whose JSON holds the joints' positions (its schema name).
    pub state_schema: &'static str,
    /// Where, in that JSON, the array of motor states is (a JSON pointer: `/motor_state`); a
    /// motor's position is the field `q` (rad) of its element.
    pub motor_states_pointer: &'static str,
    /// Every body but the base, each after its parent. The base is `base`.
    pub bodies: &'static [Body],
}

/// One body: its frame's place in its parent's frame, and the hinge that turns it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Body {
    /// Its frame's name (`FR_thigh`).
    pub name: &'static str,
    /// The frame it hangs from (`base` for the root's children).
    pub parent: &'static str,
    /// Its origin in the parent's frame, m.
    pub origin_m: [f64; 3],
    /// Its orientation in the parent's frame with the hinge at 0, a unit quaternion (w, x, y, z).
    pub rotation: [f64; 4],
    /// The hinge at its origin; `None`: welded to the parent.
    pub hinge: Option<Hinge>,
}

/// A hinge: the motor that drives it and its axis.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Hinge {
    /// The motor slot whose position is the hinge's angle.
    pub motor: usize,
    /// The axis in the body's own frame, a unit vector; positive angles turn right-handed
    /// about it.
    pub axis: [f64; 3],
}

/// Where a frame is in another: a translation, m, then a rotation (unit quaternion, w x y z).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Pose {
    /// The frame's origin, m.
    pub translation_m: [f64; 3],
    /// Its orientation (w, x, y, z).
    pub rotation: [f64; 4],
}

impl Pose {
    /// The frame itself.
    pub const IDENTITY: Self = Self { translation_m: [0.0; 3], rotation: [1.0, 0.0, 0.0, 0.0] };

    /// `child`, given in this pose's frame, in this pose's parent frame.
    pub fn then(&self, child: &Pose) -> Pose {
        let moved = rotate(self.rotation, child.translation_m);
        Pose {
            translation_m: core::array::from_fn(|i| self.translation_m[i] + moved[i]),
            rotation: multiply(self.rotation, child.rotation),
        }
    }
}

#[cfg(feature = "std")]
impl Body {
    /// Its frame in its parent's with the hinge at `q_rad` (`None`: at 0; a welded body
    /// ignores it).
    pub fn pose(&self, q_rad: Option<f64>) -> Pose {
        let turned = match (self.hinge, q_rad) {
            (Some(hinge), Some(q)) => {
                let (sin, cos) = (q / 2.0).sin_cos();
                multiply(self.rotation, [cos, hinge.axis[0] * sin, hinge.axis[1] * sin, hinge.axis[2] * sin])
            }
            _ => self.rotation,
        };
        Pose { translation_m: self.origin_m, rotation: turned }
    }
}

/// The Hamilton product `a · b` of quaternions (w, x, y, z).
pub fn multiply(a: [f64; 4], b: [f64; 4]) -> [f64; 4] {
    let [aw, ax, ay, az] = a;
    let [bw, bx, by, bz] = b;
    [
        aw * bw - ax * bx - ay * by - az * bz,
        aw * bx + ax * bw + ay * bz - az * by,
        aw * by - ax * bz + ay * bw + az * bx,
        aw * bz + ax * by - ay * bx + az * bw,
    ]
}

/// `v` in the frame of orientation `q` (a unit quaternion, w x y z): `q⁻¹ v q`, the inverse of
/// [`rotate`] (a world vector as a body of that orientation sees it).
pub fn rotate_into(q: [f64; 4], v: [f64; 3]) -> [f64; 3] {
    let [w, x, y, z] = q;
    rotate([w, -x, -y, -z], v)
}

/// `v` turned by the unit quaternion `q` (w, x, y, z): `q v q⁻¹`.
pub fn rotate(q: [f64; 4], v: [f64; 3]) -> [f64; 3] {
    let [w, x, y, z] = q;
    let t = [2.0 * (y * v[2] - z * v[1]), 2.0 * (z * v[0] - x * v[2]), 2.0 * (x * v[1] - y * v[0])];
    [
        v[0] + w * t[0] + (y * t[2] - z * t[1]),
        v[1] + w * t[1] + (z * t[0] - x * t[2]),
        v[2] + w * t[2] + (x * t[1] - y * t[0]),
    ]
}

#[cfg(all(test, feature = "std"))]
mod tests {
    use core::f64::consts::FRAC_PI_2;

    use super::*;

    fn near(a: [f64; 3], b: [f64; 3]) -> bool {
        a.iter().zip(b).all(|(a, b)| (a - b).abs() < 1e-12)
    }

    #[test]
    fn a_hinge_turns_its_body_and_everything_below_it() {
        let hip = Body {
            name: "hip",
            parent: "base",
            origin_m: [0.2, -0.05, 0.0],
            rotation: Pose::IDENTITY.rotation,
            hinge: Some(Hinge { motor: 0, axis: [1.0, 0.0, 0.0] }),
        };
        let end = Pose { translation_m: [0.0, 0.0, -0.3], ..Pose::IDENTITY };
        // A quarter turn about +x takes −z to +y.
        assert!(near(hip.pose(Some(FRAC_PI_2)).then(&end).translation_m, [0.2, 0.25, 0.0]));
        // At 0, and for a welded body, only the offset.
        assert!(near(hip.pose(None).then(&end).translation_m, [0.2, -0.05, -0.3]));
        let welded = Body { hinge: None, ..hip };
        assert_eq!(welded.pose(Some(1.0)), Pose { translation_m: [0.2, -0.05, 0.0], ..Pose::IDENTITY });
    }

    #[test]
    fn a_body_s_own_rotation_comes_before_its_hinge() {
        // A body yawed a quarter turn, its hinge about its own x: that is the parent's y.
        let h = core::f64::consts::FRAC_PI_4;
        let body = Body {
            name: "b",
            parent: "base",
            origin_m: [0.0; 3],
            rotation: [h.cos(), 0.0, 0.0, h.sin()],
            hinge: Some(Hinge { motor: 0, axis: [1.0, 0.0, 0.0] }),
        };
        let tip = Pose { translation_m: [0.0, 0.0, 1.0], ..Pose::IDENTITY };
        // Turning about the parent's +y by a quarter turn takes +z to +x.
        assert!(near(body.pose(Some(FRAC_PI_2)).then(&tip).translation_m, [1.0, 0.0, 0.0]));
        let r = body.pose(Some(0.3)).rotation;
        assert!((r.iter().map(|c| c * c).sum::<f64>() - 1.0).abs() < 1e-12, "{r:?}");
    }
}
