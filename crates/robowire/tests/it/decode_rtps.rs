//! `robowire decode rtps`: hand-built datagrams in both byte orders decoded to their fields,
//! `--file` and `--pcap` input, refusals as one line and status 1, and no panic on hostile or
//! random bytes.

use std::process::{Command, Output};

use serde_json::Value;

fn robowire(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_robowire")).args(args).output().unwrap()
}

fn hex(bytes: &[u8]) -> String {
    bytes.iter().map(|b| format!("{b:02x}")).collect()
}

fn stdout_json(out: &Output) -> Value {
    assert!(out.status.success(), "status {:?}: {}", out.status, String::from_utf8_lossy(&out.stderr));
    serde_json::from_slice(&out.stdout).unwrap()
}

fn decode(datagram: &[u8]) -> Value {
    stdout_json(&robowire(&["decode", "rtps", &hex(datagram)]))
}

/// Bytes in one byte order.
#[derive(Clone, Copy)]
struct Order {
    little: bool,
}

impl Order {
    fn u16(self, v: u16) -> [u8; 2] {
        if self.little { v.to_le_bytes() } else { v.to_be_bytes() }
    }
    fn u32(self, v: u32) -> [u8; 4] {
        if self.little { v.to_le_bytes() } else { v.to_be_bytes() }
    }
    fn sn(self, sn: i64) -> Vec<u8> {
        [self.u32((sn >> 32) as u32), self.u32(sn as u32)].concat()
    }
    /// A submessage: id, flags (E set when little-endian), length, body.
    fn submessage(self, id: u8, flags: u8, body: &[u8]) -> Vec<u8> {
        let flags = flags | u8::from(self.little);
        [&[id, flags][..], &self.u16(body.len() as u16), body].concat()
    }
    /// A parameter, its value padded to 4 bytes.
    fn parameter(self, pid: u16, value: &[u8]) -> Vec<u8> {
        let mut v = value.to_vec();
        v.resize(value.len().next_multiple_of(4), 0);
        [&self.u16(pid)[..], &self.u16(v.len() as u16), &v].concat()
    }
    fn string(self, s: &str) -> Vec<u8> {
        [&self.u32(s.len() as u32 + 1)[..], s.as_bytes(), &[0]].concat()
    }
    fn locator(self, ip: [u8; 4], port: u32) -> Vec<u8> {
        [&self.u32(1)[..], &self.u32(port), &[0; 12], &ip].concat()
    }
}

const PREFIX: [u8; 12] = [0x01, 0x0f, 0xaa, 0xbb, 1, 2, 3, 4, 5, 6, 7, 8];
const SPDP_WRITER: [u8; 4] = [0, 1, 0, 0xc2];
const SPDP_READER: [u8; 4] = [0, 1, 0, 0xc7];
const SEDP_PUBLICATIONS_WRITER: [u8; 4] = [0, 0, 3, 0xc2];
const SEDP_PUBLICATIONS_READER: [u8; 4] = [0, 0, 3, 0xc7];

fn message(submessages: &[Vec<u8>]) -> Vec<u8> {
    let mut d = b"RTPS\x02\x04\x01\x0f".to_vec();
    d.extend(PREFIX);
    submessages.iter().for_each(|s| d.extend(s));
    d
}

/// INFO_TS, then an SPDP DATA whose payload is a parameter list in the same byte order.
fn spdp(o: Order) -> Vec<u8> {
    let guid = [&PREFIX[..], &[0, 0, 1, 0xc1]].concat();
    let list = [
        o.parameter(0x0015, &[2, 4]),
        o.parameter(0x0016, &[1, 0x0f]),
        o.parameter(0x0050, &guid),
        o.parameter(0x0002, &[o.u32(10), o.u32(0x8000_0000)].concat()),
        o.parameter(0x0032, &o.locator([192, 168, 1, 2], 7410)),
        o.parameter(0x0062, &o.string("robot")),
        o.parameter(0x000f, &o.u32(7)),
        o.parameter(0x8007, &[0xde, 0xad, 0xbe, 0xef]),
        o.parameter(0x4014, &o.string("lab")),
        o.parameter(0x4000 | 0x000f, &o.u32(9)),
        o.parameter(0x0001, &[]),
    ]
    .concat();
    let encapsulation: &[u8] = if o.little { &[0, 3, 0, 0] } else { &[0, 2, 0, 0] };
    let data = [&o.u16(0)[..], &o.u16(16), &SPDP_READER, &SPDP_WRITER, &o.sn(1), encapsulation, &list].concat();
    let info_ts = [o.u32(1_700_000_000), o.u32(0x4000_0000)].concat();
    message(&[o.submessage(0x09, 0, &info_ts), o.submessage(0x15, 0x04, &data)])
}

#[test]
fn spdp_data_with_its_parameter_list_in_both_byte_orders() {
    let mut parameters = Vec::new();
    for (little, endianness, encapsulation) in [(true, "little", "PL_CDR_LE"), (false, "big", "PL_CDR_BE")] {
        let json = decode(&spdp(Order { little }));
        assert_eq!(json["header"]["version"], "2.4");
        assert_eq!(json["header"]["vendor_id"]["hex"], "010f");
        assert_eq!(json["header"]["vendor_id"]["name"], "eProsima Fast DDS");
        assert_eq!(json["header"]["guid_prefix"], hex(&PREFIX));
        let [info_ts, data] = json["submessages"].as_array().unwrap().as_slice() else { panic!("{json}") };
        assert_eq!(info_ts["kind"], "INFO_TS");
        assert_eq!(info_ts["timestamp"]["seconds"], 1_700_000_000.25);
        assert_eq!(info_ts["timestamp"]["raw"]["fraction"], 0x4000_0000u32);
        assert_eq!(data["kind"], "DATA");
        assert_eq!(data["endianness"], endianness);
        assert_eq!(data["flags"], if little { "0x05" } else { "0x04" });
        assert_eq!(data["writer_id"]["hex"], "000100c2");
        assert_eq!(data["writer_id"]["name"], "SPDP_WRITER");
        assert_eq!(data["reader_id"]["name"], "SPDP_READER");
        assert_eq!(data["writer_sn"], 1);
        let payload = &data["serialized_payload"];
        assert_eq!(payload["encapsulation"], encapsulation);
        let by_name = |name: &str| {
            payload["parameters"].as_array().unwrap().iter().find(|p| p["name"] == name).unwrap()["value"].clone()
        };
        assert_eq!(by_name("PID_PROTOCOL_VERSION"), "2.4");
        assert_eq!(by_name("PID_VENDORID")["name"], "eProsima Fast DDS");
        assert_eq!(by_name("PID_PARTICIPANT_GUID"), format!("{}000001c1", hex(&PREFIX)));
        assert_eq!(by_name("PID_PARTICIPANT_LEASE_DURATION"), 10.5);
        assert_eq!(by_name("PID_METATRAFFIC_UNICAST_LOCATOR"), "udp/192.168.1.2:7410");
        assert_eq!(by_name("PID_ENTITY_NAME"), "robot");
        assert_eq!(by_name("PID_DOMAIN_ID"), 7);
        assert_eq!(by_name("PID_DOMAIN_TAG"), "lab");
        // PID_DOMAIN_ID with the must-understand bit: named and decoded as PID_DOMAIN_ID.
        assert_eq!(
            (&payload["parameters"][9]["pid"], &payload["parameters"][9]["value"]),
            (&"0x400f".into(), &9.into())
        );
        let vendor = &payload["parameters"][7];
        assert_eq!(
            (&vendor["pid"], &vendor["name"], &vendor["value"]),
            (&"0x8007".into(), &Value::Null, &"deadbeef".into())
        );
        assert_eq!(vendor["length"], 4);
        parameters.push(payload["parameters"].clone());
    }
    assert_eq!(parameters[0], parameters[1], "the same values in either byte order");
}

#[test]
fn acknack_in_both_byte_orders() {
    for little in [true, false] {
        let o = Order { little };
        // Base 5, 10 bits, members 5, 7 and 14; count 3; final.
        let set = [o.sn(5), o.u32(10).to_vec(), o.u32(0xa000_0000 | 0x0040_0000).to_vec()].concat();
        let body = [&SEDP_PUBLICATIONS_READER[..], &SEDP_PUBLICATIONS_WRITER, &set, &o.u32(3)].concat();
        let json = decode(&message(&[o.submessage(0x06, 0x02, &body)]));
        let acknack = &json["submessages"][0];
        assert_eq!(acknack["kind"], "ACKNACK");
        assert_eq!(acknack["endianness"], if little { "little" } else { "big" });
        assert_eq!(acknack["final"], true);
        assert_eq!(acknack["reader_id"]["name"], "SEDP_PUBLICATIONS_READER");
        assert_eq!(acknack["writer_id"]["name"], "SEDP_PUBLICATIONS_WRITER");
        assert_eq!(acknack["reader_sn_state"], serde_json::json!({"base": 5, "num_bits": 10, "members": [5, 7, 14]}));
        assert_eq!(acknack["count"], 3);
    }
}

#[test]
fn data_frag_and_a_user_data_payload() {
    for little in [true, false] {
        let o = Order { little };
        let writer = [0, 0, 0x12, 0x03];
        // Fragment 1 (8 bytes) of a 12-byte sample: its encapsulation header is CDR_LE.
        let fragment = [0, 1, 0, 0, 0xa1, 0xa2, 0xa3, 0xa4];
        let frag = [
            &o.u16(0)[..],
            &o.u16(28),
            &[0; 4],
            &writer,
            &o.sn(42),
            &o.u32(1),
            &o.u16(1),
            &o.u16(8),
            &o.u32(12),
            &fragment,
        ]
        .concat();
        let data = [&o.u16(0)[..], &o.u16(16), &[0; 4], &writer, &o.sn(43), &[0, 7, 0, 0], &[1, 2, 3, 4]].concat();
        let json = decode(&message(&[o.submessage(0x16, 0, &frag), o.submessage(0x15, 0x04, &data)]));
        let frag = &json["submessages"][0];
        assert_eq!(frag["kind"], "DATA_FRAG");
        assert_eq!(frag["writer_id"], serde_json::json!({"hex": "00001203", "name": null}));
        assert_eq!(frag["writer_sn"], 42);
        assert_eq!(
            (&frag["fragment_starting_num"], &frag["fragments_in_submessage"], &frag["fragment_size"]),
            (&1.into(), &1.into(), &8.into())
        );
        assert_eq!((&frag["sample_size"], &frag["total_fragments"]), (&12.into(), &2.into()));
        assert_eq!(frag["encapsulation"], "CDR_LE");
        assert_eq!(frag["payload"], serde_json::json!({"length": 8, "hex": "00010000a1a2a3a4"}));
        let data = &json["submessages"][1];
        assert_eq!(
            data["serialized_payload"],
            serde_json::json!({"encapsulation": "CDR2_LE", "options": "0000", "length": 4, "hex": "01020304"})
        );
    }
}

#[test]
fn a_refusal_is_one_line_with_the_submessage_index_and_status_1() {
    let o = Order { little: true };
    // An INFO_DST, then a HEARTBEAT whose last number is below first - 1.
    let heartbeat = [&SEDP_PUBLICATIONS_READER[..], &SEDP_PUBLICATIONS_WRITER, &o.sn(10), &o.sn(3), &o.u32(1)].concat();
    let datagram = message(&[o.submessage(0x0e, 0, &PREFIX), o.submessage(0x07, 0, &heartbeat)]);
    let out = robowire(&["decode", "rtps", &hex(&datagram)]);
    assert_eq!(out.status.code(), Some(1));
    assert!(out.stdout.is_empty());
    let stderr = String::from_utf8(out.stderr).unwrap();
    assert_eq!(stderr, "error: HEARTBEAT range 10..=3 (last below first - 1) (submessage index 1)\n");

    for (input, message) in [("525450", "not an RTPS message"), ("zz", "not hex"), ("abc", "odd number")] {
        let out = robowire(&["decode", "rtps", input]);
        assert_eq!(out.status.code(), Some(1), "{input}");
        let stderr = String::from_utf8(out.stderr).unwrap();
        assert_eq!(stderr.lines().count(), 1, "{stderr}");
        assert!(stderr.starts_with("error: ") && stderr.contains(message), "{stderr}");
    }
}

fn temp_path(name: &str) -> std::path::PathBuf {
    let dir = std::env::temp_dir().join(format!("robowire-decode-rtps-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir.join(name)
}

#[test]
fn file_of_hex_lines() {
    let good = hex(&spdp(Order { little: true }));
    let other = hex(&spdp(Order { little: false }));
    let text = format!("# two SPDP announcements\n{good}\n\n  # and a bad line\n{other}\n52545053020401\n");
    let path = temp_path("lines.hex");
    std::fs::write(&path, text).unwrap();
    let out = robowire(&["decode", "rtps", "--file", path.to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(1));
    let lines: Vec<Value> =
        String::from_utf8(out.stdout).unwrap().lines().map(|l| serde_json::from_str(l).unwrap()).collect();
    assert_eq!(lines.len(), 2);
    assert_eq!((&lines[0]["line"], &lines[1]["line"]), (&2.into(), &5.into()));
    assert_eq!(lines[1]["submessages"][1]["endianness"], "big");
    let stderr = String::from_utf8(out.stderr).unwrap();
    assert_eq!(stderr, "error: line 6: not an RTPS message\n");
}

/// A classic pcap: little- or big-endian, microsecond stamps, one record per frame.
fn pcap(big_endian: bool, link_type: u32, frames: &[Vec<u8>]) -> Vec<u8> {
    let u32b = |v: u32| if big_endian { v.to_be_bytes() } else { v.to_le_bytes() };
    let u16b = |v: u16| if big_endian { v.to_be_bytes() } else { v.to_le_bytes() };
    let mut out = [&u32b(0xa1b2_c3d4)[..], &u16b(2), &u16b(4), &[0; 8], &u32b(65535), &u32b(link_type)].concat();
    for (i, frame) in frames.iter().enumerate() {
        let len = frame.len() as u32;
        out.extend([u32b(1_700_000_000 + i as u32), u32b(250_000), u32b(len), u32b(len)].concat());
        out.extend(frame);
    }
    out
}

/// IPv4 (no options) around a UDP datagram.
fn ipv4_udp(source: ([u8; 4], u16), destination: ([u8; 4], u16), payload: &[u8]) -> Vec<u8> {
    let udp_len = 8 + payload.len() as u16;
    let total = 20 + udp_len;
    [
        &[0x45, 0][..],
        &total.to_be_bytes(),
        &[0, 1, 0x40, 0, 64, 17, 0, 0],
        &source.0,
        &destination.0,
        &source.1.to_be_bytes(),
        &destination.1.to_be_bytes(),
        &udp_len.to_be_bytes(),
        &[0, 0],
        payload,
    ]
    .concat()
}

fn ethernet(ether_type: u16, payload: &[u8]) -> Vec<u8> {
    [&[0xff; 6][..], &[2, 0, 0, 0, 0, 1], &ether_type.to_be_bytes(), payload].concat()
}

#[test]
fn pcap_capture_of_udp_datagrams() {
    let datagram = spdp(Order { little: true });
    let udp = ipv4_udp(([10, 0, 0, 1], 39998), ([239, 255, 0, 1], 7400), &datagram);
    let arp = ethernet(0x0806, &[0; 28]);
    let path = temp_path("capture.pcap");
    for big_endian in [false, true] {
        std::fs::write(&path, pcap(big_endian, 1, &[arp.clone(), ethernet(0x0800, &udp)])).unwrap();
        let out = robowire(&["decode", "rtps", "--pcap", path.to_str().unwrap()]);
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert!(out.status.success(), "{stderr}");
        assert!(stderr.contains("2 packets, 1 RTPS datagrams decoded, 0 refused, 1 skipped (1 not IPv4)"), "{stderr}");
        let stdout = String::from_utf8(out.stdout).unwrap();
        let lines: Vec<Value> = stdout.lines().map(|l| serde_json::from_str(l).unwrap()).collect();
        let [json] = lines.as_slice() else { panic!("{stdout}") };
        assert_eq!(json["packet"], 2);
        assert_eq!(json["source"], "10.0.0.1:39998");
        assert_eq!(json["destination"], "239.255.0.1:7400");
        assert_eq!(json["time"], 1_700_000_001.25);
        assert_eq!(json["submessages"][1]["serialized_payload"]["encapsulation"], "PL_CDR_LE");
    }
    // Raw IPv4 (101), and Linux cooked (113).
    let sll = [&[0, 0, 0, 1, 0, 6][..], &[0; 8], &0x0800u16.to_be_bytes(), &udp].concat();
    for (link_type, frame) in [(101, udp.clone()), (113, sll)] {
        std::fs::write(&path, pcap(false, link_type, &[frame])).unwrap();
        let out = robowire(&["decode", "rtps", "--pcap", path.to_str().unwrap()]);
        assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
        assert_eq!(String::from_utf8(out.stdout).unwrap().lines().count(), 1, "link type {link_type}");
    }
}

#[test]
fn hostile_pcaps_end_in_one_error_not_a_panic() {
    let path = temp_path("hostile.pcap");
    let good = pcap(false, 1, &[ethernet(0x0800, &ipv4_udp(([1, 2, 3, 4], 1), ([5, 6, 7, 8], 2), b"RTPS"))]);
    let mut huge = good.clone();
    huge[32..36].copy_from_slice(&u32::MAX.to_le_bytes());
    let cases: [(&[u8], &str); 5] = [
        (&good[..good.len() - 1], "cut short"),
        (&good[..30], "record header cut short"),
        (&huge, "captured length 4294967295"),
        (&good[..10], "pcap header"),
        (b"\x0a\x0d\x0d\x0a and the rest of a pcapng file", "pcapng"),
    ];
    for (bytes, message) in cases {
        std::fs::write(&path, bytes).unwrap();
        let out = robowire(&["decode", "rtps", "--pcap", path.to_str().unwrap()]);
        assert_eq!(out.status.code(), Some(1));
        let stderr = String::from_utf8(out.stderr).unwrap();
        assert!(stderr.lines().next().unwrap().starts_with("error: ") && stderr.contains(message), "{stderr}");
        assert!(!stderr.contains("panicked"), "{stderr}");
    }
    // "RTPS" and nothing more: a refusal of packet 1 (not RTPS: shorter than the header).
    std::fs::write(&path, &good).unwrap();
    let out = robowire(&["decode", "rtps", "--pcap", path.to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(1));
    assert!(String::from_utf8(out.stderr).unwrap().starts_with("error: packet 1: not an RTPS message\n"));
}

use robowire_fixtures::rtps::hostile_datagrams as one_datagram_each;

/// JSON on stdout and status 0, or one `error:` line on stderr and status 1; never a panic.
fn json_or_one_refusal(out: &Output) -> Option<Value> {
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(!stderr.contains("panicked"), "{stderr}");
    match out.status.code() {
        Some(0) => Some(serde_json::from_slice(&out.stdout).unwrap()),
        Some(1) => {
            assert!(out.stdout.is_empty());
            assert!(stderr.starts_with("error: ") && stderr.lines().count() == 1, "{stderr}");
            None
        }
        other => panic!("status {other:?}: {stderr}"),
    }
}

#[test]
fn the_six_hostile_datagrams() {
    for (what, datagram) in one_datagram_each(PREFIX) {
        let out = robowire(&["decode", "rtps", &hex(&datagram)]);
        let json = json_or_one_refusal(&out);
        match what {
            // The 4 GiB sample is only announced; its 1024 bytes are here.
            "DATA_FRAG sampleSize" => {
                let frag = &json.unwrap()["submessages"][0];
                assert_eq!((&frag["sample_size"], &frag["payload"]["length"]), (&0xFFFF_FFF0u32.into(), &1024.into()));
            }
            "HEARTBEAT range" => assert_eq!(json.unwrap()["submessages"][0]["last_sn"], 1i64 << 40),
            "GAP range" => assert_eq!(json.unwrap()["submessages"][0]["gap_list"]["base"], 1i64 << 40),
            _ => assert!(json.is_none(), "{what}: refused by the wire layer"),
        }
    }
}

/// SplitMix64.
struct Rng(u64);

impl Rng {
    fn u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let z = (self.0 ^ (self.0 >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        let z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }
    fn below(&mut self, n: usize) -> usize {
        (self.u64() % n as u64) as usize
    }
    fn bytes(&mut self, n: usize) -> Vec<u8> {
        (0..n).map(|_| self.u64() as u8).collect()
    }
}

/// Random bytes, an RTPS header and random submessages, or a valid datagram with bytes changed.
fn random_datagram(rng: &mut Rng) -> Vec<u8> {
    let seeds = [spdp(Order { little: true }), spdp(Order { little: false })];
    match rng.below(3) {
        0 => {
            let n = rng.below(120);
            rng.bytes(n)
        }
        1 => {
            let mut d = message(&[]);
            for _ in 0..rng.below(4) {
                let kinds = [0x01, 0x06, 0x07, 0x08, 0x09, 0x0c, 0x0d, 0x0e, 0x0f, 0x12, 0x13, 0x15, 0x16, 0x80];
                let kind = kinds[rng.below(kinds.len())];
                let len = rng.below(80);
                let flags = rng.u64() as u8;
                let length = if flags & 1 == 1 { (len as u16).to_le_bytes() } else { (len as u16).to_be_bytes() };
                d.extend([kind, flags, length[0], length[1]]);
                let body_len = if rng.below(4) == 0 { rng.below(100) } else { len };
                d.extend(rng.bytes(body_len));
            }
            d
        }
        _ => {
            let mut d = seeds[rng.below(2)].clone();
            for _ in 0..1 + rng.below(4) {
                let at = rng.below(d.len());
                d[at] = rng.u64() as u8;
            }
            if rng.below(2) == 0 {
                d.truncate(rng.below(d.len() + 1).max(20));
            }
            d
        }
    }
}

#[test]
fn random_bytes_never_panic() {
    let mut rng = Rng(0x5eed_0001);
    let datagrams: Vec<Vec<u8>> = (0..400).map(|_| random_datagram(&mut rng)).collect();
    // All of them through --file in one run, each as JSON or one error line.
    let path = temp_path("random.hex");
    std::fs::write(&path, datagrams.iter().map(|d| hex(d) + "\n").collect::<String>()).unwrap();
    let out = robowire(&["decode", "rtps", "--file", path.to_str().unwrap()]);
    assert!(matches!(out.status.code(), Some(0 | 1)), "{:?}", out.status);
    let stdout = String::from_utf8(out.stdout).unwrap();
    let stderr = String::from_utf8(out.stderr).unwrap();
    assert!(!stderr.contains("panicked"), "{stderr}");
    stdout.lines().for_each(|l| drop(serde_json::from_str::<Value>(l).unwrap()));
    assert!(stderr.lines().all(|l| l.starts_with("error: line ")), "{stderr}");
    let nonempty = datagrams.iter().filter(|d| !d.is_empty()).count();
    assert_eq!(stdout.lines().count() + stderr.lines().count(), nonempty);
    // A sample of them one by one.
    for d in datagrams.iter().filter(|d| !d.is_empty()).take(60) {
        json_or_one_refusal(&robowire(&["decode", "rtps", &hex(d)]));
    }
    // Random pcaps: a valid capture with bytes changed, cut anywhere.
    let udp = ipv4_udp(([10, 0, 0, 1], 7410), ([10, 0, 0, 2], 7411), &spdp(Order { little: true }));
    let capture = pcap(false, 1, &[ethernet(0x0800, &udp), ethernet(0x0800, &udp)]);
    let path = temp_path("random.pcap");
    for _ in 0..60 {
        let mut c = capture.clone();
        for _ in 0..1 + rng.below(6) {
            let at = rng.below(c.len());
            c[at] = rng.u64() as u8;
        }
        c.truncate(rng.below(c.len() + 1));
        std::fs::write(&path, &c).unwrap();
        let out = robowire(&["decode", "rtps", "--pcap", path.to_str().unwrap()]);
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert!(matches!(out.status.code(), Some(0 | 1)) && !stderr.contains("panicked"), "{stderr}");
    }
}
