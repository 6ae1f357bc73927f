#!/usr/bin/env bash
# The project's test command (also what CI runs): installs what it needs, checks formatting,
# lints and the API documentation, builds and packages every FMU, checks every FMU with the
# third-party validators (when ../shared/validators is there), runs all Rust tests, validates
# and simulates every FMU with fmpy and compares fmpy's results with the same physics called
# directly from Rust.
set -euo pipefail
cd "$(dirname "$0")/.."
source scripts/setup.sh

# Windows DLLs compiled from C at test time stand in for binaries built on another platform
# (crates/model-description/tests/merge_binaries.rs); they are never shipped.
if ! command -v x86_64-w64-mingw32-gcc >/dev/null || ! command -v i686-w64-mingw32-gcc >/dev/null; then
  step "installing mingw-w64 (test fixtures: Windows DLLs)"
  as_root apt-get update -qq
  as_root env DEBIAN_FRONTEND=noninteractive apt-get install -y -qq gcc-mingw-w64-x86-64 gcc-mingw-w64-i686 >/dev/null
fi

step "cargo fmt --check"
cargo fmt --all -- --check

step "cargo clippy (-D warnings), without and with the FMU exports"
cargo clippy --workspace --all-targets -- -D warnings
cargo clippy --workspace --all-targets --features fmi-export -- -D warnings

step "cargo doc (-D warnings): the API documentation has no broken links"
RUSTDOCFLAGS="-D warnings" cargo doc --workspace --no-deps -q

step "package the FMUs into dist/"
package_fmus

step "portable binaries: each FMU binary fits its platform folder; Linux ones need glibc <= 2.17"
cargo run --release -q -p fmu-binary -- dist/*.fmu

step "third-party validators (fmusim, fmuCheck) on every FMU in dist/"
# ../shared/validators/check_fmu.sh (relative to the repository root) runs fmusim validate and
# simulate and fmuCheck on one FMU over its default experiment; it is not part of this
# repository, so the step is skipped, saying so, where it is not installed.
validators="../shared/validators/check_fmu.sh"
if [ -x "$validators" ]; then
    failed=0
    for fmu in dist/*.fmu; do
        if "$validators" "$fmu" > "target/validators-$(basename "$fmu" .fmu).log" 2>&1; then
            echo "$fmu: PASS"
        else
            echo "$fmu: FAIL"
            cat "target/validators-$(basename "$fmu" .fmu).log"
            failed=1
        fi
    done
    [ "$failed" -eq 0 ] || { echo "third-party validators failed"; exit 1; }
else
    echo "SKIPPED: $validators not found (the third-party validators are not installed here)"
fi

step "fmpy: validate and simulate every FMU in dist/"
rm -rf target/fmpy
"$VENV/bin/python" tests/fmpy/check_fmus.py dist target/fmpy

step "foreign FMUs into target/foreign: fmpy's container FMU around ours, a pythonfmu FMU"
# Each comes with a one-instance system for the master and fmpy's results of it
# (tests/tests/foreign_fmus.rs). The pythonfmu binary needs libpython's symbols loaded globally
# in a non-Python host (it is not linked against libpython; LD_LIBRARY_PATH would not help):
# the tests start a child process with LD_PRELOAD and PYTHONHOME from target/foreign/python_env.txt.
rm -rf target/foreign
"$VENV/bin/python" tests/fmpy/make_container.py dist target/foreign
"$VENV/bin/python" tests/fmpy/make_pythonfmu.py target/foreign

step "Rust tests (release)"
export RAIL_FMPY_RESULTS="$PWD/target/fmpy"
export RAIL_FOREIGN_FMUS="$PWD/target/foreign"
# the venv's python with fmpy: tests/tests/master_vs_fmpy.rs replays master runs in fmpy
export RAIL_PYTHON="$VENV/bin/python"
# a test that finds one of these missing fails instead of skipping
export RAIL_REQUIRE_EXTERNAL=1
if [ -f ../shared/reference-fmus/Stair.fmu ]; then
    export RAIL_REFERENCE_FMUS="$(cd ../shared/reference-fmus && pwd)"
else
    echo "SKIPPED: the Reference FMU tests (../shared/reference-fmus not found)"
fi
cargo test --release --workspace
# The glue's no-allocation test calls the exported C functions in-process (feature fmi-export).
cargo test --release -p fmu-examples --features fmi-export

step "Python package railfmu: wheel built with maturin into target/wheels, installed into the venv, pytest"
# The binding crate is a workspace member whose pyo3 module is behind its feature `python`
# (maturin sets it), so the workspace builds and lints without Python; lint the module here.
cargo clippy -q -p railfmu-python --features python --all-targets -- -D warnings
cargo build --release -q -p rail-study --bin master
python_package
"$VENV/bin/python" -m pytest -q python/tests

step "reproducible packaging: the same build gives the same .fmu bytes"
sha256sum dist/*.fmu > target/fmu.sha256
cargo run --release -q -p model-description --bin package-fmus -- --no-build >/dev/null
sha256sum -c --quiet target/fmu.sha256
echo "all checks passed"
