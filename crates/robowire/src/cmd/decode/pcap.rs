//! A classic libpcap capture read packet by packet: both byte orders, micro- or nanosecond
//! timestamps; link types null/loopback (0), Ethernet (1, VLAN tags skipped), raw IPv4 (101,
//! 228), Linux cooked (113, 276). IPv4 + UDP datagrams are handed out; every other packet is
//! skipped with a reason to count. Every length read from the file is checked before use, and a
//! packet's buffer is bounded by [`MAX_PACKET`]: a hostile file ends in an error, never a panic
//! or a large allocation.

use std::io::{self, Read};
use std::net::{Ipv4Addr, SocketAddrV4};

use anyhow::{Context, bail};

/// The largest captured length accepted (tcpdump's default snapshot length): a UDP datagram
/// with every header below fits.
pub(super) const MAX_PACKET: u32 = 262_144;

/// One UDP datagram over IPv4.
#[derive(Debug)]
pub(super) struct Udp {
    /// Seconds since the Unix epoch.
    pub(super) time: f64,
    pub(super) source: SocketAddrV4,
    pub(super) destination: SocketAddrV4,
    pub(super) payload: Vec<u8>,
}

/// What a packet of the capture holds.
#[derive(Debug)]
pub(super) enum Packet {
    Udp(Udp),
    /// Not a whole IPv4 + UDP datagram: why.
    Skipped(&'static str),
}

/// The packets of a capture, from a reader positioned after the global header.
pub(super) struct Capture<R> {
    reader: R,
    big_endian: bool,
    nanoseconds: bool,
    link_type: u32,
}

impl<R: Read> Capture<R> {
    /// Reads and checks the 24-byte global header.
    pub(super) fn new(mut reader: R) -> anyhow::Result<Self> {
        let mut header = [0u8; 24];
        reader.read_exact(&mut header).context("shorter than a pcap header (24 bytes)")?;
        let magic = [header[0], header[1], header[2], header[3]];
        let (big_endian, nanoseconds) = match u32::from_le_bytes(magic) {
            0xa1b2_c3d4 => (false, false),
            0xa1b2_3c4d => (false, true),
            _ => match u32::from_be_bytes(magic) {
                0xa1b2_c3d4 => (true, false),
                0xa1b2_3c4d => (true, true),
                _ if magic == [0x0a, 0x0d, 0x0d, 0x0a] => bail!("a pcapng file; convert it with `editcap -F pcap`"),
                _ => bail!("not a pcap file (magic {:02x?})", magic),
            },
        };
        let mut capture = Self { reader, big_endian, nanoseconds, link_type: 0 };
        capture.link_type = capture.u32_in(&header, 20) & 0x0fff_ffff;
        if !matches!(capture.link_type, 0 | 1 | 101 | 113 | 228 | 276) {
            bail!("pcap link type {} (only 0, 1, 101, 113, 228 and 276 are read)", capture.link_type);
        }
        Ok(capture)
    }

    fn u32_in(&self, bytes: &[u8], at: usize) -> u32 {
        let b = bytes.get(at..at + 4).and_then(|b| <[u8; 4]>::try_from(b).ok()).unwrap_or_default();
        if self.big_endian { u32::from_be_bytes(b) } else { u32::from_le_bytes(b) }
    }

    /// The next packet; `Ok(None)` at the end of the file, an error for a truncated or
    /// oversized record (after which nothing more can be read).
    pub(super) fn next_packet(&mut self) -> anyhow::Result<Option<Packet>> {
        let mut header = [0u8; 16];
        match read_full(&mut self.reader, &mut header)? {
            0 => return Ok(None),
            16 => {}
            n => bail!("record header cut short ({n} of 16 bytes)"),
        }
        let (seconds, fraction) = (self.u32_in(&header, 0), self.u32_in(&header, 4));
        let (captured, original) = (self.u32_in(&header, 8), self.u32_in(&header, 12));
        if captured > MAX_PACKET {
            bail!("captured length {captured} over {MAX_PACKET} bytes");
        }
        let mut data = vec![0u8; captured as usize];
        let n = read_full(&mut self.reader, &mut data)?;
        if n < data.len() {
            bail!("packet cut short ({n} of its {captured} captured bytes)");
        }
        let divisor = if self.nanoseconds { 1e9 } else { 1e6 };
        let time = f64::from(seconds) + f64::from(fraction) / divisor;
        if captured < original {
            return Ok(Some(Packet::Skipped("truncated by the capture")));
        }
        Ok(Some(match self.ipv4(&data) {
            Ok(ip) => match udp(ip) {
                Ok((source, destination, payload)) => {
                    Packet::Udp(Udp { time, source, destination, payload: payload.to_vec() })
                }
                Err(why) => Packet::Skipped(why),
            },
            Err(why) => Packet::Skipped(why),
        }))
    }

    /// The IPv4 packet inside the link-layer frame.
    fn ipv4<'a>(&self, frame: &'a [u8]) -> Result<&'a [u8], &'static str> {
        const SHORT: &str = "shorter than its link-layer header";
        const NOT_IPV4: &str = "not IPv4";
        let ether_type = |at: usize| frame.get(at..at + 2).map(|b| u16::from_be_bytes([b[0], b[1]]));
        let (ip, ether) = match self.link_type {
            0 => {
                // The capturing host's AF_INET (2), in its own byte order.
                let family = frame.get(..4).ok_or(SHORT)?;
                let ipv4 = family == [2, 0, 0, 0] || family == [0, 0, 0, 2];
                (frame.get(4..).filter(|_| ipv4).ok_or(NOT_IPV4)?, None)
            }
            1 => {
                let mut at = 12;
                // Up to two VLAN tags (802.1Q, 802.1ad).
                for _ in 0..2 {
                    if matches!(ether_type(at), Some(0x8100 | 0x88a8)) {
                        at += 4;
                    }
                }
                (frame.get(at + 2..).ok_or(SHORT)?, Some(ether_type(at).ok_or(SHORT)?))
            }
            113 => (frame.get(16..).ok_or(SHORT)?, Some(ether_type(14).ok_or(SHORT)?)),
            276 => (frame.get(20..).ok_or(SHORT)?, Some(ether_type(0).ok_or(SHORT)?)),
            _ => (frame, None),
        };
        if ether.is_some_and(|t| t != 0x0800) || ip.first().is_none_or(|b| b >> 4 != 4) {
            return Err(NOT_IPV4);
        }
        Ok(ip)
    }
}

/// The UDP datagram in an IPv4 packet: source, destination, payload.
fn udp(ip: &[u8]) -> Result<(SocketAddrV4, SocketAddrV4, &[u8]), &'static str> {
    const BAD_IPV4: &str = "malformed IPv4 header";
    let header = ip.get(..20).ok_or(BAD_IPV4)?;
    let header_len = usize::from(header[0] & 0x0f) * 4;
    let total_len = usize::from(u16::from_be_bytes([header[2], header[3]]));
    if header_len < 20 || total_len < header_len || total_len > ip.len() {
        return Err(BAD_IPV4);
    }
    if u16::from_be_bytes([header[6], header[7]]) & 0x3fff != 0 {
        return Err("an IPv4 fragment");
    }
    if header[9] != 17 {
        return Err("not UDP");
    }
    let source_ip = Ipv4Addr::new(header[12], header[13], header[14], header[15]);
    let destination_ip = Ipv4Addr::new(header[16], header[17], header[18], header[19]);
    let datagram = ip.get(header_len..total_len).ok_or(BAD_IPV4)?;
    let udp_header = datagram.get(..8).ok_or("malformed UDP header")?;
    let udp_len = usize::from(u16::from_be_bytes([udp_header[4], udp_header[5]]));
    let payload = datagram.get(8..udp_len).ok_or("malformed UDP header")?;
    Ok((
        SocketAddrV4::new(source_ip, u16::from_be_bytes([udp_header[0], udp_header[1]])),
        SocketAddrV4::new(destination_ip, u16::from_be_bytes([udp_header[2], udp_header[3]])),
        payload,
    ))
}

/// Reads until `buf` is full or the file ends; the bytes read.
fn read_full(reader: &mut impl Read, buf: &mut [u8]) -> io::Result<usize> {
    let mut filled = 0;
    while filled < buf.len() {
        match reader.read(&mut buf[filled..]) {
            Ok(0) => break,
            Ok(n) => filled += n,
            Err(e) if e.kind() == io::ErrorKind::Interrupted => {}
            Err(e) => return Err(e),
        }
    }
    Ok(filled)
}
