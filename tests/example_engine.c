/*
 * How an engine loads a pack: built against the installed (or uninstalled)
 * libskybake-formats through pkg-config alone, as tests/test_library.sh
 * does. Opens the pack (everything verified), prints what it holds and one
 * value of each product, and returns 0; for a pack that does not verify,
 * prints the reason's code and description and returns 1.
 */
#include <stdio.h>

#include <skybake.h>

int main(int argc, char **argv)
{
    if (argc != 2) {
        fprintf(stderr, "usage: example_engine PACK\n");
        return 2;
    }
    struct sb_pack pack;
    enum sb_result res = sb_pack_open(argv[1], &pack);
    if (res) {
        printf("refused: %s (%s)\n", sb_result_name(res), sb_result_description(res));
        return 1;
    }
    printf("pack format %d, scene %s, ground radius %g km\n", pack.format_version, pack.scene_hash,
           pack.scene->atmosphere.ground_radius_km);
    for (int p = 0; p < SB_PRODUCT_COUNT; p++) {
        if (!pack.present[p])
            continue;
        const struct sb_image *image = &pack.images[p];
        printf("%s %ux%ux%u x%u first value %g hash %s\n", sb_product_name((enum sb_product_id)p), image->width,
               image->height, image->depth, image->channel_count, image->data[0], pack.artifacts[p].content_hash);
    }
    sb_pack_close(&pack);
    return 0;
}
