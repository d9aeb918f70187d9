/*
 * Product families: what the formats tier knows of each family of products
 * (the atmosphere, the cloud noise, ...). A family is its rows in
 * products.def and its scene section (parsed, validated and normalised by
 * the family's own file, scene_clouds.c for the clouds, which also holds
 * the family's entry here). The baker's half of a family (its keys, bakes, references)
 * is baker/family.h. Internal to skybake; not installed.
 */
#ifndef SB_FAMILY_H
#define SB_FAMILY_H

#include <stdbool.h>
#include <stdint.h>

#include "product.h"
#include "result.h"

struct cJSON;
struct sb_scene;

struct sb_family_format {
    const char *name; /* "atmosphere", "clouds" */
    /* The scene's optional top-level key for the family's parameters, or
     * NULL. (The atmosphere's section is the scene's core: required, parsed
     * by scene.c.) */
    const char *section;
    /* Set the family's scene parameters to their defaults, before the
     * scene is parsed; NULL when it has none. */
    void (*set_defaults)(struct sb_scene *scene);
    /* Parse and validate the section into *scene, logging "source: path:
     * reason" for the first problem. */
    enum sb_result (*parse_section)(const struct cJSON *section, struct sb_scene *scene, const char *source);
    /* The normalised section (every parameter resolved, keys in a fixed
     * order), or NULL when the scene leaves it out. Written after the
     * scene's "view", in table order, so that families added later leave
     * older scenes' hashes alone. */
    struct cJSON *(*section_json)(const struct sb_scene *scene);
    /* The shape of a product whose format leaves it to the scene: fill the
     * zeros of shape[3] (width, height, depth, as the format has them);
     * NULL when no product of the family does. */
    void (*product_shape)(const struct sb_scene *scene, enum sb_product_id id, uint32_t shape[3]);
    /* Check what the whole scene asks of the family, once every section is
     * read (a product that needs another section, ...), logging "source:
     * path: reason"; NULL when there is nothing to check. */
    enum sb_result (*validate)(const struct sb_scene *scene, const char *source);
    bool default_products; /* baked when a scene names no products */
    /* Why a scene may not give the family's products a tolerance; NULL when
     * it may (the bake then picks the cheapest setting within it). */
    const char *no_tolerance;
};

/* The family's entry; `family` < SB_FAMILY_COUNT. */
const struct sb_family_format *sb_family_format(enum sb_family family);

/* The rows, each in its family's scene file (scene_<name>.c). */
#define SB_FAMILY(id, name) extern const struct sb_family_format sb_##name##_family_format;
#include "products.def"

/* The atmosphere's section, the scene's core, which scene.c reads and
 * writes first (scene_atmosphere.c). */
enum sb_result sb_atmosphere_section_parse(const struct cJSON *section, struct sb_scene *scene, const char *source);
struct cJSON *sb_atmosphere_section_json(const struct sb_scene *scene);

/* The world's section (scene_world.c): no family's, read by those that
 * bake against it. */
enum sb_result sb_world_section_parse(const struct cJSON *section, struct sb_scene *scene, const char *source);
struct cJSON *sb_world_section_json(const struct sb_scene *scene);

/* The fog's section (scene_fog.c), skyview's alone. */
enum sb_result sb_fog_section_parse(const struct cJSON *section, struct sb_scene *scene, const char *source);
struct cJSON *sb_fog_section_json(const struct sb_scene *scene);

/* The cloud layer's section (scene_cloud_layer.c), skyview's alone. */
enum sb_result sb_cloud_layer_section_parse(const struct cJSON *section, struct sb_scene *scene, const char *source);
struct cJSON *sb_cloud_layer_section_json(const struct sb_scene *scene);

/* The product's width, height and depth for `scene` (fixed by its format,
 * or, where the format says 0, set by its family's scene parameters: the
 * cloud products' sizes). */
struct sb_scene;
void sb_product_shape(const struct sb_scene *scene, enum sb_product_id id, uint32_t shape[3]);

#endif
