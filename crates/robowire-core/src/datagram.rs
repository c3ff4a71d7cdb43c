//! The datagram codec trait: one message per datagram.

/// Encodes and decodes whole datagrams (one message per UDP payload).
///
/// Implemented by datagram protocols' codecs and consumed by datagram transports, which stay
/// ignorant of the device: a transport only moves `[u8]` through a codec. The codec may keep
/// state (a lenient decoder that merges short datagrams into the previous state, say), hence
/// `&mut self`.
///
/// ```
/// use robowire_core::{BufferTooSmall, DatagramCodec};
///
/// /// A toy protocol: one little-endian u16 per datagram.
/// struct Counter;
///
/// #[derive(Debug, PartialEq)]
/// enum CounterError { Length(usize), Buffer(BufferTooSmall) }
///
/// impl DatagramCodec for Counter {
///     type Outgoing = u16;
///     type Incoming = u16;
///     type Error = CounterError;
///     const MAX_DATAGRAM_LEN: usize = 2;
///     fn encode(&mut self, message: &u16, buf: &mut [u8]) -> Result<usize, CounterError> {
///         let mut w = robowire_core::le::LeWriter::new(buf);
///         w.put_u16(*message).map_err(CounterError::Buffer)?;
///         Ok(w.written())
///     }
///     fn decode(&mut self, datagram: &[u8]) -> Result<u16, CounterError> {
///         let bytes: [u8; 2] = datagram.try_into().map_err(|_| CounterError::Length(datagram.len()))?;
///         Ok(u16::from_le_bytes(bytes))
///     }
/// }
///
/// let mut buf = [0u8; Counter::MAX_DATAGRAM_LEN];
/// let n = Counter.encode(&0x1234, &mut buf).unwrap();
/// assert_eq!(&buf[..n], &[0x34, 0x12]);
/// assert_eq!(Counter.decode(&buf[..n]), Ok(0x1234));
/// assert_eq!(Counter.decode(&[1]), Err(CounterError::Length(1)));
/// ```
pub trait DatagramCodec {
    /// What this side sends.
    type Outgoing;
    /// What this side receives.
    type Incoming;
    /// Why a message could not be encoded or a datagram decoded.
    type Error;
    /// Largest datagram either direction produces; transports size their buffers with it.
    const MAX_DATAGRAM_LEN: usize;
    /// Writes `message` at the start of `buf` and returns the datagram's length.
    fn encode(&mut self, message: &Self::Outgoing, buf: &mut [u8]) -> Result<usize, Self::Error>;
    /// Decodes one whole datagram.
    fn decode(&mut self, datagram: &[u8]) -> Result<Self::Incoming, Self::Error>;
}
