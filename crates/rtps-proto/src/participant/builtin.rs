//! Discovery inside the participant: the SEDP endpoints, SPDP announcements in and out, remote
//! endpoints in and out, and matching local endpoints with remote ones.

use alloc::vec::Vec;
use core::net::SocketAddr;

use super::receive::InlineQos;
use super::{Event, LocalEndpoint, LostReason, MatchError, Participant, RemoteParticipant};
use crate::Time;
use crate::discovery::{BuiltinEndpointSet as Builtin, EndpointData, History, ParticipantData, Qos, check_match};
use crate::endpoint::{ChangeKind, Reader, ReaderProxy, WriteMode, WriteOptions, Writer, WriterProxy};
use crate::types::{DdsDuration, EntityId, Guid, GuidPrefix, Locator, VendorId};
use crate::wire::Data;

/// The SEDP endpoints' QoS: reliable, transient-local, keep all.
fn sedp_qos() -> Qos {
    Qos {
        reliability: crate::discovery::Reliability::Reliable { max_blocking_time: DdsDuration::ZERO },
        durability: crate::discovery::Durability::TransientLocal,
        history: History::KeepAll,
        ..Qos::default()
    }
}

impl Participant {
    pub(super) fn create_builtin_endpoints(&mut self) {
        let qos = sedp_qos();
        let depth = self.config.limits.local_endpoints.saturating_mul(2).max(1);
        for id in [EntityId::SEDP_PUBLICATIONS_WRITER, EntityId::SEDP_SUBSCRIPTIONS_WRITER] {
            let mut config = self.writer_config(&qos, depth, WriteMode::RefuseWhenFull);
            config.max_readers = self.config.limits.participants;
            self.writers.push(Writer::new(id, config));
        }
        for id in [EntityId::SEDP_PUBLICATIONS_READER, EntityId::SEDP_SUBSCRIPTIONS_READER] {
            let mut config = self.reader_config(depth);
            config.max_writers = self.config.limits.participants;
            self.readers.push(Reader::new(id, config));
        }
    }

    /// This participant's SPDP data.
    pub fn participant_data(&self) -> ParticipantData {
        let c = &self.config;
        let mut d = ParticipantData::new(c.guid_prefix);
        d.domain_id = Some(c.domain_id);
        d.domain_tag = c.domain_tag.clone();
        d.metatraffic_unicast_locators = c.metatraffic_unicast.clone();
        d.metatraffic_multicast_locators = c.metatraffic_multicast.clone();
        d.default_unicast_locators = c.default_unicast.clone();
        d.default_multicast_locators = c.default_multicast.clone();
        d.lease_duration = DdsDuration::from_duration(c.lease_duration);
        d.user_data = c.user_data.clone();
        d.entity_name = c.entity_name.clone();
        d
    }

    pub(super) fn spdp_payload(&self) -> Vec<u8> {
        let mut buf = alloc::vec![0u8; self.config.limits.parameter_list_bytes.min(8192)];
        let len = self.participant_data().emit_payload(&mut buf).unwrap_or(0);
        buf.truncate(len);
        buf
    }

    /// Refreshes the lease of a participant heard from.
    pub(super) fn heard_from(&mut self, now: Time, prefix: GuidPrefix, source: SocketAddr) {
        if let Some(r) = self.remote.iter_mut().find(|r| r.data.guid_prefix == prefix) {
            r.lease_expires = now + lease(&r.data);
            r.heard_at = now;
            r.last_source = Some(source);
        }
    }

    pub(super) fn handle_spdp(&mut self, now: Time, from: GuidPrefix, data: &Data<'_>, q: InlineQos) {
        if q.status_info & 0x3 != 0 {
            self.remove_participant(from, LostReason::Left);
            return;
        }
        let payload = match data.payload {
            crate::wire::Payload::Data(b) => b,
            _ => return,
        };
        let parsed = match ParticipantData::parse_payload(payload, &self.config.limits) {
            Ok(p) => p,
            Err(_) => {
                self.counters.discovery_errors += 1;
                return;
            }
        };
        if parsed.domain_id.is_some_and(|d| d != self.config.domain_id) || parsed.domain_tag != self.config.domain_tag {
            self.counters.other_domain += 1;
            return;
        }
        let prefix = parsed.guid_prefix;
        let expires = now + lease(&parsed);
        if let Some(r) = self.remote.iter_mut().find(|r| r.data.guid_prefix == prefix) {
            r.data = parsed;
            r.lease_expires = expires;
            return;
        }
        if self.remote.len() >= self.config.limits.participants {
            // Refusing the newcomer would let announcements forged under made-up prefixes (with
            // an infinite lease, at worst) shut every real participant out until they expire.
            // A real participant is heard from all the time (announcements, heartbeats,
            // samples); one that is not makes room.
            self.counters.participants_at_limit += 1;
            let Some(quietest) = self.remote.iter().min_by_key(|r| r.heard_at).map(|r| r.data.guid_prefix) else {
                return; // a limit of 0
            };
            self.remove_participant(quietest, LostReason::Displaced);
        }
        let vendor = parsed.vendor_id;
        let builtin = parsed.builtin_endpoints;
        let meta = meta_locators(&parsed);
        self.remote.push(RemoteParticipant {
            data: parsed,
            lease_expires: expires,
            heard_at: now,
            writers: Vec::new(),
            readers: Vec::new(),
            last_source: None,
        });
        self.push_event(Event::ParticipantDiscovered { prefix, vendor });
        // Our SEDP writers to their SEDP readers and theirs to ours.
        let pairs = [
            (EntityId::SEDP_PUBLICATIONS_WRITER, EntityId::SEDP_PUBLICATIONS_READER, Builtin::PUBLICATIONS_DETECTOR),
            (EntityId::SEDP_SUBSCRIPTIONS_WRITER, EntityId::SEDP_SUBSCRIPTIONS_READER, Builtin::SUBSCRIPTIONS_DETECTOR),
        ];
        for (ours, theirs, bit) in pairs {
            if let Some(w) = self.writers.iter_mut().find(|w| w.id == ours && builtin.contains(bit)) {
                w.add_reader(ReaderProxy::new(Guid::new(prefix, theirs), true, true, meta.clone()), now);
            }
        }
        let pairs = [
            (EntityId::SEDP_PUBLICATIONS_READER, EntityId::SEDP_PUBLICATIONS_WRITER, Builtin::PUBLICATIONS_ANNOUNCER),
            (
                EntityId::SEDP_SUBSCRIPTIONS_READER,
                EntityId::SEDP_SUBSCRIPTIONS_WRITER,
                Builtin::SUBSCRIPTIONS_ANNOUNCER,
            ),
        ];
        for (ours, theirs, bit) in pairs {
            if let Some(r) = self.readers.iter_mut().find(|r| r.id == ours && builtin.contains(bit)) {
                r.add_writer(
                    WriterProxy::new(Guid::new(prefix, theirs), true, meta.clone(), preemptive_base(vendor)),
                    now,
                );
            }
        }
        // Tell the newcomer about us now rather than at the next period.
        if !self.spdp_unicast.contains(&prefix) {
            self.spdp_unicast.push(prefix);
        }
    }

    pub(super) fn remove_participant(&mut self, prefix: GuidPrefix, reason: LostReason) {
        let Some(i) = self.remote.iter().position(|r| r.data.guid_prefix == prefix) else { return };
        let r = self.remote.remove(i);
        for e in r.writers.iter().chain(&r.readers) {
            self.unmatch_remote(e.guid);
            self.push_event(Event::EndpointLost { guid: e.guid });
        }
        for w in &mut self.writers {
            w.readers.retain(|p| p.guid.prefix != prefix);
        }
        for rd in &mut self.readers {
            rd.writers.retain(|p| p.guid.prefix != prefix);
        }
        self.spdp_unicast.retain(|p| *p != prefix);
        self.push_event(Event::ParticipantLost { prefix, reason });
    }

    /// Takes the SEDP samples the builtin readers delivered.
    pub(super) fn process_discovery_inbox(&mut self, now: Time) {
        let inbox = core::mem::take(&mut self.discovery_inbox);
        for (info, payload) in &inbox {
            if info.status_info & 0x3 != 0 {
                if let Some(k) = info.key_hash {
                    let guid = Guid::from_bytes(k);
                    self.remove_remote_endpoint(guid);
                }
                continue;
            }
            match EndpointData::parse_payload(payload, info.key_hash, &self.config.limits) {
                Ok(e) => self.add_remote_endpoint(now, info.reader == EntityId::SEDP_PUBLICATIONS_READER, e),
                Err(_) => self.counters.discovery_errors += 1,
            }
        }
        self.discovery_inbox = inbox;
        self.discovery_inbox.clear();
    }

    fn add_remote_endpoint(&mut self, now: Time, is_writer: bool, e: EndpointData) {
        let limit = self.config.limits.endpoints_per_participant;
        let Some(r) = self.remote.iter_mut().find(|r| r.data.guid_prefix == e.guid.prefix) else {
            self.counters.unmatched_source += 1;
            return;
        };
        let list = if is_writer { &mut r.writers } else { &mut r.readers };
        let guid = e.guid;
        if let Some(old) = list.iter_mut().find(|o| o.guid == guid) {
            *old = e;
        } else if r.writers.len() + r.readers.len() >= limit {
            self.counters.endpoints_at_limit += 1;
            return;
        } else {
            let list = if is_writer { &mut r.writers } else { &mut r.readers };
            list.push(e);
            self.push_event(Event::EndpointDiscovered { guid });
        }
        let locals: Vec<EntityId> = self.local.iter().map(|l| l.id).collect();
        for id in locals {
            if id.is_writer() != is_writer {
                self.try_match(now, id, guid);
            }
        }
    }

    fn remove_remote_endpoint(&mut self, guid: Guid) {
        let Some(r) = self.remote.iter_mut().find(|r| r.data.guid_prefix == guid.prefix) else { return };
        let before = r.writers.len() + r.readers.len();
        r.writers.retain(|e| e.guid != guid);
        r.readers.retain(|e| e.guid != guid);
        if r.writers.len() + r.readers.len() != before {
            self.unmatch_remote(guid);
            self.push_event(Event::EndpointLost { guid });
        }
    }

    fn unmatch_remote(&mut self, guid: Guid) {
        let mut gone = Vec::new();
        for w in &mut self.writers {
            if !w.id.is_builtin() && w.remove_reader(guid) {
                gone.push(w.id);
            }
        }
        for r in &mut self.readers {
            if !r.id.is_builtin() && r.remove_writer(guid) {
                gone.push(r.id);
            }
        }
        for local in gone {
            self.push_event(Event::Unmatched { local, remote: guid });
        }
    }

    /// Matches local endpoint `id` with every remote endpoint on its topic.
    pub(super) fn match_local(&mut self, now: Time, id: EntityId) {
        let Some(local) = self.local.iter().find(|l| l.id == id) else { return };
        let remote: Vec<Guid> = self
            .remote
            .iter()
            .flat_map(|r| if id.is_writer() { &r.readers } else { &r.writers })
            .filter(|e| e.topic_name == local.topic)
            .map(|e| e.guid)
            .collect();
        for guid in remote {
            self.try_match(now, id, guid);
        }
    }

    fn try_match(&mut self, now: Time, id: EntityId, guid: Guid) {
        let Some(local) = self.local.iter().find(|l| l.id == id).cloned() else { return };
        let Some(r) = self.remote.iter().find(|r| r.data.guid_prefix == guid.prefix) else { return };
        let Some(e) = r.endpoint(guid) else { return };
        if e.topic_name != local.topic {
            return;
        }
        let verdict = if e.type_name != local.type_name {
            Err(MatchError::TypeName)
        } else if id.is_writer() {
            check_match(&local.qos, &e.qos).map_err(MatchError::Qos)
        } else {
            check_match(&e.qos, &local.qos).map_err(MatchError::Qos)
        };
        if let Err(reason) = verdict {
            self.push_event(Event::Incompatible { local: id, remote: guid, reason });
            return;
        }
        let locators = data_locators(e, &r.data, self.config.limits.locators_per_endpoint);
        let preemptive = preemptive_base(r.data.vendor_id);
        let added = if id.is_writer() {
            let reliable = e.qos.is_reliable();
            let history = e.qos.is_transient_local();
            let known = self.writers.iter().any(|w| w.id == id && w.readers.iter().any(|p| p.guid == guid));
            self.writers
                .iter_mut()
                .find(|w| w.id == id)
                .map(|w| w.add_reader(ReaderProxy::new(guid, reliable, history, locators), now) && !known)
        } else {
            let reliable = e.qos.is_reliable() && local.qos.is_reliable();
            let known = self.readers.iter().any(|rd| rd.id == id && rd.writers.iter().any(|p| p.guid == guid));
            self.readers
                .iter_mut()
                .find(|rd| rd.id == id)
                .map(|rd| rd.add_writer(WriterProxy::new(guid, reliable, locators, preemptive), now) && !known)
        };
        match added {
            Some(true) => self.push_event(Event::Matched { local: id, remote: guid }),
            Some(false) => {}
            None => self.counters.matches_at_limit += 1,
        }
    }

    /// Announces local endpoint `id` on SEDP.
    pub(super) fn announce_local(&mut self, now: Time, id: EntityId) {
        let Some(local) = self.local.iter().find(|l| l.id == id) else { return };
        let data = self.endpoint_data(local);
        let mut buf = alloc::vec![0u8; self.config.limits.parameter_list_bytes.min(16 * 1024)];
        let Ok(len) = data.emit_payload(&mut buf) else { return };
        let sedp =
            if id.is_writer() { EntityId::SEDP_PUBLICATIONS_WRITER } else { EntityId::SEDP_SUBSCRIPTIONS_WRITER };
        let options = WriteOptions { key_hash: Some(data.guid.to_bytes()), ..WriteOptions::default() };
        if let Some(w) = self.writers.iter_mut().find(|w| w.id == sedp) {
            let _ = w.write(now, ChangeKind::Alive, &buf[..len], &options);
        }
    }

    /// Announces the removal of local endpoint `id` (a dispose) and forgets its announcement.
    pub(super) fn announce_removal(&mut self, now: Time, id: EntityId) {
        let guid = Guid::new(self.config.guid_prefix, id);
        let sedp =
            if id.is_writer() { EntityId::SEDP_PUBLICATIONS_WRITER } else { EntityId::SEDP_SUBSCRIPTIONS_WRITER };
        let Some(w) = self.writers.iter_mut().find(|w| w.id == sedp) else { return };
        let old: Vec<_> =
            w.history.iter().filter(|c| c.key_hash == Some(guid.to_bytes())).map(|c| c.sequence).collect();
        for sn in old {
            w.history.remove(sn);
        }
        let options = WriteOptions { key_hash: Some(guid.to_bytes()), ..WriteOptions::default() };
        let _ = w.write(now, ChangeKind::Disposed, &[], &options);
    }

    fn endpoint_data(&self, local: &LocalEndpoint) -> EndpointData {
        let mut e = EndpointData::new(
            Guid::new(self.config.guid_prefix, local.id),
            local.topic.clone(),
            local.type_name.clone(),
        );
        e.participant_guid = Some(Guid::new(self.config.guid_prefix, EntityId::PARTICIPANT));
        e.qos = local.qos.clone();
        e
    }
}

/// The base of a pre-emptive ACKNACK to a writer of `vendor`'s: Fast DDS answers one at once
/// only at base 0 (an empty set, not final); others take the standard base 1.
fn preemptive_base(vendor: VendorId) -> i64 {
    if vendor == VendorId::FAST_DDS { 0 } else { 1 }
}

fn lease(d: &ParticipantData) -> core::time::Duration {
    d.lease_duration.to_duration().unwrap_or(core::time::Duration::from_secs(u64::from(u32::MAX)))
}

/// Where a remote participant's builtin endpoints listen.
fn meta_locators(d: &ParticipantData) -> Vec<Locator> {
    if d.metatraffic_unicast_locators.is_empty() {
        d.default_unicast_locators.clone()
    } else {
        d.metatraffic_unicast_locators.clone()
    }
}

/// Where a remote endpoint listens: its own unicast locators, else its participant's default.
fn data_locators(e: &EndpointData, p: &ParticipantData, limit: usize) -> Vec<Locator> {
    let from = if e.unicast_locators.is_empty() { &p.default_unicast_locators } else { &e.unicast_locators };
    from.iter().take(limit).copied().collect()
}
