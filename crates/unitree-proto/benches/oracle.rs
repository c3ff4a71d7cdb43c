//! Unitree's bitwise CRC routine (spec §4.1), kept only as a test oracle and a benchmark
//! baseline: 32 shifts per word, polynomial 0x04C11DB7, MSB first.

/// CRC of `covered` (little-endian words), bit by bit.
#[allow(dead_code, unreachable_pub)]
pub fn crc32_bitwise(covered: &[u8]) -> u32 {
    let mut crc: u32 = 0xFFFF_FFFF;
    for word in covered.chunks_exact(4) {
        let word = u32::from_le_bytes([word[0], word[1], word[2], word[3]]);
        for bit in (0..32).rev() {
            let top = crc >> 31;
            crc <<= 1;
            if top ^ ((word >> bit) & 1) != 0 {
                crc ^= 0x04C1_1DB7;
            }
        }
    }
    crc
}
