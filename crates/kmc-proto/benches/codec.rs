//! KMC codec throughput, each beside a memcpy of the same bytes measured in the same run.
//!
//! - `kmc_encode/pc_control`: one 0xA5 frame into a stack buffer; baseline `memcpy_9B`.
//! - `kmc_decode_1MiB/{host_side,device_side}`: a 1 MiB stream of mixed frames (every type of the
//!   direction, in a fixed pseudo-random order) through the stream decoder; baseline `memcpy`.
//!
//! `cargo xtask bench` runs this and prints the table; it passes `ROBOWIRE_BENCH_META` so the
//! frame counts of the streams land beside criterion's figures (for frames/s).

// `criterion_group!` generates an undocumented public function.
#![allow(missing_docs)]

use std::hint::black_box;

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use kmc_proto::{
    AfFrame, AllState, BatteryVoltage, ChassisFrame, ChassisFrameDecoder, HostFrame, HostFrameDecoder, MAX_FRAME_LEN,
    PcControl, StreamDecoder, VehicleSpeed,
};

const STREAM_LEN: usize = 1 << 20;

/// Frames in a deterministic order until `STREAM_LEN` bytes; returns the stream and its frame count.
fn stream(frames: &[[u8; MAX_FRAME_LEN + 1]]) -> (Vec<u8>, usize) {
    let mut out = Vec::with_capacity(STREAM_LEN + MAX_FRAME_LEN);
    let mut rng = 0x2545_f491_4f6c_dd1du64;
    let mut count = 0;
    while out.len() < STREAM_LEN {
        rng ^= rng << 13;
        rng ^= rng >> 7;
        rng ^= rng << 17;
        let frame = &frames[(rng % frames.len() as u64) as usize];
        let len = usize::from(frame[0]);
        if out.len() + len > STREAM_LEN {
            break;
        }
        out.extend_from_slice(&frame[1..=len]);
        count += 1;
    }
    out.resize(STREAM_LEN, 0); // trailing padding: skipped bytes, part of the work
    (out, count)
}

/// A frame encoded with its length in byte 0.
fn encoded(emit: impl FnOnce(&mut [u8]) -> usize) -> [u8; MAX_FRAME_LEN + 1] {
    let mut buf = [0u8; MAX_FRAME_LEN + 1];
    let len = emit(&mut buf[1..]);
    buf[0] = len as u8;
    buf
}

fn chassis_stream() -> (Vec<u8>, usize) {
    let mut state = AllState::new(1);
    state.position_deg = 90.0;
    state.speed_rpm = 1500.0;
    let frames = [
        ChassisFrame::VehicleSpeed(VehicleSpeed { speed_mps: 1.25 }),
        ChassisFrame::BatteryVoltage(BatteryVoltage { motor_id: 0, volts: 24.5 }),
        ChassisFrame::AllState(state),
    ]
    .map(|f| encoded(|b| f.emit(b).unwrap()));
    stream(&frames)
}

fn host_stream() -> (Vec<u8>, usize) {
    let frames = [
        HostFrame::PcControl(PcControl { velocity_mps: 0.5, curvature_per_m: 0.4 }),
        HostFrame::VehicleSpeedRequest,
        HostFrame::Af(AfFrame::battery_read(0)),
        HostFrame::Af(AfFrame::all_state_read(1)),
        HostFrame::Af(AfFrame::speed_write_erpm(0, 1500.0)),
    ]
    .map(|f| encoded(|b| f.emit(b).unwrap()));
    stream(&frames)
}

fn decode_all<D: StreamDecoder>(mut decoder: D, bytes: &[u8]) -> u64 {
    let mut pos = 0;
    let mut frames = 0;
    loop {
        let step = decoder.decode(&bytes[pos..]);
        pos += step.consumed;
        match step.frame {
            Some(frame) => {
                black_box(frame);
                frames += 1;
            }
            None => return frames,
        }
    }
}

fn write_meta(host: usize, chassis: usize) {
    if let Ok(path) = std::env::var("ROBOWIRE_BENCH_META") {
        let json = format!(
            "{{\"kmc_decode_1MiB\":{{\"stream_bytes\":{STREAM_LEN},\"host_side_frames\":{chassis},\"device_side_frames\":{host}}}}}"
        );
        let _ = std::fs::write(path, json);
    }
}

fn benches(c: &mut Criterion) {
    let mut encode = c.benchmark_group("kmc_encode");
    let command = HostFrame::PcControl(PcControl { velocity_mps: 0.5, curvature_per_m: 0.4 });
    let mut buf = [0u8; MAX_FRAME_LEN];
    encode.bench_function("pc_control", |b| b.iter(|| black_box(black_box(&command).emit(&mut buf))));
    let frame9 = [0xa5u8, 0, 0, 0, 0x3f, 0xcd, 0xcc, 0xcc, 0x3e];
    encode.bench_function("memcpy_9B", |b| {
        b.iter(|| {
            buf[..9].copy_from_slice(black_box(&frame9));
            black_box(&buf);
        })
    });
    encode.finish();

    let (chassis, chassis_frames) = chassis_stream();
    let (host, host_frames) = host_stream();
    write_meta(host_frames, chassis_frames);
    // The host-side decoder finds every frame; nothing is lost in the setup.
    assert_eq!(decode_all(ChassisFrameDecoder::new(), &chassis), chassis_frames as u64);
    assert_eq!(decode_all(HostFrameDecoder::new(), &host), host_frames as u64);

    let mut decode = c.benchmark_group("kmc_decode_1MiB");
    decode.throughput(Throughput::Bytes(STREAM_LEN as u64));
    decode.bench_function("host_side", |b| b.iter(|| decode_all(ChassisFrameDecoder::new(), black_box(&chassis))));
    decode.bench_function("device_side", |b| b.iter(|| decode_all(HostFrameDecoder::new(), black_box(&host))));
    let mut copy = vec![0u8; STREAM_LEN];
    decode.bench_function("memcpy", |b| {
        b.iter(|| {
            copy.copy_from_slice(black_box(&chassis));
            black_box(&copy);
        })
    });
    decode.finish();
}

criterion_group!(kmc, benches);
criterion_main!(kmc);
