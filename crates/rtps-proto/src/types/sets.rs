//! The bounded sets the wire carries: [`SequenceNumberSet`] (ACKNACK, GAP) and
//! [`FragmentNumberSet`] (NACK_FRAG), each a base and a bitmap of at most 256 members, and
//! [`SetError`], why a base and size are not valid RTPS. A value of either set is valid by
//! construction.

use super::SequenceNumber;
use core::fmt;

/// Why a set's base and size are not valid RTPS.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SetError {
    /// The base is below 1.
    Base,
    /// More than 256 bits.
    NumBits,
    /// The last member would be past the largest number.
    Overflow,
}

/// The bits of a set: bit `i` (MSB first in each 32-bit word) is member `base + i`.
#[derive(Clone, Copy, PartialEq, Eq, Hash, Default)]
struct Bitmap {
    num_bits: u32,
    words: [u32; 8],
}

impl Bitmap {
    const MAX_BITS: u32 = 256;

    fn get(&self, i: u32) -> bool {
        i < self.num_bits && self.words[(i / 32) as usize] & (0x8000_0000 >> (i % 32)) != 0
    }

    fn set(&mut self, i: u32) {
        self.words[(i / 32) as usize] |= 0x8000_0000 >> (i % 32);
    }

    fn word_count(&self) -> usize {
        self.num_bits.div_ceil(32) as usize
    }

    /// The first `num_bits` bits of `words`; bits past them (and missing words) are zero.
    fn from_words(num_bits: u32, words: &[u32]) -> Self {
        let mut out = Self { num_bits, words: [0; 8] };
        for (i, (w, &v)) in out.words.iter_mut().zip(words).enumerate() {
            let first = i as u32 * 32;
            *w = if first >= num_bits {
                0
            } else if num_bits - first < 32 {
                v & !(u32::MAX >> (num_bits - first))
            } else {
                v
            };
        }
        out
    }

    fn ones(&self) -> impl Iterator<Item = u32> + '_ {
        (0..self.num_bits).filter(|&i| self.get(i))
    }
}

/// A set of sequence numbers as ACKNACK and GAP carry it: `base` and up to 256 numbers from it.
/// A value of this type is always valid: base ≥ 1, at most 256 bits, no member past `i64::MAX`;
/// the one exception is the empty set at base 0, which Fast DDS sends in a reader's first
/// ACKNACK (nothing received, nothing asked for).
#[derive(Clone, Copy, PartialEq, Eq, Hash)]
pub struct SequenceNumberSet {
    base: SequenceNumber,
    bits: Bitmap,
}

impl SequenceNumberSet {
    /// The empty set at `base` with room for `num_bits` members.
    pub fn new(base: SequenceNumber, num_bits: u32) -> Result<Self, SetError> {
        if base.0 < 1 && !(base.0 == 0 && num_bits == 0) {
            return Err(SetError::Base);
        }
        if num_bits > Bitmap::MAX_BITS {
            return Err(SetError::NumBits);
        }
        if base.0.checked_add(i64::from(num_bits)).is_none() {
            return Err(SetError::Overflow);
        }
        Ok(Self { base, bits: Bitmap { num_bits, words: [0; 8] } })
    }

    /// From the wire's base, bit count and words (bits past `num_bits` ignored, as the spec says).
    pub fn from_words(base: SequenceNumber, num_bits: u32, words: &[u32]) -> Result<Self, SetError> {
        let set = Self::new(base, num_bits)?;
        Ok(Self { bits: Bitmap::from_words(num_bits, words), ..set })
    }

    /// The base (the first number the set can hold).
    pub fn base(&self) -> SequenceNumber {
        self.base
    }

    /// How many numbers from the base the set spans (0..=256).
    pub fn num_bits(&self) -> u32 {
        self.bits.num_bits
    }

    /// The bitmap words on the wire (`num_bits.div_ceil(32)` of them).
    pub fn words(&self) -> &[u32] {
        &self.bits.words[..self.bits.word_count()]
    }

    /// Adds `sn`; false (and nothing added) when it is outside the set's span.
    pub fn insert(&mut self, sn: SequenceNumber) -> bool {
        match self.offset(sn) {
            Some(i) => {
                self.bits.set(i);
                true
            }
            None => false,
        }
    }

    /// Whether `sn` is a member.
    pub fn contains(&self, sn: SequenceNumber) -> bool {
        self.offset(sn).is_some_and(|i| self.bits.get(i))
    }

    /// The members, ascending.
    pub fn iter(&self) -> impl Iterator<Item = SequenceNumber> + '_ {
        self.bits.ones().map(|i| SequenceNumber(self.base.0 + i64::from(i)))
    }

    /// No members.
    pub fn is_empty(&self) -> bool {
        self.bits.words.iter().all(|&w| w == 0)
    }

    fn offset(&self, sn: SequenceNumber) -> Option<u32> {
        let d = sn.0.checked_sub(self.base.0)?;
        (0..i64::from(self.bits.num_bits)).contains(&d).then_some(d as u32)
    }
}

impl fmt::Debug for SequenceNumberSet {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}/{}:", self.base.0, self.bits.num_bits)?;
        f.debug_list().entries(self.iter().map(|s| s.0)).finish()
    }
}

/// A set of fragment numbers as NACK_FRAG carries it: `base` ≥ 1 and up to 256 numbers from it.
#[derive(Clone, Copy, PartialEq, Eq, Hash)]
pub struct FragmentNumberSet {
    base: u32,
    bits: Bitmap,
}

impl FragmentNumberSet {
    /// The empty set at `base` with room for `num_bits` members.
    pub fn new(base: u32, num_bits: u32) -> Result<Self, SetError> {
        if base < 1 {
            return Err(SetError::Base);
        }
        if num_bits > Bitmap::MAX_BITS {
            return Err(SetError::NumBits);
        }
        if base.checked_add(num_bits).is_none() {
            return Err(SetError::Overflow);
        }
        Ok(Self { base, bits: Bitmap { num_bits, words: [0; 8] } })
    }

    /// From the wire's base, bit count and words (bits past `num_bits` ignored).
    pub fn from_words(base: u32, num_bits: u32, words: &[u32]) -> Result<Self, SetError> {
        let set = Self::new(base, num_bits)?;
        Ok(Self { bits: Bitmap::from_words(num_bits, words), ..set })
    }

    /// The base (the first fragment number the set can hold, ≥ 1).
    pub fn base(&self) -> u32 {
        self.base
    }

    /// How many numbers from the base the set spans (0..=256).
    pub fn num_bits(&self) -> u32 {
        self.bits.num_bits
    }

    /// The bitmap words on the wire.
    pub fn words(&self) -> &[u32] {
        &self.bits.words[..self.bits.word_count()]
    }

    /// Adds fragment `n`; false when it is outside the span.
    pub fn insert(&mut self, n: u32) -> bool {
        match n.checked_sub(self.base).filter(|&d| d < self.bits.num_bits) {
            Some(i) => {
                self.bits.set(i);
                true
            }
            None => false,
        }
    }

    /// Whether fragment `n` is a member.
    pub fn contains(&self, n: u32) -> bool {
        n.checked_sub(self.base).is_some_and(|i| self.bits.get(i))
    }

    /// The members, ascending.
    pub fn iter(&self) -> impl Iterator<Item = u32> + '_ {
        self.bits.ones().map(|i| self.base + i)
    }
}

impl fmt::Debug for FragmentNumberSet {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}/{}:", self.base, self.bits.num_bits)?;
        f.debug_list().entries(self.iter()).finish()
    }
}
