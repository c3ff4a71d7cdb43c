//! One module per subcommand, as `robowire --help` lists them.

pub(crate) mod decode;
pub(crate) mod demo;
pub(crate) mod dog;
pub(crate) mod encode;
pub(crate) mod kmc;
pub(crate) mod shm;
pub(crate) mod sim;
