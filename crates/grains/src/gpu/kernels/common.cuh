// Shared by the pipeline's kernels: the vector helpers in glam's order of
// operations (see grain_kernels.rs), and the argument structs, laid out as
// the #[repr(C)] structs of cuda.rs.
#pragma once

typedef unsigned int u32;
typedef unsigned char u8;
typedef unsigned long long u64;

struct v3 {
    double x, y, z;
};

__device__ __forceinline__ v3 mk(double a, double b, double c) {
    v3 r;
    r.x = a;
    r.y = b;
    r.z = c;
    return r;
}
__device__ __forceinline__ v3 add(v3 a, v3 b) { return mk(a.x + b.x, a.y + b.y, a.z + b.z); }
__device__ __forceinline__ v3 sub(v3 a, v3 b) { return mk(a.x - b.x, a.y - b.y, a.z - b.z); }
__device__ __forceinline__ v3 scale(v3 a, double s) { return mk(a.x * s, a.y * s, a.z * s); }
__device__ __forceinline__ v3 neg(v3 a) { return mk(-a.x, -a.y, -a.z); }
__device__ __forceinline__ double dot(v3 a, v3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
__device__ __forceinline__ v3 cross(v3 a, v3 b) {
    return mk(a.y * b.z - b.y * a.z, a.z * b.x - b.z * a.x, a.x * b.y - b.x * a.y);
}
__device__ __forceinline__ bool is_zero(v3 a) { return a.x == 0.0 && a.y == 0.0 && a.z == 0.0; }

// One vector per grain or entry, a component per array.
struct Soa3 {
    double *x, *y, *z;
};
__device__ __forceinline__ v3 get(Soa3 s, u64 i) { return mk(s.x[i], s.y[i], s.z[i]); }
__device__ __forceinline__ void set(Soa3 s, u64 i, v3 v) {
    s.x[i] = v.x;
    s.y[i] = v.y;
    s.z[i] = v.z;
}

// The grains, in cell order (Morton or the CPU engine's); rank: each
// grain's index in the CPU engine's order, which orients the pairs and
// orders the rows.
struct Grains {
    Soa3 pos, vel, omega, force, torque, reference;
    double *radius, *mass, *inv_mass, *inv_inertia;
    u8 *frozen;
    u32 *rank;
    u32 n;
};

// The full list: row g is start[g]..start[g + 1].
struct List {
    u32 *start, *partner;
    u8 *image;
    Soa3 springs;
};

// The two list buffers: the current one is l[builds % 2], the rebuild
// fills the other.
struct Lists {
    List l[2];
    u64 cap[2];
};

struct Hooke {
    double kn, gamma_n, gamma_t, kt, mu;
};

struct Plane {
    double point[3], normal[3], gamma_n;
};

#define MAX_WALLS 8

// The step words (grain_kernels.rs `words`): flags and counters the
// kernels read and write, so that a stretch of steps runs with no decision
// on the host.
#define ST_FAR 0
#define ST_NONFINITE 1
#define ST_PAIR_ENDS 2
#define ST_WALLS 3
#define ST_MAX_FRACTION 4
#define ST_BUILD 5
#define ST_SORT 6
#define ST_BUILDS 7
#define ST_SINCE_SORT 8
#define ST_HALT 9
#define ST_HALT_STEP 10
#define ST_NEED 11
#define ST_STEP 12
#define ST_LEN 13
#define HALT_OVERLAP 1
#define HALT_NONFINITE 2
#define HALT_OVERFLOW 3
// A gate argument: run always (unless halted), on BUILD, on SORT.
#define GATE_ALWAYS 0xffffffffu

// Whether a gated kernel runs (grain_kernels.rs `gate`). kick_drift and list_fill set ST_HALT only
// when every thread of the launch returns anyway, so a thread that sees it set returns as it would.
__device__ __forceinline__ bool gate(const u64 *st, u32 word) {
    return st[ST_HALT] == 0 && (word == GATE_ALWAYS || st[word] != 0);
}

__device__ __forceinline__ u64 thread_index() { return (u64)blockIdx.x * blockDim.x + threadIdx.x; }
