#!/usr/bin/env bash
# Production scale: clouds of 0.35e9, 1e9 and 4e9 active voxels made with
# Debian's OpenVDB (tools/make_large.py), then, per file, in one run:
# vdb_print -l, `cirrus info` (headers) and `cirrus info --stats`, a tiny
# render straight from the .vdb, `cirrus convert --precision f16`, and a
# tiny render of the .cbrk; wall time and peak RSS (/usr/bin/time -v) of
# each, beside the size of the bricks. Then the f16 check: the corpus cloud
# rendered from f32 and from f16 bricks, 8 seeds x 128 spp each, compared
# with tools/compare_images.py.
#
# Usage: bash tools/bench_scale.sh [SCALE...]        (default: 2.5 3.6 5.7)
# Environment:
#   LARGE=/work/large       where the clouds, bricks and logs go (never the repository)
#   CIRRUS=...              the cirrus binary (default: built here, target/release/cirrus)
#   BEFORE=...              optional: an older cirrus binary measured beside it (render from .vdb)
#   CAP_GB=16               address-space cap for vdb_print and BEFORE (vdb_print needs
#                           ~7 bytes a voxel: the cap makes it fail cleanly instead of
#                           pushing a shared machine out of memory)
#   SKIP_F16=1              skip the f16 check
# Needs: apt-get install -y --no-install-recommends python3-openvdb libopenvdb-tools
# (make_large.py, vdb_print); the f16 check needs numpy and OpenEXR in target/venv
# (bash tools/test_python.sh or tools/oidn.sh make it).
set -euo pipefail
cd "$(dirname "$0")/.."
LARGE=${LARGE:-/work/large}
CAP_GB=${CAP_GB:-16}
mkdir -p "$LARGE"
if [[ -z "${CIRRUS:-}" ]]; then
    cargo build --release -p cirrus-cli >&2
    CIRRUS=$PWD/target/release/cirrus
fi
SCALES=("$@")
[[ ${#SCALES[@]} -gt 0 ]] || SCALES=(2.5 3.6 5.7)
LOG=$LARGE/bench_scale.log
: > "$LOG"

# measure NAME CMD...: runs CMD under /usr/bin/time -v; prints "wall_s peak_MB status".
measure() {
    local name=$1; shift
    local t=$LARGE/.time.$$
    local status=ok
    echo "\$ $*" >> "$LOG"
    if ! /usr/bin/time -v -o "$t" "$@" >> "$LOG" 2>&1; then status=failed; fi
    local wall rss
    wall=$(awk -F': ' '/Elapsed \(wall clock\)/ {n=split($2,a,":"); s=0; for(i=1;i<=n;i++) s=s*60+a[i]; print s}' "$t")
    rss=$(awk -F': ' '/Maximum resident set size/ {printf "%.0f", $2/1024}' "$t")
    rm -f "$t"
    printf '%s %s %s\n' "$wall" "$rss" "$status"
}

json() { python3 -c "import json,sys; d=json.load(open(sys.argv[1])); print(eval(sys.argv[2], {}, {'d': d}))" "$@"; }

echo "cirrus production-scale benchmark, $(date -u +%Y-%m-%d), commit $(git rev-parse --short HEAD 2>/dev/null || echo '?')"
echo "machine: $(nproc) cores, $(free -g | awk '/Mem:/ {print $2}') GB; load average at start: $(cut -d' ' -f1-3 /proc/loadavg)"
echo
printf '| cloud | file | step | command | wall s | peak RSS MB | note |\n|---|---|---|---|---|---|---|\n'
for scale in "${SCALES[@]}"; do
    vdb=$LARGE/cloud_s$scale.vdb
    cbrk=$LARGE/cloud_s$scale.f16.cbrk
    mw=- mm=- ms="made before this run"
    if [[ ! -f $vdb ]]; then
        read -r mw mm ms < <(measure make /usr/bin/python3 tools/make_large.py "$vdb" --scale "$scale")
    fi
    voxels=$("$CIRRUS" info "$vdb" --json | json /dev/stdin 'd["grids"][0]["active_voxels"]')
    gb=$(du -BM "$vdb" | awk '{printf "%.2f GB", $1/1024}')
    label="$(python3 -c "print(f'{$voxels/1e9:.2f}e9')") voxels"
    row() { printf '| %s | %s | %s | `%s` | %s | %s | %s |\n' "$label" "$gb" "$1" "$2" "$3" "$4" "$5"; }
    row make "make_large.py --scale $scale" "$mw" "$mm" "$ms"
    read -r w m s < <(measure vdb_print prlimit --as=$((CAP_GB << 30)) vdb_print -l "$vdb")
    row "vdb_print" "vdb_print -l" "$w" "$m" "$s (address space capped at $CAP_GB GB)"
    read -r w m s < <(measure info "$CIRRUS" info "$vdb")
    row "info" "cirrus info" "$w" "$m" "$s"
    read -r w m s < <(measure stats "$CIRRUS" info --stats "$vdb")
    row "info --stats" "cirrus info --stats" "$w" "$m" "$s"
    if [[ -n "${BEFORE:-}" ]]; then
        read -r w m s < <(measure before prlimit --as=$((CAP_GB << 30)) "$BEFORE" render "$vdb" --res 64x64 --spp 1 -o "$LARGE/before.exr" --stats "$LARGE/before.json")
        load=$([[ $s == ok ]] && json "$LARGE/before.json" 'round(d["load_seconds"],2)' || echo -)
        row "render .vdb (before)" "cirrus-before render --res 64x64 --spp 1" "$w" "$m" "$s, load $load s (tree, then f32 bricks; capped at $CAP_GB GB)"
    fi
    read -r w m s < <(measure render "$CIRRUS" render "$vdb" --res 64x64 --spp 1 -o "$LARGE/vdb.exr" --stats "$LARGE/vdb.json")
    load=$(json "$LARGE/vdb.json" 'round(d["load_seconds"],2)')
    row "render .vdb" "cirrus render --res 64x64 --spp 1" "$w" "$m" "$s, load $load s (streamed, f16)"
    read -r w m s < <(measure convert "$CIRRUS" convert "$vdb" --precision f16 -o "$cbrk")
    bricks=$("$CIRRUS" info "$cbrk" --json | json /dev/stdin 'd["bytes"]["total"]')
    bmb=$((bricks / 1048576))
    row "convert" "cirrus convert --precision f16" "$w" "$m" "$s, bricks $bmb MB (budget 1.3x + 200 = $((bmb * 13 / 10 + 200)) MB)"
    read -r w m s < <(measure render_cbrk "$CIRRUS" render "$cbrk" --res 64x64 --spp 1 -o "$LARGE/cbrk.exr" --stats "$LARGE/cbrk.json")
    load=$(json "$LARGE/cbrk.json" 'round(d["load_seconds"],2)')
    row "render .cbrk" "cirrus render X.cbrk --res 64x64 --spp 1" "$w" "$m" "$s, load $load s (mapped)"
done

if [[ -z "${SKIP_F16:-}" ]]; then
    echo
    echo "f16 against f32 bricks: data/cloud.vdb, 128x128, seeds 1-8 x 128 spp each side"
    d=$LARGE/f16check
    mkdir -p "$d"
    "$CIRRUS" convert data/cloud.vdb --precision f32 -o "$d/f32.cbrk" 2>> "$LOG"
    "$CIRRUS" convert data/cloud.vdb --precision f16 -o "$d/f16.cbrk" 2>> "$LOG"
    "$CIRRUS" info "$d/f16.cbrk" --json | json /dev/stdin '"f16 bricks: max |f16 - f32| = %s over densities up to %s" % (d["max_error"], d["max_density"])'
    for p in f32 f16; do
        for s in 1 2 3 4 5 6 7 8; do
            "$CIRRUS" render "$d/$p.cbrk" --res 128x128 --spp 128 --seed "$s" -o "$d/${p}_$s.exr" >> "$LOG" 2>&1
        done
    done
    PY=${PY:-target/venv/bin/python}
    "$PY" tools/compare_images.py --a "$d"/f32_?.exr --b "$d"/f16_?.exr --names f32 f16 || true
    # Same seeds, so the same paths until an f16 density changes a decision:
    # what f16 changes in the 1024-spp image, against that image's own noise.
    "$PY" - "$d" <<'EOF'
import sys, numpy as np
sys.path.insert(0, "tools")
from compare_images import read_exr
d = sys.argv[1]
a = np.stack([read_exr(f"{d}/f32_{s}.exr")[..., :3] for s in range(1, 9)])
b = np.stack([read_exr(f"{d}/f16_{s}.exr")[..., :3] for s in range(1, 9)])
se = a.std(axis=0, ddof=1) / np.sqrt(8)            # per-pixel noise of the 1024-spp f32 image
diff = b.mean(axis=0) - a.mean(axis=0)             # what f16 changes, same seeds
rms = lambda x: float(np.sqrt((x ** 2).mean()))    # noqa: E731
print(f"per pixel, 1024 spp: RMS(f16 - f32) = {rms(diff):.3g}, RMS noise (standard error) = {rms(se):.3g}, "
      f"ratio {rms(diff) / rms(se):.2f}; image mean {a.mean():.6f} (f32) vs {b.mean():.6f} (f16): "
      f"{(b.mean() - a.mean()) / a.mean() * 100:+.4f}%, noise of the image mean "
      f"{a.mean(axis=(1, 2, 3)).std(ddof=1) / np.sqrt(8) / a.mean() * 100:.4f}%")
EOF
fi
