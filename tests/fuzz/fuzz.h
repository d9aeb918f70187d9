/* What the fuzz entry points share: silence and a scratch file. */
#ifndef SB_FUZZ_H
#define SB_FUZZ_H

#include <stdio.h>
#include <stdlib.h>

#include "log.h"

static inline void fuzz_quiet(void *user, enum sb_log_level level, const char *message)
{
    (void)user;
    (void)level;
    (void)message;
}

/* Write the input to `path`; the harness aborts when it cannot. */
static inline void fuzz_write(const char *path, const unsigned char *data, size_t size)
{
    FILE *f = fopen(path, "wb");
    if (!f || fwrite(data, 1, size, f) != size || fclose(f) != 0)
        abort();
}

int LLVMFuzzerTestOneInput(const unsigned char *data, size_t size);

#endif
