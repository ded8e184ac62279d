#!/usr/bin/env bash
# The install test: install the C API with cmake/install.sh into a fresh prefix, then build and
# run two tiny consumer projects against that prefix only:
#   - CMake: examples_c/consumers/cmake (find_package(tissuesim CONFIG REQUIRED), linked to
#     tissuesim::tissuesim and to tissuesim::tissuesim_static);
#   - pkg-config: cc examples_c/consumers/consumer.c $(pkg-config --cflags --libs tissuesim).
# Prints PASS/FAIL lines and "N passed, M failed" last; exits non-zero on any failure.
#
#   examples_c/test_install.sh           from anywhere in the repository
#
# Builds the release library first (cargo build --release -p tissuesim; a no-op after
# run_tests.sh), then installs it with NO_BUILD=1. Installs cmake and pkg-config with apt-get
# when they are missing. Environment: CARGO_TARGET_DIR (default: target), CC (default: cc).
# Leaves the prefix and the builds in $CARGO_TARGET_DIR/install-test for inspection.
set -u

ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
cd "$ROOT"
TARGET_DIR="${CARGO_TARGET_DIR:-target}"
case "$TARGET_DIR" in /*) ;; *) TARGET_DIR="$ROOT/$TARGET_DIR" ;; esac
CC="${CC:-cc}"
WORK="$TARGET_DIR/install-test"
PREFIX="$WORK/prefix"
VERSION="$(sed -n 's/^version *= *"\([^"]*\)".*/\1/p' Cargo.toml | head -n 1)"

passed=0
failed=0
pass() { passed=$((passed + 1)); echo "PASS $*"; }
fail() { failed=$((failed + 1)); echo "FAIL $*"; }
finish() {
    echo "$passed passed, $failed failed"
    [ "$failed" -eq 0 ]
    exit $?
}
# step NAME command...: run, log to $WORK/logs/NAME.log, count; on failure show the log's tail.
step() {
    local name="$1"
    shift
    local log
    log="$WORK/logs/$(printf '%s' "$name" | tr -c 'A-Za-z0-9_.-' '_').log"
    if "$@" >"$log" 2>&1; then
        pass "$name"
        [ "${SHOW:-0}" = 1 ] && sed 's/^/    /' "$log"
        return 0
    fi
    fail "$name (log: $log)"
    tail -n 20 "$log" | sed 's/^/    /'
    return 1
}
# check NAME command...: a quiet yes/no check, counted.
check() {
    local name="$1"
    shift
    if "$@" >/dev/null 2>&1; then pass "$name"; else fail "$name"; fi
}
# The consumers must find the library through the prefix alone, never through the build tree.
unset LD_LIBRARY_PATH PKG_CONFIG_LIBDIR CMAKE_PREFIX_PATH

missing=()
command -v cmake >/dev/null 2>&1 || missing+=(cmake)
command -v pkg-config >/dev/null 2>&1 || missing+=(pkg-config)
if [ ${#missing[@]} -gt 0 ]; then
    echo "== installing ${missing[*]} with apt-get"
    if [ "$(id -u)" = 0 ]; then
        apt-get update -qq && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq "${missing[@]}"
    else
        sudo apt-get update -qq && sudo DEBIAN_FRONTEND=noninteractive apt-get install -y -qq "${missing[@]}"
    fi >/dev/null 2>&1
fi
for tool in cmake pkg-config; do
    if ! command -v "$tool" >/dev/null 2>&1; then
        fail "$tool is not available (apt-get install $tool failed)"
        finish
    fi
done

rm -rf "$WORK"
mkdir -p "$WORK/logs"

echo "== building the library"
step "cargo build --release -p tissuesim" cargo build --release -p tissuesim || finish

echo "== installing into $PREFIX"
step "cmake/install.sh PREFIX (NO_BUILD=1)" env NO_BUILD=1 cmake/install.sh "$PREFIX" || finish
for f in include/tissuesim.h lib/libtissuesim.so lib/libtissuesim.a lib/pkgconfig/tissuesim.pc \
    lib/cmake/tissuesim/tissuesimConfig.cmake lib/cmake/tissuesim/tissuesimConfigVersion.cmake; do
    check "installed $f" test -f "$PREFIX/$f"
done
check "installed header = include/tissuesim.h" cmp include/tissuesim.h "$PREFIX/include/tissuesim.h"

# resolves PROGRAM: the program loads libtissuesim.so from the prefix (LD_LIBRARY_PATH is unset).
resolves() { ldd "$1" | grep -F "=> $PREFIX/lib/libtissuesim.so" >/dev/null; }
# no_shared PROGRAM: the program does not load libtissuesim.so at all.
no_shared() { ! ldd "$1" | grep -F libtissuesim >/dev/null; }

echo "== CMake consumer: find_package(tissuesim CONFIG REQUIRED), tissuesim::tissuesim"
CM="$WORK/cmake-build"
if step "cmake configure" cmake -S examples_c/consumers/cmake -B "$CM" \
    -DCMAKE_PREFIX_PATH="$PREFIX" -DCMAKE_C_COMPILER="$CC" -DCMAKE_BUILD_TYPE=Release &&
    step "cmake build" cmake --build "$CM"; then
    check "find_package found tissuesim $VERSION in the prefix" grep -F \
        "tissuesim $VERSION from $PREFIX/lib/cmake/tissuesim" "$WORK/logs/cmake_configure.log"
    check "cmake consumer loads $PREFIX/lib/libtissuesim.so (build RPATH)" resolves "$CM/consumer"
    SHOW=1 step "run cmake consumer (tissuesim::tissuesim)" "$CM/consumer"
    check "cmake consumer_static does not load libtissuesim.so" no_shared "$CM/consumer_static"
    SHOW=1 step "run cmake consumer_static (tissuesim::tissuesim_static)" "$CM/consumer_static"
fi

echo "== pkg-config consumer: cc consumer.c \$(pkg-config --cflags --libs tissuesim)"
export PKG_CONFIG_PATH="$PREFIX/lib/pkgconfig"
check "pkg-config --modversion tissuesim = $VERSION" \
    test "$(pkg-config --modversion tissuesim 2>/dev/null)" = "$VERSION"
PC="$WORK/pkgconfig-build"
mkdir -p "$PC"
# shellcheck disable=SC2046 # pkg-config prints a list of flags
if step "pkg-config build" "$CC" -std=c11 -Wall -Wextra -Wpedantic -Werror \
    examples_c/consumers/consumer.c $(pkg-config --cflags --libs tissuesim) \
    -Wl,-rpath,"$(pkg-config --variable=libdir tissuesim)" -o "$PC/consumer"; then
    check "pkg-config consumer loads $PREFIX/lib/libtissuesim.so (rpath from pkg-config libdir)" \
        resolves "$PC/consumer"
    SHOW=1 step "run pkg-config consumer" "$PC/consumer"
fi

finish
