#!/usr/bin/env bash
# The main job, end to end: installs what is missing, builds, then runs the
# pipeline and prints what it made.
#   simulate  a 4-scan campaign of the campus site with exact ground truth,
#             the scan files carrying pose errors of up to 3° and 0.5 m
#   import    the simulated scans, then the bundled real-format samples
#             (multi-scan georeferenced PTX, image triplet, organized PCD, E57
#             structured with its images and unstructured)
#   geometry  per-point footprints, normals and mixed-pixel flags
#   register  coarse (features) + point-to-plane ICP + global refinement
#   merge     keep masks: each surface from the scan that sampled it most finely
#   segment   scan 1 into an object tree (campus → buildings → walls, windows,
#             doors, a roof, a sign; trees → crowns, trunks) from the clicks,
#             lassos and channels in scripts/campus_segment.json
#   history   the journal of those commands; undo and redo of the merge
#   harmonize one colour correction per scan (exposure and white balance) so
#             the same wall looks the same from every scan
#   render    the merged model as splats (headless OpenGL) from three cameras,
#             beside the simulator's truth pictures (out/demo/render/)
#   recolor   the trees recoloured through their group, rendered, and undone
#   info      table and JSON
#   export    PTX (lossless), PLY and CSV (world coordinates), the merged model as
#             PLY, LAS and E57, and the E57 imported again
#   bench     raw-scan I/O throughput against PCL's reader
# Output goes to DEMO_OUT (default: out/demo/).
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

phase "simulate"
"$scanbench" simulate --site campus --seed 1 --out "$out/campus" --pose-error-deg 3 --pose-error-m 0.5

phase "import"
"$scanbench" import "$project" "$out"/campus/campus_scan_*.json
samples="$out/samples.sbproj"
"$scanbench" import "$samples" "$fixtures/ptx/two_scans.ptx" "$fixtures/ptx/tiny_color.ptx" \
  "$fixtures/triplet/small.json" "$fixtures/pcd/organized_ascii.pcd" \
  "$fixtures/e57/structured_spherical.e57" "$fixtures/e57/unstructured_cartesian.e57"

phase "geometry"
"$scanbench" geometry "$project"
"$scanbench" geometry "$samples" --window 2 --edge-window 1

phase "register"
"$scanbench" register "$project"

phase "merge"
"$scanbench" merge "$project"

phase "segment"
# Each click, commit and group is a command of its own. The click positions
# are those of the campus at seed 1, the site simulated above.
"$scanbench" segment "$project" --script "$root/scripts/campus_segment.json"
"$scanbench" objects "$project"

phase "history"
# Every stage above is a command in the project's journal; undo takes the
# last commit back (the crown returns to the pool), redo restores it exactly.
"$scanbench" history "$project"
"$scanbench" undo "$project"
"$scanbench" redo "$project"

phase "lod"
# The level-of-detail store beside the project, which `render` and the
# workbench draw from: built in parallel from the scans, a band of rows at a
# time. A colour correction leaves it current; a change to the points or
# the objects makes `render` build it again.
"$scanbench" lod "$project"

phase "harmonize"
# Each scan was taken under its own sun, exposure and white balance; the
# street view before harmonising, then one correction per scan.
mkdir -p "$out/render"
"$scanbench" render "$project" --view "$root/scripts/views/campus_street.json" \
  -o "$out/render/street_unharmonized.png"
"$scanbench" harmonize "$project"

phase "render"
# The merged model as blended splats from the three cameras of
# `bench render` (scripts/views), beside the simulator's truth pictures; the
# close-up also as raw points, and the street coloured by object.
for view in closeup street overview; do
  "$scanbench" simulate --site campus --seed 1 --render-view "$root/scripts/views/campus_$view.json" \
    -o "$out/render/${view}_truth.png"
  "$scanbench" render "$project" --view "$root/scripts/views/campus_$view.json" \
    -o "$out/render/${view}_blended.png"
done
"$scanbench" render "$project" --view "$root/scripts/views/campus_closeup.json" --mode points \
  -o "$out/render/closeup_points.png"
"$scanbench" render "$project" --view "$root/scripts/views/campus_street.json" --color object \
  --lighting -o "$out/render/street_objects.png" --json

phase "recolor"
# Non-destructive edits of objects (the scans keep their colours): the trees
# group turned autumnal (its crowns and trunks inherit the edit), tree 1's
# trunk keeping its own hue; rendered, then both undone.
"$scanbench" recolor "$project" --object trees --hue -55 --saturation 1.6 --brightness 4
"$scanbench" recolor "$project" --object "tree 1 trunk" --hue 0 --saturation 1
"$scanbench" objects "$project"
"$scanbench" render "$project" --view "$root/scripts/views/campus_street.json" \
  -o "$out/render/street_recolored.png"
"$scanbench" undo "$project"
"$scanbench" undo "$project"

phase "info"
"$scanbench" info "$project"
"$scanbench" info "$samples"
"$scanbench" info "$project" --json >"$out/info.json"
echo "JSON description: $out/info.json"

phase "export"
"$scanbench" export "$project" --format ply --scan 1 -o "$out/campus_scan_1.ply"
"$scanbench" export "$project" --format ply --merged -o "$out/campus_merged.ply"
# A PTX holds scan grids: the first sample scan (the clouds go to CSV and E57).
"$scanbench" export "$samples" --format ptx --scan 1 -o "$out/samples.ptx"
"$scanbench" export "$samples" --format csv -o "$out/samples.csv"
# The merged campus for survey tools (LAS) and scanner software (E57), and
# the E57 read back into a project of its own.
"$scanbench" export "$project" --format las --merged -o "$out/campus_merged.las"
"$scanbench" export "$project" --format e57 --merged -o "$out/campus_merged.e57"
"$scanbench" import "$out/reimported.sbproj" "$out/campus_merged.e57"
"$scanbench" info "$out/reimported.sbproj"
"$scanbench" export "$samples" --format e57 -o "$out/samples.e57"

phase "bench io"
"$scanbench" bench io
