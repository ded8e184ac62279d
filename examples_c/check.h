/*
 * check.h -- the counting checks shared by the C test programs (test_api.c,
 * test_render_surface.c, hostile.c). Header-only: each program includes it once.
 *
 * CHECK(cond) counts a pass or prints the failing line with the thread's last tissuesim error;
 * CHECK_ST(call, status) and CHECK_OK(call) check a call's status; check_summary() prints
 * "N passed, M failed" and gives the exit code.
 */
#ifndef TISSUESIM_EXAMPLES_CHECK_H
#define TISSUESIM_EXAMPLES_CHECK_H

#include <stdio.h>
#include <string.h>

#include "tissuesim.h"

static int passed, failed;

#define CHECK(cond)                                                                                \
    do {                                                                                           \
        if (cond) {                                                                                \
            passed++;                                                                              \
        } else {                                                                                   \
            failed++;                                                                              \
            char m_[512];                                                                          \
            ts_last_error_message(m_, sizeof m_);                                                  \
            fprintf(stderr, "%s:%d: CHECK failed: %s (last error: %s)\n", __FILE__, __LINE__,     \
                    #cond, m_);                                                                    \
        }                                                                                          \
    } while (0)

/* `call` returns `expected`. */
#define CHECK_ST(call, expected) CHECK((call) == (expected))
#define CHECK_OK(call) CHECK_ST(call, TS_STATUS_OK)

/* The thread's last error message contains `needle`. */
static inline int last_error_has(const char *needle) {
    char msg[1024];
    ts_last_error_message(msg, sizeof msg);
    return strstr(msg, needle) != NULL;
}

/* Print "N passed, M failed"; the process exit code (0 when nothing failed). */
static inline int check_summary(void) {
    printf("%d passed, %d failed\n", passed, failed);
    return failed == 0 ? 0 : 1;
}

#endif
