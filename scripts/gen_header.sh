#!/bin/sh
# Regenerate include/tissuesim.h from src/ffi with the pinned cbindgen (0.29.4) and cbindgen.toml.
# tests/header_drift.rs fails until the regenerated header is committed.
set -eu
cd "$(dirname "$0")/.."
cargo test -p tissuesim --test header_drift -- --ignored regenerate --exact
git --no-pager diff --stat -- include/tissuesim.h || true
