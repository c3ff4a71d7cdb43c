//! Viewers of our own: a WebSocket client speaking the Foxglove protocol's JSON and binary
//! messages by hand (the protocol's spec, not the server's code), and plain HTTP.

use std::collections::HashMap;
use std::io::{Read, Write};
use std::time::Duration;

use futures::{SinkExt, StreamExt};
use robowire_fixtures::wait;
use serde_json::{Value, json};
use tokio::net::TcpStream;
use tokio_tungstenite::tungstenite::client::IntoClientRequest;
use tokio_tungstenite::tungstenite::http::HeaderValue;
use tokio_tungstenite::tungstenite::protocol::frame::coding::CloseCode;
use tokio_tungstenite::tungstenite::{Message, protocol::CloseFrame};
use tokio_tungstenite::{MaybeTlsStream, WebSocketStream};

use crate::feed::{FR_CALF_RAD, Feed, live, low_state};

type Socket = WebSocketStream<MaybeTlsStream<TcpStream>>;

/// A bound on waiting for what must come, so that a broken server fails the test instead of
/// hanging it; not a measure of speed.
const WITHIN: Duration = Duration::from_secs(30);

async fn connect(addr: std::net::SocketAddr) -> Socket {
    let mut request = format!("ws://{addr}/").into_client_request().unwrap();
    request.headers_mut().insert("Sec-WebSocket-Protocol", HeaderValue::from_static("foxglove.sdk.v1"));
    let (socket, response) = tokio_tungstenite::connect_async(request).await.unwrap();
    assert_eq!(response.headers()["sec-websocket-protocol"], "foxglove.sdk.v1");
    socket
}

/// A channel as advertised.
#[derive(Debug, Clone)]
struct Channel {
    topic: String,
    encoding: String,
    schema_name: String,
    schema_encoding: String,
    schema: String,
}

/// What a viewer saw: the server's info, the channels by id, the first and the latest message of
/// each topic, and how many.
#[derive(Debug, Default)]
struct Seen {
    server: Value,
    channels: HashMap<u64, Channel>,
    subscribed: HashMap<u32, u64>,
    messages: HashMap<String, (Vec<u8>, Vec<u8>, u64)>,
}

impl Seen {
    /// Takes one server message: JSON ops, or binary message data (opcode 1: subscription id,
    /// log time, payload); subscribes to channels as they are advertised.
    async fn take(&mut self, socket: &mut Socket, message: Message) {
        match message {
            Message::Text(text) => {
                let op: Value = serde_json::from_str(&text).unwrap();
                match op["op"].as_str().unwrap() {
                    "serverInfo" => self.server = op,
                    "advertise" => {
                        let mut subscriptions = Vec::new();
                        for c in op["channels"].as_array().unwrap() {
                            let text = |k: &str| c[k].as_str().unwrap_or_default().to_owned();
                            let id = c["id"].as_u64().unwrap();
                            let channel = Channel {
                                topic: text("topic"),
                                encoding: text("encoding"),
                                schema_name: text("schemaName"),
                                schema_encoding: text("schemaEncoding"),
                                schema: text("schema"),
                            };
                            self.channels.insert(id, channel);
                            let sub = u32::try_from(self.subscribed.len()).unwrap();
                            self.subscribed.insert(sub, id);
                            subscriptions.push(json!({ "id": sub, "channelId": id }));
                        }
                        let subscribe = json!({ "op": "subscribe", "subscriptions": subscriptions });
                        socket.send(Message::text(subscribe.to_string())).await.unwrap();
                    }
                    _ => {}
                }
            }
            Message::Binary(bytes) => {
                assert_eq!(bytes[0], 1, "message data");
                let sub = u32::from_le_bytes(bytes[1..5].try_into().unwrap());
                let channel = &self.channels[&self.subscribed[&sub]];
                let payload = bytes[13..].to_vec();
                let entry =
                    self.messages.entry(channel.topic.clone()).or_insert_with(|| (payload.clone(), Vec::new(), 0));
                entry.1 = payload;
                entry.2 += 1;
            }
            _ => {}
        }
    }

    fn json(&self, topic: &str) -> Value {
        serde_json::from_slice(&self.messages[topic].1).unwrap()
    }

    fn channel(&self, topic: &str) -> &Channel {
        self.channels.values().find(|c| c.topic == topic).unwrap_or_else(|| panic!("no channel {topic}"))
    }
}

/// Reads `socket` until `done` holds of what it saw.
async fn read_until(socket: &mut Socket, seen: &mut Seen, what: &str, done: impl Fn(&Seen) -> bool) {
    let reading = async {
        while !done(seen) {
            let message = socket.next().await.expect("the server closed").unwrap();
            seen.take(socket, message).await;
        }
    };
    if tokio::time::timeout(WITHIN, reading).await.is_err() {
        let mut topics: Vec<_> = seen.messages.iter().map(|(topic, (_, _, n))| format!("{topic} ({n})")).collect();
        topics.sort();
        let mut advertised: Vec<_> = seen.channels.values().map(|c| c.topic.clone()).collect();
        advertised.sort();
        let log = seen.messages.get("/robowire/log").map(|(_, last, _)| String::from_utf8_lossy(last).into_owned());
        panic!("not within {WITHIN:?}: {what}; seen: {topics:?}; advertised: {advertised:?}; last log: {log:?}");
    }
}

const LOW_STATE: &str = "/go2/low_level/received/unitree_go::msg::dds_::LowState_";
const LOW_CMD: &str = "/go2/low_level/sent/unitree_go::msg::dds_::LowCmd_";

#[test]
fn a_viewer_gets_every_link_as_json_the_unitree_payloads_as_cdr_and_the_robot_s_frames() {
    let live = live(50.0);
    let feed = Feed::start(&live, Duration::from_millis(2));
    let topics =
        [LOW_STATE, LOW_CMD, "/go2/low_level/received", "/go2/low_level/sent", "/tf", "/tf_joints", "/robowire/live"];
    wait::runtime().block_on(async {
        let mut socket = connect(live.addr()).await;
        let mut seen = Seen::default();
        let kmc = |seen: &Seen| seen.messages.keys().any(|t| t.starts_with("/kmc/serial/received/"));
        read_until(&mut socket, &mut seen, "every channel's messages", |seen| {
            topics.iter().all(|t| seen.messages.contains_key(*t)) && kmc(seen)
        })
        .await;

        assert_eq!(seen.server["op"], "serverInfo");
        let state = seen.json(LOW_STATE);
        assert_eq!(state["motor_state"].as_array().map(Vec::len), Some(20), "{state}");
        let (json_channel, cdr_channel) = (seen.channel(LOW_STATE), seen.channel("/go2/low_level/received"));
        assert_eq!((json_channel.encoding.as_str(), json_channel.schema_encoding.as_str()), ("json", "jsonschema"));
        let schema: Value = serde_json::from_str(&json_channel.schema).unwrap();
        assert!(schema["properties"]["motor_state"].is_object(), "{schema}");
        assert_eq!((cdr_channel.encoding.as_str(), cdr_channel.schema_encoding.as_str()), ("cdr", "omgidl"));
        assert_eq!(cdr_channel.schema_name, "unitree_go::msg::dds_::LowState_");
        // The CDR is the frame as it travelled: a LowState of the tick its JSON says.
        let (first_cdr, last_cdr, _) = &seen.messages["/go2/low_level/received"];
        let tick = |payload: &[u8]| (0..1_000_000).find(|&n| low_state(n) == payload);
        assert!(tick(first_cdr).is_some() && tick(last_cdr).is_some(), "the CDR payloads are the frames");
        let kmc_topic = seen.messages.keys().find(|t| t.starts_with("/kmc/serial/received/")).unwrap().clone();
        assert_eq!(seen.json(&kmc_topic)["speed_mps"], 0.5, "{kmc_topic}");
        let tf = seen.json("/tf");
        assert_eq!((tf["parent_frame_id"].as_str(), tf["child_frame_id"].as_str()), (Some("world"), Some("go2/base")));
        assert_eq!(tf["rotation"]["w"], 1.0);
        assert_eq!(seen.channel("/tf").schema_name, "foxglove.FrameTransform");
        // The bodies from the LowState's joints: the Go2's 12 and its 4 feet.
        assert_eq!(seen.channel("/tf_joints").schema_name, "foxglove.FrameTransforms");
        let joints = seen.json("/tf_joints");
        let transforms = joints["transforms"].as_array().unwrap();
        assert_eq!(transforms.len(), 16, "{joints}");
        let frame = |child: &str| transforms.iter().find(|t| t["child_frame_id"] == child).unwrap().clone();
        let hip = frame("go2/FR_hip");
        assert_eq!(
            (hip["parent_frame_id"].as_str(), hip["translation"]["x"].as_f64()),
            (Some("go2/base"), Some(0.1934))
        );
        // The calf turned about its +y by its position: the quaternion of that half angle.
        let calf = frame("go2/FR_calf");
        assert_eq!(calf["parent_frame_id"], "go2/FR_thigh");
        let half = f64::from(FR_CALF_RAD) / 2.0;
        let (w, y) = (calf["rotation"]["w"].as_f64().unwrap(), calf["rotation"]["y"].as_f64().unwrap());
        assert!((w - half.cos()).abs() < 1e-9 && (y - half.sin()).abs() < 1e-9, "{calf}");
        assert_eq!(frame("go2/FR_foot")["translation"]["z"], -0.213);
        let counts = seen.json("/robowire/live");
        let go2 = counts["channels"].as_array().unwrap().iter().find(|c| c["topic"] == "/go2/low_level/received");
        let go2 = go2.unwrap_or_else(|| panic!("{counts}"));
        assert!(go2["seen"].as_u64() >= go2["sent"].as_u64() && go2["sent"].as_u64() > Some(0), "{counts}");
    });
    let tapped = feed.stop();
    let stats = live.stop();
    let go2 = stats.links.iter().find(|l| l.topic == "/go2/low_level/received").unwrap();
    // Every frame was counted, seen or dropped by a full ring (none here but under a stall).
    assert!(go2.seen <= tapped && go2.seen + stats.ring_dropped >= tapped, "{tapped} tapped: {stats:?}");
    assert!(go2.sent <= go2.seen && go2.undecodable == 0, "{stats:?}");
}

/// `GET path` on `addr`: the status line and the body.
fn get(addr: std::net::SocketAddr, request: &str) -> (String, Vec<u8>) {
    let mut stream = std::net::TcpStream::connect(addr).unwrap();
    stream.write_all(request.as_bytes()).unwrap();
    // Done sending: the server sees the end of a request cut short at once.
    stream.shutdown(std::net::Shutdown::Write).unwrap();
    let mut response = Vec::new();
    stream.read_to_end(&mut response).unwrap();
    let split = response.windows(4).position(|w| w == b"\r\n\r\n").unwrap();
    let head = String::from_utf8_lossy(&response[..split]).into_owned();
    (head.lines().next().unwrap().to_owned(), response[split + 4..].to_vec())
}

#[test]
fn the_page_what_it_loads_and_the_plots_of_every_link_are_served_on_the_same_address() {
    let live = live(50.0);
    let _feed = Feed::start(&live, Duration::from_millis(2));
    let addr = live.addr();
    let (status, page) = get(addr, "GET / HTTP/1.1\r\nHost: x\r\n\r\n");
    assert_eq!(status, "HTTP/1.1 200 OK");
    let page = String::from_utf8(page).unwrap();
    for file in ["live.js", "uPlot.iife.min.js", "uPlot.min.css"] {
        assert!(page.contains(file), "the page loads {file}");
        let (status, body) = get(addr, &format!("GET /{file} HTTP/1.1\r\n\r\n"));
        assert_eq!(status, "HTTP/1.1 200 OK", "{file}");
        assert!(body.len() > 100, "{file}");
    }
    let (status, plots) = get(addr, "GET /plots.json HTTP/1.1\r\n\r\n");
    assert_eq!(status, "HTTP/1.1 200 OK");
    let plots: Value = serde_json::from_slice(&plots).unwrap();
    let links = plots["links"].as_array().unwrap();
    let go2 = links.iter().find(|l| l["link"] == "go2/low_level").unwrap_or_else(|| panic!("{plots}"));
    assert_eq!(go2["protocol"], "unitree_go.low_level");
    let series = &go2["panels"][0]["series"][0];
    assert!(series["pointer"].as_str().is_some_and(|p| p.starts_with('/')) && series["range"].is_array(), "{go2}");
    assert!(links.iter().any(|l| l["link"] == "kmc/serial"), "{plots}");
    assert_eq!(get(addr, "GET /nothing HTTP/1.1\r\n\r\n").0, "HTTP/1.1 404 Not Found");
    assert_eq!(get(addr, "POST / HTTP/1.1\r\n\r\n").0, "HTTP/1.1 405 Method Not Allowed");
    assert_eq!(get(addr, "GET / HTTP/1.1\r\n").0.split(' ').nth(1), Some("400"), "a head cut short");
    let long = format!("GET / HTTP/1.1\r\nX: {}\r\n\r\n", "a".repeat(20_000));
    assert_eq!(get(addr, &long).0.split(' ').nth(1), Some("431"), "a head too large");
    let upgrade = "GET / HTTP/1.1\r\nHost: x\r\nUpgrade: websocket\r\nOrigin: https://evil.example\r\n\r\n";
    assert_eq!(get(addr, upgrade).0.split(' ').nth(1), Some("403"), "a web page of another origin");
    let (status, body) = get(addr, "HEAD / HTTP/1.1\r\n\r\n");
    assert_eq!((status.as_str(), body.len()), ("HTTP/1.1 200 OK", 0));
}

#[test]
fn a_viewer_that_stops_reading_loses_counted_messages_and_another_is_not_held_up() {
    let live = live(10_000.0);
    let feed = Feed::start(&live, Duration::ZERO);
    wait::runtime().block_on(async {
        let mut stalled = connect(live.addr()).await;
        let mut stalled_seen = Seen::default();
        read_until(&mut stalled, &mut stalled_seen, "the stalled viewer subscribed", |s| s.messages.len() > 3).await;
        let MaybeTlsStream::Plain(tcp) = stalled.get_ref() else { unreachable!("no TLS here") };
        let stalled_addr = tcp.local_addr().unwrap();
        // From here on it reads nothing: the kernel's buffers fill, then its queue in front.
        let mut healthy = connect(live.addr()).await;
        let mut seen = Seen::default();
        read_until(&mut healthy, &mut seen, "the healthy viewer subscribed", |s| s.messages.contains_key(LOW_STATE))
            .await;
        let dropped = |live: &robowire_live::LiveServer| {
            live.stats().viewers.iter().find(|v| v.addr == stalled_addr).map_or(0, |v| v.dropped)
        };
        read_until(&mut healthy, &mut seen, "the stalled viewer's queue overflowing", |_| dropped(&live) > 0).await;
        // The healthy viewer goes on getting messages after that.
        let before = seen.messages[LOW_STATE].2;
        read_until(&mut healthy, &mut seen, "messages after the overflow", |s| s.messages[LOW_STATE].2 > before + 100)
            .await;
        drop(stalled);
    });
    drop(feed);
}

#[test]
fn a_viewer_that_sends_what_no_foxglove_client_sends_is_closed_and_the_view_goes_on() {
    let live = live(50.0);
    let _feed = Feed::start(&live, Duration::from_millis(2));
    wait::runtime().block_on(async {
        let cases = [
            ("not JSON", Message::text("not json"), CloseCode::Protocol),
            ("an unknown op", Message::text(r#"{"op":"nope"}"#), CloseCode::Protocol),
            ("a 32 MiB frame", Message::binary(vec![0u8; 32 << 20]), CloseCode::Size),
        ];
        for (case, message, code) in cases {
            let mut socket = connect(live.addr()).await;
            // A send may fail once the server has closed: the close is what is looked at.
            let _ = socket.send(message).await;
            let closed = async {
                loop {
                    match socket.next().await {
                        Some(Ok(Message::Close(frame))) => return frame,
                        Some(Ok(_)) => continue,
                        Some(Err(_)) | None => return None,
                    }
                }
            };
            let frame = tokio::time::timeout(WITHIN, closed).await.unwrap_or_else(|_| panic!("{case}: not closed"));
            match frame {
                Some(CloseFrame { code: got, .. }) => assert_eq!(got, code, "{case}"),
                // A 32 MiB send may see the connection reset before the close frame is read.
                None => assert_eq!(code, CloseCode::Size, "{case}: no close frame"),
            }
        }
        // The view goes on: a new viewer gets messages.
        let mut socket = connect(live.addr()).await;
        let mut seen = Seen::default();
        read_until(&mut socket, &mut seen, "messages after the bad viewers", |s| s.messages.contains_key(LOW_STATE))
            .await;
    });
}

#[test]
fn a_simulator_s_body_is_the_base_frame_in_place_of_the_imu_s_attitude() {
    let live = live(50.0);
    let _feed = Feed::start(&live, Duration::from_millis(2));
    let events = live.events();
    let stop = std::sync::Arc::new(std::sync::atomic::AtomicBool::new(false));
    let posing = {
        let stop = stop.clone();
        std::thread::spawn(move || {
            while !stop.load(std::sync::atomic::Ordering::Relaxed) {
                events.base_pose("go2", [1.0, 2.0, 0.3], [0.0, 0.0, 0.5]);
                std::thread::sleep(Duration::from_millis(20));
            }
        })
    };
    wait::runtime().block_on(async {
        let mut socket = connect(live.addr()).await;
        let mut seen = Seen::default();
        let z = |seen: &Seen| seen.messages.get("/tf").map(|_| seen.json("/tf")["translation"]["z"].clone());
        read_until(&mut socket, &mut seen, "the body's pose", |s| z(s) == Some(json!(0.3))).await;
        // Once posed, every frame of the base is the body's (the IMU's stop): after a moment to let
        // what was already on its way arrive, 20 in a row.
        let posed_at = seen.messages["/tf"].2;
        read_until(&mut socket, &mut seen, "frames after the pose", |s| s.messages["/tf"].2 > posed_at + 10).await;
        for _ in 0..20 {
            let before = seen.messages["/tf"].2;
            read_until(&mut socket, &mut seen, "the next frame", |s| s.messages["/tf"].2 > before).await;
            let tf = seen.json("/tf");
            assert_eq!(
                (tf["child_frame_id"].as_str(), &tf["translation"]["z"]),
                (Some("go2/base"), &json!(0.3)),
                "{tf}"
            );
        }
    });
    stop.store(true, std::sync::atomic::Ordering::Relaxed);
    posing.join().unwrap();
}
