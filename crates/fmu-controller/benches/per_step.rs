//! Cost of one 1 ms communication step of each control board in the reference cases of
//! [`fmu_controller::perf`] (signals of a hunting bogie), one core; prints the machine
//! load beside the figures.
//!
//! Run: `cargo bench -p fmu-controller --bench per_step`.
//! Instruction counts (independent of the machine load):
//! `valgrind --tool=callgrind --collect-atstart=no --toggle-collect='*run_steps*'
//!  target/release/deps/per_step-HASH --once CASE` runs 2000 steps of case number CASE (0-3, in
//! the order of `ControllerCase::ALL`) and prints the bits of the summed command (equal bits = equal
//! results, to compare two builds).
#![allow(clippy::unwrap_used, clippy::expect_used)]

use fmu_controller::perf::{ns_per_step, ControllerCase, ControllerWorkload};

fn load_average() -> String {
    std::fs::read_to_string("/proc/loadavg")
        .map(|s| s.split_whitespace().take(3).collect::<Vec<_>>().join(" "))
        .unwrap_or_else(|_| "unknown".into())
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    if let Some(i) = args.iter().position(|a| a == "--once") {
        let case: usize = args.get(i + 1).and_then(|s| s.parse().ok()).unwrap_or(0);
        let case = ControllerCase::ALL[case.min(ControllerCase::ALL.len() - 1)];
        let mut m = ControllerWorkload::new(case).unwrap();
        let sum = m.run_steps(0, 2000).unwrap();
        println!("{}: command sum bits {:016x}", case.name(), sum.to_bits());
        return;
    }
    for case in ControllerCase::ALL {
        let before = load_average();
        let ns = ns_per_step(case, 20000, 21).unwrap();
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
