//! Unit tests of the reader that need its internals: what it owes a writer (a NACK_FRAG for the
//! fragments of a partial sample) after a heartbeat.

use super::*;
use crate::types::GuidPrefix;
use alloc::vec;

fn frag(sn: i64, n: u32, payload: &[u8]) -> DataFrag<'_> {
    DataFrag {
        reader_id: EntityId::UNKNOWN,
        writer_id: EntityId([0, 0, 1, 3]),
        writer_sn: SequenceNumber(sn),
        fragment_starting_num: n,
        fragments_in_submessage: 1,
        fragment_size: 4,
        sample_size: 6,
        inline_qos: None,
        key: false,
        non_standard_payload: false,
        payload,
    }
}

/// CycloneDDS retransmits a fragmented sample's first fragment alone and the rest on a
/// NACK_FRAG: the heartbeat that follows a partial sample is answered with one.
#[test]
fn a_heartbeat_after_some_fragments_owes_a_nack_frag_for_the_others() {
    let config = ReaderConfig {
        depth: 8,
        heartbeat_response_delay: Duration::ZERO,
        reassemblies: 4,
        reassembly_bytes: 1024,
        reassembly_timeout: Duration::from_secs(10),
        max_writers: 4,
    };
    let writer = Guid::new(GuidPrefix([1; 12]), EntityId([0, 0, 1, 3]));
    let mut reader = Reader::new(EntityId([0, 0, 1, 4]), config);
    assert!(reader.add_writer(WriterProxy::new(writer, true, Vec::new(), 1), Time::ZERO));
    let info = SampleInfo {
        reader: reader.id,
        writer,
        sequence: SequenceNumber(1),
        source_timestamp: None,
        related: None,
        key_hash: None,
        status_info: 0,
    };
    let mut delivered = Vec::new();
    let mut deliver = |_: &SampleInfo, p: &[u8]| delivered.push(p.to_vec());
    let now = Time::ZERO;
    let mut budget = usize::MAX;
    assert_eq!(
        reader.handle_data_frag(now, 0, info, &frag(1, 1, &[1, 2, 3, 4]), &mut budget, &mut deliver),
        Delivery::Fragment
    );
    let hb = Heartbeat {
        reader_id: EntityId::UNKNOWN,
        writer_id: writer.entity,
        first_sn: SequenceNumber(1),
        last_sn: SequenceNumber(1),
        count: 1,
        final_flag: false,
        liveliness_flag: false,
    };
    reader.handle_heartbeat(now, 0, &hb, &mut deliver);
    let (sn, set) = reader.writers[0].nack_frag.expect("a NACK_FRAG owed");
    assert_eq!((sn, set.base(), set.iter().collect::<Vec<_>>()), (SequenceNumber(1), 2, vec![2]));
    assert_eq!(
        reader.handle_data_frag(now, 0, info, &frag(1, 2, &[5, 6]), &mut budget, &mut deliver),
        Delivery::Delivered
    );
    assert_eq!(delivered, [vec![1, 2, 3, 4, 5, 6]]);
}
