//! Rows of the Unitree low-level codec benchmarks (`unitree-proto`'s criterion bench): the CRC
//! beside Unitree's bitwise routine, the Go2 and HG messages' encode/decode beside a memcpy, their
//! XCDR1 copy plans beside the struct-image paths.

use std::path::Path;

use super::{Row, mean_ns};

/// Rows of the Unitree LowCmd/LowState benchmarks (Go2, then HG).
pub(crate) fn rows(criterion: &Path) -> anyhow::Result<Vec<Row>> {
    let group = "lowcmd_crc_808B";
    let ours = mean_ns(criterion, group, "message_crc")?;
    let slice = mean_ns(criterion, group, "crc_fast")?;
    let kernel = mean_ns(criterion, group, "pclmul_kernel_only")?;
    let table = mean_ns(criterion, group, "table16")?;
    let bitwise = mean_ns(criterion, group, "bitwise_oracle")?;
    let mut rows = vec![
        Row {
            path: "LowCmd CRC, 808 B (padding masked and words swapped in one pass, crc-fast)".into(),
            figure: format!("{ours:.0} ns"),
            baseline: format!("PCLMUL kernel alone: {kernel:.0} ns"),
            ratio: format!("{:.2}×", ours / kernel),
            target: "≤ 2× PCLMUL and ≤ 150 ns".into(),
            met: Some(ours <= 2.0 * kernel && ours <= 150.0),
        },
        Row {
            path: "CRC of a borrowed 808 B slice (copy + swap + crc-fast)".into(),
            figure: format!("{slice:.0} ns"),
            baseline: format!("PCLMUL kernel alone: {kernel:.0} ns"),
            ratio: format!("{:.2}×", slice / kernel),
            target: "–".into(),
            met: None,
        },
        Row {
            path: "LowCmd CRC vs Unitree's bitwise routine".into(),
            figure: format!("{ours:.0} ns"),
            baseline: format!("bitwise: {bitwise:.0} ns"),
            ratio: format!("{:.0}× faster", bitwise / ours),
            target: "–".into(),
            met: None,
        },
        Row {
            path: "LowCmd CRC, no_std table backend".into(),
            figure: format!("{table:.0} ns"),
            baseline: format!("bitwise: {bitwise:.0} ns"),
            ratio: format!("{:.0}× faster", bitwise / table),
            target: "–".into(),
            met: None,
        },
    ];
    let codec = "lowcmd_codec";
    let copy_cmd = mean_ns(criterion, codec, "memcpy_812B")?;
    let copy_state = mean_ns(criterion, codec, "memcpy_1180B")?;
    for (bench, label, copy, copy_label) in [
        ("lowcmd_encode_image", "LowCmd encode (zero padding, CRC)", copy_cmd, "memcpy 812 B"),
        ("lowcmd_decode_verify_image", "LowCmd decode + verify", copy_cmd, "memcpy 812 B"),
        ("lowstate_encode_image", "LowState encode (zero padding, CRC)", copy_state, "memcpy 1180 B"),
        ("lowstate_decode_verify_image", "LowState decode + verify", copy_state, "memcpy 1180 B"),
    ] {
        let ns = mean_ns(criterion, codec, bench)?;
        rows.push(Row {
            path: label.into(),
            figure: format!("{ns:.0} ns"),
            baseline: format!("{copy_label}: {copy:.0} ns"),
            ratio: format!("{:.1}×", ns / copy),
            target: "–".into(),
            met: None,
        });
    }
    // The CDR paths run on precomputed copy plans: within 2× of the struct-image paths.
    for (bench, label, image, image_label) in [
        ("lowcmd_encode_xcdr1", "LowCmd encode XCDR1 (copy plan)", "lowcmd_encode_image", "image encode"),
        (
            "lowcmd_decode_verify_xcdr1",
            "LowCmd decode XCDR1 + verify",
            "lowcmd_decode_verify_image",
            "image decode + verify",
        ),
        ("lowstate_encode_xcdr1", "LowState encode XCDR1 (copy plan)", "lowstate_encode_image", "image encode"),
        (
            "lowstate_decode_verify_xcdr1",
            "LowState decode XCDR1 + verify",
            "lowstate_decode_verify_image",
            "image decode + verify",
        ),
    ] {
        let (ns, base) = (mean_ns(criterion, codec, bench)?, mean_ns(criterion, codec, image)?);
        rows.push(Row {
            path: label.into(),
            figure: format!("{ns:.0} ns"),
            baseline: format!("struct {image_label}: {base:.0} ns"),
            ratio: format!("{:.2}×", ns / base),
            target: "≤ 2× the struct image".into(),
            met: Some(ns <= 2.0 * base),
        });
    }
    rows.extend(hg_rows(criterion)?);
    Ok(rows)
}

/// The HG (G1) messages beside the Go2 rows: image paths against a memcpy of the image, XCDR1
/// paths against the image paths.
fn hg_rows(criterion: &Path) -> anyhow::Result<Vec<Row>> {
    let group = "hg_codec";
    let mut rows = Vec::new();
    for (name, label, bytes) in [("hg_lowcmd", "HG LowCmd", 1004), ("hg_lowstate", "HG LowState", 2092)] {
        let ns = |bench: &str| mean_ns(criterion, group, &format!("{name}_{bench}"));
        let copy = ns("memcpy")?;
        for (bench, what) in
            [("encode_image", "encode (zero padding, CRC)"), ("decode_verify_image", "decode + verify")]
        {
            let t = ns(bench)?;
            rows.push(Row {
                path: format!("{label} {what}"),
                figure: format!("{t:.0} ns"),
                baseline: format!("memcpy {bytes} B: {copy:.0} ns"),
                ratio: format!("{:.1}×", t / copy),
                target: "–".into(),
                met: None,
            });
        }
        for (bench, image, what) in [
            ("encode_xcdr1", "encode_image", "encode XCDR1 (copy plan)"),
            ("decode_verify_xcdr1", "decode_verify_image", "decode XCDR1 + verify"),
        ] {
            let (t, base) = (ns(bench)?, ns(image)?);
            rows.push(Row {
                path: format!("{label} {what}"),
                figure: format!("{t:.0} ns"),
                baseline: format!("struct image: {base:.0} ns"),
                ratio: format!("{:.2}×", t / base),
                target: "≤ 2× the struct image".into(),
                met: Some(t <= 2.0 * base),
            });
        }
    }
    Ok(rows)
}
