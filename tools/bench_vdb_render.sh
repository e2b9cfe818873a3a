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
# With BASELINE=path/to/another/cirrus, each round also runs that build
# (an older commit, say) under the same load.
# The order of the runs rotates from round to round: a run right after two
# others measured up to 0.1 s slower than the same run first in its round.
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
run() {
  case "$1" in
    vdb_render)
      vdb_render data/cloud.vdb "$out/vdb_render.png" -res 512x512 -samples "$spp" \
        -translate 150,83,-250 -lookat 150,83,100 -fov 40 -light 0.7,-0.5,0.5,1,1,1 \
        -step 1 -shadowstep 3 >/dev/null 2>&1 ;;
    cirrus | baseline)
      local bin=$cirrus
      [ "$1" = baseline ] && bin=$BASELINE
      "$bin" render data/cloud.vdb -o "$out/$1.exr" --res 512x512 --spp "$spp" \
        --integrator raymarch --step 1 --shadow-step 3 \
        --camera-from 150,83,-250 --camera-to 150,83,100 --fov 40 \
        --sun-dir 0.7,-0.5,0.5 --sun-angle 0 --env-radiance 0,0,0 --density-scale 1.6 >/dev/null 2>&1 ;;
  esac
}
runners=(vdb_render cirrus)
[ -n "${BASELINE:-}" ] && runners+=(baseline)
n=${#runners[@]}
for spp in "${spps[@]}"; do
  for r in $(seq "$rounds"); do
    rm -f "$out"/*.exr "$out"/*.png
    declare -A secs=()
    for i in $(seq 0 $((n - 1))); do
      who=${runners[$(((i + r) % n))]}
      t0=$(now)
      run "$who"
      t1=$(now)
      secs[$who]=$(python3 -c "print($t1 - $t0)")
    done
    python3 - "$spp" "$r" "${secs[vdb_render]}" "${secs[cirrus]}" "${secs[baseline]:-}" <<'PY'
import sys
spp, r, v, c, b = sys.argv[1:6]
v, c = float(v), float(c)
line = f"spp {spp} round {r}: vdb_render {v:.2f} s, cirrus raymarch {c:.2f} s = {c / v:.2f}x"
if b:
    line += f", baseline {float(b):.2f} s = {float(b) / v:.2f}x"
print(line)
PY
    unset secs
  done
done
