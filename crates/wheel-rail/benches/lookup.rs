//! Contact-table lookup on the step path: plain binary search against the segment hint, on
//! the lateral displacements of a hunting wheelset (6 mm, 4 Hz, sampled every 25 µs as by an
//! RK4 sub-step) and on jumping displacements. Both variants run in one process (paired).

use std::hint::black_box;

use criterion::{criterion_group, criterion_main, Criterion};
use wheel_rail::{GeometryTable, SegmentHint};

fn bench(c: &mut Criterion) {
    let Ok(table) = GeometryTable::synthetic(0.15, 7e-3, 0.5e-3, 2.7) else {
        return;
    };
    let hunting: Vec<f64> = (0..4000)
        .map(|k| 6e-3 * (2.0 * std::f64::consts::PI * 4.0 * k as f64 * 25e-6).sin())
        .collect();
    let jumping: Vec<f64> = (0..4000)
        .map(|k| ((k * 7919) % 2001) as f64 * 1e-5 - 10e-3)
        .collect();
    for (name, ys) in [("hunting", &hunting), ("jumping", &jumping)] {
        c.bench_function(&format!("lookup/{name}"), |b| {
            b.iter(|| {
                let mut acc = 0.0;
                for &y in ys {
                    acc += table.lookup(black_box(y)).delta_r_right_m;
                }
                acc
            })
        });
        c.bench_function(&format!("lookup_with_hint/{name}"), |b| {
            b.iter(|| {
                let mut hint = SegmentHint::default();
                let mut acc = 0.0;
                for &y in ys {
                    acc += table
                        .lookup_with_hint(&mut hint, black_box(y))
                        .delta_r_right_m;
                }
                acc
            })
        });
    }
}

criterion_group!(benches, bench);
criterion_main!(benches);
