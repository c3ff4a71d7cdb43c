//! The CRC of Unitree's low-level messages (spec §4): CRC-32/MPEG-2 over the image's 32-bit
//! little-endian words taken most-significant byte first, i.e. over the byte stream in which
//! every 4-byte group is reversed. Init `0xFFFFFFFF`, no reflection, no final XOR.
//!
//! With the `std` feature the CRC runs on `crc-fast` (PCLMUL on x86-64, NEON on aarch64,
//! detected at run time); without it, on the `crc` crate's slice-by-16 table. The vendor's
//! bitwise loop is kept only as a test oracle.

/// Largest CRC input handled: the HG `LowState_` covers 2088 bytes.
pub const MAX_COVERED_LEN: usize = 2088;

/// The portable backend: slice-by-16 tables.
const TABLE: crc::Crc<u32, crc::Table<16>> = crc::Crc::<u32, crc::Table<16>>::new(&crc::CRC_32_MPEG_2);

/// `covered` with every 4-byte group reversed, in a stack buffer; `None` for a length that is
/// not a multiple of 4 or exceeds [`MAX_COVERED_LEN`].
fn swapped(covered: &[u8]) -> Option<([u8; MAX_COVERED_LEN], usize)> {
    if !covered.len().is_multiple_of(4) || covered.len() > MAX_COVERED_LEN {
        return None;
    }
    let mut out = [0u8; MAX_COVERED_LEN];
    let (words, _) = covered.as_chunks::<4>();
    let (dst, _) = out.as_chunks_mut::<4>();
    for (o, w) in dst.iter_mut().zip(words) {
        *o = u32::from_le_bytes(*w).to_be_bytes();
    }
    Some((out, covered.len()))
}

/// CRC of `covered`, the image without its trailing `crc` word, on the fastest backend built in.
///
/// `covered.len()` must be a multiple of 4 and at most [`MAX_COVERED_LEN`] (the message types
/// guarantee both); other lengths give `None`.
pub fn crc32_words(covered: &[u8]) -> Option<u32> {
    let (buf, len) = swapped(covered)?;
    Some(backend(&buf[..len]))
}

/// CRC of `covered` with every byte ANDed with the byte of `mask` at its place first (a
/// message's padding zeroed without a copy of the message): masked and swapped in one pass into
/// a stack buffer no larger than the message needs, then one CRC. `None` as [`crc32_words`], or
/// for a `mask` shorter than `covered`.
pub fn crc32_words_masked(covered: &[u8], mask: &[u8]) -> Option<u32> {
    if !covered.len().is_multiple_of(4) || covered.len() > MAX_COVERED_LEN || mask.len() < covered.len() {
        return None;
    }
    // A Go2 LowCmd (808 B) or LowState (1176 B) does not pay for zeroing an HG LowState's buffer.
    Some(if covered.len() <= 1024 {
        masked::<1024>(covered, mask)
    } else if covered.len() <= 1280 {
        masked::<1280>(covered, mask)
    } else {
        masked::<MAX_COVERED_LEN>(covered, mask)
    })
}

/// [`crc32_words_masked`] through an `N`-byte buffer (`covered.len() <= N`, checked by the caller).
fn masked<const N: usize>(covered: &[u8], mask: &[u8]) -> u32 {
    let mut buf = [0u8; N];
    let (words, _) = covered.as_chunks::<4>();
    let (masks, _) = mask.as_chunks::<4>();
    let (out, _) = buf.as_chunks_mut::<4>();
    for ((o, w), m) in out.iter_mut().zip(words).zip(masks) {
        *o = (u32::from_le_bytes(*w) & u32::from_le_bytes(*m)).to_be_bytes();
    }
    backend(&buf[..covered.len()])
}

/// CRC of `covered` on the portable table backend (what `no_std` builds use).
pub fn crc32_words_table(covered: &[u8]) -> Option<u32> {
    let (buf, len) = swapped(covered)?;
    Some(TABLE.checksum(&buf[..len]))
}

#[cfg(feature = "std")]
fn backend(bytes: &[u8]) -> u32 {
    // A 32-bit algorithm: the u64 result fits in u32.
    crc_fast::checksum(crc_fast::CrcAlgorithm::Crc32Mpeg2, bytes) as u32
}

#[cfg(not(feature = "std"))]
fn backend(bytes: &[u8]) -> u32 {
    TABLE.checksum(bytes)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn worked_examples_of_spec_4_4_on_both_backends() {
        let sixteen: Vec<u8> = (1..=16u32).flat_map(u32::to_le_bytes).collect();
        let cases: [(&[u8], u32); 6] = [
            (&[0; 4], 0xC704_DD7B),
            (&[0xFF; 4], 0),
            (&[0x78, 0x56, 0x34, 0x12], 0xDF8A_8A2B),
            (&sixteen, 0x937E_FC66),
            (&[0; 808], 0x4B5A_4880),
            (&[0; 1176], 0x85F1_1EA6),
        ];
        for (input, crc) in cases {
            assert_eq!(crc32_words(input), Some(crc));
            assert_eq!(crc32_words_table(input), Some(crc));
            assert_eq!(crc32_words_masked(input, &[0xFF; MAX_COVERED_LEN]), Some(crc));
        }
        assert_eq!(crc32_words(&[0; 3]), None);
        assert_eq!(crc32_words_masked(&[0; 8], &[0xFF; 4]), None, "a mask shorter than the bytes");
        // Masked bytes count as zeros, wherever the chunks fall.
        let image: Vec<u8> = (0..2000u32).map(|i| i as u8 | 1).collect();
        let mask: Vec<u8> = (0..2000u32).map(|i| if i % 7 == 3 { 0 } else { 0xFF }).collect();
        let zeroed: Vec<u8> = image.iter().zip(&mask).map(|(b, m)| b & m).collect();
        assert_eq!(crc32_words_masked(&image, &mask), crc32_words_table(&zeroed));
        assert_eq!(crc32_words(&[0; MAX_COVERED_LEN + 4]), None);
    }
}
