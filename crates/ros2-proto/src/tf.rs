//! `tf2_msgs/TFMessage`, what `/tf` and `/tf_static` carry.

use alloc::vec::Vec;

use crate::geometry::TransformStamped;

ros_struct! {
    /// `tf2_msgs/TFMessage`.
    #[derive(Default)]
    pub struct TfMessage {
        /// The transforms.
        pub transforms: Vec<TransformStamped>,
    }
}

ros_message! {
    TfMessage => "tf2_msgs::msg::dds_::TFMessage_";
}
