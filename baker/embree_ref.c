#include "embree_ref.h"

#include <pthread.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "bench.h"
#include "log.h"

/* A scene of the mesh on e->device, built at `quality`; its build's wall
 * time in *ms. */
static bool create_scene(const struct sb_mesh *mesh, enum RTCBuildQuality quality, struct sb_embree *e, double *ms)
{
    e->scene = rtcNewScene(e->device);
    rtcSetSceneFlags(e->scene, RTC_SCENE_FLAG_ROBUST);
    rtcSetSceneBuildQuality(e->scene, quality);
    RTCGeometry g = rtcNewGeometry(e->device, RTC_GEOMETRY_TYPE_TRIANGLE);
    rtcSetGeometryBuildQuality(g, quality);
    float *v =
        rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, 3 * sizeof(float), mesh->vertex_count);
    unsigned *idx = rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, 3 * sizeof(unsigned),
                                            mesh->triangle_count);
    memcpy(v, mesh->positions, (size_t)mesh->vertex_count * 3 * sizeof(float));
    memcpy(idx, mesh->indices, (size_t)mesh->triangle_count * 3 * sizeof(unsigned));
    rtcCommitGeometry(g);
    rtcAttachGeometry(e->scene, g);
    rtcReleaseGeometry(g);
    double t0 = sb_now_s();
    rtcCommitScene(e->scene);
    *ms = (sb_now_s() - t0) * 1e3;
    return true;
}

/* A device and a scene of the mesh. */
static bool create(const struct sb_mesh *mesh, enum RTCBuildQuality quality, struct sb_embree *e, double *ms)
{
    memset(e, 0, sizeof(*e));
    e->device = rtcNewDevice(NULL);
    return e->device && create_scene(mesh, quality, e, ms);
}

bool sb_embree_create(const struct sb_mesh *mesh, struct sb_embree *e)
{
    double ms;
    return create(mesh, RTC_BUILD_QUALITY_MEDIUM, e, &ms);
}

double sb_embree_build_ms(const struct sb_mesh *mesh, enum RTCBuildQuality quality)
{
    struct sb_embree e = {0};
    double ms = -1;
    if (create(mesh, quality, &e, &ms))
        sb_embree_destroy(&e);
    return ms;
}

bool sb_embree_create_instanced(const struct sb_mesh *const *meshes, uint32_t mesh_count,
                                const struct sb_bvh_instance *instances, uint32_t instance_count, struct sb_embree *e)
{
    memset(e, 0, sizeof(*e));
    e->device = rtcNewDevice(NULL);
    e->triangle_base = malloc(instance_count * sizeof(*e->triangle_base));
    uint32_t *mesh_base = malloc((mesh_count + 1) * sizeof(*mesh_base));
    RTCScene *scenes = calloc(mesh_count, sizeof(*scenes));
    bool ok = e->device && e->triangle_base && mesh_base && scenes;
    for (uint32_t m = 0; ok && m < mesh_count; m++) {
        mesh_base[m + 1] = (m ? mesh_base[m] : 0) + meshes[m]->triangle_count;
        double ms;
        struct sb_embree one = {.device = e->device};
        ok = create_scene(meshes[m], RTC_BUILD_QUALITY_MEDIUM, &one, &ms);
        scenes[m] = one.scene;
    }
    if (ok) {
        mesh_base[0] = 0;
        e->scene = rtcNewScene(e->device);
        rtcSetSceneFlags(e->scene, RTC_SCENE_FLAG_ROBUST);
        for (uint32_t i = 0; i < instance_count; i++) {
            RTCGeometry g = rtcNewGeometry(e->device, RTC_GEOMETRY_TYPE_INSTANCE);
            rtcSetGeometryInstancedScene(g, scenes[instances[i].mesh]);
            float m[12];
            for (int r = 0; r < 3; r++)
                for (int c = 0; c < 4; c++)
                    m[4 * r + c] = (float)instances[i].to_world[r][c];
            rtcSetGeometryTransform(g, 0, RTC_FORMAT_FLOAT3X4_ROW_MAJOR, m);
            rtcCommitGeometry(g);
            rtcAttachGeometryByID(e->scene, g, i);
            rtcReleaseGeometry(g);
            e->triangle_base[i] = mesh_base[instances[i].mesh];
        }
        rtcCommitScene(e->scene);
    }
    for (uint32_t m = 0; scenes && m < mesh_count; m++)
        if (scenes[m])
            rtcReleaseScene(scenes[m]); /* the instances hold them */
    free(scenes);
    free(mesh_base);
    if (!ok && e->device)
        sb_embree_destroy(e);
    return ok;
}

void sb_embree_destroy(struct sb_embree *e)
{
    free(e->triangle_base);
    rtcReleaseScene(e->scene);
    rtcReleaseDevice(e->device);
}

struct sb_embree_job {
    const struct sb_embree *e;
    const float *rays;
    float *hits;
    uint32_t first, count;
};

static void *sb_embree_worker(void *arg)
{
    struct sb_embree_job *job = arg;
    struct RTCIntersectContext ctx;
    rtcInitIntersectContext(&ctx);
    for (uint32_t i = job->first; i < job->first + job->count; i++) {
        const float *r = &job->rays[8 * (size_t)i];
        struct RTCRayHit rh = {0};
        rh.ray.org_x = r[0];
        rh.ray.org_y = r[1];
        rh.ray.org_z = r[2];
        rh.ray.tnear = r[3];
        rh.ray.dir_x = r[4];
        rh.ray.dir_y = r[5];
        rh.ray.dir_z = r[6];
        rh.ray.tfar = r[7];
        rh.ray.mask = ~0u;
        rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
        rtcIntersect1(job->e->scene, &ctx, &rh);
        float *h = &job->hits[4 * (size_t)i];
        bool missed = rh.hit.geomID == RTC_INVALID_GEOMETRY_ID;
        uint32_t instance = rh.hit.instID[0];
        uint32_t tri = missed                                   ? SB_BVH_MISS
                       : instance == RTC_INVALID_GEOMETRY_ID ? rh.hit.primID
                                                               : job->e->triangle_base[instance] + rh.hit.primID;
        if (missed || instance == RTC_INVALID_GEOMETRY_ID)
            instance = SB_BVH_NO_INSTANCE;
        h[0] = rh.ray.tfar;
        memcpy(&h[1], &tri, sizeof(tri));
        memcpy(&h[2], &instance, sizeof(instance));
        h[3] = 0.0f;
    }
    return NULL;
}

/* Cast on every core; returns the wall time in seconds. */
double sb_embree_cast(const struct sb_embree *e, const float *rays, uint32_t count, float *hits)
{
    long cores = sysconf(_SC_NPROCESSORS_ONLN);
    int n = cores < 1 ? 1 : cores > 64 ? 64 : (int)cores;
    pthread_t threads[64];
    struct sb_embree_job jobs[64];
    double t0 = sb_now_s();
    for (int i = 0; i < n; i++) {
        uint32_t first = (uint32_t)((uint64_t)count * i / n), end = (uint32_t)((uint64_t)count * (i + 1) / n);
        jobs[i] = (struct sb_embree_job){e, rays, hits, first, end - first};
        pthread_create(&threads[i], NULL, sb_embree_worker, &jobs[i]);
    }
    for (int i = 0; i < n; i++)
        pthread_join(threads[i], NULL);
    return sb_now_s() - t0;
}
