#!/usr/bin/env bash
# Paths per second of the GPU backend against the CPU kernel on the same
# scenes: each scene rendered with `--device gpu` and on the CPU (all the
# machine's threads, and one), ROUNDS rounds; prints the median paths per
# second of each, the GPU's with and without its setup (upload and kernel
# compilation, `setup_seconds`). The CPU renders with its own defaults
# (residual ratio tracking, Sobol points, sunward scattering where it
# pays), the GPU with what it has (ratio tracking, one level of
# majorants), so this compares devices at each one's best, per path.
#
#   bash tools/gpu_bench.sh [CIRRUS] [ROUNDS]
#
# Also the time of one frame of the default cloud at 1920x1080, 1 sample
# per pixel, on the GPU without its setup (median of ROUNDS).
#
# Needs a Vulkan adapter: a GPU's driver, or lavapipe (Debian:
# apt-get install mesa-vulkan-drivers libvulkan1), Vulkan on the CPU. On a
# machine without a Vulkan loader, carry Debian's libvulkan1 along and
# name the folder holding its libvulkan.so.1 in VULKAN_LIB_DIR (e.g.
# `apt-get download libvulkan1 && dpkg -x libvulkan1_*.deb vk` elsewhere,
# then VULKAN_LIB_DIR=vk/usr/lib/x86_64-linux-gnu). Where NVIDIA's driver
# is installed without its Vulkan ICD file (containers often are), one is
# written for its libGLX_nvidia.so.0.
set -euo pipefail
cd "$(dirname "$0")/.."
bin=$(readlink -f "${1:-target/release/cirrus}")
rounds=${2:-3}
out=target/gpu-bench
mkdir -p "$out"
if [ -n "${VULKAN_LIB_DIR:-}" ]; then
  export LD_LIBRARY_PATH="$(readlink -f "$VULKAN_LIB_DIR")${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}"
fi
icds=$(ls /usr/share/vulkan/icd.d/*.json /etc/vulkan/icd.d/*.json 2>/dev/null || true)
if ! grep -qs nvidia <<<"$icds" && ldconfig -p 2>/dev/null | grep -q libGLX_nvidia.so.0 &&
  [ -z "${VK_ICD_FILENAMES:-}" ]; then
  printf '{"file_format_version": "1.0.0", "ICD": {"library_path": "libGLX_nvidia.so.0", "api_version": "1.3"}}\n' \
    >"$out/nvidia_icd.json"
  export VK_ICD_FILENAMES="$PWD/$out/nvidia_icd.json${icds:+:$(tr '\n' ':' <<<"$icds" | sed 's/:$//')}"
fi
start=$SECONDS
thick=(data/cloud.vdb --res 128x128 --camera-from 150,83,-250 --camera-to 150,83,100 --camera-up 0,1,0
  --fov 40 --density-scale 0.5 --albedo 0.999 --env-radiance 0.16,0.22,0.34
  --sun-dir -0.45,-0.6,-0.66 --sun-irradiance 2.6,2.5,2.3 --sun-angle 0 --phase hg --g 0.8 --spp 64)
default=(data/cloud.vdb --res 160x120 --spp 64)
sky=(data/cloud.vdb --res 160x120 --spp 128 --no-sun --albedo 0.9 --g 0.5)
runs="$out/runs.txt"
: >"$runs"
for scene in thick default sky; do
  declare -n args=$scene
  for _ in $(seq "$rounds"); do
    for device in gpu cpu cpu1; do
      case $device in
        gpu) env=() flags=(--device gpu) ;;
        cpu) env=() flags=(--device cpu) ;;
        cpu1) env=(RAYON_NUM_THREADS=1) flags=(--device cpu) ;;
      esac
      env "${env[@]}" "$bin" render "${args[@]}" "${flags[@]}" -o "$out/$device.exr" \
        --stats "$out/$device.json" 2>"$out/$device.log" >/dev/null ||
        { cat "$out/$device.log" >&2; exit 1; }
      python3 -c "import json,sys; s=json.load(open(sys.argv[3])); print(sys.argv[1], sys.argv[2], s['paths'], s['wall_seconds'], s['setup_seconds'])" \
        "$scene" "$device" "$out/$device.json" >>"$runs"
    done
  done
  unset -n args
done
frame=(data/cloud.vdb --res 1920x1080 --spp 1 --device gpu)
# A frame whose paths exceed a binding (lavapipe's 128 MiB) renders in
# bands of rows; a device that refuses it anyway is said, and the other
# figures still printed.
for _ in $(seq "$rounds"); do
  if ! "$bin" render "${frame[@]}" -o "$out/frame.exr" --stats "$out/frame.json" 2>"$out/frame.log" >/dev/null; then
    echo "1920x1080 frame not timed: $(grep -v 'rendering on' "$out/frame.log" | tail -1)"
    break
  fi
  python3 -c "import json,sys; s=json.load(open(sys.argv[1])); print('frame gpu', s['paths'], s['wall_seconds'], s['setup_seconds'])" \
    "$out/frame.json" >>"$runs"
done
grep -h "rendering on" "$out/gpu.log" || true
python3 - "$runs" "$(nproc)" <<'PY'
import collections, statistics, sys
runs = collections.defaultdict(lambda: collections.defaultdict(list))
for line in open(sys.argv[1]):
    scene, device, paths, wall, setup = line.split()
    paths, wall, setup = int(paths), float(wall), float(setup)
    runs[scene][device].append((paths / wall, paths / max(wall - setup, 1e-9)))
threads = sys.argv[2]
print(f"{'scene':<8} {'gpu paths/s':>12} {'(no setup)':>11} {'cpu paths/s':>12} {'1 thread':>10} {'gpu/cpu':>8}")
frame = runs.pop("frame", None)
for scene, d in runs.items():
    g = statistics.median(r[0] for r in d["gpu"])
    gk = statistics.median(r[1] for r in d["gpu"])
    c = statistics.median(r[0] for r in d["cpu"])
    c1 = statistics.median(r[0] for r in d["cpu1"])
    print(f"{scene:<8} {g:12.0f} {gk:11.0f} {c:12.0f} {c1:10.0f} {g / c:8.2f}")
print(f"(cpu: {threads} threads)")
if frame:
    # A frame's paths over its paths per second without setup: its time.
    ms = statistics.median(1000 * 1920 * 1080 / r[1] for r in frame["gpu"])
    print(f"1920x1080 at 1 spp, default cloud: {ms:.1f} ms a frame on the GPU (no setup)")
PY
echo "(the benchmark took $((SECONDS - start)) s)"
