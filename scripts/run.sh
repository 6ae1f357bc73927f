#!/usr/bin/env bash
# The project's main job: build and package every FMU into dist/, then run the built-in default
# study (passive, semi-active and full-active yaw dampers on the bogie, coupled by our master)
# and write the report, plots and CSVs into results/.
set -euo pipefail
cd "$(dirname "$0")/.."
source scripts/setup.sh

step "package the FMUs into dist/"
package_fmus

step "default study -> results/"
cargo run --release -q -p rail-study --bin master -- study --fmus dist --out results "$@"
echo "report: results/REPORT.md"
