#!/usr/bin/env bash
# How fast ppm and path converge on the area-light Cornell box of ../shared/reference: each
# integrator renders for 1, 2, 4, … seconds (each run from scratch, all cores, 160×160, particle
# view as in the reference) and the region errors against the independent reference are printed
# as a Markdown table. The error is the largest relative error over the RGB channels of a
# region's mean. Path lengths are cut as the reference's are (its particle tracer stops at 10
# path segments: light from a diffuse surface has met at most 9 surfaces), so both run with
# --depth 8: ppm keeps photons of at most 8 bounces and path scatters camera paths at most 9
# times (see crates/caustica/tests/it/physical.rs).
#   usage: scripts/convergence.sh [REFERENCE_DIR] [LONGEST_SECONDS]
set -euo pipefail
cd "$(dirname "$0")/.."
ref=${1:-../shared/reference}
longest=${2:-256}
bin=target/release/caustica
[ -x "$bin" ] || cargo build --release
scene="$ref/cornell_caustics_area.ray"
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
echo "| integrator | seconds | passes | caustic error | lit floor error | shadow error |"
echo "|---|---:|---:|---:|---:|---:|"
for integrator in ppm path; do
  seconds=1
  while [ "$seconds" -le "$longest" ]; do
    summary=$("$bin" render "$scene" --integrator "$integrator" --width 160 --photons 100000 \
      --no-camera-specular --depth 8 --time "$seconds" --passes 1000000 -o "$tmp/out.exr" --json)
    passes=$(sed -E 's/.*"passes":([0-9]+).*/\1/' <<<"$summary")
    errors=$("$bin" compare "$tmp/out.exr" "$ref/cornell_caustics_area_ref.exr" --json \
      --region caustic=135..139,41..45 --region floor=150..158,60..90 --region shadow=150..156,108..135 |
      grep -o '"relative_error":[0-9.e+-]*' | cut -d: -f2 |
      awk '{ printf "%.2f%% | ", 100 * $1 }')
    echo "| $integrator | $seconds | $passes | ${errors% | } |"
    seconds=$((seconds * 2))
  done
done
