"""Minimal read-only walker of the OpenVDB (.vdb) and NanoVDB (.nvdb) container layouts.

It exists only to *check* the generated corpus with facts pyopenvdb does not expose:
the order of grids in the file, the per-grid compression flags, the half-float
type suffix, the types of file-level metadata, and, by walking the tree topology
and skipping the value buffers, the per-node inactive-value mode bytes and tile
counts.  It never decompresses anything.  Values and statistics in the manifest
still come from pyopenvdb and the Debian OpenVDB/NanoVDB tools.

Layout references: /usr/include/openvdb/io/Compression.h (writeCompressedValues),
tree/RootNode.h, tree/InternalNode.h, tree/LeafNode.h, tree/LeafNodeBool.h,
math/Maps.h and /usr/include/nanovdb/util/IO.h.
"""

from __future__ import annotations

import struct
from dataclasses import dataclass, field

import numpy as np

VDB_MAGIC = 0x56444220
COMPRESS_ZIP, COMPRESS_ACTIVE_MASK, COMPRESS_BLOSC = 0x1, 0x2, 0x4
HALF_SUFFIX = "_HalfFloat"

# Serialised size in bytes of each map type's parameters (math/Maps.h read()).
MAP_BYTES = {
    "AffineMap": 16 * 8,
    "UnitaryMap": 16 * 8,
    "ScaleMap": 5 * 24,
    "UniformScaleMap": 5 * 24,
    "TranslationMap": 24,
    "ScaleTranslateMap": 6 * 24,
    "UniformScaleTranslateMap": 6 * 24,
}

# value type name -> (bytes per value, bytes per value when saved as half)
VALUE_BYTES = {
    "float": (4, 2), "double": (8, 2), "int32": (4, 4), "int64": (8, 8),
    "bool": (1, 1), "vec3s": (12, 6), "vec3d": (24, 6), "vec3i": (12, 12),
}

# Metadata type name -> struct format (for the types we decode).
META_FORMATS = {
    "bool": "<?", "int32": "<i", "int64": "<q", "float": "<f", "double": "<d",
    "vec2i": "<2i", "vec2s": "<2f", "vec2d": "<2d",
    "vec3i": "<3i", "vec3s": "<3f", "vec3d": "<3d",
}


class Reader:
    """Little-endian cursor over a bytes object."""

    def __init__(self, data: bytes, pos: int = 0):
        self.data, self.pos = data, pos

    def take(self, n: int) -> bytes:
        if n < 0 or self.pos + n > len(self.data):
            raise ValueError(f"read of {n} bytes at {self.pos} runs past end ({len(self.data)})")
        b = self.data[self.pos:self.pos + n]
        self.pos += n
        return b

    def unpack(self, fmt: str):
        vals = struct.unpack_from(fmt, self.data, self.pos)
        self.pos += struct.calcsize(fmt)
        return vals if len(vals) > 1 else vals[0]

    def string(self) -> str:
        n = self.unpack("<I")
        return self.take(n).decode("utf-8", "replace")


def read_metamap(r: Reader) -> list[tuple[str, str, object]]:
    """(name, type name, decoded value or None) for each entry of a serialised MetaMap."""
    out = []
    for _ in range(r.unpack("<I")):
        name, type_name = r.string(), r.string()
        raw = r.take(r.unpack("<I"))
        if type_name == "string":
            value = raw.decode("utf-8", "replace")
        elif type_name in META_FORMATS and struct.calcsize(META_FORMATS[type_name]) == len(raw):
            value = struct.unpack(META_FORMATS[type_name], raw)
            value = value[0] if len(value) == 1 else list(value)
        else:
            value = None
        out.append((name, type_name, value))
    return out


@dataclass
class TreeInfo:
    """What the topology walk found in one grid."""
    leaf_origins: list[tuple[int, int, int]] = field(default_factory=list)
    leaf_modes: list[int] = field(default_factory=list)        # per-leaf metadata byte
    leaf_active: list[int] = field(default_factory=list)       # active voxels per leaf
    internal_modes: list[int] = field(default_factory=list)    # metadata bytes of internal nodes
    active_tiles: list[int] = field(default_factory=lambda: [0, 0, 0])  # [8^3, 128^3, 4096^3]
    zero_count_chunks: int = 0    # value chunks holding no values at all


@dataclass
class GridRecord:
    unique_name: str               # as stored, e.g. "density\x1e1" for a duplicate name
    name: str                      # unique name without the "\x1e<n>" suffix
    type_name: str                 # e.g. "Tree_float_5_4_3_HalfFloat"
    half_float: bool
    grid_pos: int
    block_pos: int
    end_pos: int
    compression: int | None = None
    metadata: list = field(default_factory=list)
    map_type: str | None = None
    tree: TreeInfo | None = None
    tree_error: str | None = None

    @property
    def value_type(self) -> str:
        base = self.type_name[:-len(HALF_SUFFIX)] if self.half_float else self.type_name
        return base.split("_")[1]


@dataclass
class VdbFile:
    file_version: int
    library_version: tuple[int, int]
    has_grid_offsets: bool
    uuid: str
    metadata: list
    grids: list[GridRecord]


def _bits(raw: bytes) -> np.ndarray:
    return np.unpackbits(np.frombuffer(raw, dtype=np.uint8), bitorder="little").astype(bool)


class _TreeWalker:
    """Walks the topology and the leaf buffers of a Tree_<T>_5_4_3 grid."""

    def __init__(self, r: Reader, value_type: str, half: bool, compression: int):
        self.r = r
        self.vt = value_type
        self.full, half_bytes = VALUE_BYTES[value_type]
        self.data_bytes = half_bytes if half else self.full
        self.half = half and value_type in ("float", "double", "vec3s", "vec3d")
        self.compression = compression
        self.info = TreeInfo()

    def _chunk(self, count: int) -> None:
        """Skip `count` stored values (io::readData / HalfReader)."""
        if count == 0:
            self.info.zero_count_chunks += 1
            if self.half:
                return  # HalfWriter writes nothing at all for an empty chunk
        if self.compression & (COMPRESS_BLOSC | COMPRESS_ZIP):
            n = self.r.unpack("<q")
            self.r.take(abs(n))
        else:
            self.r.take(count * self.data_bytes)

    def _compressed_values(self, num_values: int, value_mask: np.ndarray) -> int:
        """Skip one writeCompressedValues block; return its metadata byte."""
        mode = self.r.unpack("<b")
        mask_compress = bool(self.compression & COMPRESS_ACTIVE_MASK)
        if mask_compress:
            if mode in (2, 4, 5):
                self.r.take(self.full)          # inactive value 0 (full size, even for half)
            if mode == 5:
                self.r.take(self.full)          # inactive value 1
            if mode in (3, 4, 5):
                self.r.take(num_values // 8)    # selection mask
        count = int(value_mask.sum()) if (mask_compress and mode != 6) else num_values
        self._chunk(count)
        return mode

    def walk(self) -> TreeInfo:
        r = self.r
        buffer_count = r.unpack("<i")
        if buffer_count != 1:
            raise ValueError(f"buffer count {buffer_count}")
        r.take(self.full)  # background
        num_tiles, num_children = r.unpack("<II")
        for _ in range(num_tiles):
            r.take(12 + self.full)
            if r.unpack("<?"):
                self.info.active_tiles[2] += 1
        for _ in range(num_children):
            origin = r.unpack("<3i")
            self._internal(origin, log2=5, child_span=128)
        return self.info

    def _internal(self, origin, log2: int, child_span: int) -> None:
        n = 1 << (3 * log2)
        child_mask = _bits(self.r.take(n // 8))
        value_mask = _bits(self.r.take(n // 8))
        tiles = value_mask & ~child_mask
        self.info.active_tiles[1 if log2 == 5 else 0] += int(tiles.sum())
        self.info.internal_modes.append(self._compressed_values(n, value_mask))
        dim = 1 << log2
        for idx in np.nonzero(child_mask)[0].tolist():
            i, j, k = idx >> (2 * log2), (idx >> log2) & (dim - 1), idx & (dim - 1)
            child = (origin[0] + i * child_span, origin[1] + j * child_span,
                     origin[2] + k * child_span)
            if log2 == 5:
                self._internal(child, log2=4, child_span=8)
            else:
                self.r.take(64)  # leaf topology: value mask
                self.info.leaf_origins.append(child)

    def leaf_buffers(self) -> None:
        for _ in self.info.leaf_origins:
            value_mask = _bits(self.r.take(64))
            self.info.leaf_active.append(int(value_mask.sum()))
            if self.vt == "bool":
                self.r.take(12 + 64)  # origin, then the value bits
                self.info.leaf_modes.append(-1)
            else:
                self.info.leaf_modes.append(self._compressed_values(512, value_mask))


def read_vdb(path: str, walk_trees: bool = True) -> VdbFile:
    """Parse the header, grid descriptors and (optionally) each grid's tree layout."""
    with open(path, "rb") as f:
        data = f.read()
    r = Reader(data)
    magic = r.unpack("<q")
    if magic != VDB_MAGIC:
        raise ValueError(f"{path}: bad magic {magic:#x}")
    file_version = r.unpack("<I")
    lib = r.unpack("<II")
    has_offsets = r.unpack("<?")
    uuid = r.take(36).decode("ascii", "replace")
    meta = read_metamap(r)
    grids = []
    for _ in range(r.unpack("<I")):
        unique = r.string()
        type_name = r.string()
        r.string()  # instance parent name
        gpos, bpos, epos = r.unpack("<3q")
        half = type_name.endswith(HALF_SUFFIX)
        g = GridRecord(unique, unique.split("\x1e")[0], type_name, half, gpos, bpos, epos)
        grids.append(g)
        r.pos = epos
    for g in grids:
        gr = Reader(data, g.grid_pos)
        g.compression = gr.unpack("<I")
        g.metadata = read_metamap(gr)
        g.map_type = gr.string()
        if not walk_trees:
            continue
        try:
            if g.map_type not in MAP_BYTES:
                raise ValueError(f"map {g.map_type} not walked")
            if not (g.type_name.startswith("Tree_") and "_5_4_3" in g.type_name):
                raise ValueError(f"tree type {g.type_name} not walked")
            gr.take(MAP_BYTES[g.map_type])
            w = _TreeWalker(gr, g.value_type, g.half_float, g.compression)
            w.walk()
            if gr.pos != g.block_pos:
                raise ValueError(f"topology ended at {gr.pos}, block starts at {g.block_pos}")
            w.leaf_buffers()
            if gr.pos != g.end_pos:
                raise ValueError(f"buffers ended at {gr.pos}, grid ends at {g.end_pos}")
            g.tree = w.info
        except (ValueError, KeyError, struct.error) as e:
            g.tree_error = str(e)
    return VdbFile(file_version, lib, has_offsets, uuid, meta, grids)


# ---------------------------------------------------------------- NanoVDB

NVDB_CODECS = {0: "NONE", 1: "ZIP", 2: "BLOSC"}


@dataclass
class NvdbSegment:
    magic: bytes
    version: tuple[int, int, int]
    codec: str
    grid_names: list[str]


def read_nvdb_segments(path: str) -> list[NvdbSegment]:
    """Walk the segment headers of a NanoVDB file (nanovdb/util/IO.h, 32.4 layout)."""
    with open(path, "rb") as f:
        data = f.read()
    r = Reader(data)
    segments = []
    while r.pos < len(data):
        magic = r.take(8)
        version = r.unpack("<I")
        grid_count, codec = r.unpack("<HH")
        metas = []
        for _ in range(grid_count):
            raw = r.take(176)
            file_size = struct.unpack_from("<Q", raw, 8)[0]
            name_size = struct.unpack_from("<I", raw, 32 + 8 + 48 + 24 + 24)[0]
            name = r.take(name_size).rstrip(b"\0").decode("utf-8", "replace")
            metas.append((name, file_size))
        for _, file_size in metas:
            r.take(file_size)
        segments.append(NvdbSegment(
            magic, (version >> 21, (version >> 10) & 0x7FF, version & 0x3FF),
            NVDB_CODECS.get(codec, str(codec)), [m[0] for m in metas]))
    return segments
