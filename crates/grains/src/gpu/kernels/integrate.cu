// Velocity Verlet, the periodic wrap and the re-sort's gathers: one thread
// per grain. Mirrors kick_drift and wrap of grain_kernels.rs.
#include "common.cuh"

// The one-thread kernel that opens a step (grain_kernels.rs step_begin):
// a grain found not finite halts the stretch; otherwise the step is
// counted, the rebuild and the re-sort decided and the step's flags and
// statistics cleared.
extern "C" __global__ void step_begin(u64 *st, u32 sort_every) {
    if (thread_index() != 0 || st[ST_HALT] != 0) return;
    if (st[ST_NONFINITE] != 0) {
        st[ST_HALT] = HALT_NONFINITE;
        st[ST_HALT_STEP] = st[ST_STEP];
        return;
    }
    st[ST_STEP] += 1;
    bool build = st[ST_FAR] != 0 || st[ST_BUILDS] == 0;
    u32 since = (u32)st[ST_SINCE_SORT];
    st[ST_BUILD] = build;
    st[ST_SORT] = build && sort_every > 0 && since % sort_every == 0;
    if (build) st[ST_SINCE_SORT] = (u64)(u32)(since + 1u);
    st[ST_FAR] = 0;
    st[ST_PAIR_ENDS] = 0;
    st[ST_WALLS] = 0;
    st[ST_MAX_FRACTION] = 0;
}

// A stretch starts (or resumes) unhalted, `step` steps taken.
extern "C" __global__ void clear_halt(u64 *st, u64 step) {
    if (thread_index() != 0) return;
    st[ST_HALT] = 0;
    st[ST_NONFINITE] = 0;
    st[ST_STEP] = step;
}

// The rebuild counted, after the list, its springs and the reference
// positions: the other list buffer becomes the current one.
extern "C" __global__ void build_end(u64 *st) {
    if (thread_index() != 0 || !gate(st, ST_BUILD)) return;
    st[ST_BUILDS] += 1;
}

// First the last force evaluation's overlap against `overlap_limit`
// (beyond it the stretch halts at this step, unkicked: every thread reads
// the same value and returns), then `kicks` half-kicks, the drift if
// `drift`, and the skin test (a grain beyond it stores 1 in st[ST_FAR]:
// the same value whichever thread stores it). At a step that is a
// multiple of `check_every` (0: never) the state after the first kick is
// tested for finiteness.
extern "C" __global__ void kick_drift(Grains g, double dt, double limit2, u32 kicks, u32 drift,
                                      u64 check_every, double overlap_limit, u64 *st) {
    u64 i = thread_index();
    if (i >= g.n || !gate(st, GATE_ALWAYS)) return;
    u64 step = st[ST_STEP];
    if (__longlong_as_double((long long)st[ST_MAX_FRACTION]) > overlap_limit) {
        if (i == 0) {
            st[ST_HALT] = HALT_OVERLAP;
            st[ST_HALT_STEP] = step;
        }
        return;
    }
    bool check = check_every > 0 && step % check_every == 0;
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

extern "C" __global__ void wrap_grains(Grains g, Box3 b, const u64 *st) {
    u64 i = thread_index();
    if (i >= g.n || !gate(st, ST_BUILD)) return;
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

// What moves with a grain besides the Grains arrays.
struct Extra {
    u64 *id;
    u32 *origin;
    Soa3 wall_springs;
};

// The re-sort, gated on SORT: dst's grain k is src's grain order[k] (k
// itself when `order` is null: the copy back from the scratch arrays).
// The reference positions are not moved: the rebuild sets them.
extern "C" __global__ void move_grains(Grains src, Extra xs, Grains dst, Extra xd,
                                       const u32 *order, u32 slots, const u64 *st) {
    u64 k = thread_index();
    if (k >= src.n || !gate(st, ST_SORT)) return;
    u64 j = order ? order[k] : k;
    set(dst.pos, k, get(src.pos, j));
    set(dst.vel, k, get(src.vel, j));
    set(dst.omega, k, get(src.omega, j));
    set(dst.force, k, get(src.force, j));
    set(dst.torque, k, get(src.torque, j));
    dst.radius[k] = src.radius[j];
    dst.mass[k] = src.mass[j];
    dst.inv_mass[k] = src.inv_mass[j];
    dst.inv_inertia[k] = src.inv_inertia[j];
    dst.frozen[k] = src.frozen[j];
    xd.id[k] = xs.id[j];
    xd.origin[k] = xs.origin[j];
    for (u32 w = 0; w < slots; w++) set(xd.wall_springs, k * slots + w, get(xs.wall_springs, j * slots + w));
}

// Gated fills and copies of integer arrays (bins, cursors).
extern "C" __global__ void zero_u32(u32 *dst, u64 n, const u64 *st, u32 word) {
    u64 k = thread_index();
    if (k < n && gate(st, word)) dst[k] = 0;
}
extern "C" __global__ void copy_u32(const u32 *src, u32 *dst, u64 n, const u64 *st, u32 word) {
    u64 k = thread_index();
    if (k < n && gate(st, word)) dst[k] = src[k];
}
