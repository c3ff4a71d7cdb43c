//! The bridge's nodes in the ROS 2 graph: on `ros_discovery_info` in Jazzy's and Humble's
//! layouts, read by robowire's own DDS and by a CycloneDDS peer, each GID the GUID DDS discovery
//! reports for the bridge's endpoint of that node's topic; at its stop, a last sample with no node.

use robowire_dds::netns::with_loopback_multicast;
use robowire_ros2::{BridgeOptions, RosDistro};
use serde_json::Value;

use crate::{Bridge, WAIT, interop_python, options, peer};

/// `ros_discovery_info` reader QoS as rmw's: reliable, transient local (a late reader gets the
/// last sample).
const GRAPH_READER: robowire_dds::qos::Qos =
    robowire_dds::qos::Qos { depth: 16, ..robowire_dds::qos::Qos::ROS_TF_STATIC };

/// The topics each node must list at least (writers, readers): a chassis and a dog.
const NODE_TOPICS: [(&str, &[&str], &[&str]); 2] = [
    ("/kmc0", &["rt/kmc0/odom", "rt/kmc0/tf", "rt/kmc0/battery_state"], &["rt/kmc0/cmd_vel"]),
    (
        "/zsl1_0",
        &["rt/zsl1_0/odom", "rt/zsl1_0/joint_states", "rt/zsl1_0/imu", "rr/zsl1_0/stand_upReply"],
        &["rt/zsl1_0/cmd_vel", "rq/zsl1_0/stand_upRequest"],
    ),
];

/// A bridge of a chassis and a dog writing `ros_discovery_info` in `distro`'s layout.
fn chassis_and_dog(distro: RosDistro, interface: Option<&str>) -> BridgeOptions {
    BridgeOptions { ros_distro: distro, interface: interface.map(Into::into), ..options(&["sim:kmc", "sim:zsl1"]) }
}

/// What is wrong with `info` as the bridge's graph, given the endpoints DDS discovery reports:
/// `None` when it lists the two nodes, each with (at least) its topics, every GID the GUID of a
/// discovered endpoint of the bridge of that node's namespace, and every endpoint of the bridge
/// but `ros_discovery_info`'s under one node.
fn graph_mismatch<const N: usize>(
    info: &ros2_proto::rmw_dds_common::ParticipantEntitiesInfo<N>,
    endpoints: &[robowire_dds::DiscoveredEndpoint],
) -> Option<String> {
    let gid = &info.gid.0;
    if gid[12..16] != [0, 0, 1, 0xc1] || gid[16..].iter().any(|&b| b != 0) {
        return Some(format!("the participant's GID {gid:02x?}"));
    }
    let ours: Vec<_> =
        endpoints.iter().filter(|e| e.guid[..12] == gid[..12] && e.topic != "ros_discovery_info").collect();
    let nodes: Vec<(&str, &str)> =
        info.node_entities_info_seq.iter().map(|n| (n.node_namespace.as_str(), n.node_name.as_str())).collect();
    if nodes != [("/kmc0", "robowire"), ("/zsl1_0", "robowire")] {
        return Some(format!("nodes {nodes:?}"));
    }
    let mut listed = 0;
    for (node, (namespace, writers, readers)) in info.node_entities_info_seq.iter().zip(NODE_TOPICS) {
        for (gids, is_writer, expected) in
            [(&node.writer_gid_seq, true, writers), (&node.reader_gid_seq, false, readers)]
        {
            let mut topics = Vec::new();
            for g in gids {
                if g.0[16..].iter().any(|&b| b != 0) {
                    return Some(format!("GID {:02x?} is not zero-padded", g.0));
                }
                let Some(e) = ours.iter().find(|e| e.guid[..] == g.0[..16]) else {
                    return Some(format!("{namespace}: GID {:02x?} not (yet) discovered", g.0));
                };
                let under = ["rt", "rq", "rr"].iter().any(|p| e.topic.starts_with(&format!("{p}{namespace}/")));
                if e.writer != is_writer || !under {
                    return Some(format!("{namespace}: GID of {e:?}"));
                }
                topics.push(e.topic.as_str());
            }
            listed += gids.len();
            if let Some(missing) = expected.iter().find(|t| !topics.contains(t)) {
                return Some(format!("{namespace}: {missing} not listed yet ({topics:?})"));
            }
        }
    }
    (listed != ours.len()).then(|| format!("{listed} GIDs listed, the bridge has {} endpoints: {ours:?}", ours.len()))
}

/// The bridge's nodes on `ros_discovery_info` in the `distro` layout, read with robowire's own
/// DDS after the bridge started (transient local), each GID the GUID DDS discovery reports for
/// the bridge's endpoint of that node's topic; at its stop, a last sample with no node.
fn nodes_on_ros_discovery_info<const N: usize>(distro: RosDistro)
where
    ros2_proto::rmw_dds_common::ParticipantEntitiesInfo<N>: robowire_core::cdr::CdrType,
{
    use robowire_dds::{Participant, ParticipantOptions};
    use ros2_proto::rmw_dds_common::{DISCOVERY_TOPIC, ParticipantEntitiesInfo};

    with_loopback_multicast(|| {
        let bridge = Bridge::start(chassis_and_dog(distro, Some("lo")));
        robowire_fixtures::wait::runtime().block_on(async {
            let participant = Participant::new(ParticipantOptions::new(0, Some("lo"))).unwrap();
            let mut graph = participant.reader::<ParticipantEntitiesInfo<N>>(DISCOVERY_TOPIC, GRAPH_READER).unwrap();
            let mut last = String::from("no sample");
            let settled = tokio::time::timeout(WAIT, async {
                loop {
                    // A new sample, or the endpoints' discovery catching up with the last one.
                    let info = tokio::time::timeout(std::time::Duration::from_millis(200), graph.recv()).await;
                    let Ok(info) = info else { continue };
                    let info = info.unwrap().value;
                    loop {
                        match graph_mismatch(&info, &participant.discovered_endpoints()) {
                            None => return info,
                            Some(why) if why.contains("not (yet) discovered") => {
                                last = why;
                                tokio::time::sleep(std::time::Duration::from_millis(20)).await;
                            }
                            Some(why) => {
                                last = why;
                                break;
                            }
                        }
                    }
                }
            })
            .await;
            let info = settled.unwrap_or_else(|_| panic!("the bridge's graph never matched: {last}"));
            assert_eq!(info.node_entities_info_seq.len(), 2);
            // Read while it stops: once its participant is gone, so is what it wrote.
            bridge.interrupt();
            let gone = tokio::time::timeout(WAIT, async {
                while !graph.recv().await.unwrap().value.node_entities_info_seq.is_empty() {}
            })
            .await;
            assert!(gone.is_ok(), "the bridge's last sample lists no node");
            bridge.stop();
        });
    });
}

#[test]
fn the_bridge_lists_its_nodes_on_ros_discovery_info_jazzy() {
    nodes_on_ros_discovery_info::<16>(RosDistro::Jazzy);
}

#[test]
fn the_bridge_lists_its_nodes_on_ros_discovery_info_humble() {
    nodes_on_ros_discovery_info::<24>(RosDistro::Humble);
}

/// A CycloneDDS peer started after the bridge reads its nodes on `ros_discovery_info` (transient
/// local: the sample comes late) in the `distro` layout, and finds every GID equal to the key
/// CycloneDDS's own discovery (DCPSPublication / DCPSSubscription) reports for the bridge's
/// endpoint of that node's topic.
fn a_cyclonedds_peer_reads_the_bridges_nodes(distro: RosDistro, gid_len: usize) {
    let Some(python) = interop_python() else { return };
    with_loopback_multicast(|| {
        let bridge = Bridge::start(chassis_and_dog(distro, None));
        let seen = peer(&python, &format!("graph_{distro}"), "");
        let hex = |v: &Value| v.as_str().unwrap_or_else(|| panic!("not a string: {v}")).to_owned();
        let gid = hex(&seen["gid"]);
        assert_eq!(gid.len(), 2 * gid_len, "{seen}");
        assert!(gid[24..32] == *"000001c1" && gid[32..].bytes().all(|b| b == b'0'), "the participant's GID: {seen}");
        let nodes = seen["nodes"].as_array().unwrap();
        let names: Vec<(&str, &str)> =
            nodes.iter().map(|n| (n["namespace"].as_str().unwrap(), n["name"].as_str().unwrap())).collect();
        assert_eq!(names, [("/kmc0", "robowire"), ("/zsl1_0", "robowire")], "{seen}");
        for (node, (namespace, writers, readers)) in nodes.iter().zip(NODE_TOPICS) {
            for (key, kind, expected) in [("writers", "writer", writers), ("readers", "reader", readers)] {
                let mut topics = Vec::new();
                for e in node[key].as_array().unwrap() {
                    let g = hex(&e["gid"]);
                    assert_eq!(g.len(), 2 * gid_len, "{e}");
                    assert!(g[32..].bytes().all(|b| b == b'0'), "zero-padded: {e}");
                    assert_eq!(e["kind"], kind, "the GID is the key of the bridge's {kind}: {e}");
                    assert_eq!(e["participant"].as_str().map(|p| &p[..24]), Some(&gid[..24]), "{e}");
                    let topic = e["topic"].as_str().unwrap();
                    assert!(
                        ["rt", "rq", "rr"].iter().any(|p| topic.starts_with(&format!("{p}{namespace}/"))),
                        "{namespace}: {e}"
                    );
                    topics.push(topic.to_owned());
                }
                for t in expected {
                    assert!(topics.iter().any(|s| s == t), "{namespace} lists its {kind} of {t}: {topics:?}");
                }
            }
        }
        bridge.stop();
    });
}

#[test]
fn a_cyclonedds_peer_reads_the_bridges_nodes_jazzy() {
    a_cyclonedds_peer_reads_the_bridges_nodes(RosDistro::Jazzy, 16);
}

#[test]
fn a_cyclonedds_peer_reads_the_bridges_nodes_humble() {
    a_cyclonedds_peer_reads_the_bridges_nodes(RosDistro::Humble, 24);
}
