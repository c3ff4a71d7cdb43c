//! `nav_msgs/Odometry`.

use alloc::string::String;

use crate::builtin::Header;
use crate::geometry::{PoseWithCovariance, TwistWithCovariance};

ros_struct! {
    /// `nav_msgs/Odometry`: the pose in `header.frame_id` (`odom`), the twist in
    /// `child_frame_id` (`base_link`).
    #[derive(Default)]
    pub struct Odometry {
        /// Time and the pose's frame.
        pub header: Header,
        /// The twist's frame.
        pub child_frame_id: String,
        /// Pose, m and quaternion.
        pub pose: PoseWithCovariance,
        /// Twist, m/s and rad/s.
        pub twist: TwistWithCovariance,
    }
}

ros_message! {
    Odometry => "nav_msgs::msg::dds_::Odometry_";
}
