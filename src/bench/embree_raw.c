/* heron's raw-Embree traversal benchmark (`heron bench traversal` builds it with gcc).
 *
 * It traces the rays heron wrote out, on the mesh heron wrote out, through Embree's C
 * API with nothing around it, so that heron's time on the same rays, in the same packet
 * grouping and with the same scene flags, can be reported as a ratio: heron's FFI
 * overhead. Embree's declarations are written here by hand (as heron's are in
 * src/accel/embree/sys.rs) so the program builds without headers, against Debian's
 * Embree 3 or the header-less Embree 4 of the embreex wheel (-DHERON_EMBREE4).
 *
 *   embree_raw MESH RAYS_COHERENT RAYS_INCOHERENT
 *
 * MESH: u32 vertex count, u32 triangle count, f32 xyz per vertex, u32 3 per triangle.
 * RAYS: u32 count, then per ray f32 org xyz, tnear, dir xyz, tfar (all little-endian).
 * After "ready" it reads commands "WIDTH SET" (WIDTH 1, 4, 8, 16 or 0 for the stream
 * API; SET 0 coherent, 1 incoherent) and answers each with one pass over the set:
 * "NANOSECONDS HITS PRIMID_SUM TFAR_SUM", or "unavailable" (the stream API on Embree 4).
 * "quit" ends it.
 */
#define _POSIX_C_SOURCE 199309L
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <xmmintrin.h>

typedef struct RTCDeviceTy *RTCDevice;
typedef struct RTCSceneTy *RTCScene;
typedef struct RTCGeometryTy *RTCGeometry;

#define RTC_INVALID_GEOMETRY_ID ((unsigned)-1)
enum { RTC_GEOMETRY_TYPE_TRIANGLE = 0 };
enum { RTC_BUFFER_TYPE_INDEX = 0, RTC_BUFFER_TYPE_VERTEX = 1 };
enum { RTC_FORMAT_UINT3 = 0x5003, RTC_FORMAT_FLOAT3 = 0x9003 };
enum { RTC_SCENE_FLAG_ROBUST = 1 << 2 };
enum { RTC_BUILD_QUALITY_HIGH = 2 };

RTCDevice rtcNewDevice(const char *config);
void rtcReleaseDevice(RTCDevice device);
int rtcGetDeviceError(RTCDevice device);
RTCScene rtcNewScene(RTCDevice device);
void rtcSetSceneFlags(RTCScene scene, int flags);
void rtcSetSceneBuildQuality(RTCScene scene, int quality);
RTCGeometry rtcNewGeometry(RTCDevice device, int type);
void *rtcSetNewGeometryBuffer(RTCGeometry geometry, int type, unsigned slot, int format,
                              size_t byteStride, size_t itemCount);
void rtcCommitGeometry(RTCGeometry geometry);
unsigned rtcAttachGeometry(RTCScene scene, RTCGeometry geometry);
void rtcReleaseGeometry(RTCGeometry geometry);
void rtcCommitScene(RTCScene scene);
void rtcReleaseScene(RTCScene scene);

struct __attribute__((aligned(16))) RTCRay {
    float org_x, org_y, org_z, tnear, dir_x, dir_y, dir_z, time, tfar;
    unsigned mask, id, flags;
};
struct __attribute__((aligned(16))) RTCHit {
    float Ng_x, Ng_y, Ng_z, u, v;
    unsigned primID, geomID, instID[1];
#ifdef HERON_EMBREE4
    unsigned instPrimID[1];
#endif
};
struct RTCRayHit {
    struct RTCRay ray;
    struct RTCHit hit;
};

#ifdef HERON_EMBREE4
#define HIT_EXTRA(W) unsigned instPrimID[1][W];
#else
#define HIT_EXTRA(W)
#endif
#define PACKET(W, A)                                                                      \
    struct __attribute__((aligned(A))) RTCRay##W {                                        \
        float org_x[W], org_y[W], org_z[W], tnear[W], dir_x[W], dir_y[W], dir_z[W],       \
            time[W], tfar[W];                                                             \
        unsigned mask[W], id[W], flags[W];                                                \
    };                                                                                    \
    struct __attribute__((aligned(A))) RTCHit##W {                                        \
        float Ng_x[W], Ng_y[W], Ng_z[W], u[W], v[W];                                      \
        unsigned primID[W], geomID[W], instID[1][W];                                      \
        HIT_EXTRA(W)                                                                      \
    };                                                                                    \
    struct RTCRayHit##W {                                                                 \
        struct RTCRay##W ray;                                                             \
        struct RTCHit##W hit;                                                             \
    };
PACKET(4, 16)
PACKET(8, 32)
PACKET(16, 64)

#ifdef HERON_EMBREE4
/* Embree 4: no context; NULL arguments are the defaults of rtcInitIntersectArguments. */
void rtcIntersect1(RTCScene, struct RTCRayHit *, void *args);
void rtcIntersect4(const int *, RTCScene, struct RTCRayHit4 *, void *args);
void rtcIntersect8(const int *, RTCScene, struct RTCRayHit8 *, void *args);
void rtcIntersect16(const int *, RTCScene, struct RTCRayHit16 *, void *args);
#define CTX_DECL(coherent) (void)(coherent)
#define I1(s, rh) rtcIntersect1(s, rh, NULL)
#define IN(W, v, s, rh) rtcIntersect##W(v, s, rh, NULL)
#else
/* Embree 3 with RTC_MAX_INSTANCE_LEVEL_COUNT 1 and RTC_MIN_WIDTH 0 (Debian's build). */
struct RTCIntersectContext {
    int flags;
    void *filter;
    unsigned instID[1];
};
void rtcIntersect1(RTCScene, struct RTCIntersectContext *, struct RTCRayHit *);
void rtcIntersect4(const int *, RTCScene, struct RTCIntersectContext *, struct RTCRayHit4 *);
void rtcIntersect8(const int *, RTCScene, struct RTCIntersectContext *, struct RTCRayHit8 *);
void rtcIntersect16(const int *, RTCScene, struct RTCIntersectContext *, struct RTCRayHit16 *);
void rtcIntersect1M(RTCScene, struct RTCIntersectContext *, struct RTCRayHit *, unsigned M,
                    size_t byteStride);
/* rtcInitIntersectContext: INCOHERENT (0) or COHERENT (1), no filter. */
#define CTX_DECL(coherent)                                                                \
    struct RTCIntersectContext ctx = {(coherent) ? 1 : 0, NULL, {RTC_INVALID_GEOMETRY_ID}}
#define I1(s, rh) rtcIntersect1(s, &ctx, rh)
#define IN(W, v, s, rh) rtcIntersect##W(v, s, &ctx, rh)
#endif

/* heron's stream chunk (src/bench/mod.rs STREAM_CHUNK). */
#define STREAM_CHUNK 256

typedef struct {
    float o[3], tnear, d[3], tfar;
} Ray;

typedef struct {
    uint64_t hits, prim_sum;
    double t_sum;
} Tally;

static void die(const char *what) {
    fprintf(stderr, "embree_raw: %s\n", what);
    exit(1);
}

static void *read_file(const char *path, size_t *len) {
    FILE *f = fopen(path, "rb");
    if (!f) die(path);
    fseek(f, 0, SEEK_END);
    long n = ftell(f);
    fseek(f, 0, SEEK_SET);
    void *p = malloc(n > 0 ? (size_t)n : 1);
    if (!p || fread(p, 1, (size_t)n, f) != (size_t)n) die(path);
    fclose(f);
    *len = (size_t)n;
    return p;
}

static Ray *read_rays(const char *path, uint32_t *count) {
    size_t len;
    unsigned char *p = read_file(path, &len);
    memcpy(count, p, 4);
    if (len != 4 + (size_t)*count * sizeof(Ray)) die("ray file length");
    Ray *rays = malloc((size_t)*count * sizeof(Ray) + 1);
    memcpy(rays, p + 4, (size_t)*count * sizeof(Ray));
    free(p);
    return rays;
}

static void tally(Tally *t, unsigned geom, unsigned prim, float tfar) {
    if (geom != RTC_INVALID_GEOMETRY_ID) {
        t->hits++;
        t->prim_sum += prim;
        t->t_sum += tfar;
    }
}

static void set_ray(struct RTCRay *r, const Ray *q) {
    r->org_x = q->o[0]; r->org_y = q->o[1]; r->org_z = q->o[2]; r->tnear = q->tnear;
    r->dir_x = q->d[0]; r->dir_y = q->d[1]; r->dir_z = q->d[2]; r->time = 0.0f;
    r->tfar = q->tfar; r->mask = ~0u; r->id = 0; r->flags = 0;
}

static void set_hit(struct RTCHit *h) {
    memset(h, 0, sizeof *h);
    h->geomID = h->primID = h->instID[0] = RTC_INVALID_GEOMETRY_ID;
}

#define TRACE_PACKETS(W)                                                                  \
    static void trace##W(RTCScene s, const Ray *rays, uint32_t n, int coherent, Tally *t) { \
        CTX_DECL(coherent);                                                               \
        for (uint32_t b = 0; b < n; b += W) {                                             \
            struct RTCRayHit##W rh;                                                       \
            int __attribute__((aligned(4 * W))) valid[W];                                 \
            memset(&rh.ray, 0, sizeof rh.ray);                                            \
            for (int i = 0; i < W; i++) {                                                 \
                valid[i] = b + i < n ? -1 : 0;                                            \
                if (!valid[i]) continue;                                                  \
                const Ray *q = &rays[b + i];                                              \
                rh.ray.org_x[i] = q->o[0]; rh.ray.org_y[i] = q->o[1];                     \
                rh.ray.org_z[i] = q->o[2]; rh.ray.tnear[i] = q->tnear;                    \
                rh.ray.dir_x[i] = q->d[0]; rh.ray.dir_y[i] = q->d[1];                     \
                rh.ray.dir_z[i] = q->d[2]; rh.ray.tfar[i] = q->tfar;                      \
                rh.ray.mask[i] = ~0u;                                                     \
            }                                                                             \
            memset(&rh.hit, 0, sizeof rh.hit);                                            \
            for (int i = 0; i < W; i++)                                                   \
                rh.hit.geomID[i] = rh.hit.primID[i] = rh.hit.instID[0][i] =               \
                    RTC_INVALID_GEOMETRY_ID;                                              \
            IN(W, valid, s, &rh);                                                         \
            for (int i = 0; i < W; i++)                                                   \
                if (valid[i]) tally(t, rh.hit.geomID[i], rh.hit.primID[i], rh.ray.tfar[i]); \
        }                                                                                 \
    }
TRACE_PACKETS(4)
TRACE_PACKETS(8)
TRACE_PACKETS(16)

static void trace1(RTCScene s, const Ray *rays, uint32_t n, int coherent, Tally *t) {
    CTX_DECL(coherent);
    for (uint32_t i = 0; i < n; i++) {
        struct RTCRayHit rh;
        set_ray(&rh.ray, &rays[i]);
        set_hit(&rh.hit);
        I1(s, &rh);
        tally(t, rh.hit.geomID, rh.hit.primID, rh.ray.tfar);
    }
}

/* Returns 0 when the stream API does not exist (Embree 4). */
static int trace_stream(RTCScene s, const Ray *rays, uint32_t n, int coherent, Tally *t) {
#ifdef HERON_EMBREE4
    (void)s; (void)rays; (void)n; (void)coherent; (void)t;
    return 0;
#else
    CTX_DECL(coherent);
    static struct RTCRayHit rh[STREAM_CHUNK];
    for (uint32_t b = 0; b < n; b += STREAM_CHUNK) {
        uint32_t m = n - b < STREAM_CHUNK ? n - b : STREAM_CHUNK;
        for (uint32_t i = 0; i < m; i++) {
            set_ray(&rh[i].ray, &rays[b + i]);
            set_hit(&rh[i].hit);
        }
        rtcIntersect1M(s, &ctx, rh, m, sizeof rh[0]);
        for (uint32_t i = 0; i < m; i++) tally(t, rh[i].hit.geomID, rh[i].hit.primID, rh[i].ray.tfar);
    }
    return 1;
#endif
}

int main(int argc, char **argv) {
    if (argc != 4) die("usage: embree_raw MESH RAYS_COHERENT RAYS_INCOHERENT");
    /* FTZ and DAZ, as heron sets them on its threads (Embree's recommendation). */
    _mm_setcsr(_mm_getcsr() | 0x8040);
    size_t len;
    unsigned char *mesh = read_file(argv[1], &len);
    uint32_t nv, nt;
    memcpy(&nv, mesh, 4);
    memcpy(&nt, mesh + 4, 4);
    if (len != 8 + (size_t)nv * 12 + (size_t)nt * 12) die("mesh file length");
    Ray *sets[2];
    uint32_t counts[2];
    sets[0] = read_rays(argv[2], &counts[0]);
    sets[1] = read_rays(argv[3], &counts[1]);

    RTCDevice dev = rtcNewDevice("");
    if (!dev) die("rtcNewDevice failed");
    RTCScene scene = rtcNewScene(dev);
    rtcSetSceneFlags(scene, RTC_SCENE_FLAG_ROBUST);
    rtcSetSceneBuildQuality(scene, RTC_BUILD_QUALITY_HIGH);
    RTCGeometry g = rtcNewGeometry(dev, RTC_GEOMETRY_TYPE_TRIANGLE);
    void *vb = rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, 12, nv);
    void *ib = rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, 12, nt);
    if (!vb || !ib) die("rtcSetNewGeometryBuffer failed");
    memcpy(vb, mesh + 8, (size_t)nv * 12);
    memcpy(ib, mesh + 8 + (size_t)nv * 12, (size_t)nt * 12);
    free(mesh);
    rtcCommitGeometry(g);
    rtcAttachGeometry(scene, g);
    rtcReleaseGeometry(g);
    rtcCommitScene(scene);
    if (rtcGetDeviceError(dev) != 0) die("Embree reported an error while building");
    printf("ready\n");
    fflush(stdout);

    char line[64];
    while (fgets(line, sizeof line, stdin)) {
        if (strncmp(line, "quit", 4) == 0) break;
        int width, set;
        if (sscanf(line, "%d %d", &width, &set) != 2 || set < 0 || set > 1) die("bad command");
        Tally t = {0, 0, 0.0};
        struct timespec a, b;
        clock_gettime(CLOCK_MONOTONIC, &a);
        int ok = 1;
        switch (width) {
        case 1: trace1(scene, sets[set], counts[set], set == 0, &t); break;
        case 4: trace4(scene, sets[set], counts[set], set == 0, &t); break;
        case 8: trace8(scene, sets[set], counts[set], set == 0, &t); break;
        case 16: trace16(scene, sets[set], counts[set], set == 0, &t); break;
        case 0: ok = trace_stream(scene, sets[set], counts[set], set == 0, &t); break;
        default: die("bad width");
        }
        clock_gettime(CLOCK_MONOTONIC, &b);
        long long ns = (long long)(b.tv_sec - a.tv_sec) * 1000000000LL + (b.tv_nsec - a.tv_nsec);
        if (ok)
            printf("%lld %llu %llu %.17g\n", ns, (unsigned long long)t.hits,
                   (unsigned long long)t.prim_sum, t.t_sum);
        else
            printf("unavailable\n");
        fflush(stdout);
    }
    rtcReleaseScene(scene);
    rtcReleaseDevice(dev);
    free(sets[0]);
    free(sets[1]);
    return 0;
}
