#!/usr/bin/env bash
# Paths per second of two cirrus builds on the five scenes of BENCHMARKS.md's
# "Towards paths per second": each render alternated between the builds,
# ROUNDS rounds, on all the machine's threads (THREADS to set them); prints
# the median wall time of each build per scene and their ratio (new/old).
#
#   bash tools/paths_per_second.sh OLD_CIRRUS NEW_CIRRUS [ROUNDS]
#
# The sparse cloudscape is made by tools/make_cloudscape.py (Debian's
# python3-openvdb) into target/cloudscape.vdb when missing; without it that
# scene is skipped.
set -euo pipefail
cd "$(dirname "$0")/.."
old=$(readlink -f "$1")
new=$(readlink -f "$2")
rounds=${3:-3}
out=target/paths-per-second
mkdir -p "$out"
scape=target/cloudscape.vdb
if [ ! -f "$scape" ]; then
  /usr/bin/python3 tools/make_cloudscape.py "$scape" >/dev/null 2>&1 || echo "no cloudscape (needs python3-openvdb): skipped" >&2
fi
thick=(data/cloud.vdb --res 128x128 --camera-from 150,83,-250 --camera-to 150,83,100 --camera-up 0,1,0
  --fov 40 --density-scale 0.5 --albedo 0.999 --env-radiance 0.16,0.22,0.34
  --sun-dir -0.45,-0.6,-0.66 --sun-irradiance 2.6,2.5,2.3 --sun-angle 0 --phase hg --g 0.8 --spp 128)
default=(data/cloud.vdb --res 160x120 --spp 192)
sky=(data/cloud.vdb --res 160x120 --spp 256 --no-sun --albedo 0.9 --g 0.5)
cloudscape=("$scape" --res 256x128 --spp 512)
march=(data/cloud.vdb --res 320x240 --spp 16 --integrator raymarch)
times="$out/times.txt"
: >"$times"
for scene in thick default sky cloudscape march; do
  [ "$scene" = cloudscape ] && [ ! -f "$scape" ] && continue
  declare -n args=$scene
  for _ in $(seq "$rounds"); do
    for build in old new; do
      bin=$old
      [ "$build" = new ] && bin=$new
      env ${THREADS:+RAYON_NUM_THREADS=$THREADS} "$bin" render "${args[@]}" -o "$out/$build.exr" \
        --stats "$out/$build.json" >/dev/null 2>&1
      python3 -c "import json,sys; print(sys.argv[1], sys.argv[2], json.load(open(sys.argv[3]))['wall_seconds'])" \
        "$scene" "$build" "$out/$build.json" >>"$times"
    done
  done
  unset -n args
done
python3 - "$times" <<'PY'
import collections, statistics, sys
runs = collections.defaultdict(lambda: collections.defaultdict(list))
for line in open(sys.argv[1]):
    scene, build, seconds = line.split()
    runs[scene][build].append(float(seconds))
print(f"{'scene':<11} {'old s':>8} {'new s':>8} {'new/old':>8} {'paths/s':>8}")
for scene, builds in runs.items():
    o, n = statistics.median(builds["old"]), statistics.median(builds["new"])
    print(f"{scene:<11} {o:8.3f} {n:8.3f} {n / o:8.3f} {o / n:7.2f}x")
PY
