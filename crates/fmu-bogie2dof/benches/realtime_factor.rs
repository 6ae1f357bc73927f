//! Real-time factor of the non-linear bogie alone on one core, 1 ms communication steps, on the
//! ideal and on the internal irregular track ([`fmu_bogie2dof::perf`]); prints the machine load
//! beside the figures.
//!
//! Run: `cargo bench -p fmu-bogie2dof --bench realtime_factor`.
//! Instruction counts (independent of the machine load):
//! `valgrind --tool=callgrind --collect-atstart=no --toggle-collect='*simulate_reference*'
//!  target/release/deps/realtime_factor-HASH --once [ideal|irregular]` runs one simulated second of each case (or of the named one).
#![allow(clippy::unwrap_used, clippy::expect_used)]

use fmu_bogie2dof::perf::{realtime_factor, reference_bogie, simulate_reference, ReferenceTrack};

fn load_average() -> String {
    std::fs::read_to_string("/proc/loadavg")
        .map(|s| s.split_whitespace().take(3).collect::<Vec<_>>().join(" "))
        .unwrap_or_else(|_| "unknown".into())
}

fn main() {
    let cases = [
        ("ideal track", ReferenceTrack::Ideal),
        (
            "internal irregular track",
            ReferenceTrack::InternalIrregular,
        ),
    ];
    let args: Vec<String> = std::env::args().collect();
    if args.iter().any(|a| a == "--once") {
        // `--once [ideal|irregular]`: one simulated second of the named case (default both)
        let only = |t: ReferenceTrack| match t {
            ReferenceTrack::Ideal => !args.iter().any(|a| a == "irregular"),
            ReferenceTrack::InternalIrregular => !args.iter().any(|a| a == "ideal"),
        };
        for (_, track) in cases.into_iter().filter(|c| only(c.1)) {
            let mut b = reference_bogie(track).unwrap();
            std::hint::black_box(simulate_reference(&mut b, 1.0).unwrap());
        }
        return;
    }
    for (name, track) in cases {
        let before = load_average();
        let rtf = realtime_factor(track, 20.0, 7).unwrap();
        println!(
            "bogie non-linear, {name}, 1 ms steps: {rtf:.0} x real time \
             (load average before/after: {before} / {})",
            load_average()
        );
    }
}
