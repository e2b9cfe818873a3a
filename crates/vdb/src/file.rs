//! Opening a volume file of either format, listing its grids, reading one.

use crate::error::{unsupported, Error, ErrorKind, Result};
use crate::grid::{Grid, GridClass, GridInfo};
use crate::metadata::{meta_get, MetaMap, MetaValue};
use crate::nanovdb::{self, NanoIndex};
use crate::openvdb::stream::GridStream;
use crate::openvdb::{self, Archive};
use crate::source::FileSource;
use crate::transform::Transform;
use crate::value::{Value, ValueType};
use std::path::Path;

/// Which of the two formats a file is in.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Format {
    OpenVdb,
    NanoVdb,
}

impl Format {
    pub fn name(self) -> &'static str {
        match self {
            Format::OpenVdb => "vdb",
            Format::NanoVdb => "nvdb",
        }
    }
}

enum Index {
    OpenVdb(Archive),
    NanoVdb(NanoIndex),
}

/// A grid's transform and inclusive index-space bounding box (min, max).
pub type GridBounds = (Transform, [i32; 3], [i32; 3]);

/// What a grid's record says before its tree: read without any voxel data.
#[derive(Clone, Debug)]
pub struct GridHeader {
    /// The grid's metadata (OpenVDB writes `class`, `file_bbox_min`,
    /// `file_bbox_max`, `file_voxel_count`, `file_mem_bytes`, ...).
    pub metadata: MetaMap,
    pub transform: Transform,
    pub class: GridClass,
    /// The background as up to three f64 components, for the value types
    /// the reader knows.
    pub background: Option<([f64; 3], usize)>,
}

/// An open volume file: its grid list is read, its grid data is not.
pub struct VolumeFile {
    source: FileSource,
    index: Index,
}

impl VolumeFile {
    /// Opens a file and reads its header and grid index (never grid data).
    /// The format is told by the magic bytes, not the extension.
    pub fn open(path: impl AsRef<Path>) -> Result<VolumeFile> {
        let path = path.as_ref();
        let err = |kind: ErrorKind| Error::new(path, kind);
        let source = FileSource::open(path).map_err(|e| err(e.into()))?;
        let magic = source.read_window(0, 8, "magic").map_err(err)?;
        let index = if magic == openvdb::MAGIC {
            Index::OpenVdb(Archive::open(&source).map_err(err)?)
        } else if nanovdb::MAGICS.iter().any(|m| magic == m.as_slice()) {
            Index::NanoVdb(NanoIndex::open(&source).map_err(err)?)
        } else if magic.len() < 8 {
            return Err(err(ErrorKind::Truncated {
                what: "magic",
                offset: 0,
                needed: 8,
                available: magic.len() as u64,
            }));
        } else {
            return Err(err(ErrorKind::BadMagic(magic)));
        };
        Ok(VolumeFile { source, index })
    }

    pub fn path(&self) -> &Path {
        self.source.path()
    }

    pub fn format(&self) -> Format {
        match self.index {
            Index::OpenVdb(_) => Format::OpenVdb,
            Index::NanoVdb(_) => Format::NanoVdb,
        }
    }

    /// The grids in file order.
    pub fn grids(&self) -> Vec<&GridInfo> {
        match &self.index {
            Index::OpenVdb(a) => a.grids.iter().map(|g| &g.info).collect(),
            Index::NanoVdb(n) => n.grids.iter().collect(),
        }
    }

    /// File-level metadata (OpenVDB only; empty for NanoVDB).
    pub fn metadata(&self) -> &MetaMap {
        static EMPTY: MetaMap = Vec::new();
        match &self.index {
            Index::OpenVdb(a) => &a.metadata,
            Index::NanoVdb(_) => &EMPTY,
        }
    }

    /// The OpenVDB file format version, or `None` for NanoVDB.
    pub fn file_version(&self) -> Option<u32> {
        match &self.index {
            Index::OpenVdb(a) => Some(a.file_version),
            Index::NanoVdb(_) => None,
        }
    }

    /// The OpenVDB library version that wrote the file, or `None` for NanoVDB.
    pub fn library_version(&self) -> Option<(u32, u32)> {
        match &self.index {
            Index::OpenVdb(a) => Some(a.library_version),
            Index::NanoVdb(_) => None,
        }
    }

    /// Bytes read from disk since the file was opened.
    pub fn bytes_read(&self) -> u64 {
        self.source.bytes_read()
    }

    pub fn file_len(&self) -> u64 {
        self.source.len()
    }

    /// `Ok` when the file has a grid `index`, else an error naming the
    /// file and how many grids it has.
    fn check_index(&self, index: usize) -> Result<()> {
        let count = self.grids().len();
        if index >= count {
            return Err(Error::new(
                self.path(),
                ErrorKind::NoSuchGrid(format!("#{index} (the file has {count})")),
            ));
        }
        Ok(())
    }

    /// Reads grid `index` (file order).
    pub fn read_grid(&self, index: usize) -> Result<Grid> {
        let err = |kind: ErrorKind| Error::new(self.path(), kind);
        self.check_index(index)?;
        match &self.index {
            Index::OpenVdb(a) => a.read_grid(&self.source, index),
            Index::NanoVdb(n) => n.read_grid(&self.source, index),
        }
        .map_err(err)
    }

    /// The index-space bounding box (inclusive voxel coordinates) and the
    /// transform of grid `index`, read from its header without its tree;
    /// `None` when the file does not say (NanoVDB files, or OpenVDB grids
    /// written without `file_bbox_min` / `file_bbox_max` metadata).
    pub fn grid_bounds(&self, index: usize) -> Result<Option<GridBounds>> {
        let err = |kind: ErrorKind| Error::new(self.path(), kind);
        self.check_index(index)?;
        let Index::OpenVdb(a) = &self.index else {
            return Ok(None);
        };
        let (meta, transform) = a.read_grid_header(&self.source, index).map_err(err)?;
        let get = |key| match meta_get(&meta, key) {
            Some(MetaValue::Vec3i(v)) => Some(*v),
            _ => None,
        };
        Ok(get("file_bbox_min")
            .zip(get("file_bbox_max"))
            .map(|(lo, hi)| (transform, lo, hi)))
    }

    /// Grid `index`'s metadata, transform, class and background, from its
    /// first few hundred bytes (OpenVDB); `None` for NanoVDB, whose header
    /// sits inside the (possibly compressed) grid buffer.
    pub fn grid_header(&self, index: usize) -> Result<Option<GridHeader>> {
        let err = |kind: ErrorKind| Error::new(self.path(), kind);
        self.check_index(index)?;
        let Index::OpenVdb(a) = &self.index else {
            return Ok(None);
        };
        type Header = (MetaMap, Transform, Option<([f64; 3], usize)>);
        fn read<V: Value>(
            a: &Archive,
            src: &FileSource,
            i: usize,
        ) -> crate::error::KindResult<Header> {
            let (m, t, bg) = a.header_and_background::<V>(src, i)?;
            Ok((m, t, Some(bg.components())))
        }
        let src = &self.source;
        let (metadata, transform, background) = match a.grids[index].info.value_type {
            Some(ValueType::Float) => read::<f32>(a, src, index),
            Some(ValueType::Double) => read::<f64>(a, src, index),
            Some(ValueType::Int32) => read::<i32>(a, src, index),
            Some(ValueType::Int64) => read::<i64>(a, src, index),
            Some(ValueType::Bool | ValueType::Mask) => read::<bool>(a, src, index),
            Some(ValueType::Vec3f) => read::<[f32; 3]>(a, src, index),
            Some(ValueType::Vec3d) => read::<[f64; 3]>(a, src, index),
            None => a.read_grid_header(src, index).map(|(m, t)| (m, t, None)),
        }
        .map_err(err)?;
        let class = meta_get(&metadata, "class")
            .and_then(|v| v.as_str())
            .map_or(GridClass::Unknown, GridClass::from_name);
        Ok(Some(GridHeader {
            metadata,
            transform,
            class,
            background,
        }))
    }

    /// Starts streaming grid `index` of value type `V` (OpenVDB files, all
    /// but bool and mask grids): reads its header and topology, not its
    /// leaf values and not into a tree. See [`GridStream::decode_leaves`].
    pub fn stream_grid<V: Value>(&self, index: usize) -> Result<GridStream<'_, V>> {
        let err = |kind: ErrorKind| Error::new(self.path(), kind);
        self.check_index(index)?;
        match &self.index {
            Index::OpenVdb(a) => a.stream_grid(&self.source, index).map_err(err),
            Index::NanoVdb(_) => Err(err(unsupported("streaming a NanoVDB grid"))),
        }
    }

    /// Index of the first grid called `name`; the unique stored name
    /// (`density\x1e1`) picks a later duplicate.
    pub fn find_grid(&self, name: &str) -> Result<usize> {
        let grids = self.grids();
        grids
            .iter()
            .position(|g| g.unique_name == name)
            .or_else(|| grids.iter().position(|g| g.name == name))
            .ok_or_else(|| {
                let names: Vec<String> = grids.iter().map(|g| format!("{:?}", g.name)).collect();
                let said = format!("named {name:?} (grids: {})", names.join(", "));
                Error::new(self.path(), ErrorKind::NoSuchGrid(said))
            })
    }

    pub fn read_grid_by_name(&self, name: &str) -> Result<Grid> {
        self.read_grid(self.find_grid(name)?)
    }
}
