//! Decode and encode of every DBC message (target < 200 ns per frame), and fast-packet
//! reassembly of one 129029 message.

use agsteer::can::codec::{decode, encode_values, MAX_SIGNALS, MESSAGES};
use agsteer::can::fastpacket::{split, Reassembler};
use criterion::{black_box, criterion_group, criterion_main, Criterion};

fn bench(c: &mut Criterion) {
    let mut g = c.benchmark_group("codec");
    for def in MESSAGES {
        // Mid-range values for every signal.
        let mut values = [None; MAX_SIGNALS];
        for (i, s) in def.signals.iter().enumerate() {
            values[i] = Some(((s.min + s.max) / 2.0 / s.factor).round() * s.factor);
        }
        let frame = encode_values(def, &values, 3, 0x1C).expect("encodes");
        g.bench_function(format!("decode/{}", def.name), |b| {
            b.iter(|| decode(black_box(frame.id), black_box(frame.payload())))
        });
        g.bench_function(format!("encode/{}", def.name), |b| {
            b.iter(|| encode_values(def, black_box(&values), 3, 0x1C))
        });
    }
    let payload: Vec<u8> = (0..47u8).collect();
    let mut frames = Vec::new();
    split(&payload, 1, &mut frames);
    let mut r = Reassembler::default();
    g.bench_function("fastpacket/129029_reassembly_7_frames", |b| {
        b.iter(|| {
            let mut n = 0;
            for f in &frames {
                if let Ok(Some(p)) = r.push(0x1C, black_box(f)) {
                    n = p.len();
                }
            }
            n
        })
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
