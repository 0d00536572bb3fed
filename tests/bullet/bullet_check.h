// SPDX-License-Identifier: MIT
// The check harness of the Bullet test programs (one per source file, no framework): CHECK(cond,
// printf-style message) counts a pass or prints "FAIL file:line: cond: message" and counts a
// failure; checkSummary() prints "N passed, N failed" and returns the exit code. Seeded numbers:
// uniform01() maps std::mt19937 (whose sequence the standard fixes) to [0, 1) by itself, so a seed
// gives the same numbers with every standard library.
#ifndef SDFCCD_TESTS_BULLET_CHECK_H
#define SDFCCD_TESTS_BULLET_CHECK_H

#include <cstdio>
#include <cstdlib>
#include <random>

static int g_pass = 0, g_fail = 0;
#define CHECK(cond, ...)                                                         \
    do {                                                                         \
        if (cond) {                                                              \
            ++g_pass;                                                            \
        } else {                                                                 \
            ++g_fail;                                                            \
            std::fprintf(stderr, "FAIL %s:%d: %s: ", __FILE__, __LINE__, #cond); \
            std::fprintf(stderr, __VA_ARGS__);                                   \
            std::fputc('\n', stderr);                                            \
        }                                                                        \
    } while (0)

// SDFCCD_TEST_VERBOSE set: the programs print every case's figures.
static const bool kVerbose = std::getenv("SDFCCD_TEST_VERBOSE") != nullptr;

// A number in [0, 1) from the generator.
static inline double uniform01(std::mt19937& g) { return (double)g() / 4294967296.0; }

// Prints the counts; the program's exit code (0: every check passed).
static inline int checkSummary()
{
    std::printf("%d passed, %d failed\n", g_pass, g_fail);
    return g_fail == 0 ? 0 : 1;
}

#endif
