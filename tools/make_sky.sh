#!/bin/sh
# Writes data/sky.exr, the procedural HDR sky of the example scene (see
# crates/render/examples/make_sky.rs for what is in it). Deterministic.
set -eu
cd "$(dirname "$0")/.."
cargo run --release -q -p cirrus-render --example make_sky -- data/sky.exr
