#!/usr/bin/env bash
# The benchmark command: builds and packages the FMUs and the master, then measures every speed
# figure in one run (tests/benches/ratios/): each model alone, the coupled passive system in
# our master vs the same physics in plain Rust (wall clock and instructions) and vs fmpy, the
# run-set speed-up on 2 workers and the studies' wall time. Writes docs/BENCHMARKS.md (linked from the README).
# Speed is never asserted by the tests; this is where it is measured.
set -euo pipefail
cd "$(dirname "$0")/.."
source scripts/setup.sh

# valgrind counts the instructions per step of the coupled system (section `instructions`)
if ! command -v valgrind >/dev/null; then
  step "installing valgrind (instruction counts)"
  as_root apt-get update -qq
  as_root env DEBIAN_FRONTEND=noninteractive apt-get install -y -qq valgrind >/dev/null
fi

step "package the FMUs into dist/ and build the master"
package_fmus
cargo build --release -q -p rail-study --bin master

step "benchmark (one run; the load average is printed beside every figure)"
export RAIL_PYTHON="$VENV/bin/python"
export BENCH_OUT="$PWD/docs/BENCHMARKS.md"
# studies to time, separated by ";" (each is `master study <options>`): the coach study (the
# default) and the 2-dof bogie study
export BENCH_STUDY="${BENCH_STUDY:---jobs 2;--vehicle bogie2dof --jobs 2}"
cargo bench -q -p tests --bench ratios
