#!/usr/bin/env bash
# The main job on the bundled data (installs missing Debian packages first, as root): on the bunny
# example, the §3.2 upsampling neighbourhoods, every interpolation baseline (Embedded, IDW, MLS,
# RBF, ridge) on the held-out frames (every 4th), then the super-resolution network trained on the
# other frames (~15 minutes on 2 cores), run on the held-out frames and evaluated the same way:
# Table-1 statistics, frame-wise errors (CSV + SVG), per-vertex error heatmaps (ParaView) in out/;
# the cantilever verification of the quasistatic solver (JSON + deformed beams for ParaView);
# plus mesh and array statistics of the bundled data and conversions to ParaView/Gmsh/MEDIT files.
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
cd "$root"
bash scripts/deps.sh run
build=${SIMSR_BUILD_DIR:-build}
cmake -S . -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build "$build" -j "$(nproc)" --target simsr_cli cantilever
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
mkdir -p "$out/bunny_network"
"$simsr" train --lr-rest "$data/bunny/lrestshape.obj" --hr-rest "$data/bunny/hrestshape.obj" \
  --frames "$data/bunny/train_frames.npz" --neighbors "$out/bunny_neighbors.npz" --holdout-every 4 \
  --checkpoint "$out/bunny_network/checkpoint.npz" --out-dir "$out/bunny_network" --out "$out/bunny_network/model.npz"
"$simsr" infer --model "$out/bunny_network/model.npz" --frames "$data/bunny/train_frames.npz" --every 4 \
  --out "$out/bunny_network/holdout_prediction.npz"
"$simsr" eval --pred "$out/bunny_network/holdout_prediction.npz" --truth "$data/bunny/train_frames.npz" \
  --hr-rest "$data/bunny/hrestshape.obj" --out "$out/bunny_network"
# The quasistatic solver against Euler–Bernoulli beam theory (conforming and BCC embedded beams).
"$build/examples/cantilever" --cells 10 --solver pcg-block-jacobi --vtu "$out/cantilever_conforming.vtu" | tee "$out/cantilever_conforming.json"
"$build/examples/cantilever" --cells 6 --embedded --vtu "$out/cantilever_bcc.vtu" | tee "$out/cantilever_bcc.json"
{ set +x; } 2>/dev/null
echo "simsr: wrote $(ls "$out" | tr '\n' ' ')to $out"
echo "simsr: open out/bunny_baselines/frame_errors.svg and out/bunny_network/{holdout_error,frame_errors}.svg in a browser,"
echo "       out/bunny_baselines/heatmaps.pvd, out/bunny_network/error_heatmap.vtu and out/*.vtu in ParaView"
