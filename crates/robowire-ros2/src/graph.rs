//! The bridge in the ROS 2 graph: one node per device on `ros_discovery_info`, so that
//! `ros2 node list`, `ros2 node info`, `ros2 topic info -v` and zenoh-bridge-ros2dds name the
//! devices' nodes and map them to their topics.
//!
//! As rmw does, the participant's whole [`ParticipantEntitiesInfo`] is written again whenever a
//! node gains a reader or a writer (the devices' writers are made on their first observation),
//! and with no node left when the bridge stops. Each endpoint is listed by its GID, its RTPS
//! GUID padded to the distribution's GID size ([`RosDistro`]). The participant announces its
//! enclave in its USER_DATA as rmw does ([`ENCLAVE_USER_DATA`]).

use std::sync::Mutex;

use robowire_core::cdr::CdrType;
use robowire_dds::qos::Qos;
use robowire_dds::{DdsError, Participant, RawSample, Reader, Writer};
use ros2_proto::rmw_dds_common::{
    DISCOVERY_TOPIC, GID_LEN_HUMBLE, GID_LEN_JAZZY, Gid, NodeEntitiesInfo, ParticipantEntitiesInfo,
};

use crate::error::BridgeError;

/// The participant USER_DATA of rmw's participants in the root enclave.
pub(crate) const ENCLAVE_USER_DATA: &[u8] = b"enclave=/;";

/// The name of every device's node (in the device's namespace: `/kmc0/robowire`).
pub const NODE_NAME: &str = "robowire";

/// The ROS 2 distribution whose `ros_discovery_info` layout the bridge writes: the GID is 24
/// bytes in Humble, 16 from Iron on (Jazzy). Both have one DDS type name, so peers of the other
/// layout cannot read the bridge's nodes (and the bridge warns when it sees one).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum RosDistro {
    /// Humble: 24-byte GIDs.
    Humble,
    /// Jazzy (and Iron, Kilted, Rolling): 16-byte GIDs.
    #[default]
    Jazzy,
}

impl RosDistro {
    /// The GID size, bytes.
    pub fn gid_len(self) -> usize {
        match self {
            Self::Humble => GID_LEN_HUMBLE,
            Self::Jazzy => GID_LEN_JAZZY,
        }
    }

    /// The distribution of the other layout.
    pub fn other(self) -> Self {
        match self {
            Self::Humble => Self::Jazzy,
            Self::Jazzy => Self::Humble,
        }
    }

    /// The layout of a distribution as `$ROS_DISTRO` names it: `humble`, or one of Iron and later
    /// (`iron`, `jazzy`, `kilted`, `rolling`: 16-byte GIDs, Jazzy's layout).
    pub fn of_environment(ros_distro: &str) -> Result<Self, UnknownDistro> {
        match ros_distro {
            "iron" | "kilted" | "rolling" => Ok(Self::Jazzy),
            other => other.parse(),
        }
    }

    /// `humble` or `jazzy`.
    pub fn name(self) -> &'static str {
        match self {
            Self::Humble => "humble",
            Self::Jazzy => "jazzy",
        }
    }
}

impl std::fmt::Display for RosDistro {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

/// A distribution name that is neither `humble` nor `jazzy`.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("unknown ROS 2 distribution {0:?}: humble (24-byte GIDs) or jazzy (16-byte GIDs, also for iron and later)")]
pub struct UnknownDistro(pub String);

impl std::str::FromStr for RosDistro {
    type Err = UnknownDistro;
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        match s {
            "humble" => Ok(Self::Humble),
            "jazzy" => Ok(Self::Jazzy),
            other => Err(UnknownDistro(other.into())),
        }
    }
}

/// A node's place in the graph.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) struct NodeId(usize);

/// One node and the GUIDs of its endpoints.
#[derive(Debug)]
struct NodeEntry {
    namespace: String,
    readers: Vec<[u8; 16]>,
    writers: Vec<[u8; 16]>,
}

impl NodeEntry {
    fn info<const N: usize>(&self) -> NodeEntitiesInfo<N> {
        let gids = |guids: &[[u8; 16]]| guids.iter().copied().map(Gid::from_guid).collect();
        NodeEntitiesInfo {
            node_namespace: self.namespace.clone(),
            node_name: NODE_NAME.into(),
            reader_gid_seq: gids(&self.readers),
            writer_gid_seq: gids(&self.writers),
        }
    }
}

/// The writer of `ros_discovery_info` in the distribution's layout.
enum GraphWriter {
    Humble(Writer<ParticipantEntitiesInfo<GID_LEN_HUMBLE>>),
    Jazzy(Writer<ParticipantEntitiesInfo<GID_LEN_JAZZY>>),
}

/// The participant's nodes on `ros_discovery_info`. Changed only when a device makes an endpoint
/// (never on a stream thread); the lock orders the samples written.
pub(crate) struct RosGraph {
    distro: RosDistro,
    participant: [u8; 16],
    writer: GraphWriter,
    nodes: Mutex<Vec<NodeEntry>>,
}

/// `ros_discovery_info`'s writer QoS (rmw's): reliable, transient local, keep last 1.
const WRITER_QOS: Qos = Qos::ROS_TF_STATIC;

/// `ros_discovery_info`'s reader QoS: reliable and transient local as rmw's (keep-all there; a
/// few samples here, only looked at).
const READER_QOS: Qos = Qos { depth: 16, ..Qos::ROS_TF_STATIC };

impl RosGraph {
    /// The graph of `participant`, with no node yet.
    pub(crate) fn new(participant: &Participant, distro: RosDistro) -> Result<Self, DdsError> {
        let writer = match distro {
            RosDistro::Humble => GraphWriter::Humble(participant.writer(DISCOVERY_TOPIC, WRITER_QOS)?),
            RosDistro::Jazzy => GraphWriter::Jazzy(participant.writer(DISCOVERY_TOPIC, WRITER_QOS)?),
        };
        Ok(Self { distro, participant: participant.guid(), writer, nodes: Mutex::default() })
    }

    /// A node in `namespace` (`""` or `/ns`, at most
    /// [`NAME_BOUND`](ros2_proto::rmw_dds_common::NAME_BOUND) bytes: peers refuse a sample with a
    /// longer one), listed once it has an endpoint.
    pub(crate) fn add_node(&self, namespace: &str) -> NodeId {
        let namespace = if namespace.is_empty() { "/".to_owned() } else { namespace.to_owned() };
        let mut nodes = robowire_rt::lock(&self.nodes);
        nodes.push(NodeEntry { namespace, readers: Vec::new(), writers: Vec::new() });
        NodeId(nodes.len() - 1)
    }

    /// Lists the reader `guid` under `node` and writes the graph.
    pub(crate) fn add_reader(&self, node: NodeId, guid: [u8; 16]) -> Result<(), DdsError> {
        self.change(|nodes| nodes.get_mut(node.0).into_iter().for_each(|n| n.readers.push(guid)))
    }

    /// Lists the writer `guid` under `node` and writes the graph.
    pub(crate) fn add_writer(&self, node: NodeId, guid: [u8; 16]) -> Result<(), DdsError> {
        self.change(|nodes| nodes.get_mut(node.0).into_iter().for_each(|n| n.writers.push(guid)))
    }

    /// Removes every node and writes the graph (no node left), waiting at most `wait` for the
    /// readers to acknowledge it.
    pub(crate) async fn stop(&self, wait: std::time::Duration) -> Result<(), DdsError> {
        self.change(Vec::clear)?;
        let acknowledged = async {
            match &self.writer {
                GraphWriter::Humble(w) => w.acknowledged().await,
                GraphWriter::Jazzy(w) => w.acknowledged().await,
            }
        };
        let _ = tokio::time::timeout(wait, acknowledged).await;
        Ok(())
    }

    fn change(&self, edit: impl FnOnce(&mut Vec<NodeEntry>)) -> Result<(), DdsError> {
        let mut nodes = robowire_rt::lock(&self.nodes);
        edit(&mut nodes);
        // Nodes with no endpoint yet are left out, as rmw lists a node once it exists with
        // its endpoints; ours exist for their endpoints.
        let listed = nodes.iter().filter(|n| !n.readers.is_empty() || !n.writers.is_empty());
        match &self.writer {
            GraphWriter::Humble(w) => w.write(self.sample(listed)),
            GraphWriter::Jazzy(w) => w.write(self.sample(listed)),
        }
    }

    fn sample<'a, const N: usize>(&self, nodes: impl Iterator<Item = &'a NodeEntry>) -> ParticipantEntitiesInfo<N> {
        ParticipantEntitiesInfo {
            gid: Gid::from_guid(self.participant),
            node_entities_info_seq: nodes.map(NodeEntry::info).collect(),
        }
    }

    /// Reads other participants' `ros_discovery_info` until `stop` resolves, and says once on
    /// stderr when one is in the other distribution's layout (its nodes are then not the
    /// bridge's peers' and the bridge's are not theirs).
    pub(crate) async fn warn_on_other_layout(
        &self,
        participant: &Participant,
        stop: impl Future<Output = ()>,
    ) -> Result<(), BridgeError> {
        let mut reader: Reader<RawSample> =
            participant.raw_reader(DISCOVERY_TOPIC, <ParticipantEntitiesInfo<GID_LEN_JAZZY>>::TYPE_NAME, READER_QOS)?;
        tokio::pin!(stop);
        loop {
            tokio::select! {
                () = &mut stop => return Ok(()),
                sample = reader.recv() => {
                    // The reader gone: nothing more to look at (the bridge goes on).
                    let Ok(sample) = sample else { break };
                    if sample.writer[..12] != self.participant[..12] && other_layout(self.distro, &sample.value) {
                        let (own, other) = (self.distro, self.distro.other());
                        eprintln!(
                            "ros2: a participant ({}) writes ros_discovery_info with {}-byte GIDs ({other}); this bridge writes \
                             {}-byte GIDs ({own}): ROS 2 tools there will not see this bridge's nodes (--ros-distro {other})",
                            hex(&sample.writer[..12]),
                            other.gid_len(),
                            own.gid_len(),
                        );
                        break;
                    }
                }
            }
        }
        stop.await;
        Ok(())
    }
}

/// Whether `sample` reads only in the layout that is not `distro`'s.
pub(crate) fn other_layout(distro: RosDistro, sample: &RawSample) -> bool {
    fn reads<T: CdrType>(sample: &RawSample) -> bool {
        T::decode_body(sample.encoding, &sample.body).is_ok()
    }
    let humble = reads::<ParticipantEntitiesInfo<GID_LEN_HUMBLE>>(sample);
    let jazzy = reads::<ParticipantEntitiesInfo<GID_LEN_JAZZY>>(sample);
    let (own, other) = match distro {
        RosDistro::Humble => (humble, jazzy),
        RosDistro::Jazzy => (jazzy, humble),
    };
    other && !own
}

fn hex(bytes: &[u8]) -> String {
    bytes.iter().map(|b| format!("{b:02x}")).collect::<Vec<_>>().join(".")
}

#[cfg(test)]
mod tests {
    use super::*;
    use robowire_core::cdr::CdrEncoding;

    fn body<const N: usize>(nodes: usize) -> RawSample
    where
        ParticipantEntitiesInfo<N>: CdrType,
    {
        let node = NodeEntry { namespace: "/kmc0".into(), readers: vec![[4; 16]], writers: vec![[3; 16], [5; 16]] };
        let info = ParticipantEntitiesInfo::<N> {
            gid: Gid::from_guid([1; 16]),
            node_entities_info_seq: (0..nodes).map(|_| node.info()).collect(),
        };
        let mut body = vec![0u8; info.body_len()];
        info.encode_body(&mut body).unwrap();
        RawSample { encoding: CdrEncoding::Xcdr1, body }
    }

    #[test]
    fn a_sample_of_the_other_layout_is_told_apart() {
        for nodes in 0..3 {
            let (humble, jazzy) = (body::<GID_LEN_HUMBLE>(nodes), body::<GID_LEN_JAZZY>(nodes));
            assert!(other_layout(RosDistro::Jazzy, &humble), "{nodes} nodes");
            assert!(!other_layout(RosDistro::Jazzy, &jazzy));
            assert!(other_layout(RosDistro::Humble, &jazzy));
            assert!(!other_layout(RosDistro::Humble, &humble));
        }
        let garbage = RawSample { encoding: CdrEncoding::Xcdr1, body: vec![0xff; 40] };
        assert!(!other_layout(RosDistro::Jazzy, &garbage) && !other_layout(RosDistro::Humble, &garbage));
    }

    #[test]
    fn distributions_by_name() {
        assert_eq!("humble".parse(), Ok(RosDistro::Humble));
        assert_eq!("jazzy".parse(), Ok(RosDistro::Jazzy));
        assert_eq!("iron".parse::<RosDistro>(), Err(UnknownDistro("iron".into())));
        assert_eq!((RosDistro::Humble.gid_len(), RosDistro::default().gid_len()), (24, 16));
        assert!(UnknownDistro("x".into()).to_string().contains("humble"));
    }
}
