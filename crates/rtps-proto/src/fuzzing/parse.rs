//! The wire layer's fuzz oracle, [`parse_all`]: parse a datagram, walk everything in it, and
//! check that every submessage (and the valid ones written as one message) emits and parses back
//! to the same repr and bytes.

use alloc::vec;
use alloc::vec::Vec;

use crate::wire::{
    Endianness, Header, LocatorList, Message, MessageWriter, ParameterList, Payload, Submessage, Submessages, pid,
};

/// Parses `datagram` and walks everything in it: every submessage, each inline QoS list, a DATA
/// payload that is a parameter list (SPDP/SEDP), every locator. Each parsed submessage is emitted
/// and parsed again and must give the same repr (and the same bytes when emitted again); the
/// valid submessages written as one message with [`MessageWriter`] must parse back in order.
/// Panics when one of these does not hold.
pub fn parse_all(datagram: &[u8]) {
    let Ok(message) = Message::parse(datagram) else { return };
    let header = message.header();
    let mut valid = Vec::new();
    for item in message.submessages() {
        let Ok(submessage) = item else { continue };
        walk(&submessage);
        round_trip(&submessage);
        valid.push(submessage);
    }
    message_round_trip(&header, &valid);
}

fn walk(submessage: &Submessage<'_>) {
    match submessage {
        Submessage::Data(d) => {
            d.inline_qos.iter().for_each(walk_list);
            if let Payload::Data(b) | Payload::Key(b) = d.payload {
                walk_payload(b);
            }
        }
        Submessage::DataFrag(d) => {
            d.inline_qos.iter().for_each(walk_list);
            assert!(d.fragment_bytes().is_some_and(|n| n == d.payload.len() as u64));
        }
        Submessage::InfoReply(r) => {
            assert_eq!(r.unicast.iter().count(), r.unicast.len());
            if let Some(m) = &r.multicast {
                assert_eq!(m.iter().count(), m.len());
            }
        }
        _ => {}
    }
}

/// A DATA payload with a PL_CDR encapsulation (discovery data) is a parameter list.
fn walk_payload(payload: &[u8]) {
    let endianness = match payload.get(..2) {
        Some([0x00, 0x02]) => Endianness::Big,
        Some([0x00, 0x03]) => Endianness::Little,
        _ => return,
    };
    if let Ok((list, used)) = ParameterList::parse(payload.get(4..).unwrap_or_default(), endianness) {
        assert!(used <= payload.len() - 4);
        walk_list(&list);
    }
}

fn walk_list(list: &ParameterList<'_>) {
    for p in list.iter() {
        let _ = pid::name(p.pid);
        assert!(p.pid != pid::PAD && p.pid != pid::SENTINEL);
        if matches!(
            p.pid & !pid::MUST_UNDERSTAND,
            pid::UNICAST_LOCATOR
                | pid::MULTICAST_LOCATOR
                | pid::DEFAULT_UNICAST_LOCATOR
                | pid::DEFAULT_MULTICAST_LOCATOR
                | pid::METATRAFFIC_UNICAST_LOCATOR
                | pid::METATRAFFIC_MULTICAST_LOCATOR
        ) {
            let whole = p.value.len() / 24 * 24;
            if let Ok(locators) = LocatorList::new(p.value.get(..whole).unwrap_or_default(), list.endianness()) {
                locators.iter().for_each(|l| {
                    let _ = (l.socket_addr(), l.is_multicast());
                });
            }
        }
    }
    assert_eq!(list.find(pid::SENTINEL), None);
}

/// Emits `submessage` alone, parses it again, compares.
fn round_trip(submessage: &Submessage<'_>) {
    let len = submessage.buffer_len();
    let mut buf = vec![0u8; len];
    assert_eq!(submessage.emit(&mut buf), Ok(len));
    if len > 0 {
        assert!(submessage.emit(&mut buf[..len - 1]).is_err(), "emit into a short buffer");
    }
    let again = reparse(&buf);
    assert!(same(submessage, &again), "emit then parse changed {submessage:?} into {again:?}");
    let mut buf2 = vec![0u8; again.buffer_len()];
    assert_eq!(again.emit(&mut buf2), Ok(buf2.len()));
    assert_eq!(buf, buf2, "a re-parsed submessage emits other bytes");
}

fn reparse(emitted: &[u8]) -> Submessage<'_> {
    let (kind, flags) = (emitted[0], emitted[1]);
    let length = [emitted[2], emitted[3]];
    let length = usize::from(if flags & 1 == 1 { u16::from_le_bytes(length) } else { u16::from_be_bytes(length) });
    let body = if length == 0 { &emitted[4..] } else { &emitted[4..4 + length] };
    Submessage::parse(kind, flags, body).expect("an emitted submessage parses")
}

/// Equal, but inline QoS and locator lists that came big-endian compare by their contents.
fn same(a: &Submessage<'_>, b: &Submessage<'_>) -> bool {
    fn lists(a: &Option<ParameterList<'_>>, b: &Option<ParameterList<'_>>) -> bool {
        match (a, b) {
            (None, None) => true,
            (Some(a), Some(b)) if a.endianness() == Endianness::Little => a == b,
            (Some(a), Some(b)) => a.iter().eq(b.iter()),
            _ => false,
        }
    }
    fn locators(a: &LocatorList<'_>, b: &LocatorList<'_>) -> bool {
        a.iter().eq(b.iter())
    }
    match (a, b) {
        (Submessage::Data(x), Submessage::Data(y)) => {
            lists(&x.inline_qos, &y.inline_qos)
                && Submessage::Data(crate::wire::Data { inline_qos: None, ..*x })
                    == Submessage::Data(crate::wire::Data { inline_qos: None, ..*y })
        }
        (Submessage::DataFrag(x), Submessage::DataFrag(y)) => {
            lists(&x.inline_qos, &y.inline_qos)
                && crate::wire::DataFrag { inline_qos: None, ..*x } == crate::wire::DataFrag { inline_qos: None, ..*y }
        }
        (Submessage::InfoReply(x), Submessage::InfoReply(y)) => {
            locators(&x.unicast, &y.unicast)
                && match (&x.multicast, &y.multicast) {
                    (None, None) => true,
                    (Some(m), Some(n)) => locators(m, n),
                    _ => false,
                }
        }
        _ => a == b,
    }
}

/// The valid submessages as one little-endian message parse back in order, when each can be
/// framed (a body over 65535 bytes, or an unknown one with no body, is written with length 0
/// and must end the message).
fn message_round_trip(header: &Header, submessages: &[Submessage<'_>]) {
    let framed = |s: &Submessage<'_>| {
        let body = s.buffer_len() - 4;
        body <= usize::from(u16::MAX) && (body > 0 || matches!(s, Submessage::Pad | Submessage::InfoTs(_)))
    };
    if !submessages.iter().all(framed) {
        return;
    }
    let len = Header::LEN + submessages.iter().map(Submessage::buffer_len).sum::<usize>();
    let mut buf = vec![0u8; len];
    let mut writer = MessageWriter::new(&mut buf, header).expect("room for the header");
    for s in submessages {
        writer.push(s).expect("room for every submessage");
    }
    assert_eq!(writer.finish(), len);
    let message = Message::parse(&buf).expect("an emitted message parses");
    assert_eq!(message.header(), *header);
    let parsed: Submessages<'_> = message.submessages();
    let mut n = 0;
    for (s, again) in submessages.iter().zip(parsed) {
        let again = again.expect("an emitted submessage parses");
        assert!(same(s, &again), "{s:?} came back as {again:?}");
        n += 1;
    }
    assert_eq!(n, submessages.len());
    assert_eq!(message.submessages().count(), submessages.len());
}
