#!/usr/bin/env bash
# Build the release library, compile every C program in examples_c/ against the shared library
# (and test_api.c also against the static one), run them, then run them again under valgrind
# (no errors, no definite/indirect leaks). Prints "N passed, M failed" last; exits non-zero on
# any failure.
#
#   examples_c/run_tests.sh            from anywhere in the repository
#
# Environment: CARGO_TARGET_DIR (default: target), CC (default: cc), SOFA_LIVER (default:
# $TISSUESIM_MESHES/liver.msh when TISSUESIM_MESHES is set, else data/meshes/liver.msh in the
# repository; a missing file is a failure, not a skip), SKIP_VALGRIND=1 to skip the valgrind runs.
set -u

ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
cd "$ROOT"
TARGET_DIR="${CARGO_TARGET_DIR:-target}"
case "$TARGET_DIR" in /*) ;; *) TARGET_DIR="$ROOT/$TARGET_DIR" ;; esac
LIB_DIR="$TARGET_DIR/release"
OUT="$TARGET_DIR/examples_c"
CC="${CC:-cc}"
CFLAGS=(-Wall -Wextra -Wpedantic -Werror -std=c11 -O2 -g -I"$ROOT/include")
LIVER="${SOFA_LIVER:-${TISSUESIM_MESHES:-$ROOT/data/meshes}/liver.msh}"
mkdir -p "$OUT"

passed=0
failed=0
pass() { passed=$((passed + 1)); echo "PASS $*"; }
fail() { failed=$((failed + 1)); echo "FAIL $*"; }

finish() {
    echo "$passed passed, $failed failed"
    [ "$failed" -eq 0 ]
    exit $?
}

echo "== building the library ($LIB_DIR)"
if cargo build --release -p tissuesim; then
    pass "cargo build --release -p tissuesim"
else
    fail "cargo build --release -p tissuesim"
    finish
fi

echo "== checking that test_api.c calls every function of the header"
missing=""
for fn in $(grep -oE '\bts_[a-z0-9_]+\(' include/tissuesim.h | tr -d '(' | sort -u); do
    grep -q "\b$fn(" examples_c/test_api.c || missing="$missing $fn"
done
if [ -z "$missing" ]; then pass "test_api.c covers the header"; else fail "test_api.c misses:$missing"; fi

echo "== checking the shared library exports exactly the header's functions"
if command -v nm >/dev/null 2>&1; then
    exported="$(nm -D --defined-only "$LIB_DIR/libtissuesim.so" | awk '$2 == "T" {print $3}' | sort -u)"
    declared="$(grep -oE '\bts_[a-z0-9_]+\(' include/tissuesim.h | tr -d '(' | sort -u)"
    if [ "$exported" = "$declared" ]; then
        pass "exports = header ($(echo "$declared" | wc -l) functions)"
    else
        fail "exports differ from the header: $(diff <(echo "$declared") <(echo "$exported") | grep '^[<>]' | tr '\n' ' ')"
    fi
fi

echo "== compiling"
PROGRAMS=(hello haptic_loop sofa_liver test_api)
for p in "${PROGRAMS[@]}"; do
    if "$CC" "${CFLAGS[@]}" "examples_c/$p.c" -L"$LIB_DIR" -ltissuesim -lm -o "$OUT/$p"; then
        pass "compile $p.c (shared)"
    else
        fail "compile $p.c (shared)"
    fi
done
if "$CC" "${CFLAGS[@]}" examples_c/test_api.c "$LIB_DIR/libtissuesim.a" -lpthread -ldl -lm \
    -o "$OUT/test_api_static"; then
    pass "compile test_api.c (static)"
else
    fail "compile test_api.c (static)"
fi
if command -v c++ >/dev/null 2>&1; then
    if echo '#include "tissuesim.h"
int main() { ts_world *w = nullptr; ts_world_free(w); return ts_version() == TISSUESIM_VERSION ? 0 : 1; }' |
        c++ -std=c++11 -Wall -Wextra -Werror -I"$ROOT/include" -x c++ - -L"$LIB_DIR" -ltissuesim \
            -o "$OUT/cxx_header" && LD_LIBRARY_PATH="$LIB_DIR" "$OUT/cxx_header"; then
        pass "header compiles and links as C++"
    else
        fail "header compiles and links as C++"
    fi
fi

export LD_LIBRARY_PATH="$LIB_DIR${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}"
LOGS="$OUT/logs"
mkdir -p "$LOGS"

# run NAME [env...] -- command...: run, log, and count.
run() {
    local name="$1"
    shift
    local envs=()
    while [ "$1" != "--" ]; do envs+=("$1"); shift; done
    shift
    if env ${envs[@]+"${envs[@]}"} "$@" >"$LOGS/$name.log" 2>&1; then
        pass "$name"
        grep -v "^[0-9]" "$LOGS/$name.log" | tail -n 4 | sed 's/^/    /'
    else
        fail "$name (log: $LOGS/$name.log)"
        tail -n 20 "$LOGS/$name.log" | sed 's/^/    /'
    fi
}

echo "== running"
[ -x "$OUT/hello" ] && run hello -- "$OUT/hello"
[ -x "$OUT/haptic_loop" ] && run haptic_loop -- "$OUT/haptic_loop" "$OUT/haptic_force.csv"
if [ -f "$LIVER" ]; then
    [ -x "$OUT/sofa_liver" ] && run sofa_liver -- "$OUT/sofa_liver" "$LIVER" "$OUT/sofa_liver.csv"
else
    fail "sofa_liver: mesh not found at $LIVER (from SOFA_LIVER, else TISSUESIM_MESHES, else data/meshes)"
fi
[ -x "$OUT/test_api" ] && run test_api -- "$OUT/test_api"
[ -x "$OUT/test_api_static" ] && run test_api_static -- "$OUT/test_api_static"

if [ "${SKIP_VALGRIND:-0}" = 1 ]; then
    echo "SKIP valgrind (SKIP_VALGRIND=1)"
    finish
fi
if ! command -v valgrind >/dev/null 2>&1; then
    echo "== installing valgrind"
    if [ "$(id -u)" = 0 ]; then
        (apt-get update -qq && apt-get install -y -qq valgrind) >/dev/null 2>&1
    else
        (sudo apt-get update -qq && sudo apt-get install -y -qq valgrind) >/dev/null 2>&1
    fi
fi
if ! command -v valgrind >/dev/null 2>&1; then
    fail "valgrind is not available"
    finish
fi

echo "== running under valgrind (short runs)"
VG=(valgrind --error-exitcode=1 --leak-check=full --errors-for-leak-kinds=definite,indirect
    --track-origins=yes)
[ -x "$OUT/hello" ] && run valgrind-hello TS_STEPS=5 -- "${VG[@]}" "$OUT/hello"
[ -x "$OUT/haptic_loop" ] && run valgrind-haptic_loop TS_STEPS=10 TS_NO_SLEEP=1 -- \
    "${VG[@]}" "$OUT/haptic_loop" "$OUT/haptic_force_valgrind.csv"
if [ -f "$LIVER" ]; then
    [ -x "$OUT/sofa_liver" ] && run valgrind-sofa_liver TS_STEPS=5 -- \
        "${VG[@]}" "$OUT/sofa_liver" "$LIVER" "$OUT/sofa_liver_valgrind.csv"
else
    fail "valgrind-sofa_liver: mesh not found at $LIVER"
fi
[ -x "$OUT/test_api" ] && run valgrind-test_api TS_STEPS=3 -- "${VG[@]}" "$OUT/test_api"
[ -x "$OUT/test_api_static" ] && run valgrind-test_api_static TS_STEPS=3 -- \
    "${VG[@]}" "$OUT/test_api_static"

finish
