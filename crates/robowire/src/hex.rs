//! Hex input: `a5 00 00 00 3f`, `a500:00:003f`, `0xa5 0x00`, or `-` for standard input.

use std::io::Read;

use anyhow::{Context, bail};

/// The bytes of `text`, or of standard input when `text` is `-`.
pub(crate) fn parse_arg(text: &str) -> anyhow::Result<Vec<u8>> {
    if text == "-" {
        let mut input = String::new();
        std::io::stdin().read_to_string(&mut input).context("reading hex from standard input")?;
        parse(&input)
    } else {
        parse(text)
    }
}

/// Hex digits with optional whitespace, `:`/`,` separators and `0x` prefixes.
pub(crate) fn parse(text: &str) -> anyhow::Result<Vec<u8>> {
    let mut digits = Vec::with_capacity(text.len());
    for token in text.split(|c: char| c.is_whitespace() || c == ':' || c == ',') {
        let token = token.strip_prefix("0x").or_else(|| token.strip_prefix("0X")).unwrap_or(token);
        digits.extend(token.chars());
    }
    if !digits.len().is_multiple_of(2) {
        bail!("odd number of hex digits ({})", digits.len());
    }
    digits
        .chunks(2)
        .enumerate()
        .map(|(i, pair)| {
            let s: String = pair.iter().collect();
            u8::from_str_radix(&s, 16).with_context(|| format!("byte {i}: {s:?} is not hex"))
        })
        .collect()
}

/// Lowercase hex without separators.
pub(crate) fn format(bytes: &[u8]) -> String {
    bytes.iter().map(|b| format!("{b:02x}")).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn separators_and_prefixes() {
        assert_eq!(parse("a5 00:3F,0xb3").unwrap(), [0xa5, 0x00, 0x3f, 0xb3]);
        assert_eq!(parse("").unwrap(), Vec::<u8>::new());
        assert!(parse("a5 0").is_err());
        assert!(parse("zz").is_err());
        assert_eq!(format(&[0xaf, 0x01]), "af01");
    }
}
