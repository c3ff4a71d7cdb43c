//! Unitree's side of the wire, for the simulators' tests: a robot's service called as Unitree's
//! clients call it (the request written again until answered), and LowCmds with a wrong CRC.

use std::time::Duration;

use robowire_core::cdr::{CdrEncoding, CdrType};
use robowire_dds::qos::Qos;
use robowire_dds::{Participant, Reader, Writer};
use unitree_proto::api::{self, ApiRequest, ApiResponse, RequestHeader};

/// Generous: a condition not reached within this is a failure, not slowness.
pub(crate) const WAIT: Duration = Duration::from_secs(20);

/// How long a call waits for its answer before it writes its request again (a request
/// written before the service's reader is matched is lost).
const RESEND_EVERY: Duration = Duration::from_millis(250);

/// One of the robot's services, called by hand: its request writer and answer reader.
pub(crate) struct ServiceClient {
    requests: Writer<ApiRequest>,
    answers: Reader<ApiResponse>,
    /// Requests written, those written again included.
    pub(crate) written: u64,
}

impl ServiceClient {
    /// A client of `service` (`rt/api/<service>/request` and `/response`).
    pub(crate) fn new(participant: &Participant, service: &str) -> Self {
        let (requests, answers) = (api::request_topic(service).to_string(), api::response_topic(service).to_string());
        Self {
            requests: participant.writer(&requests, Qos::WRITER).unwrap(),
            answers: participant.reader(&answers, Qos::RPC_READER).unwrap(),
            written: 0,
        }
    }

    /// Calls `api_id` with `parameter` as request `id`, writing it again every
    /// [`RESEND_EVERY`] until answered; fails after [`WAIT`].
    pub(crate) async fn call(&mut self, id: i64, api_id: i64, parameter: &str) -> ApiResponse {
        let request =
            ApiRequest { header: RequestHeader::call(id, api_id), parameter: parameter.into(), binary: vec![] };
        let answered = async {
            loop {
                self.requests.write(request.clone()).unwrap();
                self.written += 1;
                let answer = async {
                    loop {
                        match self.answers.recv().await {
                            Ok(sample) if sample.value.id == id => return sample.value,
                            _ => {}
                        }
                    }
                };
                if let Ok(answer) = tokio::time::timeout(RESEND_EVERY, answer).await {
                    return answer;
                }
            }
        };
        tokio::time::timeout(WAIT, answered).await.expect("an answer in time")
    }
}

/// A LowCmd sent with a wrong CRC.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Unsealed<C>(pub(crate) C);

impl<C: CdrType> CdrType for Unsealed<C> {
    const TYPE_NAME: &'static str = C::TYPE_NAME;
    type Error = C::Error;
    fn body_len(&self) -> usize {
        self.0.body_len()
    }
    fn encode_body(&self, out: &mut [u8]) -> Result<usize, robowire_core::BufferTooSmall> {
        let n = self.0.encode_body(out)?;
        out[n - 1] ^= 0xFF; // the CRC is the body's last word
        Ok(n)
    }
    fn decode_body(encoding: CdrEncoding, body: &[u8]) -> Result<Self, Self::Error> {
        C::decode_body(encoding, body).map(Self)
    }
}
