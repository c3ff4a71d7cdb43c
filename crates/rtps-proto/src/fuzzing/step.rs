//! The steps of a participant run ([`Step`]) and their byte format: [`Step::decode`] reads the
//! bytes the fuzzer mutates (every input is a valid sequence of steps), [`Step::encode`] and
//! [`encode_steps`] write them (the seed corpus).

use alloc::vec;
use alloc::vec::Vec;

/// One step of a participant run. [`Step::encode`] and [`Step::decode`] are each other's
/// inverse on the byte format the fuzzer mutates: a tag byte (modulo the number of kinds), then
/// the fields in order, little-endian; missing bytes read as zeros (as `arbitrary`'s
/// `Unstructured` does), so every input is a valid sequence of steps.
///
/// Datagram steps that name endpoints choose them with a selector byte from the matched pair
/// (the peer's writer or reader and ours), the builtin SPDP/SEDP endpoints, `UNKNOWN`, and the
/// wrong kind. Their `wrap` byte: bit 0 an INFO_DST to us first, bit 1 an INFO_DST to someone
/// else, bit 2 an INFO_TS, bit 3 big-endian submessages, bit 4 received on multicast.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Step<'a> {
    /// Any bytes as a datagram.
    Raw(&'a [u8]),
    /// The peer's RTPS header, then any bytes.
    FromPeer(&'a [u8]),
    /// One of the setup's discovery datagrams (index modulo their number), with up to two bytes
    /// replaced (position `at - 1` modulo the length; `at` 0 leaves it).
    Discovery {
        /// Which datagram.
        index: u8,
        /// Two patches: (position + 1, value).
        patches: [(u16, u8); 2],
    },
    /// DATA from the peer (payload: a CDR header and `len` bytes; flags bit 0 inline QoS with a
    /// status info of `flags >> 4`, bit 1 a key instead of data, bit 2 no payload).
    Data {
        /// The datagram's wrap byte.
        wrap: u8,
        /// Reader selector.
        to: u8,
        /// Writer selector.
        from: u8,
        /// writerSN.
        sn: i64,
        /// Payload bytes after the CDR header (modulo 16 KiB + 1).
        len: u16,
        /// Flags.
        flags: u8,
    },
    /// DATA_FRAG from the peer (`len` 0: the payload the numbers imply; else `len - 1` bytes).
    DataFrag {
        /// The datagram's wrap byte.
        wrap: u8,
        /// Reader selector.
        to: u8,
        /// Writer selector.
        from: u8,
        /// writerSN.
        sn: i64,
        /// fragmentStartingNum.
        start: u32,
        /// fragmentsInSubmessage.
        count: u16,
        /// fragmentSize.
        size: u16,
        /// sampleSize.
        sample: u32,
        /// Payload length.
        len: u16,
    },
    /// HEARTBEAT from the peer (flags bit 0 F, bit 1 L).
    Heartbeat {
        /// The datagram's wrap byte.
        wrap: u8,
        /// Reader selector.
        to: u8,
        /// Writer selector.
        from: u8,
        /// firstSN.
        first: i64,
        /// lastSN.
        last: i64,
        /// count.
        count: i32,
        /// Flags.
        flags: u8,
    },
    /// HEARTBEAT_FRAG from the peer.
    HeartbeatFrag {
        /// The datagram's wrap byte.
        wrap: u8,
        /// Reader selector.
        to: u8,
        /// Writer selector.
        from: u8,
        /// writerSN.
        sn: i64,
        /// lastFragmentNum.
        last: u32,
        /// count.
        count: i32,
    },
    /// ACKNACK from the peer's side (the set's words: as many as `bits` implies, at most 8).
    AckNack {
        /// The datagram's wrap byte.
        wrap: u8,
        /// Reader selector (remote).
        from: u8,
        /// Writer selector (ours).
        to: u8,
        /// The set's base.
        base: i64,
        /// numBits.
        bits: u32,
        /// The bitmap words.
        words: [u32; 8],
        /// count.
        count: i32,
        /// F.
        final_flag: bool,
    },
    /// GAP from the peer.
    Gap {
        /// The datagram's wrap byte.
        wrap: u8,
        /// Reader selector.
        to: u8,
        /// Writer selector.
        from: u8,
        /// gapStart.
        start: i64,
        /// The list's base.
        base: i64,
        /// numBits.
        bits: u32,
        /// The bitmap words.
        words: [u32; 8],
    },
    /// NACK_FRAG from the peer's side.
    NackFrag {
        /// The datagram's wrap byte.
        wrap: u8,
        /// Reader selector (remote).
        from: u8,
        /// Writer selector (ours).
        to: u8,
        /// writerSN.
        sn: i64,
        /// The set's base.
        base: u32,
        /// numBits.
        bits: u32,
        /// The bitmap words.
        words: [u32; 8],
        /// count.
        count: i32,
    },
    /// The clock moves `ms` (modulo 10 001) milliseconds, then `handle_timeout`.
    Clock {
        /// Milliseconds.
        ms: u16,
    },
    /// Drains `poll_transmit` and `poll_event` (sample buffers recycled).
    Poll,
    /// Our writer writes a sample of a CDR header and `len` bytes (modulo 16 KiB + 1; longer
    /// than the fragment size: DATA_FRAG).
    Write {
        /// Bytes after the CDR header.
        len: u16,
    },
}

/// Fields read from the front of the input; missing bytes are zeros.
struct Input<'a>(&'a [u8]);

impl<'a> Input<'a> {
    fn bytes(&mut self, n: usize) -> &'a [u8] {
        let (head, tail) = self.0.split_at(n.min(self.0.len()));
        self.0 = tail;
        head
    }
    fn array<const N: usize>(&mut self) -> [u8; N] {
        let mut a = [0; N];
        let b = self.bytes(N);
        a[..b.len()].copy_from_slice(b);
        a
    }
    fn u8(&mut self) -> u8 {
        self.array::<1>()[0]
    }
    fn u16(&mut self) -> u16 {
        u16::from_le_bytes(self.array())
    }
    fn u32(&mut self) -> u32 {
        u32::from_le_bytes(self.array())
    }
    fn i32(&mut self) -> i32 {
        i32::from_le_bytes(self.array())
    }
    fn i64(&mut self) -> i64 {
        i64::from_le_bytes(self.array())
    }
    fn words(&mut self) -> [u32; 8] {
        core::array::from_fn(|_| self.u32())
    }
}

const STEP_KINDS: u8 = 13;

impl<'a> Step<'a> {
    /// Reads one step; `None` at the end of the input.
    pub fn decode(input: &mut &'a [u8]) -> Option<Self> {
        if input.is_empty() {
            return None;
        }
        let mut i = Input(input);
        let step = match i.u8() % STEP_KINDS {
            0 => {
                let n = usize::from(i.u16());
                Step::Raw(i.bytes(n))
            }
            1 => {
                let n = usize::from(i.u16());
                Step::FromPeer(i.bytes(n))
            }
            2 => Step::Discovery { index: i.u8(), patches: [(i.u16(), i.u8()), (i.u16(), i.u8())] },
            3 => Step::Data { wrap: i.u8(), to: i.u8(), from: i.u8(), sn: i.i64(), len: i.u16(), flags: i.u8() },
            4 => Step::DataFrag {
                wrap: i.u8(),
                to: i.u8(),
                from: i.u8(),
                sn: i.i64(),
                start: i.u32(),
                count: i.u16(),
                size: i.u16(),
                sample: i.u32(),
                len: i.u16(),
            },
            5 => Step::Heartbeat {
                wrap: i.u8(),
                to: i.u8(),
                from: i.u8(),
                first: i.i64(),
                last: i.i64(),
                count: i.i32(),
                flags: i.u8(),
            },
            6 => Step::HeartbeatFrag {
                wrap: i.u8(),
                to: i.u8(),
                from: i.u8(),
                sn: i.i64(),
                last: i.u32(),
                count: i.i32(),
            },
            7 => Step::AckNack {
                wrap: i.u8(),
                from: i.u8(),
                to: i.u8(),
                base: i.i64(),
                bits: i.u32(),
                words: i.words(),
                count: i.i32(),
                final_flag: i.u8() & 1 == 1,
            },
            8 => Step::Gap {
                wrap: i.u8(),
                to: i.u8(),
                from: i.u8(),
                start: i.i64(),
                base: i.i64(),
                bits: i.u32(),
                words: i.words(),
            },
            9 => Step::NackFrag {
                wrap: i.u8(),
                from: i.u8(),
                to: i.u8(),
                sn: i.i64(),
                base: i.u32(),
                bits: i.u32(),
                words: i.words(),
                count: i.i32(),
            },
            10 => Step::Clock { ms: i.u16() },
            11 => Step::Poll,
            _ => Step::Write { len: i.u16() },
        };
        *input = i.0;
        Some(step)
    }

    /// Appends the step's bytes (what [`decode`](Self::decode) reads back as this step).
    pub fn encode(&self, out: &mut Vec<u8>) {
        let mut put = |b: &[u8]| out.extend_from_slice(b);
        match *self {
            Step::Raw(b) | Step::FromPeer(b) => {
                let n = b.len().min(usize::from(u16::MAX));
                put(&[if matches!(self, Step::Raw(_)) { 0 } else { 1 }]);
                put(&(n as u16).to_le_bytes());
                put(&b[..n]);
            }
            Step::Discovery { index, patches } => {
                put(&[2, index]);
                for (at, value) in patches {
                    put(&at.to_le_bytes());
                    put(&[value]);
                }
            }
            Step::Data { wrap, to, from, sn, len, flags } => {
                put(&[3, wrap, to, from]);
                put(&sn.to_le_bytes());
                put(&len.to_le_bytes());
                put(&[flags]);
            }
            Step::DataFrag { wrap, to, from, sn, start, count, size, sample, len } => {
                put(&[4, wrap, to, from]);
                put(&sn.to_le_bytes());
                put(&start.to_le_bytes());
                put(&count.to_le_bytes());
                put(&size.to_le_bytes());
                put(&sample.to_le_bytes());
                put(&len.to_le_bytes());
            }
            Step::Heartbeat { wrap, to, from, first, last, count, flags } => {
                put(&[5, wrap, to, from]);
                put(&first.to_le_bytes());
                put(&last.to_le_bytes());
                put(&count.to_le_bytes());
                put(&[flags]);
            }
            Step::HeartbeatFrag { wrap, to, from, sn, last, count } => {
                put(&[6, wrap, to, from]);
                put(&sn.to_le_bytes());
                put(&last.to_le_bytes());
                put(&count.to_le_bytes());
            }
            Step::AckNack { wrap, from, to, base, bits, words, count, final_flag } => {
                put(&[7, wrap, from, to]);
                put(&base.to_le_bytes());
                put(&bits.to_le_bytes());
                words.iter().for_each(|w| put(&w.to_le_bytes()));
                put(&count.to_le_bytes());
                put(&[u8::from(final_flag)]);
            }
            Step::Gap { wrap, to, from, start, base, bits, words } => {
                put(&[8, wrap, to, from]);
                put(&start.to_le_bytes());
                put(&base.to_le_bytes());
                put(&bits.to_le_bytes());
                words.iter().for_each(|w| put(&w.to_le_bytes()));
            }
            Step::NackFrag { wrap, from, to, sn, base, bits, words, count } => {
                put(&[9, wrap, from, to]);
                put(&sn.to_le_bytes());
                put(&base.to_le_bytes());
                put(&bits.to_le_bytes());
                words.iter().for_each(|w| put(&w.to_le_bytes()));
                put(&count.to_le_bytes());
            }
            Step::Clock { ms } => {
                put(&[10]);
                put(&ms.to_le_bytes());
            }
            Step::Poll => put(&[11]),
            Step::Write { len } => {
                put(&[12]);
                put(&len.to_le_bytes());
            }
        }
    }
}

/// A whole input: the setup byte (bit 0: do not feed the peer's discovery first; bit 1: create
/// our endpoints after it), then the steps.
pub fn encode_steps(setup: u8, steps: &[Step<'_>]) -> Vec<u8> {
    let mut out = vec![setup];
    steps.iter().for_each(|s| s.encode(&mut out));
    out
}
