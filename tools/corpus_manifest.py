"""The manifest side of tools/make_corpus.py: describe each corpus file and cross-check it.

describe_vdb reads a .vdb back with pyopenvdb and vdbfile.py and turns it into
its manifest entry (per-grid counts, bounds, transform, sampled values);
cross_check_vdb_print compares that entry with `vdb_print -l`; describe_nvdb
builds a .nvdb entry from nanovdb_print / nanovdb_validate and the entry of
the .vdb it was converted from, and checks its values by converting it back.
dump_json formats the manifest.  The files themselves come from
corpus_cases.py; make_corpus.py drives both.
"""

from __future__ import annotations

import json
import math
import re
from pathlib import Path

import numpy as np
import pyopenvdb as vdb

import vdbfile
from corpus_plumbing import Product, Substitute, require, rng_for, run

ACTIVE_SAMPLES = 160       # random active leaf voxels per grid
INACTIVE_SAMPLES = 80      # random inactive voxels inside leaves per grid
TILE_SAMPLES = 40          # tiles sampled per grid (one random voxel each, plus corners)


# --------------------------------------------------------------------------- description

def jnum(x):
    """JSON-safe number: NaN/inf become strings, numpy scalars become Python numbers."""
    if isinstance(x, (bool, np.bool_)):
        return bool(x)
    if isinstance(x, (int, np.integer)):
        return int(x)
    x = float(x)
    if math.isnan(x):
        return "nan"
    if math.isinf(x):
        return "inf" if x > 0 else "-inf"
    return x


def jval(v):
    if isinstance(v, (tuple, list)):
        return [jval(c) for c in v]
    return jnum(v)


def same(a, b) -> bool:
    return json.dumps(jval(a)) == json.dumps(jval(b))


def jmeta(value):
    """File metadata value -> JSON, or None when JSON cannot express it."""
    if isinstance(value, (str, bool, int, float)):
        return jnum(value) if not isinstance(value, str) else value
    if isinstance(value, (tuple, list)) and all(isinstance(c, (int, float)) for c in value):
        return [jnum(c) for c in value]
    return None


class GridView:
    """Uniform access to a read-back grid (or a Substitute for a type pyopenvdb lacks)."""

    def __init__(self, grid, sub: Substitute | None = None):
        self.grid = grid if sub is None else sub.grid
        self.convert = (lambda v: v) if sub is None else sub.convert
        self.value_type = grid.valueTypeName if sub is None else sub.value_type

    def value(self, v):
        return self.convert(v)


def sample_points(view: GridView, rng, bbox, extra) -> tuple[list, list]:
    """Pick sample coordinates; also count active tiles per level.

    Returns (coords, [tiles at 8^3, 128^3, 4096^3]).
    """
    g = view.grid
    bg = g.background
    n_leaf_on = g.activeLeafVoxelCount()
    chosen = set(rng.choice(n_leaf_on, min(ACTIVE_SAMPLES, n_leaf_on), replace=False).tolist()) \
        if n_leaf_on else set()
    active, tiles, tile_counts = [], [], [0, 0, 0]
    i = 0
    for it in g.citerOnValues():
        if it["depth"] == 3:
            if i in chosen:
                active.append(list(it["min"]))
            i += 1
        else:
            tile_counts[2 - it["depth"]] += 1
            tiles.append((it["min"], it["max"]))
    # Reservoir samples of inactive voxels inside leaves; inactive tiles that are
    # not background are all interesting.
    reservoir, seen, odd_tiles = [], 0, []
    for it in g.citerOffValues():
        if it["depth"] == 3:
            if len(reservoir) < INACTIVE_SAMPLES:
                reservoir.append(list(it["min"]))
            else:
                j = int(rng.integers(seen + 1))
                if j < INACTIVE_SAMPLES:
                    reservoir[j] = list(it["min"])
            seen += 1
        elif not same(it["value"], bg) and len(odd_tiles) < 1000:
            odd_tiles.append((it["min"], it["max"]))
    tile_pts = []
    for group in (tiles, odd_tiles):
        picks = rng.choice(len(group), min(TILE_SAMPLES, len(group)), replace=False) if group else []
        for p in sorted(int(p) for p in picks):
            lo, hi = group[p]
            tile_pts.append(list(lo))
            tile_pts.append([int(rng.integers(a, b + 1)) for a, b in zip(lo, hi)])
            tile_pts.append(list(hi))
    outside = [[-1, -1, -1], [-100000, 3, 7], [1 << 20, 0, 0], [0, -(1 << 20), 5],
               [-(1 << 31), 0, 0], [(1 << 31) - 1, (1 << 31) - 1, (1 << 31) - 1],
               [-4096, -4096, -4096], [4095, 4095, 4095]]
    if bbox:
        lo, hi = bbox
        outside += [[c + 1 for c in hi], [c - 1 for c in lo], [hi[0] + 200, lo[1], lo[2]],
                    [lo[0], hi[1] + 4096, lo[2]]]
    coords, keys = [], set()
    for p in active + reservoir + tile_pts + outside + [list(map(int, q)) for q in extra]:
        t = tuple(p)
        if t not in keys:
            keys.add(t)
            coords.append(p)
    return coords, tile_counts


def index_to_world(xform, bbox) -> list:
    pts = [(0, 0, 0), (1, 0, 0), (0, 1, 0), (0, 0, 1), (1, 2, 3), (0.5, -1.25, 2.75),
           (-7, 100, 1000)]
    if bbox:
        pts += [tuple(bbox[0]), tuple(bbox[1])]
    return [{"ijk": list(p), "world": [float(c) for c in xform.indexToWorld(p)]} for p in pts]


def describe_grid(view: GridView, rec: vdbfile.GridRecord | None, rng, extra) -> dict:
    g = view.grid
    lo, hi = g.evalActiveVoxelBoundingBox()
    empty = g.activeVoxelCount() == 0
    bbox = None if empty else [list(lo), list(hi)]
    coords, tile_counts = sample_points(view, rng, bbox, extra)
    acc = g.getConstAccessor()
    samples = [{"ijk": p, "value": jval(view.value(acc.getValue(tuple(p)))),
                "active": bool(acc.isValueOn(tuple(p)))} for p in coords]
    if empty:
        vmin = vmax = None
    elif view.value_type == "int32":
        vals = [view.value(it["value"]) for it in g.citerOnValues()]
        vmin, vmax = min(vals), max(vals)
    else:
        vmin, vmax = g.evalMinMax()
    d = {"name": g.name}
    if rec is not None and rec.unique_name != rec.name:
        d["unique_name"] = rec.unique_name
    d.update({
        "value_type": view.value_type,
        "class": g.gridClass,
        "half_float": bool(rec.half_float) if rec else bool(g.saveFloatAsHalf),
    })
    if rec is not None:
        d["compression"] = rec.compression
    d.update({
        "background": jval(view.value(g.background)),
        "active_voxels": int(g.activeVoxelCount()),
        "leaf_count": int(g.leafCount()),
        "active_tile_count": tile_counts,
        "index_bbox": bbox,
        "voxel_size": [float(c) for c in g.transform.voxelSize()],
        "transform": g.transform.typeName,
        "index_to_world": index_to_world(g.transform, bbox),
        "min": None if vmin is None else jval(vmin),
        "max": None if vmax is None else jval(vmax),
    })
    if g.valueTypeName == "vec3s":
        d["vector_type"] = g.vectorType
        if not empty:
            # evalMinMax orders vectors lexicographically; also give per-component
            # extremes over all active values (voxels and tiles), NaN excluded.
            vals = np.array([it["value"] for it in g.citerOnValues()], dtype=np.float64)
            d["min_components"] = jval(np.nanmin(vals, axis=0).tolist())
            d["max_components"] = jval(np.nanmax(vals, axis=0).tolist())
    if rec is not None and rec.tree is not None:
        t = rec.tree
        d["layout"] = {
            "leaf_modes": [t.leaf_modes.count(m) for m in range(7)],
            "internal_modes": [t.internal_modes.count(m) for m in range(7)],
            "zero_count_chunks": t.zero_count_chunks,
        }
    d["samples"] = samples
    return d


def compression_from_string(text: str) -> int:
    """Invert io::compressionToString ("blosc + active values" -> 6, "none" -> 0)."""
    bits = {"zip": 0x1, "active values": 0x2, "blosc": 0x4, "none": 0}
    return sum(bits[part.strip()] for part in text.split("+"))


def grid_request_name(rec: vdbfile.GridRecord) -> str:
    """Name pyopenvdb.read accepts for this descriptor ("density[1]" for "density\\x1e1")."""
    if "\x1e" in rec.unique_name:
        base, _, n = rec.unique_name.partition("\x1e")
        return f"{base}[{n}]"
    return rec.unique_name


def describe_vdb(prod: Product, path: str) -> tuple[dict, vdbfile.VdbFile]:
    vf = vdbfile.read_vdb(path)
    entry = {"file": prod.file, "format": "vdb", "file_version": vf.file_version}
    entry.update(prod.extra)
    meta = vdb.readMetadata(path)
    entry["file_metadata"] = {k: jmeta(v) for k, v in sorted(meta.items()) if jmeta(v) is not None}
    entry["file_metadata_types"] = {name: type_name for name, type_name, _ in vf.metadata}
    entry["library_version"] = list(vf.library_version)
    grids = []
    for idx, rec in enumerate(vf.grids):
        sub = prod.substitutes.get(rec.unique_name)
        if sub is None:
            grid = vdb.read(path, grid_request_name(rec))
            require(grid.name == rec.name, f"{path}: read {grid.name!r} for {rec.unique_name!r}")
            require(grid.valueTypeName == rec.value_type,
                    f"{path}: {grid.valueTypeName} vs {rec.type_name}")
            view = GridView(grid)
        else:
            view = GridView(None, sub)
            require(rec.value_type == sub.value_type, f"{path}: {rec.type_name}")
        require(rec.map_type == view.grid.transform.typeName,
                f"{path}: stored map {rec.map_type} vs {view.grid.transform.typeName}")
        stored = dict((n, v) for n, _, v in rec.metadata).get("file_compression")
        require(stored is None or compression_from_string(stored) == rec.compression,
                f"{path}: file_compression {stored!r} vs flags {rec.compression}")
        rng = rng_for(prod.file, idx)
        d = describe_grid(view, rec, rng, prod.extra_samples.get(rec.unique_name, []))
        if rec.tree is not None:
            require(len(rec.tree.leaf_origins) == d["leaf_count"],
                    f"{path}:{rec.name}: walker leaves {len(rec.tree.leaf_origins)}")
            require(rec.tree.active_tiles == d["active_tile_count"],
                    f"{path}:{rec.name}: walker tiles {rec.tree.active_tiles}")
        if rec.tree is not None and prod.file.startswith("inactive_modes"):
            d["mode_leaves"] = [{"origin": list(o), "mode": m, "active": a} for o, m, a in
                                zip(rec.tree.leaf_origins, rec.tree.leaf_modes,
                                    rec.tree.leaf_active)]
        grids.append(d)
    entry["grids"] = grids
    return entry, vf


# --------------------------------------------------------------------------- vdb_print

def parse_vdb_print(text: str) -> list[dict]:
    """Per-grid facts from `vdb_print -l` (grids appear in name order)."""
    out = []
    for block in re.split(r"^Name: ", text, flags=re.M)[1:]:
        name = block.split("\n", 1)[0]
        info = {"name": name}
        m = re.search(r"Type: (\S+)", block)
        info["type"] = m.group(1) if m else None
        m = re.search(r"Leaf\(([\d,]+) x 8\^3\)", block)
        info["leaves"] = int(m.group(1).replace(",", "")) if m else 0
        m = re.search(r"Number of active voxels:\s+([\d,]+)", block)
        info["voxels"] = int(m.group(1).replace(",", "")) if m else 0
        m = re.search(r"Number of active tiles:\s+([\d,]+)", block)
        info["tiles"] = int(m.group(1).replace(",", "")) if m else 0
        m = re.search(r"Bounding box of active voxels: \[(-?\d+), (-?\d+), (-?\d+)\] -> "
                      r"\[(-?\d+), (-?\d+), (-?\d+)\]", block)
        info["bbox"] = [list(map(int, m.groups()[:3])), list(map(int, m.groups()[3:]))] if m else None
        for key in ("Min", "Max"):
            m = re.search(rf"{key} value: (\S+)", block)
            info[key.lower()] = m.group(1) if m else None
        out.append(info)
    return out


def cross_check_vdb_print(entry: dict, path: str) -> None:
    """Assert that vdb_print -l agrees with the manifest for every grid of a .vdb file."""
    printed = parse_vdb_print(run("vdb_print", "-l", path))
    require(len(printed) == len(entry["grids"]),
            f"{path}: vdb_print lists {len(printed)} grids, manifest {len(entry['grids'])}")

    def key(d):
        return (d["name"], d["voxels"], d["leaves"], d["tiles"], json.dumps(d["bbox"]))

    mine = sorted(key({"name": g["name"], "voxels": g["active_voxels"], "leaves": g["leaf_count"],
                       "tiles": sum(g["active_tile_count"]), "bbox": g["index_bbox"]})
                  for g in entry["grids"])
    theirs = sorted(key(p) for p in printed)
    require(mine == theirs, f"{path}: vdb_print disagrees:\n  manifest {mine}\n  vdb_print {theirs}")
    # Min/max: vdb_print prints 6 significant digits; compare finite scalars only.
    by_name = {}
    for p in printed:
        by_name.setdefault(p["name"], []).append(p)
    for g in entry["grids"]:
        if g["value_type"] not in ("float", "int32") or g["min"] is None:
            continue
        for p in by_name[g["name"]]:
            if p["voxels"] != g["active_voxels"]:
                continue
            for k in ("min", "max"):
                try:
                    theirs_v = float(p[k])
                except (TypeError, ValueError):
                    continue
                mine_v = g[k]
                if isinstance(mine_v, str) or not math.isfinite(theirs_v):
                    continue
                require(abs(theirs_v - mine_v) <= 1e-5 * max(1.0, abs(mine_v)),
                        f"{path}:{g['name']}: vdb_print {k} {p[k]} vs {mine_v}")


# --------------------------------------------------------------------------- NanoVDB

def parse_nanovdb_print(text: str) -> list[dict]:
    """Rows of the fixed-width table printed by `nanovdb_print -l`, keyed by header."""
    lines = [l for l in text.splitlines() if l.strip()]
    hi = next(i for i, l in enumerate(lines) if l.startswith("#  Name"))
    header = lines[hi]
    cols = [m.start() for m in re.finditer(r"(?:(?<=  )|^)\S", header)]
    names = [header[a:b].strip() for a, b in zip(cols, cols[1:] + [None])]
    rows = []
    for line in lines[hi + 1:]:
        if not re.match(r"^\d+\s", line):
            continue
        rows.append({n: line[a:b].strip() for n, a, b in zip(names, cols, cols[1:] + [None])})
    return rows


def _bbox(text: str):
    nums = list(map(int, re.findall(r"-?\d+", text)))
    return [nums[:3], nums[3:]]


QUANTISED_NVDB_TYPES = {"Fp4", "Fp8", "Fp16", "FpN", "Float4", "Float8", "Float16", "FloatN"}


def verify_nvdb_values(path: str, tmp: Path, entry: dict) -> None:
    """Convert the .nvdb back to .vdb with nanovdb_convert and check every sample.

    This proves that the NanoVDB file holds the manifest's values (exactly, or
    within value_tolerance for quantised grids) and activity states.
    """
    back = str(tmp / (Path(path).stem + "_roundtrip.vdb"))
    run("nanovdb_convert", "-f", path, back)
    for g in entry["grids"]:
        acc = vdb.read(back, g["name"]).getConstAccessor()
        tol = g["value_tolerance"]
        for s in g["samples"]:
            ijk = tuple(s["ijk"])
            got, want = jval(acc.getValue(ijk)), s["value"]
            require(bool(acc.isValueOn(ijk)) == s["active"], f"{path}:{g['name']} {ijk} activity")
            if got == want or same(got, want):
                continue
            require(tol > 0 and isinstance(got, float) and isinstance(want, float)
                    and abs(got - want) <= tol,
                    f"{path}:{g['name']} {ijk}: nvdb {got} vs vdb {want} (tolerance {tol})")


def describe_nvdb(prod: Product, path: str, manifest_by_file: dict, tmp: Path) -> dict:
    rows = parse_nanovdb_print(run("nanovdb_print", "-l", path))
    validate = run("nanovdb_validate", "-v", path)
    segments = vdbfile.read_nvdb_segments(path)
    source = manifest_by_file[prod.source]
    src_path = str(Path(path).parent / prod.source)
    seg_names = [n for s in segments for n in s.grid_names]
    require([r["Name"] for r in rows] == seg_names, f"{path}: print order {rows} vs {seg_names}")
    entry = {"file": prod.file, "format": "nvdb", "source": prod.source,
             "segments": [{"magic": s.magic.decode("ascii", "replace"),
                           "version": ".".join(map(str, s.version)), "codec": s.codec,
                           "grids": s.grid_names} for s in segments],
             "grids": []}
    for row in rows:
        name = row["Name"]
        require(re.search(rf'Grid named "{re.escape(name)}": passed', validate) is not None,
                f"{path}: nanovdb_validate did not pass {name}:\n{validate}")
        src = [g for g in source["grids"] if g["name"] == name]
        require(len(src) == 1, f"{path}: no unique source grid {name}")
        src = src[0]
        upper, lower, leaves = map(int, row["32^3->16^3->8^3"].split("->"))
        root_t, upper_t, lower_t = map(int, row["# Active tiles"].split("->"))
        d = {
            "name": name,
            "value_type": src["value_type"],
            "nvdb_grid_type": row["Type"],
            "class": src["class"],
            "codec": row["Codec"],
            "background": src["background"],
            "active_voxels": int(row["# Voxels"]),
            "leaf_count": leaves,
            "node_count": [leaves, lower, upper],
            "active_tile_count": [lower_t, upper_t, root_t],
            "index_bbox": _bbox(row["Index Bounding Box"]),
            "world_bbox_printed": row["World Bounding Box"],
            "voxel_size": src["voxel_size"],
            "source_transform": src["transform"],  # NanoVDB stores a matrix, not a map type
            "index_to_world": src["index_to_world"],
            "min": src["min"], "max": src["max"],
        }
        for k in ("min_components", "max_components"):
            if k in src:
                d[k] = src[k]
        for k in ("active_voxels", "leaf_count", "active_tile_count", "index_bbox"):
            require(d[k] == src[k], f"{path}:{name}: {k} {d[k]} (nanovdb_print) vs {src[k]} (vdb)")
        if row["Type"] in QUANTISED_NVDB_TYPES:
            grid = vdb.read(src_path, name)
            lo = hi = None
            for it in grid.citerAllValues():
                if it["depth"] == 3:
                    v = it["value"]
                    lo = v if lo is None else min(lo, v)
                    hi = v if hi is None else max(hi, v)
            ulp = float(np.spacing(np.float32(max(abs(lo), abs(hi)))))
            d["value_tolerance"] = (hi - lo) / 65535.0 + 4.0 * ulp
        else:
            d["value_tolerance"] = 0.0
        d["samples"] = src["samples"]
        entry["grids"].append(d)
    verify_nvdb_values(path, tmp, entry)
    return entry


# --------------------------------------------------------------------------- output

def dump_json(obj, indent: int = 0, width: int = 110) -> str:
    """Pretty JSON that keeps small objects/arrays (e.g. each sample) on one line."""
    flat = json.dumps(obj, separators=(", ", ": "))
    if len(flat) + indent <= width or not isinstance(obj, (dict, list)) or not obj:
        return flat
    pad, inner = " " * indent, " " * (indent + 2)
    if isinstance(obj, dict):
        items = [f"{inner}{json.dumps(k)}: {dump_json(v, indent + 2, width).lstrip()}"
                 for k, v in obj.items()]
        return "{\n" + ",\n".join(items) + "\n" + pad + "}"
    items = [inner + dump_json(v, indent + 2, width).lstrip() for v in obj]
    return "[\n" + ",\n".join(items) + "\n" + pad + "]"
