"""Plumbing shared by the corpus cases and the manifest of tools/make_corpus.py.

corpus_cases.py writes the corpus files and records each as a Product in a
Ctx; corpus_manifest.py describes and cross-checks those products; both run
tools, seed RNGs and fail through the helpers here.  The seed is here because
both the cases and the sample picking derive their random numbers from it.
"""

from __future__ import annotations

import os
import subprocess
import zlib
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

SEED = 20240611


@dataclass
class Product:
    """One corpus file plus what its manifest entry needs beyond the generic description."""
    file: str
    format: str = "vdb"                       # "vdb" | "nvdb"
    source: str | None = None                 # nvdb: the .vdb it was converted from
    extra_samples: dict[str, list] = field(default_factory=dict)   # grid name -> ijk list
    extra: dict = field(default_factory=dict)  # extra top-level keys (e.g. expect_error)
    substitutes: dict[str, "Substitute"] = field(default_factory=dict)  # by grid name
    check: object = None                      # callable(entry, VdbFile) run after describing


@dataclass
class Substitute:
    """Stand-in for a grid type pyopenvdb cannot load (see case_other_types)."""
    grid: object                   # pyopenvdb grid read back from the unpatched file
    value_type: str
    convert: object                # float value -> value of the real type


class Ctx:
    def __init__(self, out: Path, tmp: Path):
        self.out, self.tmp = out, tmp
        self.products: list[Product] = []

    def path(self, name: str) -> str:
        return str(self.out / name)

    def add(self, product: Product) -> Product:
        self.products.append(product)
        return product


def run(*cmd: str) -> str:
    """Run a tool, fail loudly on a non-zero exit, return stdout."""
    p = subprocess.run(cmd, capture_output=True, text=True)
    if p.returncode != 0:
        raise RuntimeError(f"{' '.join(cmd)} failed ({p.returncode}):\n{p.stdout}\n{p.stderr}")
    return p.stdout


def vdb_tool_rewrite(src: str, dst: str, codec: str, bits: int = 32) -> None:
    """Rewrite every grid of `src` with vdb_tool's chosen codec (drops file metadata)."""
    if os.path.exists(dst):
        os.remove(dst)
    args = ["vdb_tool", "-quiet", "-read", src, "-write", f"codec={codec}"]
    if bits != 32:
        args.append(f"bits={bits}")
    run(*args, dst)


def rng_for(*keys) -> np.random.Generator:
    """A generator seeded from SEED and stable string/int keys (independent of case order)."""
    return np.random.default_rng([SEED] + [zlib.crc32(str(k).encode()) for k in keys])


class CorpusError(RuntimeError):
    pass


def require(cond: bool, msg: str) -> None:
    if not cond:
        raise CorpusError(msg)
