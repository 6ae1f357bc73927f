#!/usr/bin/env bash
# The project's main job: build and package every FMU into dist/, then run the built-in default
# study (passive, semi-active and full-active yaw dampers on the coach, coupled by our master)
# into results/, and the same study on the 2-dof bogie (the seed's HIL configuration) into
# results/bogie2dof/: reports, plots and CSVs.
set -euo pipefail
cd "$(dirname "$0")/.."
source scripts/setup.sh

step "package the FMUs into dist/"
package_fmus

step "default study (coach) -> results/"
cargo run --release -q -p rail-study --bin master -- study --fmus dist --out results "$@"
step "bogie study (HIL configuration) -> results/bogie2dof/"
cargo run --release -q -p rail-study --bin master -- study --vehicle bogie2dof --fmus dist --out results/bogie2dof "$@"
echo "reports: results/REPORT.md, results/bogie2dof/REPORT.md"
