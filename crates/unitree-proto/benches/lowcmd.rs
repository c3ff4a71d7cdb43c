//! CRC, encode and decode+verify of the Go2 and HG (G1) messages, each beside its baseline from
//! the same run: the CRC beside Unitree's bitwise routine (and the portable table backend),
//! encode/decode beside a memcpy of the same image.

// `criterion_group!` generates an undocumented public function.
#![allow(missing_docs)]

mod oracle;

use std::hint::black_box;

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use unitree_proto::crc::{crc32_words, crc32_words_table};
use unitree_proto::g1::{self, G1Variant};
use unitree_proto::{CdrEncoding, HgLowState, LowCmd, LowState, Message, MotorCmd};

fn stand_command() -> LowCmd {
    let mut cmd = LowCmd::default();
    for (i, m) in cmd.motor_cmd.iter_mut().take(12).enumerate() {
        let q = [0.0, 0.67, -1.3][i % 3];
        *m = MotorCmd::servo(q, 0.0, 60.0, 5.0, 0.0);
    }
    cmd
}

fn benches(c: &mut Criterion) {
    let cmd = stand_command();
    let image = cmd.to_image();
    let covered = &image[..808];

    let mut crc = c.benchmark_group("lowcmd_crc_808B");
    crc.throughput(Throughput::Bytes(808));
    crc.bench_function("crc_fast", |b| b.iter(|| crc32_words(black_box(covered))));
    // The encoder's path: the padding masked and the words swapped in one pass, then the CRC.
    crc.bench_function("message_crc", |b| b.iter(|| black_box(&cmd).computed_crc()));
    // The PCLMUL kernel alone, on bytes already in CRC order: the reference for "within 2x".
    let swapped: Vec<u8> = covered.chunks_exact(4).flat_map(|w| [w[3], w[2], w[1], w[0]]).collect();
    crc.bench_function("pclmul_kernel_only", |b| {
        b.iter(|| crc_fast::checksum(crc_fast::CrcAlgorithm::Crc32Mpeg2, black_box(&swapped)))
    });
    crc.bench_function("table16", |b| b.iter(|| crc32_words_table(black_box(covered))));
    crc.bench_function("bitwise_oracle", |b| b.iter(|| oracle::crc32_bitwise(black_box(covered))));
    crc.finish();

    let state_image = {
        let mut state = LowState::default();
        state.tick = 12345.into();
        state.imu_state.quaternion[0] = 1.0.into();
        state.to_image()
    };
    let mut codec = c.benchmark_group("lowcmd_codec");
    let mut out = [0u8; 1188];
    codec.bench_function("lowcmd_encode_image", |b| b.iter(|| black_box(&cmd).encode_image(&mut out)));
    codec.bench_function("lowcmd_decode_verify_image", |b| b.iter(|| LowCmd::decode_image(black_box(&image)).is_ok()));
    codec.bench_function("lowstate_encode_image", |b| {
        let state = LowState::decode_image(&state_image).unwrap();
        b.iter(|| black_box(&state).encode_image(&mut out))
    });
    codec.bench_function("lowstate_decode_verify_image", |b| {
        b.iter(|| LowState::decode_image(black_box(&state_image)).is_ok())
    });
    codec
        .bench_function("lowcmd_encode_xcdr1", |b| b.iter(|| black_box(&cmd).encode_cdr(CdrEncoding::Xcdr1, &mut out)));
    let mut cdr = [0u8; 812];
    cmd.encode_cdr(CdrEncoding::Xcdr1, &mut cdr).unwrap();
    codec.bench_function("lowcmd_decode_verify_xcdr1", |b| b.iter(|| LowCmd::decode_cdr(black_box(&cdr)).is_ok()));
    let state = LowState::decode_image(&state_image).unwrap();
    codec.bench_function("lowstate_encode_xcdr1", |b| {
        b.iter(|| black_box(&state).encode_cdr(CdrEncoding::Xcdr1, &mut out))
    });
    let mut state_cdr = [0u8; 1180];
    state.encode_cdr(CdrEncoding::Xcdr1, &mut state_cdr).unwrap();
    codec.bench_function("lowstate_decode_verify_xcdr1", |b| {
        b.iter(|| LowState::decode_cdr(black_box(&state_cdr)).is_ok())
    });
    codec.bench_function("memcpy_812B", |b| {
        b.iter(|| {
            out[..812].copy_from_slice(black_box(&image));
            black_box(&out);
        })
    });
    codec.bench_function("memcpy_1180B", |b| {
        b.iter(|| {
            out[..1180].copy_from_slice(black_box(&state_image));
            black_box(&out);
        })
    });
    codec.finish();

    // The G1's messages: a 29-joint hold and a LowState, image and XCDR1, beside a memcpy.
    let mut hg = c.benchmark_group("hg_codec");
    let hold = g1::hold(&[0.1; g1::JOINTS], 5, G1Variant::Dof29);
    let mut state = HgLowState::default();
    state.mode_machine = 5;
    state.tick = 12345.into();
    let mut out = [0u8; 2200];
    image_and_xcdr1(&mut hg, "hg_lowcmd", &hold, &mut out);
    image_and_xcdr1(&mut hg, "hg_lowstate", &state, &mut out);
    hg.finish();
}

/// `{name}_encode_image`, `_decode_verify_image`, `_encode_xcdr1`, `_decode_verify_xcdr1` and
/// `{name}_memcpy` (the image's length) of `message`.
fn image_and_xcdr1<M: Message>(
    group: &mut criterion::BenchmarkGroup<'_, criterion::measurement::WallTime>,
    name: &str,
    message: &M,
    out: &mut [u8],
) {
    let mut image = vec![0u8; M::IMAGE_LEN];
    message.encode_image(&mut image).unwrap();
    let mut cdr = vec![0u8; out.len()];
    let n = message.encode_cdr(CdrEncoding::Xcdr1, &mut cdr).unwrap();
    cdr.truncate(n);
    group.bench_function(format!("{name}_encode_image"), |b| b.iter(|| black_box(message).encode_image(out)));
    group.bench_function(format!("{name}_decode_verify_image"), |b| {
        b.iter(|| M::decode_image(black_box(&image)).is_ok())
    });
    group.bench_function(format!("{name}_encode_xcdr1"), |b| {
        b.iter(|| black_box(message).encode_cdr(CdrEncoding::Xcdr1, out))
    });
    group.bench_function(format!("{name}_decode_verify_xcdr1"), |b| b.iter(|| M::decode_cdr(black_box(&cdr)).is_ok()));
    group.bench_function(format!("{name}_memcpy"), |b| {
        b.iter(|| {
            out[..image.len()].copy_from_slice(black_box(&image));
            black_box(&out);
        })
    });
}

criterion_group!(lowcmd, benches);
criterion_main!(lowcmd);
