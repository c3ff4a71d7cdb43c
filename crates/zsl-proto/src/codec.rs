//! The ZSL-1 datagrams as [`DatagramCodec`]s, one per side: [`ClientCodec`] (sends commands,
//! receives state) for the client facades, [`DogCodec`] (receives commands, sends state) for the
//! simulator. A datagram transport moves bytes through them and never sees a ZSL-1 type.

use core::marker::PhantomData;

use robowire_core::DatagramCodec;

use crate::udp::{
    DatagramError, HighLevelCommand, HighLevelState, LenientUpdate, LowLevelCommand, LowLevelState, Model,
};

/// A command datagram: the magic and checksum are written by the encoder.
pub trait CommandDatagram: Copy + Default + Send + Sync + 'static {
    /// Datagram length in bytes.
    const LEN: usize;
    /// Writes the datagram for `model` at the start of `buf`; returns its length.
    fn encode_into(&self, model: Model, buf: &mut [u8]) -> Result<usize, DatagramError>;
    /// Strict decoding: exact length, a known magic, the checksum.
    fn decode(bytes: &[u8]) -> Result<(Self, Model), DatagramError>;
}

/// A state datagram, decoded strictly or leniently (spec decision 2).
pub trait StateDatagram: Copy + Default + Send + Sync + 'static {
    /// Datagram length in bytes.
    const LEN: usize;
    /// Exact length and header or magic.
    fn decode_strict(bytes: &[u8]) -> Result<Self, DatagramError>;
    /// The bytes present overwrite a prefix of `self`.
    fn update_lenient(&mut self, bytes: &[u8]) -> Result<LenientUpdate, DatagramError>;
    /// Writes the datagram at the start of `buf`; returns its length.
    fn encode_into(&self, buf: &mut [u8]) -> Result<usize, DatagramError>;
}

/// How a client decodes state datagrams (spec decision 2).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum StateDecoding {
    /// Like the vendor client, and what a real robot is known to be accepted with: a short
    /// datagram updates a prefix of the previous state (anomalies are reported, not refused).
    #[default]
    Lenient,
    /// Exact length and header or magic; anything else is a decode error.
    Strict,
}

/// A state datagram as the client received it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StateReceived<S> {
    /// The state after this datagram (in lenient mode, merged into the previous one).
    pub state: S,
    /// What the datagram held: its length, whether it was short, whether the header was right.
    pub update: LenientUpdate,
}

const fn max(a: usize, b: usize) -> usize {
    if a > b { a } else { b }
}

/// The client side: encodes commands `C` for a model, decodes state `S`.
#[derive(Debug, Clone)]
pub struct ClientCodec<C, S> {
    model: Model,
    decoding: StateDecoding,
    state: S,
    command: PhantomData<fn(C)>,
}

/// The HighLevel client codec.
pub type HighLevelClientCodec = ClientCodec<HighLevelCommand, HighLevelState>;
/// The LowLevel client codec.
pub type LowLevelClientCodec = ClientCodec<LowLevelCommand, LowLevelState>;

impl<C, S: Default> ClientCodec<C, S> {
    /// A codec for `model` that decodes state as `decoding` says.
    pub fn new(model: Model, decoding: StateDecoding) -> Self {
        Self { model, decoding, state: S::default(), command: PhantomData }
    }

    /// The model whose magic the commands carry.
    pub fn model(&self) -> Model {
        self.model
    }

    /// Forgets the merged state: the next short datagram updates a prefix of zeros.
    pub fn reset(&mut self) {
        self.state = S::default();
    }
}

impl<C: CommandDatagram, S: StateDatagram> DatagramCodec for ClientCodec<C, S> {
    type Outgoing = C;
    type Incoming = StateReceived<S>;
    type Error = DatagramError;
    const MAX_DATAGRAM_LEN: usize = max(C::LEN, S::LEN);

    fn encode(&mut self, message: &C, buf: &mut [u8]) -> Result<usize, DatagramError> {
        message.encode_into(self.model, buf)
    }

    fn decode(&mut self, datagram: &[u8]) -> Result<StateReceived<S>, DatagramError> {
        let update = match self.decoding {
            StateDecoding::Strict => {
                self.state = S::decode_strict(datagram)?;
                LenientUpdate { len: datagram.len(), short: false, header_ok: true }
            }
            StateDecoding::Lenient => self.state.update_lenient(datagram)?,
        };
        Ok(StateReceived { state: self.state, update })
    }
}

/// The dog side: decodes commands `C` strictly, encodes state `S`.
#[derive(Debug, Clone, Copy, Default)]
pub struct DogCodec<C, S> {
    types: PhantomData<fn(C, S)>,
}

/// The HighLevel dog codec.
pub type HighLevelDogCodec = DogCodec<HighLevelCommand, HighLevelState>;
/// The LowLevel dog codec.
pub type LowLevelDogCodec = DogCodec<LowLevelCommand, LowLevelState>;

impl<C: CommandDatagram, S: StateDatagram> DatagramCodec for DogCodec<C, S> {
    type Outgoing = S;
    type Incoming = (C, Model);
    type Error = DatagramError;
    const MAX_DATAGRAM_LEN: usize = max(C::LEN, S::LEN);

    fn encode(&mut self, message: &S, buf: &mut [u8]) -> Result<usize, DatagramError> {
        message.encode_into(buf)
    }

    fn decode(&mut self, datagram: &[u8]) -> Result<(C, Model), DatagramError> {
        C::decode(datagram)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::udp::ControlMode;

    #[test]
    fn client_and_dog_codecs_meet_on_the_wire() {
        let mut client = HighLevelClientCodec::new(Model::Zsl1W, StateDecoding::Strict);
        let mut dog = HighLevelDogCodec::default();
        let mut buf = [0u8; HighLevelClientCodec::MAX_DATAGRAM_LEN + 1];
        let n = client.encode(&HighLevelCommand::stand_up(), &mut buf).unwrap();
        assert_eq!(n, 40);
        let (command, model) = dog.decode(&buf[..n]).unwrap();
        assert_eq!((command.control_mode(), command.magic(), model), (ControlMode::Stand, 0x5AA6, Model::Zsl1W));

        let state = HighLevelState {
            header: crate::udp::HIGH_LEVEL_STATE_HEADER,
            control_mode: 1.into(),
            ..HighLevelState::default()
        };
        let n = dog.encode(&state, &mut buf).unwrap();
        assert_eq!(client.decode(&buf[..n]).unwrap().state, state);
        assert_eq!(client.decode(&buf[..n + 1]), Err(DatagramError::Length { expected: 560, found: 561 }));
        assert_eq!(
            dog.encode(&state, &mut buf[..10]),
            Err(robowire_core::BufferTooSmall { needed: 560, available: 10 }.into())
        );
    }

    #[test]
    fn lenient_client_merges_a_short_datagram_into_the_previous_state() {
        let mut client = LowLevelClientCodec::new(Model::Zsl1, StateDecoding::Lenient);
        let full = LowLevelState {
            magic: crate::udp::MAGIC_ZSL1.into(),
            rpy: [1.0.into(), 2.0.into(), 3.0.into()],
            ..LowLevelState::default()
        };
        client.decode(&full.encode()).unwrap();
        let received = client.decode(&[0, 0, 0, 0]).unwrap();
        assert_eq!(received.update, LenientUpdate { len: 4, short: true, header_ok: false });
        assert_eq!(received.state.rpy, full.rpy, "the rest of the state is kept");
        assert_eq!(client.decode(&[0; 273]), Err(DatagramError::TooLong { max: 272, found: 273 }));
    }
}
