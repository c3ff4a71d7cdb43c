//! Foxglove's server (0.30.3) queues a channel's advertisement to a viewer before it records the
//! channel as advertised to it. A viewer that subscribes at once can be answered "Unknown channel
//! ID" in between, and never gets that channel (seen under load, 1 run in 15, for a channel made
//! while a viewer was connected). The relay remembers what its viewer subscribed to; when the
//! server refuses one of those for an unknown channel, it keeps the refusal from the viewer and
//! asks again, after a pause, a few times, unless the viewer has let that subscription go.

use std::collections::HashMap;
use std::time::Duration;

use serde_json::{Value, json};

/// Times one subscription is asked again, at most.
const RETRIES: u8 = 5;
/// The pause before the n-th time, n × this.
const PAUSE: Duration = Duration::from_millis(20);
/// The server's refusal, as `send_error` words it.
const UNKNOWN: &str = "Unknown channel ID: ";

/// A viewer's subscriptions, by channel: the subscription id, and the times asked again.
#[derive(Debug, Default)]
pub(crate) struct Subscriptions {
    by_channel: HashMap<u64, (u64, u8)>,
}

impl Subscriptions {
    /// Notes a viewer's request: a `subscribe` adds, an `unsubscribe` takes away.
    pub(crate) fn note(&mut self, request: &Value) {
        let entries = |key: &str| request.get(key).and_then(Value::as_array).cloned().unwrap_or_default();
        match request.get("op").and_then(Value::as_str) {
            Some("subscribe") => {
                for s in entries("subscriptions") {
                    if let (Some(id), Some(channel)) = (s["id"].as_u64(), s["channelId"].as_u64()) {
                        self.by_channel.insert(channel, (id, 0));
                    }
                }
            }
            Some("unsubscribe") => {
                let ids: Vec<u64> = entries("subscriptionIds").iter().filter_map(Value::as_u64).collect();
                self.by_channel.retain(|_, (id, _)| !ids.contains(id));
            }
            _ => {}
        }
    }

    /// Forgets every subscription (the viewer is closing).
    pub(crate) fn clear(&mut self) {
        self.by_channel.clear();
    }

    /// For a server's text message: if it refuses one of the viewer's subscriptions for an unknown
    /// channel and retries remain, the retry to make. A refusal so handled is not the viewer's to
    /// see.
    pub(crate) fn retry(&mut self, message: &[u8]) -> Option<Retry> {
        // Most server messages are data or advertisements: only a status naming the refusal is parsed.
        if !message.windows(UNKNOWN.len()).any(|w| w == UNKNOWN.as_bytes()) {
            return None;
        }
        let status: Value = serde_json::from_slice(message).ok()?;
        if status.get("op").and_then(Value::as_str) != Some("status") {
            return None;
        }
        let channel: u64 = status.get("message")?.as_str()?.strip_prefix(UNKNOWN)?.trim().parse().ok()?;
        let (id, retries) = self.by_channel.get_mut(&channel)?;
        if *retries >= RETRIES {
            return None;
        }
        *retries += 1;
        let request = json!({ "op": "subscribe", "subscriptions": [{ "id": *id, "channelId": channel }] });
        let frame = masked_text(request.to_string().as_bytes());
        Some(Retry { pause: PAUSE * u32::from(*retries), channel, subscription: *id, frame })
    }

    /// Whether the viewer still holds `subscription` on `channel` (a retry due is sent only then).
    pub(crate) fn holds(&self, channel: u64, subscription: u64) -> bool {
        self.by_channel.get(&channel).is_some_and(|(id, _)| *id == subscription)
    }
}

/// A subscription to ask for again.
#[derive(Debug)]
pub(crate) struct Retry {
    /// How long to wait first.
    pub(crate) pause: Duration,
    /// The channel and the viewer's subscription id.
    pub(crate) channel: u64,
    pub(crate) subscription: u64,
    /// The request: a masked text frame.
    pub(crate) frame: Vec<u8>,
}

/// A text frame as a client sends it: masked (with a zero key, which leaves the bytes as they are).
fn masked_text(payload: &[u8]) -> Vec<u8> {
    let mut frame = vec![0x81];
    match u16::try_from(payload.len()) {
        Ok(len) if len < 126 => frame.push(0x80 | len as u8),
        Ok(len) => {
            frame.push(0x80 | 126);
            frame.extend_from_slice(&len.to_be_bytes());
        }
        Err(_) => {
            frame.push(0x80 | 127);
            frame.extend_from_slice(&(payload.len() as u64).to_be_bytes());
        }
    }
    frame.extend_from_slice(&[0; 4]);
    frame.extend_from_slice(payload);
    frame
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::ws_frame::{FrameHeader, Opcode};

    fn refusal(channel: u64) -> Vec<u8> {
        json!({ "op": "status", "level": 2, "message": format!("{UNKNOWN}{channel}") }).to_string().into_bytes()
    }

    #[test]
    fn a_refused_subscription_is_asked_again_a_few_times_with_longer_pauses() {
        let mut subscriptions = Subscriptions::default();
        subscriptions.note(&json!({ "op": "subscribe", "subscriptions": [{ "id": 7, "channelId": 3 }] }));
        let Retry { pause, channel, subscription, frame } = subscriptions.retry(&refusal(3)).unwrap();
        assert_eq!((pause, channel, subscription), (PAUSE, 3, 7));
        assert!(subscriptions.holds(3, 7) && !subscriptions.holds(3, 8));
        let header = FrameHeader::parse(&frame).unwrap().unwrap();
        assert_eq!((header.opcode, header.mask, header.fin), (Opcode::Text, Some([0; 4]), true));
        let request: Value = serde_json::from_slice(&frame[header.header_len..]).unwrap();
        assert_eq!(request, json!({ "op": "subscribe", "subscriptions": [{ "id": 7, "channelId": 3 }] }));
        for n in 2..=RETRIES {
            assert_eq!(subscriptions.retry(&refusal(3)).unwrap().pause, PAUSE * u32::from(n));
        }
        assert!(subscriptions.retry(&refusal(3)).is_none(), "at most {RETRIES} times");
    }

    #[test]
    fn only_a_refusal_of_the_viewer_s_own_subscription_is_retried() {
        let mut subscriptions = Subscriptions::default();
        subscriptions.note(&json!({ "op": "subscribe", "subscriptions": [{ "id": 1, "channelId": 4 }] }));
        // Not subscribed, other messages, a warning that is not the refusal.
        assert!(subscriptions.retry(&refusal(5)).is_none());
        assert!(subscriptions.retry(br#"{"op":"advertise","channels":[]}"#).is_none());
        assert!(
            subscriptions.retry(br#"{"op":"status","level":1,"message":"Client is already subscribed"}"#).is_none()
        );
        assert!(subscriptions.retry(b"Unknown channel ID: 4, not JSON").is_none());
        subscriptions.note(&json!({ "op": "unsubscribe", "subscriptionIds": [1] }));
        assert!(subscriptions.retry(&refusal(4)).is_none(), "unsubscribed");
        assert!(!subscriptions.holds(4, 1), "a retry due is not sent");
        subscriptions.note(&json!({ "op": "subscribe", "subscriptions": [{ "id": 2, "channelId": 4 }] }));
        subscriptions.clear();
        assert!(!subscriptions.holds(4, 2), "closing");
    }

    #[test]
    fn a_long_request_has_an_extended_length() {
        let frame = masked_text(&[b' '; 300]);
        let header = FrameHeader::parse(&frame).unwrap().unwrap();
        assert_eq!((header.payload_len, frame.len() - header.header_len), (300, 300));
    }
}
