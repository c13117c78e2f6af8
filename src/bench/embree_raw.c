/* heron's raw-Embree program (`heron bench traversal --raw`, `heron bench replay` and
 * `heron bench limit` build it with gcc).
 *
 * It traces rays heron wrote out, on geometry heron wrote out, through Embree's C API
 * with nothing around it, so that heron's time on the same rays, in the same packet
 * grouping and with the same scene flags, can be reported as a ratio. Embree's
 * declarations are written here by hand (as heron's are in src/accel/embree/sys.rs) so
 * the program builds without headers, against Debian's Embree 3 or the header-less
 * Embree 4 of the embreex wheel (-DHERON_EMBREE4).
 *
 *   embree_raw MESH RAYS_COHERENT RAYS_INCOHERENT
 *
 * MESH: u32 vertex count, u32 triangle count, f32 xyz per vertex, u32 3 per triangle.
 * RAYS: u32 count, then per ray f32 org xyz, tnear, dir xyz, tfar (all little-endian).
 * After "ready" it reads commands "WIDTH SET" (WIDTH 1, 4, 8, 16 or 0 for the stream
 * API; SET 0 coherent, 1 incoherent) and answers each with one pass over the set:
 * "NANOSECONDS HITS PRIMID_SUM TFAR_SUM", or "unavailable" (the stream API on Embree 4).
 * "quit" ends it.
 *
 *   embree_raw --replay RAYLOG
 *
 * RAYLOG: a ray log of `heron bench record` (src/bench/limit.rs describes the file;
 * heron has checked it before starting this program): the scene's geometry, then the
 * calls a render made, each an 8-byte header (op, coherent, valid lanes, ray count) and
 * its rays. After "ready" each "replay" makes every call again, in order, and answers
 * "NANOSECONDS CALLS RAYS HITS PRIMID_SUM TFAR_SUM OCCLUDED"; "quit" ends it.
 */
#define _POSIX_C_SOURCE 199309L
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <emmintrin.h>
#include <time.h>

typedef struct RTCDeviceTy *RTCDevice;
typedef struct RTCSceneTy *RTCScene;
typedef struct RTCGeometryTy *RTCGeometry;

#define RTC_INVALID_GEOMETRY_ID ((unsigned)-1)
enum { RTC_GEOMETRY_TYPE_TRIANGLE = 0, RTC_GEOMETRY_TYPE_SPHERE_POINT = 50 };
enum { RTC_BUFFER_TYPE_INDEX = 0, RTC_BUFFER_TYPE_VERTEX = 1 };
enum { RTC_FORMAT_UINT3 = 0x5003, RTC_FORMAT_FLOAT3 = 0x9003, RTC_FORMAT_FLOAT4 = 0x9004 };
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
void rtcOccluded1(RTCScene, struct RTCRay *, void *args);
void rtcIntersect4(const int *, RTCScene, struct RTCRayHit4 *, void *args);
void rtcIntersect8(const int *, RTCScene, struct RTCRayHit8 *, void *args);
void rtcIntersect16(const int *, RTCScene, struct RTCRayHit16 *, void *args);
void rtcOccluded4(const int *, RTCScene, struct RTCRay4 *, void *args);
void rtcOccluded8(const int *, RTCScene, struct RTCRay8 *, void *args);
void rtcOccluded16(const int *, RTCScene, struct RTCRay16 *, void *args);
typedef struct {
    int unused;
} Ctx;
static inline void ctx_init(Ctx *c, int coherent) { (void)c; (void)coherent; }
#define I1(s, c, rh) ((void)(c), rtcIntersect1(s, rh, NULL))
#define O1(s, c, r) ((void)(c), rtcOccluded1(s, r, NULL))
#define IN(W, v, s, c, rh) ((void)(c), rtcIntersect##W(v, s, rh, NULL))
#define ON(W, v, s, c, r) ((void)(c), rtcOccluded##W(v, s, r, NULL))
#else
/* Embree 3 with RTC_MAX_INSTANCE_LEVEL_COUNT 1 and RTC_MIN_WIDTH 0 (Debian's build). */
struct RTCIntersectContext {
    int flags;
    void *filter;
    unsigned instID[1];
};
typedef struct RTCIntersectContext Ctx;
void rtcIntersect1(RTCScene, Ctx *, struct RTCRayHit *);
void rtcOccluded1(RTCScene, Ctx *, struct RTCRay *);
void rtcIntersect4(const int *, RTCScene, Ctx *, struct RTCRayHit4 *);
void rtcIntersect8(const int *, RTCScene, Ctx *, struct RTCRayHit8 *);
void rtcIntersect16(const int *, RTCScene, Ctx *, struct RTCRayHit16 *);
void rtcOccluded4(const int *, RTCScene, Ctx *, struct RTCRay4 *);
void rtcOccluded8(const int *, RTCScene, Ctx *, struct RTCRay8 *);
void rtcOccluded16(const int *, RTCScene, Ctx *, struct RTCRay16 *);
void rtcIntersect1M(RTCScene, Ctx *, struct RTCRayHit *, unsigned M, size_t byteStride);
/* rtcInitIntersectContext: INCOHERENT (0) or COHERENT (1), no filter. */
static inline void ctx_init(Ctx *c, int coherent) {
    c->flags = coherent ? 1 : 0;
    c->filter = NULL;
    c->instID[0] = RTC_INVALID_GEOMETRY_ID;
}
#define I1(s, c, rh) rtcIntersect1(s, c, rh)
#define O1(s, c, r) rtcOccluded1(s, c, r)
#define IN(W, v, s, c, rh) rtcIntersect##W(v, s, c, rh)
#define ON(W, v, s, c, r) rtcOccluded##W(v, s, c, r)
#endif

/* One function per benchmark pass, never inlined nor cloned (gcc's .constprop copies
 * would rename it), so that scripts/callgrind_traversal.sh can count each pass's
 * instructions (as heron's HeronTracer::trace). */
#define NOINLINE __attribute__((noinline, noclone))

/* heron's stream chunk (src/bench/mod.rs STREAM_CHUNK); a logged stream is longer at
 * most by heron's own chunking, which the replay keeps. */
#define STREAM_CHUNK 256

typedef struct {
    float o[3], tnear, d[3], tfar;
} Ray;

typedef struct {
    uint64_t calls, rays, hits, prim_sum, occluded;
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

static inline void tally_hit(Tally *t, unsigned geom, unsigned prim, float tfar) {
    if (geom != RTC_INVALID_GEOMETRY_ID) {
        t->hits++;
        t->prim_sum += prim;
        t->t_sum += tfar;
    }
}

/* The record written as Embree's tutorials write it (their Ray constructor stores the
 * origin with tnear, and the direction with time, as 16-byte vectors, Vec3ff): three
 * 16-byte stores. Scalar stores would make Embree's first 16-byte loads of the record
 * wait for them (no store-to-load forwarding from several smaller stores), which cost
 * 15% on coherent single rays. */
static inline void set_ray(struct RTCRay *r, const Ray *q) {
    __m128 a = _mm_loadu_ps(q->o), b = _mm_loadu_ps(q->d);
    __m128 xyz = _mm_castsi128_ps(_mm_setr_epi32(-1, -1, -1, 0));
    /* [tfar, mask = all bits, id = 0, flags = 0] */
    __m128 tail = _mm_move_ss(_mm_castsi128_ps(_mm_setr_epi32(0, -1, 0, 0)),
                              _mm_shuffle_ps(b, b, 0xff));
    _mm_store_ps(&r->org_x, a);
    _mm_store_ps(&r->dir_x, _mm_and_ps(b, xyz));
    _mm_store_ps(&r->tfar, tail);
}

static inline void set_hit(struct RTCHit *h) {
    memset(h, 0, sizeof *h);
    h->geomID = h->primID = h->instID[0] = RTC_INVALID_GEOMETRY_ID;
}

/* One query of each kind, as Embree's tutorials make it: the records filled from the
 * ray, the call, the answer read. Packets copy the active lanes only. */
static inline void intersect1(RTCScene s, Ctx *c, const Ray *q, Tally *t) {
    struct RTCRayHit rh;
    set_ray(&rh.ray, q);
    set_hit(&rh.hit);
    I1(s, c, &rh);
    tally_hit(t, rh.hit.geomID, rh.hit.primID, rh.ray.tfar);
}

static inline void occluded1(RTCScene s, Ctx *c, const Ray *q, Tally *t) {
    struct RTCRay r;
    set_ray(&r, q);
    O1(s, c, &r);
    t->occluded += r.tfar == -__builtin_inff();
}

/* A packet's rays (all W lanes; Embree reads no field of an inactive lane) as SoA
 * vectors, four lanes at a time by two 4x4 transposes (_MM_TRANSPOSE4_PS), as an ISPC
 * gang or Embree's vfloat<K> writes a packet: whole-vector stores, for the reason
 * set_ray gives. */
static inline void transpose4(__m128 *v) {
    __m128 t0 = _mm_unpacklo_ps(v[0], v[1]), t1 = _mm_unpacklo_ps(v[2], v[3]);
    __m128 t2 = _mm_unpackhi_ps(v[0], v[1]), t3 = _mm_unpackhi_ps(v[2], v[3]);
    v[0] = _mm_movelh_ps(t0, t1);
    v[1] = _mm_movehl_ps(t1, t0);
    v[2] = _mm_movelh_ps(t2, t3);
    v[3] = _mm_movehl_ps(t3, t2);
}

#define SET_LANES(W, r)                                                                   \
    for (int k = 0; k < W; k += 4) {                                                      \
        __m128 a[4], b[4];                                                                \
        for (int i = 0; i < 4; i++) {                                                     \
            a[i] = _mm_loadu_ps(rays[k + i].o);                                           \
            b[i] = _mm_loadu_ps(rays[k + i].d);                                           \
        }                                                                                 \
        transpose4(a);                                                                    \
        transpose4(b);                                                                    \
        _mm_store_ps(&(r).org_x[k], a[0]); _mm_store_ps(&(r).org_y[k], a[1]);             \
        _mm_store_ps(&(r).org_z[k], a[2]); _mm_store_ps(&(r).tnear[k], a[3]);             \
        _mm_store_ps(&(r).dir_x[k], b[0]); _mm_store_ps(&(r).dir_y[k], b[1]);             \
        _mm_store_ps(&(r).dir_z[k], b[2]); _mm_store_ps(&(r).tfar[k], b[3]);              \
        _mm_store_ps(&(r).time[k], _mm_setzero_ps());                                     \
        _mm_store_si128((__m128i *)&(r).mask[k], _mm_set1_epi32(-1));                     \
        _mm_store_si128((__m128i *)&(r).id[k], _mm_setzero_si128());                      \
        _mm_store_si128((__m128i *)&(r).flags[k], _mm_setzero_si128());                   \
    }

#define PACKET_QUERIES(W)                                                                 \
    static inline void intersect##W(RTCScene s, Ctx *c, const Ray *rays, const int *valid, \
                                    Tally *t) {                                           \
        struct RTCRayHit##W rh;                                                           \
        SET_LANES(W, rh.ray)                                                              \
        memset(&rh.hit, 0, sizeof rh.hit);                                                \
        for (int i = 0; i < W; i++)                                                       \
            rh.hit.geomID[i] = rh.hit.primID[i] = rh.hit.instID[0][i] =                   \
                RTC_INVALID_GEOMETRY_ID;                                                  \
        IN(W, valid, s, c, &rh);                                                          \
        for (int i = 0; i < W; i++)                                                       \
            if (valid[i]) tally_hit(t, rh.hit.geomID[i], rh.hit.primID[i], rh.ray.tfar[i]); \
    }                                                                                     \
    static inline void occluded##W(RTCScene s, Ctx *c, const Ray *rays, const int *valid, \
                                   Tally *t) {                                            \
        struct RTCRay##W r;                                                               \
        SET_LANES(W, r)                                                                   \
        ON(W, valid, s, c, &r);                                                           \
        for (int i = 0; i < W; i++)                                                       \
            if (valid[i]) t->occluded += r.tfar[i] == -__builtin_inff();                  \
    }                                                                                     \
    NOINLINE static void trace##W(RTCScene s, const Ray *rays, uint32_t n, int coherent,  \
                                  Tally *t) {                                             \
        Ctx c;                                                                            \
        ctx_init(&c, coherent);                                                           \
        for (uint32_t b = 0; b < n; b += W) {                                             \
            int __attribute__((aligned(4 * W))) valid[W];                                 \
            for (int i = 0; i < W; i++) valid[i] = b + i < n ? -1 : 0;                    \
            if (b + W <= n) {                                                             \
                intersect##W(s, &c, rays + b, valid, t);                                  \
            } else { /* the last, partial packet: inactive lanes repeat the first ray */  \
                Ray pad[W];                                                               \
                for (int i = 0; i < W; i++) pad[i] = rays[b + (b + i < n ? i : 0)];       \
                intersect##W(s, &c, pad, valid, t);                                       \
            }                                                                             \
        }                                                                                 \
    }
PACKET_QUERIES(4)
PACKET_QUERIES(8)
PACKET_QUERIES(16)

NOINLINE static void trace1(RTCScene s, const Ray *rays, uint32_t n, int coherent, Tally *t) {
    Ctx c;
    ctx_init(&c, coherent);
    for (uint32_t i = 0; i < n; i++) intersect1(s, &c, &rays[i], t);
}

/* Embree 3's stream query over n rays; 0 on Embree 4, which has none. */
static inline int stream(RTCScene s, Ctx *c, const Ray *rays, uint32_t n, Tally *t) {
#ifdef HERON_EMBREE4
    (void)s; (void)c; (void)rays; (void)n; (void)t;
    return 0;
#else
    static struct RTCRayHit *rh;
    static uint32_t cap;
    if (n > cap) {
        free(rh);
        rh = aligned_alloc(16, (size_t)n * sizeof *rh);
        if (!rh) die("out of memory");
        cap = n;
    }
    for (uint32_t i = 0; i < n; i++) {
        set_ray(&rh[i].ray, &rays[i]);
        set_hit(&rh[i].hit);
    }
    rtcIntersect1M(s, c, rh, n, sizeof rh[0]);
    for (uint32_t i = 0; i < n; i++) tally_hit(t, rh[i].hit.geomID, rh[i].hit.primID, rh[i].ray.tfar);
    return 1;
#endif
}

/* Returns 0 when the stream API does not exist (Embree 4). */
NOINLINE static int trace_stream(RTCScene s, const Ray *rays, uint32_t n, int coherent, Tally *t) {
    Ctx c;
    ctx_init(&c, coherent);
    for (uint32_t b = 0; b < n; b += STREAM_CHUNK) {
        uint32_t m = n - b < STREAM_CHUNK ? n - b : STREAM_CHUNK;
        if (!stream(s, &c, rays + b, m, t)) return 0;
    }
    return 1;
}

/* A ray log's calls (see the top of this file and src/accel/embree/record.rs). */
enum { OP_OCCLUDED = 0x80, CALL_HEADER = 8 };

/* Every call of the log, in order; 0 if the log has a stream call and Embree has none.
 * The rays are read in place (`calls` is 16-byte aligned, and every ray starts 8 + 32k
 * bytes into it). */
NOINLINE static int replay(RTCScene s, const unsigned char *calls, size_t len, Tally *t) {
    const unsigned char *p = calls, *end = calls + len;
    while (p < end) {
        unsigned op = p[0];
        uint16_t bits;
        uint32_t n;
        memcpy(&bits, p + 2, 2);
        memcpy(&n, p + 4, 4);
        const Ray *rays = (const Ray *)(const void *)(p + CALL_HEADER);
        Ctx c;
        ctx_init(&c, p[1]);
        p += CALL_HEADER + (size_t)n * sizeof(Ray);
        t->calls++;
        int __attribute__((aligned(64))) valid[16];
        if ((op & 0x7f) > 1)
            for (int i = 0; i < 16; i++) valid[i] = (bits >> i) & 1 ? -1 : 0;
        t->rays += op == 0 ? n : (uint64_t)__builtin_popcount(bits);
        switch (op) {
        case 1: intersect1(s, &c, rays, t); break;
        case OP_OCCLUDED | 1: occluded1(s, &c, rays, t); break;
        case 4: intersect4(s, &c, rays, valid, t); break;
        case 8: intersect8(s, &c, rays, valid, t); break;
        case 16: intersect16(s, &c, rays, valid, t); break;
        case OP_OCCLUDED | 4: occluded4(s, &c, rays, valid, t); break;
        case OP_OCCLUDED | 8: occluded8(s, &c, rays, valid, t); break;
        case OP_OCCLUDED | 16: occluded16(s, &c, rays, valid, t); break;
        case 0:
            if (!stream(s, &c, rays, n, t)) return 0;
            break;
        default: die("bad call in the ray log");
        }
    }
    return 1;
}

static RTCDevice dev;

static RTCScene new_scene(void) {
    RTCScene scene = rtcNewScene(dev);
    rtcSetSceneFlags(scene, RTC_SCENE_FLAG_ROBUST);
    rtcSetSceneBuildQuality(scene, RTC_BUILD_QUALITY_HIGH);
    return scene;
}

static void add_mesh(RTCScene scene, uint32_t nv, uint32_t nt, const unsigned char *v,
                     const unsigned char *idx) {
    RTCGeometry g = rtcNewGeometry(dev, RTC_GEOMETRY_TYPE_TRIANGLE);
    void *vb = rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, 12, nv);
    void *ib = rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, 12, nt);
    if (!vb || !ib) die("rtcSetNewGeometryBuffer failed");
    memcpy(vb, v, (size_t)nv * 12);
    memcpy(ib, idx, (size_t)nt * 12);
    rtcCommitGeometry(g);
    rtcAttachGeometry(scene, g);
    rtcReleaseGeometry(g);
}

static void add_sphere(RTCScene scene, const unsigned char *xyzr) {
    RTCGeometry g = rtcNewGeometry(dev, RTC_GEOMETRY_TYPE_SPHERE_POINT);
    void *vb = rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT4, 16, 1);
    if (!vb) die("rtcSetNewGeometryBuffer failed");
    memcpy(vb, xyzr, 16);
    rtcCommitGeometry(g);
    rtcAttachGeometry(scene, g);
    rtcReleaseGeometry(g);
}

static void commit(RTCScene scene) {
    rtcCommitScene(scene);
    if (rtcGetDeviceError(dev) != 0) die("Embree reported an error while building");
    printf("ready\n");
    fflush(stdout);
}

static long long now_ns(void) {
    struct timespec a;
    clock_gettime(CLOCK_MONOTONIC, &a);
    return (long long)a.tv_sec * 1000000000LL + a.tv_nsec;
}

/* The ray log: magic, geometry, calls, tally (src/bench/limit.rs). heron checked it. */
static int main_replay(const char *path) {
    size_t len;
    unsigned char *f = read_file(path, &len);
    if (len < 16 || memcmp(f, "heron-rays 1\n", 13) != 0) die("not a heron ray log");
    const unsigned char *p = f + 16, *end = f + len;
#define NEED(k) if ((size_t)(end - p) < (size_t)(k)) die("ray log too short")
    uint32_t ngeom;
    NEED(4);
    memcpy(&ngeom, p, 4);
    p += 4;
    RTCScene scene = new_scene();
    for (uint32_t g = 0; g < ngeom; g++) {
        uint32_t kind;
        NEED(4);
        memcpy(&kind, p, 4);
        p += 4;
        if (kind == 0) {
            uint32_t nv, nt;
            NEED(8);
            memcpy(&nv, p, 4);
            memcpy(&nt, p + 4, 4);
            p += 8;
            NEED((size_t)nv * 12 + (size_t)nt * 12);
            add_mesh(scene, nv, nt, p, p + (size_t)nv * 12);
            p += (size_t)nv * 12 + (size_t)nt * 12;
        } else if (kind == 1) {
            NEED(16);
            add_sphere(scene, p);
            p += 16;
        } else {
            die("bad geometry kind in the ray log");
        }
    }
    uint64_t clen;
    NEED(8);
    memcpy(&clen, p, 8);
    p += 8;
    NEED(clen);
    unsigned char *calls = aligned_alloc(16, clen + 16);
    if (!calls) die("out of memory");
    memcpy(calls, p, clen);
    free(f);
    commit(scene);

    char line[64];
    while (fgets(line, sizeof line, stdin)) {
        if (strncmp(line, "quit", 4) == 0) break;
        if (strncmp(line, "replay", 6) != 0) die("bad command");
        Tally t = {0, 0, 0, 0, 0, 0.0};
        long long a = now_ns();
        int ok = replay(scene, calls, clen, &t);
        long long b = now_ns();
        if (ok)
            printf("%lld %llu %llu %llu %llu %.17g %llu\n", b - a, (unsigned long long)t.calls,
                   (unsigned long long)t.rays, (unsigned long long)t.hits,
                   (unsigned long long)t.prim_sum, t.t_sum, (unsigned long long)t.occluded);
        else
            printf("unavailable\n");
        fflush(stdout);
    }
    rtcReleaseScene(scene);
    free(calls);
    return 0;
}

int main(int argc, char **argv) {
    /* FTZ and DAZ, as heron sets them on its threads (Embree's recommendation). */
    _mm_setcsr(_mm_getcsr() | 0x8040);
    dev = rtcNewDevice("");
    if (!dev) die("rtcNewDevice failed");
    if (argc == 3 && strcmp(argv[1], "--replay") == 0) {
        int r = main_replay(argv[2]);
        rtcReleaseDevice(dev);
        return r;
    }
    if (argc != 4) die("usage: embree_raw MESH RAYS_COHERENT RAYS_INCOHERENT | --replay RAYLOG");
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

    RTCScene scene = new_scene();
    add_mesh(scene, nv, nt, mesh + 8, mesh + 8 + (size_t)nv * 12);
    free(mesh);
    commit(scene);

    char line[64];
    while (fgets(line, sizeof line, stdin)) {
        if (strncmp(line, "quit", 4) == 0) break;
        int width, set;
        if (sscanf(line, "%d %d", &width, &set) != 2 || set < 0 || set > 1) die("bad command");
        Tally t = {0, 0, 0, 0, 0, 0.0};
        long long a = now_ns();
        int ok = 1;
        switch (width) {
        case 1: trace1(scene, sets[set], counts[set], set == 0, &t); break;
        case 4: trace4(scene, sets[set], counts[set], set == 0, &t); break;
        case 8: trace8(scene, sets[set], counts[set], set == 0, &t); break;
        case 16: trace16(scene, sets[set], counts[set], set == 0, &t); break;
        case 0: ok = trace_stream(scene, sets[set], counts[set], set == 0, &t); break;
        default: die("bad width");
        }
        long long b = now_ns();
        if (ok)
            printf("%lld %llu %llu %.17g\n", b - a, (unsigned long long)t.hits,
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
