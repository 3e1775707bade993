// The neighbour list, count-scan-fill: bins, prefix sums, rows in the
// reduction's order, springs remapped. Mirrors bin, exclusive_scan,
// build_list (mirror.rs) and visit_partners, order_row, remap_row
// (grain_kernels.rs). Only integer atomics (counts and fill cursors); every
// order that they leave to the threads is sorted afterwards.
#include "common.cuh"

struct Grid {
    u64 dims[3];
    double lo[3], inv_width[3];
};

__device__ __forceinline__ u64 coord(const Grid &gr, int a, double x) {
    double f = (x - gr.lo[a]) * gr.inv_width[a];
    f = fmax(f, 0.0);  // a NaN lands in cell 0, as Rust's max does
    double top = (double)(gr.dims[a] - 1);
    return f < top ? (u64)f : gr.dims[a] - 1;
}

// The kernels of the rebuild are gated on a step word (ST_BUILD, ST_SORT:
// `word`), so that they are launched every step and do nothing at a step
// without a rebuild.

// Cell of each grain, and the count of each cell (integer atomics).
extern "C" __global__ void bin_count(Grains g, Grid gr, u32 *cell, u32 *count, const u64 *st,
                                     u32 word) {
    u64 i = thread_index();
    if (i >= g.n || !gate(st, word)) return;
    u64 c = coord(gr, 0, g.pos.x[i]) +
            gr.dims[0] * (coord(gr, 1, g.pos.y[i]) + gr.dims[1] * coord(gr, 2, g.pos.z[i]));
    cell[i] = (u32)c;
    atomicAdd(&count[c], 1u);
}

// Exclusive prefix sums of `data` (n entries) in place, in three passes:
// each block of 1024 its own, the block totals, the totals added back.
#define SCAN_BLOCK 1024
extern "C" __global__ void scan_local(u32 *data, u32 *sums, u64 n, const u64 *st, u32 word) {
    if (!gate(st, word)) return;
    __shared__ u32 s[SCAN_BLOCK];
    u64 i = thread_index();
    u32 t = threadIdx.x;
    u32 x = i < n ? data[i] : 0;
    s[t] = x;
    __syncthreads();
    for (u32 off = 1; off < SCAN_BLOCK; off <<= 1) {
        u32 y = t >= off ? s[t - off] : 0;
        __syncthreads();
        s[t] += y;
        __syncthreads();
    }
    if (i < n) data[i] = s[t] - x;
    if (t == SCAN_BLOCK - 1) sums[blockIdx.x] = s[t];
}
// One block: the block totals' exclusive sums, 1024 at a time; the grand
// total goes to sums[nb].
extern "C" __global__ void scan_sums(u32 *sums, u64 nb, const u64 *st, u32 word) {
    if (!gate(st, word)) return;
    __shared__ u32 s[SCAN_BLOCK];
    __shared__ u32 carry;
    u32 t = threadIdx.x;
    if (t == 0) carry = 0;
    __syncthreads();
    for (u64 base = 0; base < nb; base += SCAN_BLOCK) {
        u64 i = base + t;
        u32 x = i < nb ? sums[i] : 0;
        s[t] = x;
        __syncthreads();
        for (u32 off = 1; off < SCAN_BLOCK; off <<= 1) {
            u32 y = t >= off ? s[t - off] : 0;
            __syncthreads();
            s[t] += y;
            __syncthreads();
        }
        if (i < nb) sums[i] = carry + s[t] - x;
        __syncthreads();
        if (t == SCAN_BLOCK - 1) carry += s[t];
        __syncthreads();
    }
    if (t == 0) sums[nb] = carry;
}
extern "C" __global__ void scan_add(u32 *data, const u32 *sums, u64 n, const u64 *st, u32 word) {
    u64 i = thread_index();
    if (i < n && gate(st, word)) data[i] += sums[blockIdx.x];
}

// Fill the bins in whatever order the threads come, then sort each cell.
extern "C" __global__ void bin_fill(const u32 *cell, u32 *cursor, u32 *members, u64 n,
                                    const u64 *st, u32 word) {
    u64 i = thread_index();
    if (i >= n || !gate(st, word)) return;
    u32 slot = atomicAdd(&cursor[cell[i]], 1u);
    members[slot] = (u32)i;
}
// Each cell's members by rank (the CPU engine's order within a cell).
extern "C" __global__ void bin_sort(const u32 *start, u32 *members, u64 ncells, const u32 *rank,
                                    const u64 *st, u32 word) {
    u64 c = thread_index();
    if (c >= ncells || !gate(st, word)) return;
    u32 a = start[c], b = start[c + 1];
    for (u32 k = a + 1; k < b; k++) {
        u32 x = members[k];
        u32 j = k;
        while (j > a && rank[members[j - 1]] > rank[x]) {
            members[j] = members[j - 1];
            j--;
        }
        members[j] = x;
    }
}

// The re-sort's permutation (list_build.rs sort_slots), gated on SORT.
// First each cell's count at its place in the stored order (Morton or the
// cells' own), then scanned into `first`; then for the q-th member of the
// bins read cell by cell (its new rank): its slot, its old index, its rank
// before, its new rank (into a buffer copied to the ranks after the move).
extern "C" __global__ void place_counts(const u32 *start, const u32 *places, u32 *counts,
                                        u64 ncells, const u64 *st) {
    u64 c = thread_index();
    if (c >= ncells || !gate(st, ST_SORT)) return;
    counts[places[c]] = start[c + 1] - start[c];
    if (c == 0) counts[ncells] = 0;
}
extern "C" __global__ void sort_slots(const u32 *members, const u32 *cell, const u32 *start,
                                      const u32 *places, const u32 *first, const u32 *rank,
                                      u32 *rank_before, u32 *order, u32 *new_rank, u64 n,
                                      const u64 *st) {
    u64 q = thread_index();
    if (q >= n || !gate(st, ST_SORT)) return;
    u32 k = members[q];
    u32 c = cell[k];
    rank_before[k] = rank[k];
    u32 slot = first[places[c]] + (u32)q - start[c];
    order[slot] = k;
    new_rank[slot] = (u32)q;
}

struct ListArgs {
    Grid grid;
    u32 *start_cells, *members, *cell;
    double length[3];
    double shifts[27][3];
    double skin;
    u32 periodic[3];
    u32 block;
};

struct AxisCells {
    u64 cells[3];
    int shift[3];
    u32 len;
    u32 min_image;
};

__device__ __forceinline__ AxisCells axis_cells(u64 n, u32 periodic, u64 c) {
    AxisCells st;
    st.len = 0;
    st.min_image = 0;
    if (periodic && n < 3) {
        for (u64 k = 0; k < n; k++) {
            st.cells[k] = k;
            st.shift[k] = 0;
        }
        st.len = (u32)n;
        st.min_image = 1;
    } else if (periodic) {
        st.cells[0] = c == 0 ? n - 1 : c - 1;
        st.shift[0] = c == 0 ? -1 : 0;
        st.cells[1] = c;
        st.shift[1] = 0;
        st.cells[2] = c + 1 == n ? 0 : c + 1;
        st.shift[2] = c + 1 == n ? 1 : 0;
        st.len = 3;
    } else {
        u64 k = c == 0 ? 0 : c - 1;
        u64 top = c + 1 < n - 1 ? c + 1 : n - 1;
        for (; k <= top; k++) {
            st.cells[st.len] = k;
            st.shift[st.len] = 0;
            st.len++;
        }
    }
    return st;
}

// The stencil walk of grain i: for every partner within reach, FOUND(p,
// code) with the image code of i's side.
#define VISIT_PARTNERS(FOUND)                                                                    \
    {                                                                                            \
        const Grid &gr = a.grid;                                                                 \
        v3 pg = get(g.pos, i);                                                                   \
        double rg = g.radius[i];                                                                 \
        bool fg = g.frozen[i] != 0;                                                              \
        u64 cl0 = a.cell[i];                                                                     \
        u64 c0 = cl0 % gr.dims[0], c1 = cl0 / gr.dims[0] % gr.dims[1],                           \
            c2 = cl0 / gr.dims[0] / gr.dims[1];                                                  \
        AxisCells st0 = axis_cells(gr.dims[0], a.periodic[0], c0);                               \
        AxisCells st1 = axis_cells(gr.dims[1], a.periodic[1], c1);                               \
        AxisCells st2 = axis_cells(gr.dims[2], a.periodic[2], c2);                               \
        bool any_min = st0.min_image || st1.min_image || st2.min_image;                          \
        for (u32 kz = 0; kz < st2.len; kz++)                                                     \
            for (u32 ky = 0; ky < st1.len; ky++)                                                 \
                for (u32 kx = 0; kx < st0.len; kx++) {                                           \
                    int base = 13 + st0.shift[kx] + 3 * st1.shift[ky] + 9 * st2.shift[kz];       \
                    u64 cl = st0.cells[kx] + gr.dims[0] * (st1.cells[ky] + gr.dims[1] * st2.cells[kz]); \
                    for (u32 m = a.start_cells[cl]; m < a.start_cells[cl + 1]; m++) {            \
                        u32 p = a.members[m];                                                    \
                        if (p == i || (fg && g.frozen[p] != 0)) continue;                        \
                        v3 pp = get(g.pos, p);                                                   \
                        int code = base;                                                         \
                        if (any_min) {                                                           \
                            double dpg[3] = {pg.x, pg.y, pg.z}, dpp[3] = {pp.x, pp.y, pp.z};     \
                            const AxisCells *sts[3] = {&st0, &st1, &st2};                        \
                            const int pow3[3] = {1, 3, 9};                                       \
                            for (int ax = 0; ax < 3; ax++)                                       \
                                if (sts[ax]->min_image)                                          \
                                    code += (int)round((dpg[ax] - dpp[ax]) / a.length[ax]) * pow3[ax]; \
                        }                                                                        \
                        v3 sh = mk(a.shifts[code][0], a.shifts[code][1], a.shifts[code][2]);     \
                        v3 d = sub(sub(pg, pp), sh);                                             \
                        double cut = rg + g.radius[p] + a.skin;                                  \
                        if (dot(d, d) < cut * cut) { FOUND(p, code); }                           \
                    }                                                                            \
                }                                                                                \
    }

// Partners of each grain (count[n] = 0: the scan makes it the total);
// scanned into row starts.
extern "C" __global__ void list_count(Grains g, ListArgs a, u32 *count, const u64 *st) {
    u32 i = (u32)thread_index();
    if (i >= g.n || !gate(st, ST_BUILD)) return;
    if (i == 0) count[g.n] = 0;
    u32 c = 0;
#define COUNT_ONE(p, code) c++
    VISIT_PARTNERS(COUNT_ONE)
    count[i] = c;
}

// row_key of grain_kernels.rs as one integer: class in the top bits.
__device__ __forceinline__ u64 row_key(u32 g, u32 p, u32 block) {
    if (p > g) return 1ull << 32;
    if (p >= g / block * block) return (u64)p;
    return (2ull << 32) | p;
}

// The rows into the other buffer, from the scanned counts `start`; when
// they do not fit its capacity, a halt at this step with the entries
// needed (every thread reads the same total and returns).
extern "C" __global__ void list_fill(Grains g, ListArgs a, Lists ls, const u32 *start, u64 *st) {
    u32 i = (u32)thread_index();
    if (i >= g.n || !gate(st, ST_BUILD)) return;
    u32 next = (u32)((st[ST_BUILDS] + 1) & 1);
    u64 total = start[g.n];
    if (total > ls.cap[next]) {
        if (i == 0) {
            st[ST_HALT] = HALT_OVERFLOW;
            st[ST_HALT_STEP] = st[ST_STEP];
            st[ST_NEED] = total;
        }
        return;
    }
    List l = ls.l[next];
    l.start[i] = start[i];
    if (i + 1 == g.n) l.start[g.n] = start[g.n];
    u32 k = start[i];
#define FILL_ONE(p, code)                                         \
    l.partner[k] = p;                                             \
    l.image[k] = (u8)(g.rank[p] > g.rank[i] ? code : 26 - code);  \
    k++
    VISIT_PARTNERS(FILL_ONE)
    // The row in the reduction's order: a stable insertion sort in place.
    u32 r0 = start[i], r1 = start[i + 1];
    for (u32 e = r0 + 1; e < r1; e++) {
        u32 p = l.partner[e];
        u8 code = l.image[e];
        u64 key = row_key(g.rank[i], g.rank[p], a.block);
        u32 m = e;
        while (m > r0 && row_key(g.rank[i], g.rank[l.partner[m - 1]], a.block) > key) {
            l.partner[m] = l.partner[m - 1];
            l.image[m] = l.image[m - 1];
            m--;
        }
        l.partner[m] = p;
        l.image[m] = code;
    }
}

// Each new entry's spring from the old list (old_of: old index of each
// grain after a re-sort, rank_before: ranks by old index), negated when
// the pair's lower rank changed sides; and the grain's reference position
// for the skin test.
extern "C" __global__ void remap_springs(Grains gr, Lists ls, const u32 *old_of,
                                         const u32 *rank_before, const u64 *st) {
    u32 g = (u32)thread_index();
    if (g >= gr.n || !gate(st, ST_BUILD)) return;
    u32 cur = (u32)(st[ST_BUILDS] & 1);
    List nl = ls.l[cur ^ 1u], ol = ls.l[cur];
    bool sorted = st[ST_SORT] != 0;
    const u32 *old_rank = sorted ? rank_before : gr.rank;
    u32 og = sorted ? old_of[g] : g;
    for (u32 e = nl.start[g]; e < nl.start[g + 1]; e++) {
        u32 p = nl.partner[e];
        u32 op = sorted ? old_of[p] : p;
        v3 s = mk(0.0, 0.0, 0.0);
        for (u32 k = ol.start[og]; k < ol.start[og + 1]; k++) {
            if (ol.partner[k] == op) {
                v3 o = get(ol.springs, k);
                if (!is_zero(o))
                    s = ((gr.rank[g] < gr.rank[p]) == (old_rank[og] < old_rank[op])) ? o : neg(o);
                break;
            }
        }
        set(nl.springs, e, s);
    }
    set(gr.reference, g, get(gr.pos, g));
}
