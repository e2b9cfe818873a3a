//! Links OpenEXR's C library, OpenEXRCore, found through pkg-config
//! (Debian: `apt-get install libopenexr-dev pkg-config`).

fn main() {
    // The `OpenEXR` pkg-config module lists the C++ libraries as well;
    // only OpenEXRCore (the C API) is used here, so link it alone from the
    // module's library directories.
    let lib = match pkg_config::Config::new()
        .atleast_version("3.1")
        .cargo_metadata(false)
        .probe("OpenEXR")
    {
        Ok(lib) => lib,
        Err(e) => panic!(
            "OpenEXR 3.1+ (its C library OpenEXRCore) was not found by pkg-config: {e}\n\
             install it with `apt-get install libopenexr-dev pkg-config`"
        ),
    };
    for dir in &lib.link_paths {
        println!("cargo:rustc-link-search=native={}", dir.display());
    }
    let core = lib
        .libs
        .iter()
        .find(|l| l.starts_with("OpenEXRCore"))
        .cloned()
        .unwrap_or_else(|| "OpenEXRCore".into());
    println!("cargo:rustc-link-lib={core}");
    println!("cargo:rerun-if-changed=build.rs");
}
