"""Import Mitsuba 3 and pick a variant, with a clear message when it is missing.

Shared by vdb_to_mitsuba_vol.py, mitsuba_render.py and compare_images.py.
See tools/README.md, "Peer renderers", for the install commands and versions.
"""

from __future__ import annotations

import sys

INSTALL_HINT = """\
Mitsuba 3 is not installed for this interpreter ({exe}). Install it into Debian's python
(the one that also has pyopenvdb):

    apt-get install -y libllvm19          # for the fast llvm_ad_rgb variant (LLVM 14/15 do not work)
    /usr/bin/python3 -m pip install --break-system-packages mitsuba==3.9.1

and run the tools with /usr/bin/python3."""

PREFERRED_VARIANTS = ("llvm_ad_rgb", "scalar_rgb")


def mitsuba(variant: str | None = None):
    """Returns (mi, dr) with a variant set: `variant`, else llvm_ad_rgb when Dr.Jit
    finds a usable libLLVM, else scalar_rgb."""
    try:
        import drjit as dr
        import mitsuba as mi
    except ImportError as e:
        sys.exit(f"{INSTALL_HINT.format(exe=sys.executable)}\n(import error: {e})")
    if mi.variant() is not None and (variant is None or mi.variant() == variant):
        return mi, dr
    candidates = (variant,) if variant else PREFERRED_VARIANTS
    errors = []
    for v in candidates:
        if v not in mi.variants():
            errors.append(f"{v}: not built into this mitsuba wheel")
            continue
        try:
            mi.set_variant(v)
            if v.startswith("llvm"):
                # set_variant succeeds without LLVM; the first kernel launch does not.
                x = dr.arange(mi.Float, 4) * 2
                dr.eval(x)
                if list(x) != [0.0, 2.0, 4.0, 6.0]:
                    raise RuntimeError("LLVM backend computed a wrong result")
            return mi, dr
        except Exception as e:  # noqa: BLE001 - report and try the next variant
            errors.append(f"{v}: {e}")
    sys.exit(
        "no usable Mitsuba variant among "
        + ", ".join(candidates)
        + ":\n  "
        + "\n  ".join(errors)
        + "\n(llvm_ad_rgb needs Debian's libllvm19: apt-get install -y libllvm19)"
    )


def versions() -> dict:
    mi, dr = mitsuba()
    llvm = None
    if mi.variant().startswith("llvm"):
        try:
            llvm = ".".join(str(v) for v in dr.detail.llvm_version())
        except Exception:  # noqa: BLE001 - informational only
            llvm = "unknown"
    return {"mitsuba": mi.__version__, "drjit": dr.__version__, "variant": mi.variant(), "libllvm": llvm}
