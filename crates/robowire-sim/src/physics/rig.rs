//! What the physics needs to know of a robot: its own model, which joint each motor turns,
//! the motors' torques, where it starts.

/// A robot as the physics drives it.
#[derive(Debug, Clone)]
pub struct Rig {
    /// The robot's name in messages (`"Go2"`).
    pub robot: &'static str,
    /// robowire's own MJCF of the robot (with its floor).
    pub mjcf: &'static str,
    /// The joint each motor slot turns, by name (a model's joint of that name or that name
    /// with `_joint` appended); `None`: a slot the robot does not drive.
    pub joints: Vec<Option<&'static str>>,
    /// Each motor's torque limit, N·m, by slot.
    pub tau_max_nm: Vec<f32>,
    /// Each motor's joint at the start, rad, by slot.
    pub start_pose_rad: Vec<f32>,
    /// The base's height above the floor at the start, m.
    pub base_height_m: f64,
    /// The motors whose joint's body (with the bodies below it) is a foot, in the order of the
    /// state's foot forces.
    pub feet: Vec<usize>,
}
