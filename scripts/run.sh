#!/usr/bin/env bash
# The main job on the bundled data (installs missing Debian packages first, as root).
# Until the super-resolution pipeline lands, this is the richest thing that works: mesh and
# array statistics of the bundled data and conversions to ParaView/Gmsh/MEDIT files in out/.
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
{ set +x; } 2>/dev/null
echo "simsr: wrote $(ls "$out" | tr '\n' ' ')to $out (open the .vtu files in ParaView)"
