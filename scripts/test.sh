#!/usr/bin/env bash
# The project's test command (also what CI runs): installs what it needs, checks formatting and
# lints, builds and packages every FMU, runs all Rust tests, validates and simulates every FMU
# with fmpy and compares fmpy's results with the same physics called directly from Rust.
set -euo pipefail
cd "$(dirname "$0")/.."
source scripts/setup.sh

step "cargo fmt --check"
cargo fmt --all -- --check

step "cargo clippy (-D warnings), without and with the FMU exports"
cargo clippy --workspace --all-targets -- -D warnings
cargo clippy --workspace --all-targets --features fmi-export -- -D warnings

step "package the FMUs into dist/"
package_fmus

step "fmpy: validate and simulate every FMU in dist/"
rm -rf target/fmpy
"$VENV/bin/python" tests/fmpy/check_fmus.py dist target/fmpy

step "Rust tests (release)"
export RAIL_FMPY_RESULTS="$PWD/target/fmpy"
cargo test --release --workspace
# The glue's no-allocation test calls the exported C functions in-process (feature fmi-export).
cargo test --release -p fmu-examples --features fmi-export

step "reproducible packaging: the same build gives the same .fmu bytes"
sha256sum dist/*.fmu > target/fmu.sha256
cargo run --release -q -p model-description --bin package-fmus -- --no-build >/dev/null
sha256sum -c --quiet target/fmu.sha256
echo "all checks passed"
