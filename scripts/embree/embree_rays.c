/* Embree's single-ray and 16-ray packet throughput on the meshes and rays of caustica's `bvh` bench, for an
 * apples-to-apples comparison (see BENCHMARKS.md). Built and run by ./compare.sh.
 *
 * Embree's headers are not needed: the few entry points and the ray layout used are declared
 * here from its public API documentation. Usage: embree_rays RINGS SEGMENTS BUMPS
 * [RAYS_FILE|-] [DEVICE_CONFIG] (the bench's meshes: 96 192 0 = sphere-37k, 500 1000 1 = bumpy-1M;
 * without a rays file, the bench's incoherent rays are generated here). */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

typedef void *Handle;
Handle rtcNewDevice(const char *config);
Handle rtcNewScene(Handle device);
Handle rtcNewGeometry(Handle device, int type);
void *rtcSetNewGeometryBuffer(Handle geometry, int type, unsigned slot, int format, size_t stride, size_t count);
void rtcCommitGeometry(Handle geometry);
unsigned rtcAttachGeometry(Handle scene, Handle geometry);
void rtcReleaseGeometry(Handle geometry);
void rtcCommitScene(Handle scene);
void rtcIntersect1(Handle scene, void *rayhit, void *args);
void rtcOccluded1(Handle scene, void *ray, void *args);
void rtcIntersect16(const int *valid, Handle scene, void *rayhit, void *args);

enum { GEOMETRY_TRIANGLE = 0, BUFFER_INDEX = 0, BUFFER_VERTEX = 1, FORMAT_UINT3 = 0x5003, FORMAT_FLOAT3 = 0x9003 };
#define INVALID_ID 0xffffffffu

/* Ray and hit as Embree 4 lays them out; the tail leaves room for instance ids. */
typedef struct {
    float org[3], tnear, dir[3], time, tfar;
    unsigned mask, id, flags;
    float ng[3], u, v;
    unsigned prim_id, geom_id, inst_id[8];
} __attribute__((aligned(16))) RayHit;

/* Sixteen rays and hits as structure of arrays (Embree 4's packet layout), with room for
 * instance ids at the tail. */
typedef struct {
    float org[3][16], tnear[16], dir[3][16], time[16], tfar[16];
    unsigned mask[16], id[16], flags[16];
    float ng[3][16], u[16], v[16];
    unsigned prim_id[16], geom_id[16], inst_id[8][16];
} __attribute__((aligned(64))) RayHit16;

/* splitmix64, as the bench's generator. */
static uint64_t rng_state;
static float rng_f(void) {
    rng_state += 0x9e3779b97f4a7c15ULL;
    uint64_t z = rng_state;
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
    return (float)((z ^ (z >> 31)) >> 40) / (float)(1ULL << 24);
}

/* The bench's latitude-longitude sphere, radially displaced by `bumps`. */
static void sphere_point(int i, int j, int rings, int segments, float bumps, float *out) {
    float theta = (float)M_PI * (float)i / (float)rings;
    float phi = 2.0f * (float)M_PI * (float)(j % segments) / (float)segments;
    float r = 1.0f + bumps * (0.08f * sinf(9 * theta) * cosf(7 * phi) + 0.03f * sinf(31 * theta + 17 * phi) +
                              0.01f * cosf(97 * theta) * sinf(83 * phi));
    out[0] = sinf(theta) * cosf(phi) * r;
    out[1] = sinf(theta) * sinf(phi) * r;
    out[2] = cosf(theta) * r;
}

static double seconds(void) {
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)t.tv_sec + (double)t.tv_nsec * 1e-9;
}

int main(int argc, char **argv) {
    if (argc < 4) {
        fprintf(stderr, "usage: %s RINGS SEGMENTS BUMPS [RAYS_FILE|-] [DEVICE_CONFIG]\n", argv[0]);
        return 2;
    }
    const char *ray_file = argc > 4 && strcmp(argv[4], "-") != 0 ? argv[4] : NULL;
    int rings = atoi(argv[1]), segments = atoi(argv[2]);
    float bumps = (float)atof(argv[3]);
    int n_rays = 1 << 18;
    const int runs = 5;
    /* Rays written by the bench (BVH_BENCH_DUMP): origin xyz, direction xyz as f32. */
    float *loaded = NULL;
    if (ray_file) {
        FILE *f = fopen(ray_file, "rb");
        if (!f) {
            fprintf(stderr, "cannot open %s\n", ray_file);
            return 1;
        }
        fseek(f, 0, SEEK_END);
        n_rays = (int)(ftell(f) / 24);
        fseek(f, 0, SEEK_SET);
        loaded = malloc((size_t)n_rays * 24);
        if (fread(loaded, 24, (size_t)n_rays, f) != (size_t)n_rays) {
            fprintf(stderr, "short read from %s\n", ray_file);
            return 1;
        }
        fclose(f);
    }
    Handle device = rtcNewDevice(argc > 5 ? argv[5] : NULL);
    Handle scene = rtcNewScene(device);
    Handle geometry = rtcNewGeometry(device, GEOMETRY_TRIANGLE);
    size_t n_tris = 2 * (size_t)rings * (size_t)segments;
    float *vertices = rtcSetNewGeometryBuffer(geometry, BUFFER_VERTEX, 0, FORMAT_FLOAT3, 12, 3 * n_tris);
    unsigned *indices = rtcSetNewGeometryBuffer(geometry, BUFFER_INDEX, 0, FORMAT_UINT3, 12, n_tris);
    float lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    size_t tri = 0;
    for (int i = 0; i < rings; i++) {
        for (int j = 0; j < segments; j++) {
            float p[4][3];
            sphere_point(i, j, rings, segments, bumps, p[0]);
            sphere_point(i + 1, j, rings, segments, bumps, p[1]);
            sphere_point(i + 1, j + 1, rings, segments, bumps, p[2]);
            sphere_point(i, j + 1, rings, segments, bumps, p[3]);
            const int corners[2][3] = {{0, 1, 2}, {0, 2, 3}};
            for (int t = 0; t < 2; t++, tri++) {
                for (int c = 0; c < 3; c++) {
                    const float *v = p[corners[t][c]];
                    memcpy(vertices + 3 * (3 * tri + c), v, 12);
                    indices[3 * tri + c] = (unsigned)(3 * tri + c);
                    for (int a = 0; a < 3; a++) {
                        lo[a] = fminf(lo[a], v[a]);
                        hi[a] = fmaxf(hi[a], v[a]);
                    }
                }
            }
        }
    }
    rtcCommitGeometry(geometry);
    rtcAttachGeometry(scene, geometry);
    rtcReleaseGeometry(geometry);
    double start = seconds();
    rtcCommitScene(scene);
    printf("build %zu triangles: %.1f ms\n", n_tris, (seconds() - start) * 1e3);

    /* Origins uniform in the mesh bounds, directions uniform on the sphere (the bench's seed 7). */
    RayHit *rays = aligned_alloc(64, sizeof(RayHit) * n_rays);
    rng_state = 7;
    for (int i = 0; i < n_rays; i++) {
        memset(&rays[i], 0, sizeof rays[i]);
        if (loaded) {
            memcpy(rays[i].org, loaded + 6 * i, 12);
            memcpy(rays[i].dir, loaded + 6 * i + 3, 12);
            continue;
        }
        float o[3];
        for (int a = 0; a < 3; a++) o[a] = lo[a] + (hi[a] - lo[a]) * rng_f();
        float z = 2 * rng_f() - 1, phi = 2 * (float)M_PI * rng_f(), s = sqrtf(fmaxf(1 - z * z, 0));
        memcpy(rays[i].org, o, 12);
        rays[i].dir[0] = s * cosf(phi);
        rays[i].dir[1] = s * sinf(phi);
        rays[i].dir[2] = z;
    }
    /* The same rays, sixteen consecutive ones to a packet. */
    int n_packets = n_rays / 16;
    RayHit16 *packets = aligned_alloc(64, sizeof(RayHit16) * n_packets);
    memset(packets, 0, sizeof(RayHit16) * n_packets);
    int valid[16];
    for (int l = 0; l < 16; l++) valid[l] = -1;
    for (int query = 0; query < 3; query++) {
        double best = INFINITY, sum = 0;
        long hits = 0;
        for (int run = 0; run < runs; run++) {
            for (int i = 0; i < n_rays; i++) {
                rays[i].tnear = 0;
                rays[i].tfar = INFINITY;
                rays[i].mask = INVALID_ID;
                rays[i].geom_id = rays[i].prim_id = INVALID_ID;
            }
            if (query == 2) {
                for (int i = 0; i < n_packets * 16; i++) {
                    RayHit16 *p = &packets[i / 16];
                    int l = i % 16;
                    for (int a = 0; a < 3; a++) {
                        p->org[a][l] = rays[i].org[a];
                        p->dir[a][l] = rays[i].dir[a];
                    }
                    p->tnear[l] = 0;
                    p->tfar[l] = INFINITY;
                    p->mask[l] = INVALID_ID;
                    p->geom_id[l] = p->prim_id[l] = INVALID_ID;
                }
            }
            start = seconds();
            if (query == 2)
                for (int i = 0; i < n_packets; i++) rtcIntersect16(valid, scene, &packets[i], NULL);
            else if (query == 0)
                for (int i = 0; i < n_rays; i++) rtcIntersect1(scene, &rays[i], NULL);
            else
                for (int i = 0; i < n_rays; i++) rtcOccluded1(scene, &rays[i], NULL);
            double elapsed = seconds() - start;
            best = elapsed < best ? elapsed : best;
            hits = 0;
            sum = 0;
            for (int i = 0; i < n_rays; i++) {
                int hit = query == 0 ? rays[i].geom_id != INVALID_ID : rays[i].tfar < 0;
                float t = rays[i].tfar;
                if (query == 2) {
                    if (i >= n_packets * 16) break;
                    hit = packets[i / 16].geom_id[i % 16] != INVALID_ID;
                    t = packets[i / 16].tfar[i % 16];
                }
                hits += hit;
                if (hit && query != 1) sum += t;
            }
        }
        static const char *names[] = {"rtcIntersect1", "rtcOccluded1", "rtcIntersect16"};
        int traced = query == 2 ? n_packets * 16 : n_rays;
        printf("| %s | %.2f Mrays/s | hits %ld | mean t %.4f |\n", names[query], traced / best / 1e6, hits,
               hits ? sum / (double)hits : 0.0);
    }
    return 0;
}
