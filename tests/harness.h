/*
 * A tiny test harness: CHECK records a failure with file:line and goes on;
 * main returns 0, 1 (failures) or 77 (skip, e.g. no Vulkan device).
 */
#ifndef SB_TEST_HARNESS_H
#define SB_TEST_HARNESS_H

#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>

static int test_failures;
static int test_checks;

#define CHECK(cond, ...)                                                                                               \
    do {                                                                                                               \
        test_checks++;                                                                                                 \
        if (!(cond)) {                                                                                                 \
            test_failures++;                                                                                           \
            fprintf(stderr, "%s:%d: FAILED: %s: ", __FILE__, __LINE__, #cond);                                         \
            fprintf(stderr, __VA_ARGS__);                                                                              \
            fprintf(stderr, "\n");                                                                                     \
        }                                                                                                              \
    } while (0)

#define TEST_SKIP 77

static inline int test_finish(const char *name)
{
    printf("%s: %d checks, %d failed\n", name, test_checks, test_failures);
    return test_failures ? 1 : 0;
}

/* A new directory under $TMPDIR (/tmp without TMPDIR), named `name`, a dash
 * and six characters mkdtemp picks, in dir[size]; false when it could not
 * be made. */
static inline bool test_temp_dir(const char *name, char *dir, size_t size)
{
    const char *tmp = getenv("TMPDIR");
    int n = snprintf(dir, size, "%s/%s-XXXXXX", tmp && *tmp ? tmp : "/tmp", name);
    return n > 0 && (size_t)n < size && mkdtemp(dir) != NULL;
}

/* Remove a directory test_temp_dir made, with all it holds. */
static inline bool test_remove_dir(const char *dir)
{
    char cmd[4200];
    int n = snprintf(cmd, sizeof(cmd), "rm -rf '%s'", dir);
    return n > 0 && (size_t)n < sizeof(cmd) && system(cmd) == 0;
}

#endif
