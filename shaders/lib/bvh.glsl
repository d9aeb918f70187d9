// Ray casts against skybake's BVH (geometry/bvh.h): the GPU twin of
// sb_bvh_intersect, the same traversal (nearer child first, one stack entry
// a level) and the same fp32 Möller-Trumbore test of both faces. A kernel
// that includes this declares the node and triangle buffers as
//   bvh_nodes[]: two vec4s a node (min, first; max, count),
//   bvh_triangles[]: three vec4s a triangle (v0, triangle; e1, material; e2, -),
// and then includes this file. With BVH_ANY_HIT_MATERIAL_0_PASSES defined,
// an any-hit trace goes through the triangles of material 0.
//
// Two builds of each kernel that traces (the baker picks by the BVH):
// without BVH_INSTANCES, one level, the traversal as it always was (its
// SPIR-V, its speed on lavapipe, its bake hashes); with it, one or two
// levels (instances): at an instance's leaf the ray goes into the mesh's
// space (an affine map keeps t), and a marker on the stack brings it back.
//
// A tiled probe bake's reach (docs/probes.md, "Tiles"): with instances, a
// kernel may set bvh_reach; an instance whose record is not flagged
// SB_BVH_INSTANCE_WIDE (a terrain, a ground) is then met only closer than
// that (t along the world direction). Unset, nothing changes.
float bvh_reach = 1e30;

struct BvhHit {
    float t;
    uint triangle; // SB_BVH_MISS when none; | SB_BVH_BACK_FACE on a back face
    vec2 uv;
#ifdef BVH_INSTANCES
    uint instance; // the instance's record (a node index), SB_BVH_NO_INSTANCE when none
#endif
#ifdef BVH_HIT_SLOT
    uint slot; // the triangle's place in bvh_triangles[] (kernels that define BVH_HIT_SLOT)
#endif
};

bool bvh_hit_box(uint node, vec3 o, vec3 inv_d, float tmin, float tmax, out float t_enter)
{
    vec3 a = (bvh_nodes[2 * node].xyz - o) * inv_d;
    vec3 b = (bvh_nodes[2 * node + 1].xyz - o) * inv_d;
    vec3 lo = min(a, b), hi = max(a, b);
    float t0 = max(tmin, max(lo.x, max(lo.y, lo.z)));
    float t1 = min(tmax, min(hi.x, min(hi.y, hi.z)));
    t_enter = t0;
    return t0 <= t1;
}

bool bvh_hit_triangle(uint i, vec3 o, vec3 d, float tmin, float tmax, bool any_hit, inout BvhHit hit)
{
    vec4 v0 = bvh_triangles[3 * i], e1 = bvh_triangles[3 * i + 1], e2 = bvh_triangles[3 * i + 2];
#ifdef BVH_ANY_HIT_MATERIAL_0_PASSES
    if (any_hit && floatBitsToUint(e1.w) == 0u)
        return false;
#endif
    vec3 p = cross(d, e2.xyz);
    float det = dot(e1.xyz, p);
    if (det == 0.0)
        return false;
    float inv = 1.0 / det;
    vec3 s = o - v0.xyz;
    float u = dot(s, p) * inv;
    if (u < 0.0 || u > 1.0)
        return false;
    vec3 q = cross(s, e1.xyz);
    float v = dot(d, q) * inv;
    if (v < 0.0 || u + v > 1.0)
        return false;
    float t = dot(e2.xyz, q) * inv;
    if (!(t > tmin && t < tmax))
        return false;
    hit.t = t;
    hit.uv = vec2(u, v);
#ifdef BVH_HIT_SLOT
    hit.slot = i;
#endif
    hit.triangle = floatBitsToUint(v0.w) | (det < 0.0 ? SB_BVH_BACK_FACE : 0u);
    return true;
}

#ifdef BVH_INSTANCES
vec3 bvh_inverse_direction(vec3 d)
{
    // a zero component: a huge but finite slope keeps the slabs NaN-free
    vec3 tiny = vec3(lessThan(d, vec3(0.0))) * -2e-30 + 1e-30;
    return 1.0 / mix(d, tiny, lessThanEqual(abs(d), vec3(1e-30)));
}

// The geometric normal of a triangle in world space (unnormalised; its
// sense the triangle's winding): object space through the instance's
// world-to-object rows, transposed.
vec3 bvh_world_normal(vec3 n, uint instance)
{
    if (instance == SB_BVH_NO_INSTANCE)
        return n;
    return n.x * bvh_nodes[2 * instance].xyz + n.y * bvh_nodes[2 * instance + 1].xyz +
           n.z * bvh_nodes[2 * instance + 2].xyz;
}

// The closest hit in (tmin, tmax), or any when `any_hit`.
BvhHit bvh_trace(vec3 world_o, vec3 world_d, float tmin, float tmax, bool any_hit)
{
    BvhHit hit;
    hit.t = tmax;
    hit.triangle = SB_BVH_MISS;
    hit.uv = vec2(0.0);
    hit.instance = SB_BVH_NO_INSTANCE;
#ifdef BVH_HIT_SLOT
    hit.slot = 0u;
#endif
    vec3 o = world_o, d = world_d;
    vec3 inv_d = bvh_inverse_direction(d);
    uint instance = SB_BVH_NO_INSTANCE;
    float limit = 1e30; // the instance's: bvh_reach unless it is wide
    // the top level's path, the instance's end (SB_BVH_MISS), the mesh's path
    uint stack[2 * SB_BVH_MAX_DEPTH + 3];
    int top = 0;
    uint node = 0u;
    float ta, tb;
    if (!bvh_hit_box(0u, o, inv_d, tmin, tmax, ta))
        return hit;
    for (;;) {
        uint first = floatBitsToUint(bvh_nodes[2 * node].w);
        uint count = floatBitsToUint(bvh_nodes[2 * node + 1].w);
        if (count == SB_BVH_INSTANCE_LEAF) {
            vec4 r0 = bvh_nodes[2 * first], r1 = bvh_nodes[2 * first + 1], r2 = bvh_nodes[2 * first + 2];
            o = vec3(dot(r0.xyz, world_o), dot(r1.xyz, world_o), dot(r2.xyz, world_o)) + vec3(r0.w, r1.w, r2.w);
            d = vec3(dot(r0.xyz, world_d), dot(r1.xyz, world_d), dot(r2.xyz, world_d));
            inv_d = bvh_inverse_direction(d);
            instance = first;
            limit = (floatBitsToUint(bvh_nodes[2 * first + 3].z) & SB_BVH_INSTANCE_WIDE) != 0u ? 1e30 : bvh_reach;
            stack[top++] = SB_BVH_MISS;
            node = floatBitsToUint(bvh_nodes[2 * first + 3].x);
            continue;
        }
        if (count != 0u) {
            for (uint i = first; i < first + count; i++) {
                if (bvh_hit_triangle(i, o, d, tmin, min(hit.t, limit), any_hit, hit)) {
                    hit.instance = instance;
                    if (any_hit)
                        return hit;
                }
            }
        } else {
            bool a = bvh_hit_box(first, o, inv_d, tmin, min(hit.t, limit), ta);
            bool b = bvh_hit_box(first + 1u, o, inv_d, tmin, min(hit.t, limit), tb);
            if (a && b) {
                bool right_nearer = tb < ta;
                stack[top++] = right_nearer ? first : first + 1u;
                node = right_nearer ? first + 1u : first;
                continue;
            }
            if (a || b) {
                node = a ? first : first + 1u;
                continue;
            }
        }
        for (;;) {
            if (top == 0)
                return hit;
            node = stack[--top];
            if (node != SB_BVH_MISS)
                break;
            o = world_o;
            d = world_d;
            inv_d = bvh_inverse_direction(d);
            instance = SB_BVH_NO_INSTANCE;
            limit = 1e30;
        }
    }
    return hit;
}
#else // one level
// The closest hit in (tmin, tmax), or any when `any_hit`.
BvhHit bvh_trace(vec3 o, vec3 d, float tmin, float tmax, bool any_hit)
{
    BvhHit hit;
    hit.t = tmax;
    hit.triangle = SB_BVH_MISS;
    hit.uv = vec2(0.0);
#ifdef BVH_HIT_SLOT
    hit.slot = 0u;
#endif
    // a zero component: a huge but finite slope keeps the slabs NaN-free
    vec3 tiny = vec3(lessThan(d, vec3(0.0))) * -2e-30 + 1e-30;
    vec3 inv_d = 1.0 / mix(d, tiny, lessThanEqual(abs(d), vec3(1e-30)));
    uint stack[SB_BVH_MAX_DEPTH + 1];
    int top = 0;
    uint node = 0u;
    float ta, tb;
    if (!bvh_hit_box(0u, o, inv_d, tmin, tmax, ta))
        return hit;
    for (;;) {
        uint first = floatBitsToUint(bvh_nodes[2 * node].w);
        uint count = floatBitsToUint(bvh_nodes[2 * node + 1].w);
        if (count != 0u) {
            for (uint i = first; i < first + count; i++) {
                if (bvh_hit_triangle(i, o, d, tmin, hit.t, any_hit, hit) && any_hit)
                    return hit;
            }
        } else {
            bool a = bvh_hit_box(first, o, inv_d, tmin, hit.t, ta);
            bool b = bvh_hit_box(first + 1u, o, inv_d, tmin, hit.t, tb);
            if (a && b) {
                bool right_nearer = tb < ta;
                stack[top++] = right_nearer ? first : first + 1u;
                node = right_nearer ? first + 1u : first;
                continue;
            }
            if (a || b) {
                node = a ? first : first + 1u;
                continue;
            }
        }
        if (top == 0)
            break;
        node = stack[--top];
    }
    return hit;
}
#endif
