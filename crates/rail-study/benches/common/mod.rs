//! CPU time from /proc/self/stat (Linux; 0 elsewhere), shared by the benches.

/// CPU time (user + system) [s] of this process so far, or of its waited-for children.
pub fn cpu_seconds(children: bool) -> f64 {
    let stat = std::fs::read_to_string("/proc/self/stat").unwrap_or_default();
    // fields after the ")" closing the command name: utime, stime are the 12th and 13th,
    // cutime, cstime (children) the 14th and 15th
    let rest = stat.rsplit_once(')').map_or("", |(_, r)| r);
    let f: Vec<f64> = rest
        .split_whitespace()
        .skip(if children { 13 } else { 11 })
        .take(2)
        .filter_map(|x| x.parse().ok())
        .collect();
    // clock ticks are 100 per second on Linux x86_64/aarch64
    f.iter().sum::<f64>() / 100.0
}

/// The 1-minute load average, from /proc/loadavg.
#[allow(dead_code)] // not every bench prints it
pub fn load_average() -> f64 {
    std::fs::read_to_string("/proc/loadavg")
        .ok()
        .and_then(|s| s.split_whitespace().next().and_then(|x| x.parse().ok()))
        .unwrap_or(f64::NAN)
}
