#!/usr/bin/env bash
# Ray marching against OpenVDB's vdb_render: the same file, resolution, view,
# sun, step and shadow step, runs alternated so that both see the same load.
#   bash tools/bench_vdb_render.sh [ROUNDS] [SPP...]
# Prints each run's wall time (whole process: read, render, write) and the
# ratio cirrus / vdb_render per round, for each samples-per-pixel count
# (`vdb_render -samples`, `cirrus --spp`). Only 1 spp compares like with
# like: vdb_render's volume renderer takes the same time at `-samples 8`
# as at 1 (0.53-0.60 s against 0.46-0.60 s, measured), so it does not
# trace more rays. A 1-spp run is about half a second, so cirrus's start-up
# (reading, bricks, EXR writing: about 0.04 s) is part of its figure.
# Needs Debian's openvdb-tools (vdb_render).
set -euo pipefail
cd "$(dirname "$0")/.."
rounds=${1:-3}
shift || true
spps=("${@:-1}")
cargo build --release -p cirrus-cli --quiet
cirrus=target/release/cirrus
out=target/bench_vdb_render
mkdir -p "$out"
now() { date +%s.%N; }
for spp in ${spps[@]}; do
  for r in $(seq "$rounds"); do
    t0=$(now)
    vdb_render data/cloud.vdb "$out/vdb_render.png" -res 512x512 -samples "$spp" \
      -translate 150,83,-250 -lookat 150,83,100 -fov 40 -light 0.7,-0.5,0.5,1,1,1 \
      -step 1 -shadowstep 3 >/dev/null 2>&1
    t1=$(now)
    "$cirrus" render data/cloud.vdb -o "$out/raymarch.exr" --res 512x512 --spp "$spp" \
      --integrator raymarch --step 1 --shadow-step 3 \
      --camera-from 150,83,-250 --camera-to 150,83,100 --fov 40 \
      --sun-dir 0.7,-0.5,0.5 --sun-angle 0 --env-radiance 0,0,0 --density-scale 1.6 >/dev/null 2>&1
    t2=$(now)
    python3 -c "a=$t1-$t0; b=$t2-$t1; print(f'spp $spp round $r: vdb_render {a:.2f} s, cirrus raymarch {b:.2f} s = {b/a:.2f}x')"
  done
done
