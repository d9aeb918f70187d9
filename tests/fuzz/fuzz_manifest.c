/*
 * libFuzzer entry point: the pack reader, manifest first. A pack of every
 * product with synthetic content is written once; each input replaces its
 * manifest.json and the pack is opened. Any manifest is refused with a
 * code of the closed set, or opens with every artifact present and
 * verified; never a crash, never a read outside the pack (its file names
 * are checked before any file is opened).
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "fuzz.h"
#include "log.h"
#include "pack.h"
#include "scene.h"
#include "synthetic_pack.h"

static char pack_dir[64];

int LLVMFuzzerTestOneInput(const unsigned char *data, size_t size)
{
    if (!pack_dir[0]) {
        sb_log_set_sink(fuzz_quiet, NULL);
        snprintf(pack_dir, sizeof(pack_dir), "/tmp/skybake-fuzz-pack-%ld", (long)getpid());
        enum sb_result res = write_synthetic_pack(pack_dir, "fuzz", NULL); /* what corpus/manifest/ describes */
        if (res != SB_OK) {
            fprintf(stderr,
                    "fuzz_manifest: cannot write the pack it reads in %s: %s (its volumes need skybake-vdb: "
                    "meson compile -C build-fuzz fuzzers)\n",
                    pack_dir, sb_result_description(res));
            abort();
        }
        const char *seed = getenv("SKYBAKE_FUZZ_WRITE_SEED"); /* regenerate the seed manifest */
        if (seed) {
            char cmd[256];
            snprintf(cmd, sizeof(cmd), "cp '%s/manifest.json' '%s'", pack_dir, seed);
            if (system(cmd) != 0)
                abort();
        }
    }
    char path[128];
    snprintf(path, sizeof(path), "%s/manifest.json", pack_dir);
    fuzz_write(path, data, size);
    struct sb_pack pack;
    enum sb_result res = sb_pack_open(pack_dir, &pack);
    if ((unsigned)res >= SB_RESULT_COUNT)
        abort();
    for (int p = 0; p < SB_PRODUCT_COUNT; p++)
        if (res == SB_OK && pack.present[p] && !pack.images[p].data)
            abort();
    sb_pack_close(&pack);
    return 0;
}
