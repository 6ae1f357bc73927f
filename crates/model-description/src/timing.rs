//! Per-step timing for the FMU crates' benchmark workloads (speed is measured by benchmarks,
//! never by tests).

use std::time::Instant;

/// Wall-clock nanoseconds per step: the median of `repeats` (at least one) timed runs of
/// `steps` steps each. `run(k0, n)` takes steps `k0 .. k0 + n` of one workload (the runs follow
/// each other from `first_step` on) and returns a value kept from the optimiser.
pub fn median_ns_per_step<T, E>(
    first_step: u64,
    steps: u64,
    repeats: usize,
    mut run: impl FnMut(u64, u64) -> Result<T, E>,
) -> Result<f64, E> {
    let mut k0 = first_step;
    let mut per_step = Vec::with_capacity(repeats.max(1));
    for _ in 0..repeats.max(1) {
        let start = Instant::now();
        std::hint::black_box(run(k0, steps)?);
        per_step.push(start.elapsed().as_secs_f64() * 1e9 / steps.max(1) as f64);
        k0 += steps;
    }
    per_step.sort_by(f64::total_cmp);
    Ok(per_step[per_step.len() / 2])
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_runs_follow_each_other_and_a_failure_stops_them() {
        let mut starts = Vec::new();
        let t = median_ns_per_step(5, 10, 3, |k0, n| {
            starts.push((k0, n));
            Ok::<_, ()>(k0)
        });
        assert!(t.is_ok_and(|ns| ns >= 0.0));
        assert_eq!(starts, [(5, 10), (15, 10), (25, 10)]);
        let mut calls = 0;
        let e = median_ns_per_step(0, 1, 4, |_, _| {
            calls += 1;
            Err::<(), _>("no")
        });
        assert_eq!((e, calls), (Err("no"), 1));
    }
}
