#!/usr/bin/env python3
"""Files of a Rust crate that import each other in a circle.

    python tools/file_circles.py crates/render [crates/scene ...]

Each `use crate::...`, `use super::...` and `use self::...` (and inline `crate::a::b::`
paths) is taken to depend on the deepest module file its path names (`a/b.rs` or
`a/b/mod.rs`), following a `mod.rs`'s `pub use` of the item to the file that defines it. A module's own
declaration (`mod x;`), comments (doc links) and `#[cfg(test)]` modules are not imports. Prints each strongly
connected set of more than one file, and exits 1 if there is any.
"""
import re
import sys
from pathlib import Path


def module_file(src: Path, parts: list[str]) -> Path | None:
    """The deepest existing file for module path `parts` under `src`."""
    best = None
    for n in range(1, len(parts) + 1):
        base = src.joinpath(*parts[:n])
        for cand in (base.with_suffix(".rs"), base / "mod.rs"):
            if cand.exists():
                best = cand
                break
        else:
            break
    return best


def module_path(src: Path, f: Path) -> list[str]:
    rel = f.relative_to(src).with_suffix("")
    parts = list(rel.parts)
    if parts[-1] in ("mod", "lib", "main"):
        parts = parts[:-1]
    return parts


def strip_tests(text: str) -> str:
    """The text before any `#[cfg(test)]` module, without comments (doc links are no imports)."""
    i = text.find("#[cfg(test)]")
    text = text if i < 0 else text[:i]
    return re.sub(r"//[^\n]*", "", text)


USE = re.compile(r"\buse\s+((?:crate|super|self)(?:::\w+)*)(?:::\{([^;]*)\})?")
INLINE = re.compile(r"\b(crate(?:::\w+)+)")


PUB_USE = re.compile(r"\bpub(?:\([^)]*\))?\s+use\s+((?:self::|super::|crate::)?[\w:]+?)(?:::\{([^;]*)\}|::(\w+))?\s*;")


def reexports(src: Path, f: Path) -> dict[str, list[str]]:
    """Item name -> the module path it is re-exported from, for `pub use` lines of `f`."""
    here = module_path(src, f)
    out = {}
    for m in PUB_USE.finditer(strip_tests(f.read_text())):
        head = m.group(1).split("::")
        items = []
        if m.group(2):
            items = [i.split(" as ")[-1].strip() for i in re.split(r",", re.sub(r"\{[^}]*\}", "", m.group(2)))]
        elif m.group(3):
            items = [m.group(3)]
        else:
            head, items = head[:-1], [head[-1]]
        if head and head[0] == "crate":
            mod = head[1:]
        else:
            base = list(here)
            while head and head[0] in ("self", "super"):
                if head.pop(0) == "super":
                    base = base[:-1]
            mod = base + head
        for i in items:
            if i:
                out[i] = mod
    return out


def resolve(src: Path, parts: list[str], depth: int = 0) -> Path | None:
    """The file defining the item at `parts`, following `pub use` re-exports."""
    target = module_file(src, parts)
    if target is None or depth > 8:
        return target
    consumed = len(module_path(src, target))
    rest = parts[consumed:]
    if rest and target.name in ("mod.rs", "lib.rs"):
        via = reexports(src, target).get(rest[0])
        if via is not None and via != parts[:consumed]:
            return resolve(src, via + rest, depth + 1) or target
    return target


def deps(src: Path, f: Path) -> set[Path]:
    text = strip_tests(f.read_text())
    here = module_path(src, f)
    out = set()
    paths = []
    for m in USE.finditer(text):
        head = m.group(1).split("::")
        if m.group(2):
            for item in re.split(r"[,\s]+", re.sub(r"\{[^}]*\}", "", m.group(2))):
                if item and item not in ("self",):
                    paths.append(head + [item.split("::")[0]])
            paths.append(head)
        else:
            paths.append(head)
    paths += [m.group(1).split("::") for m in INLINE.finditer(text)]
    for p in paths:
        if p[0] == "crate":
            parts = p[1:]
        else:
            base = list(here)
            i = 0
            while i < len(p) and p[i] in ("super", "self"):
                if p[i] == "super":
                    base = base[:-1]
                i += 1
            parts = base + p[i:]
        target = resolve(src, parts) if parts else src / "lib.rs"
        if target and target != f:
            out.add(target)
    return out


def circles(src: Path) -> list[list[Path]]:
    files = sorted(src.rglob("*.rs"))
    graph = {f: deps(src, f) & set(files) for f in files}
    index, low, stack, on, out, counter = {}, {}, [], set(), [], [0]

    def strong(v):
        index[v] = low[v] = counter[0]
        counter[0] += 1
        stack.append(v)
        on.add(v)
        for w in graph[v]:
            if w not in index:
                strong(w)
                low[v] = min(low[v], low[w])
            elif w in on:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            comp = []
            while True:
                w = stack.pop()
                on.discard(w)
                comp.append(w)
                if w == v:
                    break
            if len(comp) > 1:
                out.append(sorted(comp))

    sys.setrecursionlimit(10000)
    for f in files:
        if f not in index:
            strong(f)
    return out


def main() -> int:
    found = 0
    for crate in sys.argv[1:] or ["crates/render"]:
        src = Path(crate) / "src"
        for comp in circles(src):
            found += 1
            print(f"{crate}: " + " <-> ".join(str(f.relative_to(src)) for f in comp))
    if not found:
        print("no file circles")
    return 1 if found else 0


if __name__ == "__main__":
    sys.exit(main())
