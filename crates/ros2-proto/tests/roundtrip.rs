//! Every message round-trips through its XCDR1 body; bad bodies are typed errors, never panics.

use proptest::prelude::*;
use robowire_core::cdr::{CdrEncoding, CdrError, CdrType};
use ros2_proto::builtin::{Header, Time};
use ros2_proto::diagnostic::{DiagnosticArray, DiagnosticStatus, KeyValue};
use ros2_proto::geometry::{
    Point, Pose, PoseWithCovariance, Quaternion, Transform, TransformStamped, Twist, TwistWithCovariance, Vector3,
};
use ros2_proto::nav::Odometry;
use ros2_proto::rmw_dds_common::{Gid, NodeEntitiesInfo, ParticipantEntitiesInfo};
use ros2_proto::sensor::{BatteryState, Imu, JointState};
use ros2_proto::srv::{
    AnyTriggerRequest, RequestId, TriggerRequest, TriggerRequestBody, TriggerResponse, TriggerResponseBody,
};
use ros2_proto::tf::TfMessage;

fn round_trip<T: CdrType + PartialEq + std::fmt::Debug>(message: &T) -> Vec<u8> {
    let mut body = vec![0u8; message.body_len()];
    assert_eq!(message.encode_body(&mut body), Ok(body.len()));
    assert_eq!(&T::decode_body(CdrEncoding::Xcdr1, &body).unwrap(), message);
    for cut in 0..body.len().saturating_sub(7) {
        assert!(T::decode_body(CdrEncoding::Xcdr1, &body[..cut]).is_err(), "a body cut at {cut} is refused");
    }
    body
}

fn text() -> impl Strategy<Value = String> {
    "[a-z_/0-9]{0,12}"
}

fn header() -> impl Strategy<Value = Header> {
    (any::<i32>(), 0u32..1_000_000_000, text())
        .prop_map(|(sec, nanosec, frame_id)| Header { stamp: Time { sec, nanosec }, frame_id })
}

fn vector3() -> impl Strategy<Value = Vector3> {
    (-1e6..1e6f64, -1e6..1e6f64, -1e6..1e6f64).prop_map(|(x, y, z)| Vector3 { x, y, z })
}

fn quaternion() -> impl Strategy<Value = Quaternion> {
    (-1.0..1.0f64, -1.0..1.0f64, -1.0..1.0f64, -1.0..1.0f64).prop_map(|(x, y, z, w)| Quaternion { x, y, z, w })
}

/// A node: namespace, name, reader GUIDs, writer GUIDs.
type Node = (String, String, Vec<[u8; 16]>, Vec<[u8; 16]>);

fn covariance36() -> impl Strategy<Value = [f64; 36]> {
    prop::array::uniform32(-10.0..10.0f64).prop_map(|a| std::array::from_fn(|i| a[i % 32] * (i as f64 + 1.0)))
}

proptest! {
    #[test]
    fn twist(linear in vector3(), angular in vector3()) {
        let body = round_trip(&Twist { linear, angular });
        prop_assert_eq!(body.len(), 48);
    }

    #[test]
    fn odometry(header in header(), child in text(), p in vector3(), q in quaternion(), v in vector3(), w in vector3(), c1 in covariance36(), c2 in covariance36()) {
        round_trip(&Odometry {
            header,
            child_frame_id: child,
            pose: PoseWithCovariance { pose: Pose { position: Point { x: p.x, y: p.y, z: p.z }, orientation: q }, covariance: c1 },
            twist: TwistWithCovariance { twist: Twist { linear: v, angular: w }, covariance: c2 },
        });
    }

    #[test]
    fn tf(transforms in prop::collection::vec((header(), text(), vector3(), quaternion()), 0..4)) {
        let transforms = transforms.into_iter().map(|(header, child_frame_id, translation, rotation)| TransformStamped {
            header, child_frame_id, transform: Transform { translation, rotation },
        }).collect();
        round_trip(&TfMessage { transforms });
    }

    #[test]
    fn imu(header in header(), q in quaternion(), g in vector3(), a in vector3(), c in prop::array::uniform9(-1.0..1.0f64)) {
        round_trip(&Imu {
            header, orientation: q, orientation_covariance: c, angular_velocity: g,
            angular_velocity_covariance: c, linear_acceleration: a, linear_acceleration_covariance: c,
        });
    }

    #[test]
    fn joint_state(header in header(), joints in prop::collection::vec((text(), -10.0..10.0f64, -10.0..10.0f64, -50.0..50.0f64), 0..16)) {
        round_trip(&JointState {
            header,
            name: joints.iter().map(|j| j.0.clone()).collect(),
            position: joints.iter().map(|j| j.1).collect(),
            velocity: joints.iter().map(|j| j.2).collect(),
            effort: joints.iter().map(|j| j.3).collect(),
        });
    }

    #[test]
    fn battery_state(header in header(), v in 0.0..60.0f32, pct in 0.0..1.0f32, cells in prop::collection::vec(3.0..4.2f32, 0..15), present: bool, location in text()) {
        round_trip(&BatteryState {
            header, voltage: v, temperature: 25.0, current: -1.5, charge: 3.0, capacity: 5.0,
            design_capacity: 5.0, percentage: pct, power_supply_status: BatteryState::STATUS_DISCHARGING,
            power_supply_health: BatteryState::HEALTH_UNKNOWN, power_supply_technology: BatteryState::TECHNOLOGY_LION,
            present, cell_temperature: cells.clone(), cell_voltage: cells, location, serial_number: String::new(),
        });
    }

    #[test]
    fn diagnostics(header in header(), statuses in prop::collection::vec((0u8..4, text(), text(), prop::collection::vec((text(), text()), 0..3)), 0..4)) {
        let status = statuses.into_iter().map(|(level, name, message, values)| DiagnosticStatus {
            level, name, message, hardware_id: "kmc".into(),
            values: values.into_iter().map(|(key, value)| KeyValue { key, value }).collect(),
        }).collect();
        round_trip(&DiagnosticArray { header, status });
    }

    #[test]
    fn trigger(guid: u64, seq: i64, success: bool, message in text()) {
        let id = RequestId { guid, seq };
        prop_assert_eq!(round_trip(&TriggerRequest { id, structure_needs_at_least_one_member: 0 }).len(), 17);
        let with_header = round_trip(&TriggerResponse { id, success, message: message.clone() });
        prop_assert_eq!(round_trip(&TriggerRequestBody::default()).len(), 1, "rmw_fastrtps' bare request");
        let bare = round_trip(&TriggerResponseBody { success, message });
        prop_assert_eq!(&with_header[16..], &bare[..], "the two mappings differ by the 16-byte header only");
    }

    #[test]
    fn participant_entities_info(guid: [u8; 16], nodes in prop::collection::vec((text(), text(), prop::collection::vec(any::<[u8; 16]>(), 0..4), prop::collection::vec(any::<[u8; 16]>(), 0..4)), 0..4)) {
        fn info<const N: usize>(guid: [u8; 16], nodes: &[Node]) -> ParticipantEntitiesInfo<N> {
            ParticipantEntitiesInfo {
                gid: Gid::from_guid(guid),
                node_entities_info_seq: nodes.iter().map(|(ns, name, readers, writers)| NodeEntitiesInfo {
                    node_namespace: ns.clone(),
                    node_name: name.clone(),
                    reader_gid_seq: readers.iter().copied().map(Gid::from_guid).collect(),
                    writer_gid_seq: writers.iter().copied().map(Gid::from_guid).collect(),
                }).collect(),
            }
        }
        let jazzy = round_trip(&info::<16>(guid, &nodes));
        let humble = round_trip(&info::<24>(guid, &nodes));
        // GIDs are 16 or 24 bytes, both multiples of every alignment in the body: 8 more bytes each.
        let gids = 1 + nodes.iter().map(|n| n.2.len() + n.3.len()).sum::<usize>();
        prop_assert_eq!(humble.len(), jazzy.len() + 8 * gids);
    }

    #[test]
    fn arbitrary_bytes_never_panic(body in prop::collection::vec(any::<u8>(), 0..256)) {
        let _ = Odometry::decode_body(CdrEncoding::Xcdr1, &body);
        let _ = JointState::decode_body(CdrEncoding::Xcdr1, &body);
        let _ = TfMessage::decode_body(CdrEncoding::Xcdr1, &body);
        let _ = DiagnosticArray::decode_body(CdrEncoding::Xcdr1, &body);
        let _ = BatteryState::decode_body(CdrEncoding::Xcdr1, &body);
        let _ = ParticipantEntitiesInfo::<16>::decode_body(CdrEncoding::Xcdr1, &body);
        let _ = ParticipantEntitiesInfo::<24>::decode_body(CdrEncoding::Xcdr1, &body);
    }
}

#[test]
fn header_bytes_by_the_idl() {
    let header = Header { stamp: Time { sec: 1, nanosec: 2 }, frame_id: "odom".into() };
    let body = round_trip(&header);
    assert_eq!(body, [1, 0, 0, 0, 2, 0, 0, 0, 5, 0, 0, 0, b'o', b'd', b'o', b'm', 0]);
    assert_eq!(Header::TYPE_NAME, "std_msgs::msg::dds_::Header_");
}

#[test]
fn a_double_after_a_header_is_aligned_to_8_from_the_body_start() {
    // Odometry: header (17 bytes with "odom"), child_frame_id at 20 ("base_link": 4 + 10 → 34),
    // the pose's first double at 40.
    let odometry = Odometry {
        header: Header { stamp: Time::default(), frame_id: "odom".into() },
        child_frame_id: "base_link".into(),
        pose: PoseWithCovariance {
            pose: Pose { position: Point { x: 1.0, y: 0.0, z: 0.0 }, ..Pose::default() },
            ..PoseWithCovariance::default()
        },
        ..Odometry::default()
    };
    let body = round_trip(&odometry);
    assert_eq!(body[34..40], [0; 6], "padding");
    assert_eq!(body[40..48], 1.0f64.to_le_bytes());
    assert_eq!(body.len(), 40 + 7 * 8 + 36 * 8 + 6 * 8 + 36 * 8);
}

#[test]
fn xcdr2_and_lying_counts_are_refused() {
    assert_eq!(Twist::decode_body(CdrEncoding::Xcdr2, &[0; 48]), Err(CdrError::Encoding(CdrEncoding::Xcdr2)));
    let mut body = round_trip(&JointState::default());
    body[16..20].copy_from_slice(&u32::MAX.to_le_bytes()); // the name count, after 13 bytes of header and padding
    assert!(matches!(JointState::decode_body(CdrEncoding::Xcdr1, &body), Err(CdrError::Count { .. })));
    let mut body = round_trip(&TriggerResponse::default());
    body[16] = 7;
    assert!(matches!(TriggerResponse::decode_body(CdrEncoding::Xcdr1, &body), Err(CdrError::Bool { value: 7, .. })));
}

/// A Trigger request's mapping is told by its length: rmw_cyclonedds' header and struct (17
/// bytes, padded to 24 by some writers), rmw_fastrtps' bare struct (1 byte, padded up to 8);
/// anything between or shorter is refused.
#[test]
fn a_trigger_requests_mapping_is_told_by_its_length() {
    let id = RequestId { guid: 0x0110_3f5a_0000_0107, seq: 3 };
    let mut with_header = round_trip(&TriggerRequest { id, structure_needs_at_least_one_member: 0 });
    let decode = |body: &[u8]| AnyTriggerRequest::decode_body(CdrEncoding::Xcdr1, body);
    let expected = AnyTriggerRequest::WithHeader(TriggerRequest { id, structure_needs_at_least_one_member: 0 });
    assert_eq!(decode(&with_header), Ok(expected.clone()));
    with_header.resize(24, 0);
    assert_eq!(decode(&with_header), Ok(expected));
    let bare = AnyTriggerRequest::Bare(TriggerRequestBody::default());
    assert_eq!(decode(&[0]), Ok(bare.clone()));
    assert_eq!(decode(&[0; 8]), Ok(bare));
    for len in [0, 9, 12, 16] {
        assert!(decode(&vec![0; len]).is_err(), "{len} bytes: neither shape");
    }
    assert!(decode(&with_header[..20]).is_ok(), "17 to 24 bytes: the header's shape");
    assert!(AnyTriggerRequest::decode_body(CdrEncoding::Xcdr2, &[0]).is_err());
}
