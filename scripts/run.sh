#!/usr/bin/env bash
# The project's main job: build and package every FMU into dist/, then run the built-in default
# study (passive, semi-active and full-active yaw dampers on the coach, coupled by our master)
# into results/, and the same study on the 2-dof bogie (the seed's HIL configuration) into
# results/bogie2dof/: reports, plots and CSVs.
set -euo pipefail
cd "$(dirname "$0")/.."
source scripts/setup.sh

# every run's full-rate results are kept (Parquet): about 2.1 GB for the two studies
mkdir -p results
free_kb=$(df -Pk results | awk 'NR == 2 {print $4}')
if [ "$#" -eq 0 ] && [ -n "$free_kb" ] && [ "$free_kb" -lt 2600000 ]; then
  echo "warning: the two studies store about 2.1 GB of results under results/ and only" \
    "$((free_kb / 1024)) MB are free; a run that cannot be written fails the study." \
    "'bash scripts/run.sh --format csv' stores about a third." >&2
fi

step "package the FMUs into dist/"
package_fmus

step "default study (coach) -> results/"
cargo run --release -q -p rail-study --bin master -- study --fmus dist --out results "$@"
step "bogie study (HIL configuration) -> results/bogie2dof/"
cargo run --release -q -p rail-study --bin master -- study --vehicle bogie2dof --fmus dist --out results/bogie2dof "$@"
echo "reports: results/REPORT.md, results/bogie2dof/REPORT.md"
