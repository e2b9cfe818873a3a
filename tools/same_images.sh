#!/usr/bin/env bash
# Renders one suite of small images with each of two cirrus builds and
# compares the EXRs byte for byte: what a change that must not move a
# single pixel (a refactor, a new option left off) is checked with.
#
#   bash tools/same_images.sh OLD_CIRRUS NEW_CIRRUS [OUTDIR]
#
# Covers every integrator and estimator, chromatic media, phases, the sky
# map, motion blur, emission, the example scene, AOVs, the global and
# automatic majorants, .nvdb and .cbrk input, light groups, deep images, a depth holdout, sunward scattering on and off, one and
# every light per vertex, a back-lit Mie cloud, and crops with their merge.
# Not Cryptomatte: the exr crate writes a layer's text attributes (its
# manifest and names) in hash-map order, so the same pixels come in files
# whose header bytes differ from run to run.
# Prints one line per image and exits non-zero if any differ. NEW_FLAGS,
# if set, is added to every render of the new build (say, to turn off a
# default the old build did not have: NEW_FLAGS="--sunward off").
set -euo pipefail
cd "$(dirname "$0")/.."
old=$(readlink -f "$1")
new=$(readlink -f "$2")
out=${3:-target/same-images}
rm -rf "$out"
mkdir -p "$out/old" "$out/new"
out=$(readlink -f "$out")

emission_scene="$out/emission.toml"
cat >"$emission_scene" <<EOF
[render]
spp = 4
[camera]
res = "48x48"
[[volume]]
file = "$PWD/data/fireball.vdb"
temperature = "temperature"
blackbody = { scale = 2, temperature_scale = 1 }
EOF

# name | arguments after `render` (the output is appended)
suite=(
  "path|data/cloud.vdb --res 64x48 --spp 4"
  "raymarch|data/cloud.vdb --res 64x48 --spp 2 --integrator raymarch"
  "raymarch2pass|data/cloud.vdb --res 64x48 --spp 2 --integrator raymarch2pass"
  "track_length|data/cloud.vdb --res 64x48 --spp 4 --transmittance track-length"
  "ratio|data/cloud.vdb --res 64x48 --spp 4 --transmittance ratio"
  "global|data/cloud.vdb --res 64x48 --spp 4 --majorant global"
  "hierarchy|data/cloud.vdb --res 64x48 --spp 4 --majorant hierarchy"
  "chromatic|data/cloud.vdb --res 64x48 --spp 4 --density-scale 0.2,0.5,0.35 --albedo 0.9,0.95,0.99"
  "chromatic_march|data/cloud.vdb --res 64x48 --spp 2 --integrator raymarch --density-scale 0.2,0.5,0.35"
  "mie|data/cloud.vdb --res 64x48 --spp 4 --phase mie --max-depth 3"
  "hg2_random|data/cloud.vdb --res 64x48 --spp 4 --phase hg2 --sampler random"
  "sky_map|data/cloud.vdb --res 64x48 --spp 4 --env-map data/sky.exr --no-sun"
  "adaptive|data/cloud.vdb --res 64x48 --spp 16 --noise-threshold 0.1 --min-spp 4"
  "aovs|data/cloud.vdb --res 64x48 --spp 4 --aov albedo,depth,emission,direct,samples"
  "motion|data/multi_grid.vdb --res 48x48 --spp 4 --shutter -0.25,0.25"
  "nvdb|data/sphere_fog.nvdb --res 48x48 --spp 4"
  "emission|$emission_scene"
  "emission_march|$emission_scene --integrator raymarch"
  "scene|data/scene_example.toml --res 96x54 --spp 2 --aov albedo,depth"
  "scene_march|data/scene_example.toml --res 96x54 --spp 1 --integrator raymarch"
  "light_groups|data/cloud.vdb --res 64x48 --spp 4 --aov lights"
  "deep|data/cloud.vdb --res 64x48 --spp 4 --deep @OUT@/deep.deep.exr --deep-samples 4"
  "holdout|data/cloud.vdb --res 64x48 --spp 4 --holdout-depth @OUT@/aovs.exr:depth.Z"
  "sunward_on|data/cloud.vdb --res 64x48 --spp 4 --sunward on"
  "sunward_off|data/cloud.vdb --res 64x48 --spp 4 --sunward off"
  "every_light|data/cloud.vdb --res 64x48 --spp 4 --light-sampling all"
  "backlit_mie|data/cloud.vdb --res 64x48 --spp 4 --camera-from 150,83,-250 --camera-to 150,83,100 --sun-dir 0.05,0,-1 --phase mie --env-radiance 0.02,0.02,0.03"
)

failed=0
for build in old new; do
  bin=$old
  extra=""
  [ "$build" = new ] && bin=$new && extra=${NEW_FLAGS:-}
  d="$out/$build"
  for entry in "${suite[@]}"; do
    name=${entry%%|*}
    args=${entry#*|}
    args=${args//@OUT@/$d}
    # shellcheck disable=SC2086
    "$bin" render $args $extra -o "$d/$name.exr" >/dev/null 2>"$d/$name.log" ||
      { echo "$build $name: render failed (see $d/$name.log)"; failed=1; }
  done
  "$bin" convert data/cloud.vdb -o "$d/cloud.cbrk" >/dev/null 2>&1
  # shellcheck disable=SC2086
  "$bin" render "$d/cloud.cbrk" --res 64x48 --spp 4 $extra -o "$d/cbrk.exr" >/dev/null 2>&1
  for crop in 0,0,40,48 40,0,64,48; do
    # shellcheck disable=SC2086
    "$bin" render data/cloud.vdb --res 64x48 --spp 4 --aov depth --crop "$crop" $extra \
      -o "$d/tile_${crop//,/_}.exr" >/dev/null 2>&1
  done
  "$bin" merge "$d/merged.exr" "$d"/tile_*.exr >/dev/null 2>&1
done

for f in "$out"/old/*.exr; do
  name=$(basename "$f")
  if cmp -s "$f" "$out/new/$name"; then
    echo "same      $name"
  else
    echo "DIFFERENT $name"
    failed=1
  fi
done
exit $failed
