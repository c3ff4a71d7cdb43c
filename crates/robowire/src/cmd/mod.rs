//! One module per subcommand, as `robowire --help` lists them.

pub(crate) mod dds;
pub(crate) mod decode;
pub(crate) mod demo;
pub(crate) mod dog;
pub(crate) mod encode;
pub(crate) mod go2;
pub(crate) mod kmc;
pub(crate) mod live;
pub(crate) mod record;
pub(crate) mod replay_device;
pub(crate) mod ros2;
pub(crate) mod shm;
pub(crate) mod sim;
