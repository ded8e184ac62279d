#!/usr/bin/env bash
# Build the release library, check that test_api.c and test_render_surface.c together call every
# function of the header, that the header compiles cleanly as C99, C11, C++11 and C++17
# (header_check.c), compile every C program in examples_c/ and the C++17 example hello_cpp.cpp
# against the shared library (and test_api.c also against the static one), run them, then run
# them again under valgrind (no errors, no definite/indirect leaks); the hostile client hostile.c
# also runs built with -fsanitize=address,undefined. Prints "N passed, M failed"
# last; exits non-zero on any failure.
#
#   examples_c/run_tests.sh            from anywhere in the repository
#
# Environment: CARGO_TARGET_DIR (default: target), CC (default: cc), CXX (default: c++),
# SOFA_LIVER (default:
# $TISSUESIM_MESHES/liver.msh when TISSUESIM_MESHES is set, else data/meshes/liver.msh in the
# repository; a missing file is a failure, not a skip), TISSUESIM_MESHES (the folder of liver.msh
# and liver-smooth.obj for render_surface; default data/meshes), SKIP_VALGRIND=1 to skip the
# valgrind runs.
set -u

ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
cd "$ROOT"
TARGET_DIR="${CARGO_TARGET_DIR:-target}"
case "$TARGET_DIR" in /*) ;; *) TARGET_DIR="$ROOT/$TARGET_DIR" ;; esac
LIB_DIR="$TARGET_DIR/release"
OUT="$TARGET_DIR/examples_c"
CC="${CC:-cc}"
CXX="${CXX:-c++}"
CFLAGS=(-Wall -Wextra -Wpedantic -Werror -std=c11 -O2 -g -I"$ROOT/include")
CXXFLAGS=(-Wall -Wextra -Wpedantic -Werror -std=c++17 -O2 -g -I"$ROOT/include")
LIVER="${SOFA_LIVER:-${TISSUESIM_MESHES:-$ROOT/data/meshes}/liver.msh}"
MESHES="${TISSUESIM_MESHES:-$ROOT/data/meshes}"
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

echo "== checking that test_api.c and test_render_surface.c call every function of the header"
missing=""
for fn in $(grep -oE '\bts_[a-z0-9_]+\(' include/tissuesim.h | tr -d '(' | sort -u); do
    cat examples_c/test_api.c examples_c/test_render_surface.c | grep -q "\b$fn(" ||
        missing="$missing $fn"
done
if [ -z "$missing" ]; then
    pass "test_api.c + test_render_surface.c cover the header"
else
    fail "test_api.c + test_render_surface.c miss:$missing"
fi

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

# Binaries of an earlier run must not stand in for ones that fail to compile now.
rm -f "$OUT"/header_check_* "$OUT"/hello "$OUT"/hello_cpp "$OUT"/haptic_loop "$OUT"/sofa_liver \
    "$OUT"/test_api "$OUT"/test_api_static "$OUT"/hostile "$OUT"/hostile_asan \
    "$OUT"/render_surface "$OUT"/test_render_surface "$OUT"/surgery

echo "== compiling the header as C and C++ (header_check.c)"
for std in c99 c11; do
    if "$CC" -std=$std -pedantic -Wall -Wextra -Werror -I"$ROOT/include" examples_c/header_check.c \
        -L"$LIB_DIR" -ltissuesim -o "$OUT/header_check_$std"; then
        pass "header compiles as $std (-pedantic -Wall -Wextra -Werror)"
    else
        fail "header compiles as $std (-pedantic -Wall -Wextra -Werror)"
    fi
done
for std in c++11 c++17; do
    if "$CXX" -std=$std -pedantic -Wall -Wextra -Werror -I"$ROOT/include" -x c++ \
        examples_c/header_check.c -x none -L"$LIB_DIR" -ltissuesim -o "$OUT/header_check_$std"; then
        pass "header compiles as $std (-pedantic -Wall -Wextra -Werror)"
    else
        fail "header compiles as $std (-pedantic -Wall -Wextra -Werror)"
    fi
done

echo "== compiling"
PROGRAMS=(hello haptic_loop sofa_liver test_api render_surface test_render_surface surgery)
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
if "$CC" "${CFLAGS[@]}" examples_c/hostile.c -L"$LIB_DIR" -ltissuesim -lpthread -lm \
    -o "$OUT/hostile"; then
    pass "compile hostile.c (shared)"
else
    fail "compile hostile.c (shared)"
fi
# The hostile client again with AddressSanitizer and UndefinedBehaviorSanitizer on the C side
# (the Rust library is checked by its own tests; ASan also sees its heap through malloc).
if "$CC" "${CFLAGS[@]}" -fsanitize=address,undefined -fno-omit-frame-pointer \
    examples_c/hostile.c -L"$LIB_DIR" -ltissuesim -lpthread -lm -o "$OUT/hostile_asan"; then
    pass "compile hostile.c (-fsanitize=address,undefined)"
else
    fail "compile hostile.c (-fsanitize=address,undefined)"
fi
if "$CXX" "${CXXFLAGS[@]}" examples_c/hello_cpp.cpp -L"$LIB_DIR" -ltissuesim -o "$OUT/hello_cpp"; then
    pass "compile hello_cpp.cpp (C++17, shared)"
else
    fail "compile hello_cpp.cpp (C++17, shared)"
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
for std in c99 c11 c++11 c++17; do
    [ -x "$OUT/header_check_$std" ] && run "header_check_$std" -- "$OUT/header_check_$std"
done
[ -x "$OUT/hello" ] && run hello -- "$OUT/hello"
[ -x "$OUT/hello_cpp" ] && run hello_cpp -- "$OUT/hello_cpp"
[ -x "$OUT/haptic_loop" ] && run haptic_loop -- "$OUT/haptic_loop" "$OUT/haptic_force.csv"
if [ -f "$LIVER" ]; then
    [ -x "$OUT/sofa_liver" ] && run sofa_liver -- "$OUT/sofa_liver" "$LIVER" "$OUT/sofa_liver.csv"
else
    fail "sofa_liver: mesh not found at $LIVER (from SOFA_LIVER, else TISSUESIM_MESHES, else data/meshes)"
fi
[ -x "$OUT/test_api" ] && run test_api -- "$OUT/test_api"
[ -x "$OUT/test_api_static" ] && run test_api_static -- "$OUT/test_api_static"
[ -x "$OUT/hostile" ] && run hostile -- "$OUT/hostile"
[ -x "$OUT/hostile_asan" ] && run hostile_asan ASAN_OPTIONS=detect_leaks=1:abort_on_error=1 \
    UBSAN_OPTIONS=halt_on_error=1:print_stacktrace=1 -- "$OUT/hostile_asan"
mkdir -p "$OUT/render_frames" "$OUT/render_scratch"
rm -f "$OUT"/render_frames/*.obj
[ -x "$OUT/render_surface" ] && run render_surface -- "$OUT/render_surface" "$MESHES" "$OUT/render_frames"
if [ -x "$OUT/render_surface" ]; then
    frames=$(ls "$OUT"/render_frames/liver_surface_*.obj 2>/dev/null | wc -l)
    if [ "$frames" -eq 5 ]; then pass "render_surface wrote 5 OBJ frames"; else fail "render_surface wrote $frames OBJ frames, 5 expected"; fi
fi
[ -x "$OUT/test_render_surface" ] && run test_render_surface -- "$OUT/test_render_surface" "$OUT/render_scratch"
[ -x "$OUT/surgery" ] && run surgery -- "$OUT/surgery"

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
[ -x "$OUT/hello_cpp" ] && run valgrind-hello_cpp TS_STEPS=5 -- "${VG[@]}" "$OUT/hello_cpp"
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
[ -x "$OUT/hostile" ] && run valgrind-hostile -- "${VG[@]}" "$OUT/hostile"
[ -x "$OUT/render_surface" ] && run valgrind-render_surface TS_STEPS=4 -- \
    "${VG[@]}" "$OUT/render_surface" "$MESHES" "$OUT/render_frames"
[ -x "$OUT/test_render_surface" ] && run valgrind-test_render_surface -- \
    "${VG[@]}" "$OUT/test_render_surface" "$OUT/render_scratch"
[ -x "$OUT/surgery" ] && run valgrind-surgery TS_STEPS=3 -- "${VG[@]}" "$OUT/surgery"

finish
