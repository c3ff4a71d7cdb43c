//! Request and answer over two topics, for any request/answer pair of CDR types: a client that
//! pairs answers with its calls by an id the [`Service`] reads out of both, and a server that
//! hands out requests and writes answers. The types and how they correlate are the caller's (a
//! vendor's service protocol lives with its device, not here).
//!
//! DDS discovery takes a moment and volatile topics keep nothing for late readers: a request
//! written before the service's reader is matched is lost. The client therefore waits for a
//! matched reader before its first write and writes the same request again until an answer
//! comes or the call times out, so a service's calls must be idempotent.

use std::collections::HashMap;
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

use robowire_core::cdr::CdrType;
use robowire_rt::lock;
use robowire_tap::Tap;
use tokio::sync::oneshot;
use tokio::task::JoinHandle;

use crate::qos::Qos;
use crate::{DdsError, Participant, Reader, Writer};

/// How often a request without an answer is written again.
pub const RESEND_EVERY: Duration = Duration::from_millis(250);

/// How often a call looks for a matched service reader before its first write.
const DISCOVERY_POLL: Duration = Duration::from_millis(10);

/// A request/answer protocol: its two types and how an answer names its request.
pub trait Service: 'static {
    /// What a client writes.
    type Request: CdrType + Clone + Send + Sync + 'static;
    /// What the service answers.
    type Answer: CdrType + Send + 'static;
    /// The id that pairs `request` with its answer.
    fn request_id(request: &Self::Request) -> i64;
    /// The id of the request `answer` answers.
    fn answer_id(answer: &Self::Answer) -> i64;
}

type Pending<A> = Arc<Mutex<HashMap<i64, oneshot::Sender<A>>>>;

/// Calls one service. Create it inside a tokio runtime: a task of that runtime reads the
/// answers, and calls need its timer.
pub struct RpcClient<S: Service> {
    requests: Writer<S::Request>,
    answer_topic: String,
    pending: Pending<S::Answer>,
    answers: JoinHandle<()>,
}

impl<S: Service> std::fmt::Debug for RpcClient<S> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("RpcClient").field("requests", &self.requests.topic()).finish_non_exhaustive()
    }
}

impl<S: Service> Drop for RpcClient<S> {
    fn drop(&mut self) {
        self.answers.abort();
    }
}

impl<S: Service> RpcClient<S> {
    /// A client writing requests to `request_topic` and reading answers from `answer_topic`.
    pub fn new(participant: &Participant, request_topic: &str, answer_topic: &str) -> Result<Self, DdsError> {
        Self::tapped(participant, request_topic, answer_topic, None)
    }

    /// As [`new`](Self::new), the requests and answers handed to `tap` (sent and received).
    pub fn tapped(
        participant: &Participant,
        request_topic: &str,
        answer_topic: &str,
        tap: Option<Tap>,
    ) -> Result<Self, DdsError> {
        let mut requests = participant.writer::<S::Request>(request_topic, Qos::WRITER)?;
        let mut answers = participant.reader::<S::Answer>(answer_topic, Qos::RPC_READER)?;
        requests.set_tap(tap.clone());
        answers.set_tap(tap);
        let pending: Pending<S::Answer> = Arc::default();
        let task = tokio::spawn({
            let pending = pending.clone();
            async move {
                while let Ok(answer) = answers.recv().await {
                    // An answer to another client's call, or to a call that gave up: dropped.
                    let waiter = lock(&pending).remove(&S::answer_id(&answer.value));
                    if let Some(waiter) = waiter {
                        let _ = waiter.send(answer.value);
                    }
                }
            }
        });
        Ok(Self { requests, answer_topic: answer_topic.into(), pending, answers: task })
    }

    /// Writes `request` (again every [`RESEND_EVERY`]) until its answer arrives, up to
    /// `timeout`. The caller makes the request's id unique among its calls.
    pub async fn call(&self, request: S::Request, timeout: Duration) -> Result<S::Answer, DdsError> {
        let id = S::request_id(&request);
        let (tx, mut rx) = oneshot::channel();
        lock(&self.pending).insert(id, tx);
        let deadline = Instant::now() + timeout;
        let no_answer = || DdsError::NoAnswer { topic: self.answer_topic.clone(), timeout };
        let result = async {
            // Discovery first: a request nobody reads is lost.
            while self.requests.matched_readers() == 0 {
                if Instant::now() >= deadline {
                    return Err(no_answer());
                }
                tokio::time::sleep(DISCOVERY_POLL).await;
            }
            loop {
                self.requests.write(request.clone())?;
                let wait = RESEND_EVERY.min(deadline.saturating_duration_since(Instant::now()));
                match tokio::time::timeout(wait, &mut rx).await {
                    Ok(Ok(answer)) => return Ok(answer),
                    Ok(Err(_)) => return Err(no_answer()),
                    Err(_) if Instant::now() >= deadline => return Err(no_answer()),
                    Err(_) => {}
                }
            }
        }
        .await;
        lock(&self.pending).remove(&id);
        result
    }
}

/// Serves one service: hands out its requests (`Q`), writes its answers (`A`). The answer names
/// its request the way the protocol says (the server needs no [`Service`]).
pub struct RpcServer<Q: CdrType + 'static, A: CdrType + 'static> {
    requests: Reader<Q>,
    answers: Writer<A>,
}

impl<Q: CdrType + 'static, A: CdrType + 'static> std::fmt::Debug for RpcServer<Q, A> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("RpcServer").field("requests", &self.requests.topic()).finish_non_exhaustive()
    }
}

impl<Q: CdrType + 'static, A: CdrType + 'static> RpcServer<Q, A> {
    /// A server reading requests from `request_topic` and answering on `answer_topic`.
    pub fn new(participant: &Participant, request_topic: &str, answer_topic: &str) -> Result<Self, DdsError> {
        Self::tapped(participant, request_topic, answer_topic, None)
    }

    /// As [`new`](Self::new), the requests and answers handed to `tap` (received and sent).
    pub fn tapped(
        participant: &Participant,
        request_topic: &str,
        answer_topic: &str,
        tap: Option<Tap>,
    ) -> Result<Self, DdsError> {
        let mut requests = participant.reader(request_topic, Qos::RPC_READER)?;
        let mut answers = participant.writer(answer_topic, Qos::WRITER)?;
        requests.set_tap(tap.clone());
        answers.set_tap(tap);
        Ok(Self { requests, answers })
    }

    /// The next request.
    pub async fn next_request(&mut self) -> Result<Q, DdsError> {
        Ok(self.requests.recv().await?.value)
    }

    /// Writes `answer`.
    pub fn answer(&self, answer: A) -> Result<(), DdsError> {
        self.answers.write(answer)
    }

    /// Counters of the request reader and the answer writer.
    pub fn stats(&self) -> (crate::TopicStats, crate::TopicStats) {
        (self.requests.stats(), self.answers.stats())
    }
}
