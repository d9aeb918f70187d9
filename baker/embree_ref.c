#include "embree_ref.h"

#include <pthread.h>
#include <string.h>
#include <unistd.h>

#include "bench.h"
#include "log.h"

/* A scene of the mesh, built at `quality`; its build's wall time in *ms. */
static bool create(const struct sb_mesh *mesh, enum RTCBuildQuality quality, struct sb_embree *e, double *ms)
{
    e->device = rtcNewDevice(NULL);
    if (!e->device)
        return false;
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

void sb_embree_destroy(struct sb_embree *e)
{
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
        uint32_t tri = rh.hit.geomID == RTC_INVALID_GEOMETRY_ID ? SB_BVH_MISS : rh.hit.primID;
        h[0] = rh.ray.tfar;
        memcpy(&h[1], &tri, sizeof(tri));
        h[2] = rh.hit.u;
        h[3] = rh.hit.v;
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
