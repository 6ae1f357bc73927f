//! Cost of one 1 ms communication step of each damper model in the reference cases of
//! [`fmu_damper::perf`] (coupled-like stroke and valve command), one core; prints the machine
//! load beside the figures.
//!
//! Run: `cargo bench -p fmu-damper --bench per_step`.
//! Instruction counts (independent of the machine load):
//! `valgrind --tool=callgrind --collect-atstart=no --toggle-collect='*run_steps*'
//!  target/release/deps/per_step-HASH --once CASE` runs 2000 steps of case number CASE (0-4, in
//! the order of `DamperCase::ALL`) and prints the bits of the summed force (equal bits = equal
//! results, to compare two builds).
#![allow(clippy::unwrap_used, clippy::expect_used)]

use fmu_damper::perf::{ns_per_step, DamperCase, DamperWorkload};

fn load_average() -> String {
    std::fs::read_to_string("/proc/loadavg")
        .map(|s| s.split_whitespace().take(3).collect::<Vec<_>>().join(" "))
        .unwrap_or_else(|_| "unknown".into())
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    if let Some(i) = args.iter().position(|a| a == "--once") {
        let case: usize = args.get(i + 1).and_then(|s| s.parse().ok()).unwrap_or(0);
        let case = DamperCase::ALL[case.min(DamperCase::ALL.len() - 1)];
        let mut m = DamperWorkload::new(case).unwrap();
        let sum = m.run_steps(0, 2000).unwrap();
        println!("{}: force sum bits {:016x}", case.name(), sum.to_bits());
        return;
    }
    for case in DamperCase::ALL {
        let before = load_average();
        let ns = ns_per_step(case, 5000, 21).unwrap();
        println!(
            "{:<26} {:>8.0} ns per 1 ms step ({:>6.0} x real time; load average before/after: \
             {before} / {})",
            case.name(),
            ns,
            1e6 / ns,
            load_average()
        );
    }
}
