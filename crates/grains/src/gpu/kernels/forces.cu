// The force kernel: one thread per grain over its row of the full list,
// each pair in its canonical orientation, then the grain's wall contacts in
// wall order, then gravity. Mirrors hooke, damping_mass and grain_forces
// of grain_kernels.rs. No floating-point atomics: a grain writes only its
// own sums and springs; the statistics are integers and a maximum
// (order-free), reduced per warp, then one integer atomic per warp.
#include "common.cuh"

struct Push {
    v3 force, nt;
};

__device__ __forceinline__ Push hooke(const Hooke &law, v3 n, double overlap, v3 v_rel,
                                      double damping_mass, v3 *spring, double dt, bool update) {
    double vn = dot(v_rel, n);
    double fn_total = law.kn * overlap + -law.gamma_n * damping_mass * vn;
    v3 vt = sub(v_rel, scale(n, vn));
    double gamma = law.gamma_t * damping_mass;
    if (update) {
        *spring = add(*spring, scale(vt, dt));
        double along = dot(*spring, n);
        *spring = sub(*spring, scale(n, along));
    }
    v3 fs = neg(add(scale(*spring, law.kt), scale(vt, gamma)));
    double cap = law.mu * fabs(fn_total);
    double fs2 = dot(fs, fs);
    bool sliding = fs2 > cap * cap;
    double s = cap / sqrt(fs2);
    double s2 = dot(*spring, *spring);
    bool cut = sliding && s2 != 0.0;
    bool kill = sliding && s2 == 0.0;
    v3 damp = scale(vt, gamma / law.kt);
    v3 cut_spring = sub(scale(add(*spring, damp), s), damp);
    if (cut) *spring = cut_spring;
    v3 capped = sliding ? scale(fs, s) : fs;
    v3 tangential = kill ? mk(0.0, 0.0, 0.0) : capped;
    Push out;
    out.force = add(scale(n, fn_total), tangential);
    out.nt = cross(n, tangential);
    return out;
}

__device__ __forceinline__ double damping_mass(double mi, bool fi, double mj, bool fj) {
    if (fj) return mi;
    if (fi) return mj;
    return mi * mj / (mi + mj);
}

struct ForceArgs {
    Hooke law;
    double shifts[27][3];
    Plane walls[MAX_WALLS];
    u32 n_walls;
    double gravity[3];
    double dt;
    u32 update;
};

extern "C" __global__ void forces(Grains g, Lists ls, Soa3 wall_springs, ForceArgs a, u64 *st) {
    if (!gate(st, GATE_ALWAYS)) return;
    const List l = ls.l[st[ST_BUILDS] & 1];
    u64 gi = thread_index();
    u64 pair_ends = 0, walls = 0;
    double worst = 0.0;
    if (gi < g.n) {
        v3 f = mk(0.0, 0.0, 0.0);
        v3 t = mk(0.0, 0.0, 0.0);
        for (u32 e = l.start[gi]; e < l.start[gi + 1]; e++) {
            u64 p = l.partner[e];
            bool lower = g.rank[gi] < g.rank[p];
            u64 i = lower ? gi : p;
            u64 j = lower ? p : gi;
            u8 code = l.image[e];
            v3 sh = mk(a.shifts[code][0], a.shifts[code][1], a.shifts[code][2]);
            v3 del = sub(get(g.pos, i), add(get(g.pos, j), sh));
            double ri = g.radius[i], rj = g.radius[j];
            double radsum = ri + rj;
            double r2 = dot(del, del);
            if (r2 >= radsum * radsum) {
                set(l.springs, e, mk(0.0, 0.0, 0.0));
                continue;
            }
            double r = sqrt(r2);
            double overlap = ri + rj - r;
            v3 n = scale(del, 1.0 / r);
            v3 spin = add(scale(get(g.omega, i), ri), scale(get(g.omega, j), rj));
            v3 v_rel = sub(sub(get(g.vel, i), get(g.vel, j)), cross(spin, n));
            double dm = damping_mass(g.mass[i], g.frozen[i] != 0, g.mass[j], g.frozen[j] != 0);
            v3 spring = get(l.springs, e);
            Push push = hooke(a.law, n, overlap, v_rel, dm, &spring, a.dt, a.update != 0);
            set(l.springs, e, spring);
            if (gi == i) {
                f = add(f, push.force);
                t = sub(t, scale(push.nt, ri));
            } else {
                f = add(f, neg(push.force));
                t = sub(t, scale(push.nt, rj));
            }
            pair_ends++;
            worst = fmax(worst, overlap / fmin(ri, rj));
        }
        if (g.frozen[gi] == 0) {
            v3 x = get(g.pos, gi);
            double r = g.radius[gi], m = g.mass[gi];
            for (u32 w = 0; w < a.n_walls; w++) {
                const Plane &wall = a.walls[w];
                u64 k = gi * a.n_walls + w;
                v3 point = mk(wall.point[0], wall.point[1], wall.point[2]);
                v3 n = mk(wall.normal[0], wall.normal[1], wall.normal[2]);
                double s = dot(sub(x, point), n);
                double overlap = r - s;
                if (overlap <= 0.0 || s < -r) {
                    set(wall_springs, k, mk(0.0, 0.0, 0.0));
                    continue;
                }
                v3 v_rel = sub(get(g.vel, gi), cross(scale(get(g.omega, gi), r), n));
                Hooke law = a.law;
                law.gamma_n = wall.gamma_n;
                v3 spring = get(wall_springs, k);
                Push push = hooke(law, n, overlap, v_rel, m, &spring, a.dt, a.update != 0);
                set(wall_springs, k, is_zero(spring) ? mk(0.0, 0.0, 0.0) : spring);
                f = add(f, push.force);
                t = sub(t, scale(push.nt, r));
                walls++;
                worst = fmax(worst, overlap / r);
            }
            f = add(f, scale(mk(a.gravity[0], a.gravity[1], a.gravity[2]), m));
        }
        set(g.force, gi, f);
        set(g.torque, gi, t);
    }
    // Per warp, then one atomic each (integers; the maximum of
    // non-negative doubles is the maximum of their bits).
    for (int off = 16; off > 0; off >>= 1) {
        pair_ends += __shfl_down_sync(0xffffffffu, pair_ends, off);
        walls += __shfl_down_sync(0xffffffffu, walls, off);
        worst = fmax(worst, __shfl_down_sync(0xffffffffu, worst, off));
    }
    if ((threadIdx.x & 31) == 0) {
        if (pair_ends) atomicAdd(&st[ST_PAIR_ENDS], pair_ends);
        if (walls) atomicAdd(&st[ST_WALLS], walls);
        if (worst > 0.0) atomicMax(&st[ST_MAX_FRACTION], (u64)__double_as_longlong(worst));
    }
}
