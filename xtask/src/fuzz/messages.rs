//! Seed messages for the decoders no golden fixture covers (the ROS 2 messages, the HG
//! low-level messages, the services' requests and answers), made with the codecs from values
//! like those robowire's bridges and simulators send.

use ros2_proto::builtin::{Header, Time};
use ros2_proto::decode_roundtrip::input;
use ros2_proto::diagnostic::{DiagnosticArray, DiagnosticStatus, KeyValue};
use ros2_proto::geometry::{
    Point, Pose, PoseWithCovariance, Quaternion, Transform, TransformStamped, Twist, TwistWithCovariance, Vector3,
};
use ros2_proto::nav::Odometry;
use ros2_proto::rmw_dds_common::{Gid, NodeEntitiesInfo, ParticipantEntitiesInfo};
use ros2_proto::sensor::{BatteryState, Imu, JointState};
use ros2_proto::srv::{RequestId, TriggerRequest, TriggerRequestBody, TriggerResponse, TriggerResponseBody};
use ros2_proto::tf::TfMessage;
use unitree_proto::api::{self, Request, RequestHeader, Response};
use unitree_proto::robot::GO2_JOINT_NAMES;
use unitree_proto::{BufferTooSmall, CdrEncoding, Message};

/// A named seed input.
type Seed = (String, Vec<u8>);

fn header(frame_id: &str) -> Header {
    Header { stamp: Time::from_nanos(1_700_000_000_123_456_789), frame_id: frame_id.into() }
}

fn transform(child: &str, x_m: f64, yaw_rad: f64) -> TransformStamped {
    TransformStamped {
        header: header("odom"),
        child_frame_id: child.into(),
        transform: Transform {
            translation: Vector3 { x: x_m, y: -0.25, z: 0.3 },
            rotation: Quaternion::from_rpy(0.0, 0.0, yaw_rad),
        },
    }
}

/// Every ROS 2 message: its default and one as a bridge sends it, each as a
/// `ros2_proto::decode_roundtrip` input (selector, XCDR1 body).
pub(super) fn ros2_seeds() -> Vec<Seed> {
    let twist = Twist { linear: Vector3 { x: 0.5, y: 0.0, z: 0.0 }, angular: Vector3 { x: 0.0, y: 0.0, z: 0.3 } };
    let mut covariance = [0.0; 36];
    covariance.iter_mut().step_by(7).for_each(|c| *c = 1e-3);
    let odometry = Odometry {
        header: header("odom"),
        child_frame_id: "base_link".into(),
        pose: PoseWithCovariance {
            pose: Pose {
                position: Point { x: 1.5, y: -0.25, z: 0.0 },
                orientation: Quaternion::from_rpy(0.0, 0.0, 0.7),
            },
            covariance,
        },
        twist: TwistWithCovariance { twist, covariance },
    };
    let imu = Imu {
        header: header("imu_link"),
        orientation: Quaternion::from_rpy(0.01, -0.02, 1.2),
        orientation_covariance: [-1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0],
        angular_velocity: Vector3 { x: 0.001, y: -0.002, z: 0.3 },
        linear_acceleration: Vector3 { x: 0.1, y: 0.0, z: 9.81 },
        ..Imu::default()
    };
    let joints = JointState {
        header: header(""),
        name: GO2_JOINT_NAMES.iter().map(|n| format!("{n}_joint")).collect(),
        position: (0..12).map(|i| f64::from(i) * 0.1 - 0.6).collect(),
        velocity: vec![0.0; 12],
        effort: vec![f64::NAN; 12],
    };
    let mut battery = BatteryState::unmeasured(header("battery"));
    battery.voltage = 25.2;
    battery.percentage = 0.87;
    battery.cell_voltage = vec![4.2; 6];
    let diagnostics = DiagnosticArray {
        header: header(""),
        status: vec![
            DiagnosticStatus {
                level: DiagnosticStatus::OK,
                name: "kmc/link".into(),
                message: "ok".into(),
                hardware_id: "kmc".into(),
                values: vec![KeyValue { key: "frames".into(), value: "1024".into() }],
            },
            DiagnosticStatus {
                level: DiagnosticStatus::ERROR,
                name: "kmc/motor 1".into(),
                message: "over current".into(),
                hardware_id: "kmc".into(),
                values: Vec::new(),
            },
        ],
    };
    let id = RequestId { guid: 0x0110_3f5a_0000_0107, seq: 1 };
    let refused = TriggerResponse { id, success: false, message: "refused: the guard holds the robot".into() };
    // The bridge's graph: one node with a reader and a writer (GUIDs of a rustdds participant).
    fn guid(entity: [u8; 4]) -> [u8; 16] {
        let mut g = [0x01, 0x0f, 0x3a, 0x5b, 0, 0, 0, 7, 0, 0, 0, 1, 0, 0, 0, 0];
        g[12..].copy_from_slice(&entity);
        g
    }
    fn graph<const N: usize>(namespace: &str) -> ParticipantEntitiesInfo<N> {
        ParticipantEntitiesInfo {
            gid: Gid::from_guid(guid([0, 0, 1, 0xc1])),
            node_entities_info_seq: vec![NodeEntitiesInfo {
                node_namespace: namespace.into(),
                node_name: "robowire".into(),
                reader_gid_seq: vec![Gid::from_guid(guid([0, 0, 1, 4]))],
                writer_gid_seq: vec![Gid::from_guid(guid([0, 0, 2, 3]))],
            }],
        }
    }
    let seeds = [
        ("header-default", input(&Header::default())),
        ("header", input(&header("odom"))),
        ("twist-default", input(&Twist::default())),
        ("twist", input(&twist)),
        ("transform", input(&transform("base_link", 1.5, 0.7))),
        ("odometry-default", input(&Odometry::default())),
        ("odometry", input(&odometry)),
        ("tf-default", input(&TfMessage::default())),
        (
            "tf",
            input(&TfMessage { transforms: vec![transform("base_link", 1.5, 0.7), transform("imu_link", 0.0, 0.0)] }),
        ),
        ("imu-default", input(&Imu::default())),
        ("imu", input(&imu)),
        ("joint-state-default", input(&JointState::default())),
        ("joint-state", input(&joints)),
        ("battery-state-default", input(&BatteryState::default())),
        ("battery-state", input(&battery)),
        ("diagnostics-default", input(&DiagnosticArray::default())),
        ("diagnostics", input(&diagnostics)),
        ("trigger-request", input(&TriggerRequest { id, structure_needs_at_least_one_member: 0 })),
        ("trigger-response-default", input(&TriggerResponse::default())),
        ("trigger-response", input(&refused)),
        ("participant-entities-jazzy", input(&graph::<16>("/kmc0"))),
        ("participant-entities-humble", input(&graph::<24>("/"))),
        ("trigger-request-body", input(&TriggerRequestBody::default())),
        ("trigger-response-body", input(&TriggerResponseBody { success: refused.success, message: refused.message })),
    ];
    seeds.into_iter().map(|(name, input)| (format!("seed-{name}"), input)).collect()
}

/// Service bodies (name, whether a request, body): requests and answers of `motion_switcher`
/// and `sport`.
fn api_bodies() -> Vec<(&'static str, bool, Vec<u8>)> {
    let check = RequestHeader::call(1_700_000_000_123, api::motion_switcher::CHECK_MODE);
    let select =
        RequestHeader { lease_id: 7, priority: 1, ..RequestHeader::call(2, api::motion_switcher::SELECT_MODE) };
    let stand = RequestHeader { noreply: true, ..RequestHeader::call(3, api::sport::STAND_UP) };
    let check_data = api::motion_switcher::check_mode_data("normal").to_string();
    let requests = [
        ("check-mode", Request { header: check, parameter: "{}", binary: &[] }),
        ("select-mode", Request { header: select, parameter: r#"{"name":"ai"}"#, binary: &[1, 2, 3] }),
        ("stand-up", Request { header: stand, parameter: "", binary: &[] }),
    ];
    let responses = [
        ("check-mode-answer", Response::to(&check, api::status::OK, &check_data)),
        (
            "select-mode-refused",
            Response { binary: &[0xff], ..Response::to(&select, api::status::SERVER_API_PARAMETER, "") },
        ),
    ];
    let body = |len: usize, encode: &dyn Fn(&mut [u8]) -> Result<usize, BufferTooSmall>| {
        let mut out = vec![0u8; len];
        encode(&mut out).expect("body_len is the length written");
        out
    };
    let requests = requests.iter().map(|(name, r)| (*name, true, body(r.body_len(), &|out| r.encode_body(out))));
    let responses = responses.iter().map(|(name, r)| (*name, false, body(r.body_len(), &|out| r.encode_body(out))));
    requests.chain(responses).collect()
}

/// `unitree_proto::decode_roundtrip::api_decode` inputs: selector 0 (request) or 1 (answer),
/// the body.
pub(super) fn api_seeds() -> Vec<Seed> {
    api_bodies()
        .into_iter()
        .map(|(name, request, body)| (format!("seed-{name}"), [&[u8::from(!request)][..], &body].concat()))
        .collect()
}

/// `unitree::fuzz_receive` inputs that no golden vector gives: HG `LowCmd_` and
/// `LowState_` (selectors 2, 3), default and filled with a byte pattern, and the service bodies
/// (selectors 4, 5), each in XCDR1 and XCDR2.
pub(super) fn dds_seeds() -> Vec<Seed> {
    let mut seeds = Vec::new();
    for encoding in [CdrEncoding::Xcdr1, CdrEncoding::Xcdr2] {
        let tag = if encoding == CdrEncoding::Xcdr1 { "xcdr1" } else { "xcdr2" };
        for (name, payload) in [
            ("hg-lowcmd", payload_of(unitree_proto::HgLowCmd::default(), encoding)),
            ("hg-lowcmd-pattern", payload_of(pattern::<unitree_proto::HgLowCmd>(), encoding)),
            ("hg-lowstate", payload_of(unitree_proto::HgLowState::default(), encoding)),
            ("hg-lowstate-pattern", payload_of(pattern::<unitree_proto::HgLowState>(), encoding)),
        ] {
            let selector = if name.starts_with("hg-lowcmd") { 2 } else { 3 };
            seeds.push((format!("seed-{name}-{tag}"), [&[selector][..], &payload].concat()));
        }
        for (name, request, body) in api_bodies() {
            let selector = if request { 4 } else { 5 };
            seeds.push((format!("seed-{name}-{tag}"), [&[selector][..], &encoding.header(), &body].concat()));
        }
    }
    seeds
}

/// A message whose every byte is set (padding and CRC are sealed on encoding).
fn pattern<M: Message>() -> M {
    let mut message = M::new_zeroed();
    message.as_mut_bytes().iter_mut().enumerate().for_each(|(i, b)| *b = (i * 37 % 251) as u8);
    message
}

/// `message`'s CDR payload (header, body) in `encoding`.
fn payload_of<M: Message>(message: M, encoding: CdrEncoding) -> Vec<u8> {
    let mut payload = vec![0u8; M::cdr_len(encoding)];
    message.encode_cdr(encoding, &mut payload).expect("cdr_len is the length written");
    payload
}
