#!/usr/bin/env bash
# The main job on the bundled data (installs missing Debian packages first, as root).
# Until the super-resolution network lands, this is the richest thing that works: the bunny
# example's §3.2 upsampling neighbourhoods, then every interpolation baseline (Embedded, IDW, MLS,
# RBF, and the data-driven ridge baseline) on held-out frames, with Table-1 statistics, frame-wise
# errors (CSV + SVG plot) and per-vertex error heatmaps (ParaView .pvd) in out/; plus mesh and
# array statistics of the bundled data and conversions to ParaView/Gmsh/MEDIT files.
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
cd "$root"
bash scripts/deps.sh run
build=${SIMSR_BUILD_DIR:-build}
cmake -S . -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build "$build" -j "$(nproc)" --target simsr_cli
data=${SIMSR_DATA:-$root/../shared/data}
out=${SIMSR_OUT:-$root/out}
mkdir -p "$out"
simsr="$build/examples/simsr"
set -x
"$simsr" info "$data/bunny/lrestshape.obj"
"$simsr" info "$data/bunny/hrestshape.obj"
"$simsr" info "$data/bunny/train_frames.npz"
"$simsr" info "$data/ict_face/neutral_face_head.obj"
"$simsr" info "$data/ict_face/expressions.npz"
"$simsr" convert "$data/bunny/lrestshape.obj" "$out/bunny_lr.vtu"
"$simsr" convert "$data/bunny/lrestshape.obj" "$out/bunny_lr.msh"
"$simsr" convert "$data/bunny/lrestshape.obj" "$out/bunny_lr.mesh"
"$simsr" convert "$data/bunny/hrestshape.obj" "$out/bunny_hr.vtu"
"$simsr" convert "$data/ict_face/neutral_face_head.obj" "$out/face.vtu"
"$simsr" info "$out/bunny_lr.msh"
"$simsr" neighbors --lr-rest "$data/bunny/lrestshape.obj" --hr-rest "$data/bunny/hrestshape.obj" --k 20 --lr-k 5 \
  --out "$out/bunny_neighbors.npz"
"$simsr" baselines --lr-rest "$data/bunny/lrestshape.obj" --hr-rest "$data/bunny/hrestshape.obj" \
  --frames "$data/bunny/train_frames.npz" --neighbors "$out/bunny_neighbors.npz" --out-dir "$out/bunny_baselines"
{ set +x; } 2>/dev/null
echo "simsr: wrote $(ls "$out" | tr '\n' ' ')to $out"
echo "simsr: open out/bunny_baselines/frame_errors.svg in a browser, out/bunny_baselines/heatmaps.pvd and out/*.vtu in ParaView"
