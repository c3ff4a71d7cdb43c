//! `rmw_dds_common`: the ROS 2 graph on `ros_discovery_info`.
//!
//! Every ROS 2 participant publishes one [`ParticipantEntitiesInfo`] on the DDS topic
//! [`DISCOVERY_TOPIC`] (no `rt/` prefix; reliable, transient local, keep last 1): its nodes, and
//! the GIDs of each node's readers and writers, so that `ros2 node list` and `ros2 node info` can
//! name the nodes and map them to the endpoints DDS discovery reports. A GID is the endpoint's
//! 16-byte RTPS GUID (prefix, entity key, entity kind), zero-padded to the GID size: 16 bytes
//! from Iron on (Jazzy), 24 in Humble and before. Both layouts share one DDS type name, so a
//! deployment picks one ([`GID_LEN_JAZZY`], [`GID_LEN_HUMBLE`]).
//!
//! ```
//! use robowire_core::cdr::{CdrEncoding, CdrType};
//! use ros2_proto::rmw_dds_common::{Gid, NodeEntitiesInfo, ParticipantEntitiesInfo};
//!
//! let guid = |entity: [u8; 4]| {
//!     let mut g = [0u8; 16];
//!     g[..12].copy_from_slice(&[1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12]);
//!     g[12..].copy_from_slice(&entity);
//!     g
//! };
//! let info = ParticipantEntitiesInfo::<16> {
//!     gid: Gid::from_guid(guid([0, 0, 1, 0xc1])),
//!     node_entities_info_seq: vec![NodeEntitiesInfo {
//!         node_namespace: "/".into(),
//!         node_name: "robowire".into(),
//!         reader_gid_seq: vec![Gid::from_guid(guid([0, 0, 0x12, 0x04]))],
//!         writer_gid_seq: vec![Gid::from_guid(guid([0, 0, 0x10, 0x03]))],
//!     }],
//! };
//! let mut body = vec![0u8; info.body_len()];
//! info.encode_body(&mut body).unwrap();
//! assert_eq!(ParticipantEntitiesInfo::<16>::decode_body(CdrEncoding::Xcdr1, &body).unwrap(), info);
//! // The same sample in Humble's layout is not a Jazzy one.
//! assert!(ParticipantEntitiesInfo::<24>::decode_body(CdrEncoding::Xcdr1, &body).is_err());
//! ```

use alloc::string::String;
use alloc::vec::Vec;

use robowire_core::cdr::{CdrError, CdrReader, CdrWriter};

use crate::CdrValue;

/// The DDS topic of the ROS 2 graph (created without ROS's `rt/` prefix).
pub const DISCOVERY_TOPIC: &str = "ros_discovery_info";

/// The bound of a node's namespace and name (`string<256>`), bytes without the NUL.
pub const NAME_BOUND: usize = 256;

/// GID size from Iron on (Jazzy, Rolling): the GUID.
pub const GID_LEN_JAZZY: usize = 16;

/// GID size in Humble: the GUID and 8 zero bytes.
pub const GID_LEN_HUMBLE: usize = 24;

/// `rmw_dds_common/Gid`: an entity's GUID in `N` bytes (`char[N]`, alignment 1).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct Gid<const N: usize>(pub [u8; N]);

impl<const N: usize> Gid<N> {
    /// The GID of the entity whose RTPS GUID (wire order: prefix 12, entity key 3, kind 1) is
    /// `guid`: its bytes, zero-padded to `N` (cut to `N` if `N` < 16).
    pub fn from_guid(guid: [u8; 16]) -> Self {
        let mut gid = [0u8; N];
        let n = N.min(16);
        gid[..n].copy_from_slice(&guid[..n]);
        Self(gid)
    }
}

impl<const N: usize> CdrValue for Gid<N> {
    const MIN_LEN: usize = N;
    fn write(&self, w: &mut CdrWriter<'_>) {
        w.bytes(1, &self.0);
    }
    fn read(r: &mut CdrReader<'_>, field: &'static str) -> Result<Self, CdrError> {
        let mut gid = [0u8; N];
        gid.copy_from_slice(r.take(field, 1, N)?);
        Ok(Self(gid))
    }
}

/// `rmw_dds_common/NodeEntitiesInfo`: one node and its endpoints.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct NodeEntitiesInfo<const N: usize> {
    /// The namespace, `/` for the root; at most [`NAME_BOUND`] bytes (decoding refuses more;
    /// encoding writes what it is given).
    pub node_namespace: String,
    /// The node's name; at most [`NAME_BOUND`] bytes.
    pub node_name: String,
    /// The GIDs of the node's readers (a service's request reader among them).
    pub reader_gid_seq: Vec<Gid<N>>,
    /// The GIDs of the node's writers (a service's reply writer among them).
    pub writer_gid_seq: Vec<Gid<N>>,
}

impl<const N: usize> CdrValue for NodeEntitiesInfo<N> {
    const MIN_LEN: usize = 2 * String::MIN_LEN + 2 * <Vec<Gid<N>>>::MIN_LEN;
    fn write(&self, w: &mut CdrWriter<'_>) {
        self.node_namespace.write(w);
        self.node_name.write(w);
        self.reader_gid_seq.write(w);
        self.writer_gid_seq.write(w);
    }
    fn read(r: &mut CdrReader<'_>, _field: &'static str) -> Result<Self, CdrError> {
        Ok(Self {
            node_namespace: r.bounded_string("NodeEntitiesInfo.node_namespace", NAME_BOUND)?.into(),
            node_name: r.bounded_string("NodeEntitiesInfo.node_name", NAME_BOUND)?.into(),
            reader_gid_seq: CdrValue::read(r, "NodeEntitiesInfo.reader_gid_seq")?,
            writer_gid_seq: CdrValue::read(r, "NodeEntitiesInfo.writer_gid_seq")?,
        })
    }
}

/// `rmw_dds_common/ParticipantEntitiesInfo`: a participant's GID and all its nodes, the sample on
/// [`DISCOVERY_TOPIC`]. `N`: the GID size ([`GID_LEN_JAZZY`] or [`GID_LEN_HUMBLE`]).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ParticipantEntitiesInfo<const N: usize> {
    /// The participant's GID (its GUID prefix and entity `00 00 01 c1`).
    pub gid: Gid<N>,
    /// Its nodes; empty when it has none left.
    pub node_entities_info_seq: Vec<NodeEntitiesInfo<N>>,
}

impl<const N: usize> CdrValue for ParticipantEntitiesInfo<N> {
    const MIN_LEN: usize = N + <Vec<NodeEntitiesInfo<N>>>::MIN_LEN;
    fn write(&self, w: &mut CdrWriter<'_>) {
        self.gid.write(w);
        self.node_entities_info_seq.write(w);
    }
    fn read(r: &mut CdrReader<'_>, _field: &'static str) -> Result<Self, CdrError> {
        Ok(Self {
            gid: CdrValue::read(r, "ParticipantEntitiesInfo.gid")?,
            node_entities_info_seq: CdrValue::read(r, "ParticipantEntitiesInfo.node_entities_info_seq")?,
        })
    }
}

ros_message! {
    ParticipantEntitiesInfo<GID_LEN_JAZZY> => "rmw_dds_common::msg::dds_::ParticipantEntitiesInfo_";
    ParticipantEntitiesInfo<GID_LEN_HUMBLE> => "rmw_dds_common::msg::dds_::ParticipantEntitiesInfo_";
}

#[cfg(test)]
mod tests {
    use super::*;
    use alloc::vec;
    use robowire_core::cdr::{CdrEncoding, CdrType};

    const PREFIX: [u8; 12] = [1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12];

    fn guid(entity: [u8; 4]) -> [u8; 16] {
        let mut g = [0u8; 16];
        g[..12].copy_from_slice(&PREFIX);
        g[12..].copy_from_slice(&entity);
        g
    }

    /// The sample of the facts' example: one node `/` `robowire`, 1 reader, 2 writers.
    fn sample<const N: usize>() -> ParticipantEntitiesInfo<N> {
        ParticipantEntitiesInfo {
            gid: Gid::from_guid(guid([0, 0, 1, 0xc1])),
            node_entities_info_seq: vec![NodeEntitiesInfo {
                node_namespace: "/".into(),
                node_name: "robowire".into(),
                reader_gid_seq: vec![Gid::from_guid(guid([0, 0, 0x12, 0x04]))],
                writer_gid_seq: vec![
                    Gid::from_guid(guid([0, 0, 0x10, 0x03])),
                    Gid::from_guid(guid([0, 0, 0x11, 0x03])),
                ],
            }],
        }
    }

    /// The XCDR1 body with GIDs of `n` bytes, written out by hand from the IDL.
    fn golden(n: usize) -> Vec<u8> {
        let gid = |entity: [u8; 4]| {
            let mut g = guid(entity).to_vec();
            g.resize(n, 0);
            g
        };
        let mut body = gid([0, 0, 1, 0xc1]);
        body.extend([1, 0, 0, 0]); // one node (offset n: a multiple of 4)
        body.extend([2, 0, 0, 0, b'/', 0, 0, 0]); // "/" and 2 bytes of padding
        body.extend([9, 0, 0, 0]);
        body.extend(b"robowire\0\0\0\0"); // and 3 bytes of padding
        body.extend([1, 0, 0, 0]);
        body.extend(gid([0, 0, 0x12, 0x04]));
        body.extend([2, 0, 0, 0]);
        body.extend(gid([0, 0, 0x10, 0x03]));
        body.extend(gid([0, 0, 0x11, 0x03]));
        body
    }

    fn encode<T: CdrType>(message: &T) -> Vec<u8> {
        let mut body = vec![0u8; message.body_len()];
        assert_eq!(message.encode_body(&mut body), Ok(body.len()));
        body
    }

    /// The Jazzy body byte for byte, as laid out from the IDL (offsets on the left).
    const JAZZY: [u8; 100] = [
        1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 0x00, 0x00, 0x01, 0xc1, // 0: gid
        1, 0, 0, 0, // 16: one node
        2, 0, 0, 0, b'/', 0, 0, 0, // 20: "/" + padding
        9, 0, 0, 0, b'r', b'o', b'b', b'o', b'w', b'i', b'r', b'e', 0, 0, 0, 0, // 28: "robowire" + padding
        1, 0, 0, 0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 0x00, 0x00, 0x12, 0x04, // 44: one reader
        2, 0, 0, 0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 0x00, 0x00, 0x10, 0x03, // 64: two writers
        1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 0x00, 0x00, 0x11, 0x03,
    ];

    #[test]
    fn jazzy_and_humble_bodies_are_the_idls() {
        let jazzy = golden(16);
        assert_eq!(jazzy, JAZZY);
        assert_eq!(jazzy[..20], [1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 0, 0, 1, 0xc1, 1, 0, 0, 0]);
        assert_eq!(jazzy[28..44], *b"\x09\0\0\0robowire\0\0\0\0");
        assert_eq!(encode(&sample::<16>()), jazzy);
        assert_eq!(ParticipantEntitiesInfo::<16>::decode_body(CdrEncoding::Xcdr1, &jazzy), Ok(sample()));
        let humble = golden(24);
        assert_eq!(humble.len(), 132);
        assert_eq!(humble[16..28], [0, 0, 0, 0, 0, 0, 0, 0, 1, 0, 0, 0], "the GUID zero-padded, then the count");
        assert_eq!(encode(&sample::<24>()), humble);
        assert_eq!(ParticipantEntitiesInfo::<24>::decode_body(CdrEncoding::Xcdr1, &humble), Ok(sample()));
        assert_eq!(<ParticipantEntitiesInfo<16>>::TYPE_NAME, "rmw_dds_common::msg::dds_::ParticipantEntitiesInfo_");
        assert_eq!(<ParticipantEntitiesInfo<24>>::TYPE_NAME, <ParticipantEntitiesInfo<16>>::TYPE_NAME);
    }

    #[test]
    fn one_layout_does_not_read_as_the_other() {
        assert!(ParticipantEntitiesInfo::<24>::decode_body(CdrEncoding::Xcdr1, &golden(16)).is_err());
        assert!(ParticipantEntitiesInfo::<16>::decode_body(CdrEncoding::Xcdr1, &golden(24)).is_err());
        // No node: a Jazzy body's 20 bytes are too few for Humble; a Humble body read as Jazzy
        // leaves 8 bytes after the last field.
        let mut no_node = [7u8; 16].to_vec();
        no_node.extend([0, 0, 0, 0]);
        assert!(ParticipantEntitiesInfo::<24>::decode_body(CdrEncoding::Xcdr1, &no_node).is_err());
        no_node.splice(16..16, [0; 8]);
        assert!(ParticipantEntitiesInfo::<24>::decode_body(CdrEncoding::Xcdr1, &no_node).is_ok());
        assert_eq!(
            ParticipantEntitiesInfo::<16>::decode_body(CdrEncoding::Xcdr1, &no_node),
            Err(CdrError::Trailing { extra: 8 })
        );
    }

    #[test]
    fn bad_bodies_are_errors() {
        let jazzy = golden(16);
        for cut in 0..jazzy.len() - 7 {
            assert!(
                ParticipantEntitiesInfo::<16>::decode_body(CdrEncoding::Xcdr1, &jazzy[..cut]).is_err(),
                "cut at {cut}"
            );
        }
        let mut long = sample::<16>();
        long.node_entities_info_seq[0].node_name = "n".repeat(NAME_BOUND + 1);
        let body = encode(&long);
        assert_eq!(
            ParticipantEntitiesInfo::<16>::decode_body(CdrEncoding::Xcdr1, &body),
            Err(CdrError::Bound { field: "NodeEntitiesInfo.node_name", len: NAME_BOUND + 1, bound: NAME_BOUND })
        );
        long.node_entities_info_seq[0].node_name = "n".repeat(NAME_BOUND);
        assert!(ParticipantEntitiesInfo::<16>::decode_body(CdrEncoding::Xcdr1, &encode(&long)).is_ok());
        let mut lying = jazzy.clone();
        lying[16..20].copy_from_slice(&u32::MAX.to_le_bytes());
        assert!(matches!(
            ParticipantEntitiesInfo::<16>::decode_body(CdrEncoding::Xcdr1, &lying),
            Err(CdrError::Count { .. })
        ));
    }
}
