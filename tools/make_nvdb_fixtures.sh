#!/usr/bin/env bash
# Regenerates the NanoVDB test fixtures of crates/vdb (tests/nanovdb.rs):
# small .nvdb files written by NanoVDB 32.4.2's own tools, and expected.json:
# the values pyopenvdb reads back from the source .vdb files, and the values
# NanoVDB's own accessor reads from the quantised files.
#
# Needs Debian bookworm's python3-openvdb (for /usr/bin/python3 only),
# libnanovdb-tools, libopenvdb-dev, libnanovdb-dev, libblosc-dev, zlib1g-dev
# and g++. Takes about a minute (mostly compiling the C++ helpers).
set -euo pipefail
here="$(cd "$(dirname "$0")/.." && pwd)"
out="$here/crates/vdb/tests/fixtures"
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
mkdir -p "$out"

# 1. Source grids with pyopenvdb, and what pyopenvdb reads back from them.
cat > "$work/sources.py" <<'EOF'
import json, math, sys
import pyopenvdb as vdb

out = sys.argv[1]

def fog():
    g = vdb.FloatGrid(0.0)
    g.name = "density"
    g.gridClass = vdb.GridClass.FOG_VOLUME
    acc = g.getAccessor()
    c, r = (24, 20, 16), 7.5
    for x in range(c[0] - 8, c[0] + 9):
        for y in range(c[1] - 8, c[1] + 9):
            for z in range(c[2] - 8, c[2] + 9):
                d = math.sqrt((x - c[0]) ** 2 + (y - c[1]) ** 2 + (z - c[2]) ** 2)
                if d <= r:
                    acc.setValueOn((x, y, z), 1.0 - d / r + 0.001 * ((x * 7 + y * 3 + z) % 11))
    acc.setValueOff((30, 30, 30), 0.75)  # inactive, stored in a leaf
    g.fill((64, 0, 0), (71, 7, 7), 0.5, True)  # an active 8^3 tile in a lower node
    g.fill((128, 0, 0), (255, 127, 127), 0.25, True)  # an active 128^3 tile in an upper node
    g.fill((256, 0, 0), (383, 127, 127), 0.3, False)  # an inactive 128^3 tile
    g.fill((4096, 0, 0), (8191, 4095, 4095), 0.125, True)  # an active 4096^3 root tile
    g.transform = vdb.createLinearTransform(
        [[0.5, 0, 0, 0], [0, 0.5, 0, 0], [0, 0, 0.5, 0], [1.0, 2.0, 3.0, 1]])
    return g

def velocity():
    g = vdb.Vec3SGrid((0.0, 0.0, 0.0))
    g.name = "velocity"
    g.gridClass = vdb.GridClass.STAGGERED
    acc = g.getAccessor()
    for x in range(3, 19):
        for y in range(5, 13):
            for z in range(0, 10):
                acc.setValueOn((x, y, z), (x * 0.5, -y * 0.25, z + 0.125))
    g.fill((16, 32, 16), (23, 39, 23), (1.0, 2.0, 3.0), True)
    # 30 degrees about z, non-uniform scale, translation; OpenVDB's row-vector matrix
    a = math.radians(30.0)
    ca, sa = math.cos(a), math.sin(a)
    s = (0.25, 0.5, 0.75)
    g.transform = vdb.createLinearTransform(
        [[s[0] * ca, s[0] * sa, 0, 0], [-s[1] * sa, s[1] * ca, 0, 0], [0, 0, s[2], 0], [10.0, -5.0, 2.0, 1]])
    return g

def level_set():
    g = vdb.createLevelSetSphere(radius=6.0, center=(20.0, 20.0, 20.0), voxelSize=1.0, halfWidth=3.0)
    g.name = "sphere_sdf"
    return g

def flags():
    g = vdb.BoolGrid(False)
    g.name = "flags"
    acc = g.getAccessor()
    for x in range(0, 12):
        for y in range(0, 4):
            acc.setValueOn((x, y, 5), (x + y) % 3 == 0)
    g.fill((32, 32, 32), (39, 39, 39), True, True)
    return g

files = {"fog": [fog()], "vec": [velocity()], "multi": [level_set(), flags()]}
for stem, gs in files.items():
    vdb.write(f"{out}/{stem}.vdb", grids=gs)

def probe_points(g):
    pts, n = set(), 0
    for item in g.citerOnValues():
        if item.count == 1:
            n += 1
            if n % 7 == 0:
                pts.add(tuple(item.min))
        else:
            pts.add(tuple(item.min))
            pts.add(tuple(item.max))
    k = 0
    for item in g.citerOffValues():
        if item.count == 1:
            k += 1
            if k % 5 == 0:
                pts.add(tuple(item.min))
        if k > 300:
            break
    pts |= {(0, 0, 0), (-1, -1, -1), (30, 30, 30), (100000, 5, 5), (-5000, 3, 3),
            (4095, 4095, 4095), (8191, 4095, 4095), (8192, 0, 0), (300, 64, 64)}
    return sorted(pts)

def plain(v):
    return list(v) if isinstance(v, tuple) else v

expected = {}
for stem in files:
    for g in vdb.readAll(f"{out}/{stem}.vdb")[0]:
        acc = g.getConstAccessor()
        probes = []
        for p in probe_points(g):
            v, on = acc.probeValue(p)
            probes.append({"ijk": list(p), "value": plain(v), "active": bool(on)})
        pts = [(0, 0, 0), (1, 0, 0), (0, 1, 0), (0, 0, 1), (10, -20, 30.5)]
        expected[g.name] = {
            "class": str(g.gridClass),
            "background": plain(g.background),
            "active_voxel_count": g.activeVoxelCount(),
            "leaf_count": g.leafCount(),
            "index_to_world": [[list(p), list(g.transform.indexToWorld(p))] for p in pts],
            "probes": probes,
        }
with open(f"{out}/expected.json", "w") as f:
    json.dump(expected, f, indent=0, sort_keys=True)
EOF
/usr/bin/python3 "$work/sources.py" "$work"

# 2. Grids of the types pyopenvdb cannot make, all in one NanoVDB segment
#    (nanovdb_convert writes one segment per grid and cannot convert Vec3d).
cat > "$work/typed.cpp" <<'EOF'
#include <openvdb/openvdb.h>
#include <nanovdb/util/OpenToNanoVDB.h>
#include <nanovdb/util/GridBuilder.h>
#include <nanovdb/util/IO.h>
#include <cstdint>
int main(int argc, char** argv)
{
    openvdb::initialize();
    auto d = openvdb::DoubleGrid::create(-1.0);
    d->setName("temperature");
    auto i32 = openvdb::Int32Grid::create(-1);
    i32->setName("labels");
    auto i64 = openvdb::Int64Grid::create(-1);
    i64->setName("ids");
    auto v3d = openvdb::Vec3DGrid::create(openvdb::Vec3d(0.0));
    v3d->setName("normals");
    auto m = openvdb::MaskGrid::create();
    m->setName("topology");
    auto da = d->getAccessor(); auto ia = i32->getAccessor(); auto la = i64->getAccessor();
    auto va = v3d->getAccessor(); auto ma = m->getAccessor();
    for (int x = 0; x < 10; ++x) for (int y = 0; y < 6; ++y) for (int z = 0; z < 5; ++z) {
        const openvdb::Coord ijk(x, y, z);
        da.setValue(ijk, 300.0 + x * 0.1 + y * 0.01 + z * 0.001);
        ia.setValue(ijk, x * 10000 + y * 100 + z - 5000);
        la.setValue(ijk, (int64_t(1) << 40) + x * 1000000 + y * 1000 + z);
        va.setValue(ijk, openvdb::Vec3d(x * 0.5, y * 0.25, -z * 2.0));
        if ((x + y + z) % 2 == 0) ma.setValueOn(ijk);
    }
    da.setValueOff(openvdb::Coord(9, 9, 9), 42.0);  // inactive, in a second leaf
    ia.setValueOff(openvdb::Coord(9, 9, 9), 42);
    const openvdb::CoordBBox tile(openvdb::Coord(16, 0, 0), openvdb::Coord(23, 7, 7));
    d->fill(tile, 2.5, true);
    i32->fill(tile, 7, true);
    i64->fill(tile, int64_t(1) << 50, true);
    v3d->fill(tile, openvdb::Vec3d(1.0, -2.0, 3.0), true);
    m->fill(tile, true, true);
    std::vector<nanovdb::GridHandle<nanovdb::HostBuffer>> handles;
    handles.push_back(nanovdb::openToNanoVDB(d));
    handles.push_back(nanovdb::openToNanoVDB(i32));
    handles.push_back(nanovdb::openToNanoVDB(i64));
    {   // 32.4.2's OpenToNanoVDB has no Vec3d case: set each active voxel (the tile too)
        nanovdb::GridBuilder<nanovdb::Vec3d> builder(nanovdb::Vec3d(0.0));
        auto acc = builder.getAccessor();
        for (auto it = v3d->cbeginValueOn(); it; ++it) {
            const auto v = *it;
            openvdb::CoordBBox box;
            it.getBoundingBox(box);
            for (auto c = box.begin(); c; ++c)
                acc.setValue(nanovdb::Coord((*c)[0], (*c)[1], (*c)[2]), nanovdb::Vec3d(v[0], v[1], v[2]));
        }
        handles.push_back(builder.getHandle<>(1.0, nanovdb::Vec3d(0.0), "normals"));
    }
    handles.push_back(nanovdb::openToNanoVDB(m));
    nanovdb::io::writeGrids(argv[1], handles, nanovdb::io::Codec::ZIP);
    return 0;
}
EOF
g++ -std=c++17 -O0 -w -DNANOVDB_USE_ZIP -I/usr/include/Imath "$work/typed.cpp" -o "$work/typed" \
    -lopenvdb -lImath-3_1 -ltbb -lz -lblosc -lpthread
"$work/typed" "$out/typed_zip.nvdb"

# 3. Conversions with nanovdb_convert (one file segment per grid).
cd "$work"
nanovdb_convert -f fog.vdb "$out/fog.nvdb"
nanovdb_convert -f --fp16 -z fog.vdb "$out/fog_fp16_zip.nvdb"
nanovdb_convert -f --fp8 -b fog.vdb "$out/fog_fp8_blosc.nvdb"
nanovdb_convert -f --fp4 -z fog.vdb "$out/fog_fp4_zip.nvdb"
nanovdb_convert -f --fpN -a 0.001 -z fog.vdb "$out/fog_fpN_zip.nvdb"
nanovdb_convert -f -b vec.vdb "$out/vec3f_blosc.nvdb"
nanovdb_convert -f -z multi.vdb "$out/multi_zip.nvdb"

# 4. What NanoVDB's own accessor reads from the quantised files at the probe
#    coordinates: exact reference values for the dequantisation.
cat > "$work/probe.cpp" <<'CPP'
#include <nanovdb/util/IO.h>
#include <cstdio>
#include <vector>
template<typename BuildT>
void probe(const char* path, const std::vector<nanovdb::Coord>& pts)
{
    auto handle = nanovdb::io::readGrid(path);
    auto* grid = handle.template grid<BuildT>();
    if (!grid) { fprintf(stderr, "%s: unexpected grid type\n", path); exit(1); }
    auto acc = grid->getAccessor();
    printf("[");
    for (size_t i = 0; i < pts.size(); ++i) {
        const auto& c = pts[i];
        printf("%s[%d,%d,%d,%.9g,%s]", i ? "," : "", c[0], c[1], c[2], double(acc.getValue(c)),
               acc.isActive(c) ? "true" : "false");
    }
    printf("]");
}
int main(int argc, char** argv)
{
    std::vector<nanovdb::Coord> pts;
    int x, y, z;
    while (scanf("%d %d %d", &x, &y, &z) == 3) pts.emplace_back(x, y, z);
    printf("{\"fog_fp16_zip.nvdb\":"); probe<nanovdb::Fp16>(argv[1], pts);
    printf(",\"fog_fp8_blosc.nvdb\":"); probe<nanovdb::Fp8>(argv[2], pts);
    printf(",\"fog_fp4_zip.nvdb\":"); probe<nanovdb::Fp4>(argv[3], pts);
    printf(",\"fog_fpN_zip.nvdb\":"); probe<nanovdb::FpN>(argv[4], pts);
    printf("}\n");
    return 0;
}
CPP
g++ -std=c++17 -O1 -w -DNANOVDB_USE_ZIP -DNANOVDB_USE_BLOSC "$work/probe.cpp" -o "$work/probe" -lz -lblosc -lpthread
/usr/bin/python3 - "$work" "$out" <<'PY'
import json, subprocess, sys
work, out = sys.argv[1:]
expected = json.load(open(f"{work}/expected.json"))
coords = "".join("%d %d %d\n" % tuple(p["ijk"]) for p in expected["density"]["probes"])
names = ("fog_fp16_zip.nvdb", "fog_fp8_blosc.nvdb", "fog_fp4_zip.nvdb", "fog_fpN_zip.nvdb")
run = subprocess.run([f"{work}/probe", *(f"{out}/{n}" for n in names)],
                     input=coords, capture_output=True, text=True, check=True)
expected["nanovdb_decoded"] = json.loads(run.stdout)
with open(f"{out}/expected.json", "w") as f:
    json.dump(expected, f, indent=0, sort_keys=True)
PY
cd "$out"
nanovdb_print -l ./*.nvdb > nanovdb_print.txt
for f in ./*.nvdb; do nanovdb_validate -v "$f"; done
ls -l "$out"
