// Velocity Verlet, the periodic wrap and the re-sort's gathers: one thread
// per grain. Mirrors kick_drift and wrap of grain_kernels.rs.
#include "common.cuh"

// `kicks` half-kicks, then the drift if `drift`, and the skin test (a
// grain beyond it stores 1 in st[ST_FAR]: the same value whichever thread
// stores it). `check` tests the state after the first kick for finiteness.
extern "C" __global__ void kick_drift(Grains g, double dt, double limit2, u32 kicks, u32 drift,
                                      u32 check, u64 *st) {
    u64 i = thread_index();
    if (i >= g.n) return;
    if (g.frozen[i] == 0) {
        double half = 0.5 * dt;
        double kick = half * g.inv_mass[i];
        double spin_kick = half * g.inv_inertia[i];
        v3 f = get(g.force, i);
        v3 tq = get(g.torque, i);
        v3 v = get(g.vel, i);
        v3 w = get(g.omega, i);
        for (u32 k = 0; k < kicks; k++) {
            v = add(v, scale(f, kick));
            w = add(w, scale(tq, spin_kick));
            if (check && k == 0) {
                v3 x = get(g.pos, i);
                if (!(isfinite(x.x) && isfinite(x.y) && isfinite(x.z) && isfinite(v.x) &&
                      isfinite(v.y) && isfinite(v.z)))
                    st[ST_NONFINITE] = 1;
            }
        }
        set(g.vel, i, v);
        set(g.omega, i, w);
        if (drift) set(g.pos, i, add(get(g.pos, i), scale(v, dt)));
    }
    if (!drift) return;
    v3 d = sub(get(g.pos, i), get(g.reference, i));
    if (dot(d, d) > limit2) st[ST_FAR] = 1;
}

struct Box3 {
    double lo[3], length[3];
    u32 periodic[3];
};

extern "C" __global__ void wrap_grains(Grains g, Box3 b) {
    u64 i = thread_index();
    if (i >= g.n) return;
    double p[3] = {g.pos.x[i], g.pos.y[i], g.pos.z[i]};
    for (int a = 0; a < 3; a++) {
        if (!b.periodic[a]) continue;
        double lo = b.lo[a], l = b.length[a];
        double x = p[a];
        if (x < lo || x >= lo + l) {
            x -= l * floor((x - lo) / l);
            if (x >= lo + l) x -= l;
            p[a] = x;
        }
    }
    g.pos.x[i] = p[0];
    g.pos.y[i] = p[1];
    g.pos.z[i] = p[2];
}

// dst[k] = src[order[k]], for each kind of per-grain array.
extern "C" __global__ void gather_f64(const double *src, double *dst, const u32 *order, u64 n) {
    u64 k = thread_index();
    if (k < n) dst[k] = src[order[k]];
}
extern "C" __global__ void gather_u64(const u64 *src, u64 *dst, const u32 *order, u64 n) {
    u64 k = thread_index();
    if (k < n) dst[k] = src[order[k]];
}
extern "C" __global__ void gather_u32(const u32 *src, u32 *dst, const u32 *order, u64 n) {
    u64 k = thread_index();
    if (k < n) dst[k] = src[order[k]];
}
extern "C" __global__ void gather_u8(const u8 *src, u8 *dst, const u32 *order, u64 n) {
    u64 k = thread_index();
    if (k < n) dst[k] = src[order[k]];
}
// The walls' springs: `slots` consecutive entries per grain.
extern "C" __global__ void gather_slots(const double *src, double *dst, const u32 *order, u64 n,
                                        u32 slots) {
    u64 k = thread_index();
    if (k >= n * slots) return;
    u64 g = k / slots, w = k % slots;
    dst[k] = src[(u64)order[g] * slots + w];
}
