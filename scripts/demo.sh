#!/usr/bin/env bash
# The main job, end to end: installs what is missing, builds, then runs the
# pipeline on the bundled sample scans and prints what it made.
#   import  PTX (multi-scan, georeferenced), image triplet, organized PCD
#   info    table and JSON
#   export  PTX (lossless), PLY and CSV (world coordinates)
#   bench   raw-scan I/O throughput against PCL's reader
# Output goes to DEMO_OUT (default: out/demo/). Later stages (simulate,
# geometry, register, merge, segment, render) join this script as they land.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
"$root/scripts/build.sh"
scanbench="$root/build/bin/scanbench"
fixtures="$root/fixtures/good"
out=${DEMO_OUT:-$root/out/demo}
rm -rf "$out"
mkdir -p "$out"
project="$out/demo.sbproj"

phase() { printf '\n== %s ==\n' "$1"; }

phase "import"
"$scanbench" import "$project" "$fixtures/ptx/two_scans.ptx" "$fixtures/ptx/tiny_color.ptx" \
  "$fixtures/triplet/small.json" "$fixtures/pcd/organized_ascii.pcd"

phase "info"
"$scanbench" info "$project"
"$scanbench" info "$project" --json >"$out/info.json"
echo "JSON description: $out/info.json"

phase "export"
"$scanbench" export "$project" --format ptx -o "$out/all_scans.ptx"
"$scanbench" export "$project" --format ply -o "$out/all_scans.ply"
"$scanbench" export "$project" --format csv -o "$out/all_scans.csv"

phase "bench io"
"$scanbench" bench io
