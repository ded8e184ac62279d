#!/bin/sh
# Install the tissuesim C API into PREFIX (default /usr/local):
#   PREFIX/include/tissuesim.h
#   PREFIX/lib/libtissuesim.so, PREFIX/lib/libtissuesim.a
#   PREFIX/lib/pkgconfig/tissuesim.pc
#   PREFIX/lib/cmake/tissuesim/tissuesimConfig.cmake, tissuesimConfigVersion.cmake
#
#   cmake/install.sh [PREFIX]        builds the release library first (cargo build --release)
#
# Respects CARGO_TARGET_DIR (default: target). Set NO_BUILD=1 to install an existing build.
set -eu
ROOT="$(cd "$(dirname "$0")/.." && pwd)"
PREFIX="${1:-/usr/local}"
cd "$ROOT"
TARGET_DIR="${CARGO_TARGET_DIR:-target}"
case "$TARGET_DIR" in /*) ;; *) TARGET_DIR="$ROOT/$TARGET_DIR" ;; esac
VERSION="$(sed -n 's/^version *= *"\([^"]*\)".*/\1/p' Cargo.toml | head -n 1)"
[ "${NO_BUILD:-0}" = 1 ] || cargo build --release -p tissuesim

install -d "$PREFIX/include" "$PREFIX/lib/pkgconfig" "$PREFIX/lib/cmake/tissuesim"
install -m 644 include/tissuesim.h "$PREFIX/include/"
install -m 755 "$TARGET_DIR/release/libtissuesim.so" "$PREFIX/lib/"
install -m 644 "$TARGET_DIR/release/libtissuesim.a" "$PREFIX/lib/"
sed -e "s|@PREFIX@|$PREFIX|g" -e "s|@VERSION@|$VERSION|g" tissuesim.pc.in \
    >"$PREFIX/lib/pkgconfig/tissuesim.pc"
install -m 644 cmake/tissuesimConfig.cmake "$PREFIX/lib/cmake/tissuesim/"
sed -e "s|@VERSION@|$VERSION|g" cmake/tissuesimConfigVersion.cmake.in \
    >"$PREFIX/lib/cmake/tissuesim/tissuesimConfigVersion.cmake"
echo "installed tissuesim $VERSION into $PREFIX"
