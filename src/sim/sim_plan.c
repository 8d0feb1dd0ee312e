// SPDX-License-Identifier: MIT
// The direct solver's schedule: which bodies are eliminated side by side (SIM_W lanes of a
// block) and in which order, and how the tree is cut between threads.
//
// A body can be eliminated once its children are. Tips are ready at once and go first, in
// blocks of tips only (their body matrix is diagonal, sim_direct.c has a kernel for it); then
// list scheduling: each block takes the SIM_W ready bodies farthest from the root (the longest
// chain still to go), which packs the tomato's 1455 bodies into 190 blocks of 8 (182 at best).
// For several threads the tree is cut into subtrees, split from the root down until the largest
// holds at most nbody / (4 nthread) bodies, and handed out largest first to the least loaded
// thread; the bodies split off form the top part, eliminated after the subtrees.
#include <stdlib.h>

#include "sim_internal.h"

// binary max-heap of bodies by (depth, -index)
typedef struct heap {
  int* v;
  int n;
  const int* key;
} heap;

static int above(const heap* h, int a, int b) {
  int ka = h->key[a], kb = h->key[b];
  return ka > kb || (ka == kb && a < b);
}

static void heap_push(heap* h, int x) {
  int i = h->n++;
  h->v[i] = x;
  while (i > 0 && above(h, h->v[i], h->v[(i - 1) / 2])) {
    int p = (i - 1) / 2, t = h->v[p];
    h->v[p] = h->v[i], h->v[i] = t, i = p;
  }
}

static int heap_pop(heap* h) {
  int top = h->v[0];
  h->v[0] = h->v[--h->n];
  for (int i = 0;;) {
    int l = 2 * i + 1, r = l + 1, b = i;
    if (l < h->n && above(h, h->v[l], h->v[b])) b = l;
    if (r < h->n && above(h, h->v[r], h->v[b])) b = r;
    if (b == i) break;
    int t = h->v[b];
    h->v[b] = h->v[i], h->v[i] = t, i = b;
  }
  return top;
}

// scratch of a plan build (segment-indexed unless said)
typedef struct build {
  const vd_sim_model* m;
  int ns;
  int* par;      // parent body or -1
  int* kstart;   // children of t: kids[kstart[t] .. kstart[t + 1]) in index order (ns + 1)
  int* kids;
  int* depth;    // bodies between t and its root
  int* size;     // bodies in t's subtree
  int* owner;    // part of each body: thread k, or nthread for the top part
  int* pending;  // children not yet scheduled
  int* order;    // bodies in schedule order, -1 for padding lanes (grows by SIM_W per block)
  int norder;
  unsigned char* tips;  // per block
  unsigned char* holds; // 1 for bodies with held children (not tips)
  int nblock;
  heap hp;
} build;

static int is_body(const vd_sim_model* m, int t) { return !(m->seg_flags[t] & VD_SIM_FIXED); }

// close the current block: pad it to SIM_W lanes
static void close_block(build* b, int lanes, int tip) {
  for (int l = lanes; l < SIM_W; l++) b->order[b->norder++] = -1;
  b->tips[b->nblock++] = (unsigned char)tip;
}

// a body was scheduled: its parent (in the same part) may become ready
static void release(build* b, int t, int part) {
  int p = b->par[t];
  if (p >= 0 && b->owner[p] == part && --b->pending[p] == 0) heap_push(&b->hp, p);
}

// schedule the bodies of one part: tips in blocks of their own, then list scheduling
static void schedule_part(build* b, int part) {
  const vd_sim_model* m = b->m;
  int lanes = 0;
  // pending children inside the part (children elsewhere are done before this part runs)
  for (int t = 0; t < b->ns; t++) {
    if (!is_body(m, t) || b->owner[t] != part) continue;
    b->pending[t] = 0;
    for (int k = b->kstart[t]; k < b->kstart[t + 1]; k++) b->pending[t] += b->owner[b->kids[k]] == part;
  }
  b->hp.n = 0;
  // bodies whose children are all elsewhere (or held) are ready at once
  for (int t = 0; t < b->ns; t++)
    if (is_body(m, t) && b->owner[t] == part && (b->kstart[t + 1] > b->kstart[t] || b->holds[t]) && b->pending[t] == 0)
      heap_push(&b->hp, t);
  // tips (no children at all), in index order
  for (int t = 0; t < b->ns; t++) {
    if (!is_body(m, t) || b->owner[t] != part || b->kstart[t + 1] > b->kstart[t] || b->holds[t]) continue;
    b->order[b->norder++] = t;
    if (++lanes == SIM_W) close_block(b, lanes, 1), lanes = 0;
  }
  if (lanes) close_block(b, lanes, 1);
  for (int t = 0; t < b->ns; t++)
    if (is_body(m, t) && b->owner[t] == part && b->kstart[t + 1] == b->kstart[t] && !b->holds[t]) release(b, t, part);
  // list scheduling: a block takes the ready bodies farthest from the root; their parents may
  // become ready only for the next block
  int batch[SIM_W];
  while (b->hp.n) {
    int nb = 0;
    while (nb < SIM_W && b->hp.n) batch[nb++] = heap_pop(&b->hp);
    for (int k = 0; k < nb; k++) b->order[b->norder++] = batch[k];
    close_block(b, nb, 0);
    for (int k = 0; k < nb; k++) release(b, batch[k], part);
  }
}

int sim_parallel(int nt, int n, sim_range_fn fn, void* ctx) {
  int nc = nt < n / 256 ? nt : n / 256;
  if (nc > SIM_MAX_THREADS) nc = SIM_MAX_THREADS;
  if (nc <= 1) {
    fn(ctx, 0, 0, n);
    return 1;
  }
#pragma omp parallel for num_threads(nt) schedule(static, 1)
  for (int k = 0; k < nc; k++) fn(ctx, k, (int)((long)n * k / nc), (int)((long)n * (k + 1) / nc));
  return nc;
}

void sim_plan_free(sim_plan* p) {
  vd_free(p->mem, p->nbytes);
  memset(p, 0, sizeof *p);
}

vd_status sim_plan_build(const vd_sim_model* m, int nthread, sim_plan* p) {
  sim_plan_free(p);
  if (nthread < 1) nthread = 1;
  if (nthread > SIM_MAX_THREADS) nthread = SIM_MAX_THREADS;
  int ns = m->nseg, nsp = m->nspare;
  build b;
  memset(&b, 0, sizeof b);
  b.m = m, b.ns = ns;
  size_t n1 = (size_t)ns + 1, I = sizeof(int);
  // worst case every block holds one body: SIM_W slots per body
  size_t nord = (size_t)SIM_W * (size_t)(ns + 1);
  b.par = vd_malloc(n1 * I), b.kstart = vd_calloc(n1 + 1, I), b.kids = vd_malloc(n1 * I);
  b.depth = vd_calloc(n1, I), b.size = vd_calloc(n1, I), b.owner = vd_calloc(n1, I);
  b.pending = vd_calloc(n1, I), b.order = vd_malloc(nord * I), b.tips = vd_malloc(nord);
  b.hp.v = vd_malloc(n1 * I);
  vd_status st = VD_OK;
  if (!b.par || !b.kstart || !b.kids || !b.depth || !b.size || !b.owner || !b.pending || !b.order || !b.tips ||
      !b.hp.v) {
    st = VD_ERR_NOMEM;
    goto done;
  }
  // parents, children (index order), depth and subtree size through the model's order; bodies
  // with held children (region of interest) are not tips: their joints add to the body matrix
  int nbody = 0, nheld = 0;
  for (int t = 0; t < ns; t++) {
    int q = m->seg_parent[t];
    if ((m->seg_flags[t] & VD_SIM_HELD) && q >= 0 && is_body(m, q)) nheld++, b.depth[q] = -1;
  }
  for (int t = 0; t < ns; t++) {
    int q = m->seg_parent[t];
    b.par[t] = is_body(m, t) && q >= 0 && is_body(m, q) ? q : -1;
    if (is_body(m, t)) nbody++;
    if (b.par[t] >= 0) b.kstart[b.par[t] + 1]++;
  }
  for (int t = 0; t < ns; t++) b.kstart[t + 1] += b.kstart[t];
  {
    int* fill = b.pending;  // reused as a cursor
    for (int t = 0; t < ns; t++) fill[t] = b.kstart[t];
    for (int t = 0; t < ns; t++)
      if (b.par[t] >= 0) b.kids[fill[b.par[t]]++] = t;
  }
  unsigned char* holds = vd_calloc(n1, 1);  // bodies with held children
  if (!holds) {
    st = VD_ERR_NOMEM;
    goto done;
  }
  for (int t = 0; t < ns; t++) holds[t] = b.depth[t] < 0, b.depth[t] = 0;
  b.holds = holds;
  for (int i = ns - 1; i >= 0; i--) {  // parents first
    int t = m->seg_order[i];
    if (is_body(m, t)) b.depth[t] = b.par[t] >= 0 ? b.depth[b.par[t]] + 1 : 0;
  }
  for (int i = 0; i < ns; i++) {  // children first
    int t = m->seg_order[i];
    if (!is_body(m, t)) continue;
    b.size[t] += 1;
    if (b.par[t] >= 0) b.size[b.par[t]] += b.size[t];
  }
  b.hp.key = b.depth;
  // the cut: split the largest subtree (its root goes to the top part, its children become
  // subtrees) as long as that shortens the estimated elimination, the largest thread's bodies
  // / SIM_W (subtrees pack into full blocks, handed out largest first to the least loaded
  // thread) plus the top part's bodies (a chain: about a block each); then cut there
  if (nthread > 1) {
    heap cut = {b.hp.v, 0, b.size};
    int* sorted = b.pending;  // scratch for the assignment
    int best_splits = 0, splits = 0;
    double best = 1e300;
    for (int pass = 0; pass < 2; pass++) {
      cut.n = 0, splits = 0;
      for (int t = 0; t < ns; t++) {
        b.owner[t] = 0;
        if (is_body(m, t) && b.par[t] < 0) heap_push(&cut, t);
      }
      for (;;) {
        // the assignment of the current subtrees (the heap holds them, largest first)
        long load[SIM_MAX_THREADS] = {0};
        int nsub = cut.n;
        memcpy(sorted, cut.v, (size_t)nsub * sizeof(int));
        heap tmp = {sorted, nsub, b.size};  // a copy of the heap: popped largest first
        while (tmp.n) {
          int t = heap_pop(&tmp), k0 = 0;
          for (int k = 1; k < nthread; k++)
            if (load[k] < load[k0]) k0 = k;
          load[k0] += b.size[t];
          if (pass == 1 && splits == best_splits) b.owner[t] = k0;
        }
        long mx = 0;
        for (int k = 0; k < nthread; k++) mx = load[k] > mx ? load[k] : mx;
        double est = (double)mx / SIM_W + splits;
        if (pass == 0 && est < best) best = est, best_splits = splits;
        // finer cuts than nbody / (16 nthread) do not pay
        if ((pass == 1 && splits == best_splits) || !cut.n || b.size[cut.v[0]] * 16 * nthread <= nbody) break;
        int t = heap_pop(&cut);
        b.owner[t] = nthread;
        splits++;
        for (int k = b.kstart[t]; k < b.kstart[t + 1]; k++) heap_push(&cut, b.kids[k]);
      }
    }
    // every body below a cut root takes its root's owner: walk parents first
    for (int i = ns - 1; i >= 0; i--) {
      int u = m->seg_order[i];
      if (!is_body(m, u) || b.owner[u] == nthread) continue;
      int q = b.par[u];
      if (q >= 0 && b.owner[q] != nthread) b.owner[u] = b.owner[q];
    }
  }
  // schedule each part
  for (int k = 0; k <= nthread; k++) {
    p->part[k] = b.nblock;
    schedule_part(&b, k);
  }
  p->nthread = nthread;
  // one allocation: slots, parents, children, tips, ties, spares, then the aligned blocks
  {
    int nblock = b.nblock, nslot = nblock * SIM_W, nkid = b.kstart[ns];
    size_t top = 0;
#define TAKE(n) (top = (top + 15) & ~(size_t)15, top += (n), top - (n))
    size_t o_ss = TAKE((size_t)nslot * I), o_gs = TAKE((size_t)ns * I), o_ps = TAKE((size_t)nslot * I);
    size_t o_ks = TAKE(((size_t)nslot + 1) * I), o_kd = TAKE(((size_t)nkid + 1) * I), o_tb = TAKE((size_t)nblock + 1);
    size_t o_th = TAKE(((size_t)nslot + nsp) * sizeof(double)), o_tg = TAKE(((size_t)nslot + nsp) * 3 * sizeof(double));
    size_t o_sd = TAKE(((size_t)nsp + 1) * 3 * sizeof(double));
    size_t o_hs = TAKE(((size_t)nslot + 1) * I), o_hg = TAKE(((size_t)nheld + 1) * I);
    size_t o_hl = TAKE(((size_t)nheld + 1) * 30 * sizeof(double));
    size_t o_bk = TAKE((size_t)nblock * sizeof(sim_blk) + 64);
    size_t o_st = TAKE((size_t)nblock * sizeof(sim_stat) + 64);
    size_t o_kc = TAKE((size_t)nblock * sizeof(sim_kid) + 64);
    // rounds of children: the most children of a body in each block
    int nround = 0;
    for (int bk = 0; bk < nblock; bk++)
      for (int l = 0, most = 0; l < SIM_W; l++) {
        int t = b.order[bk * SIM_W + l], nk = t >= 0 ? b.kstart[t + 1] - b.kstart[t] : 0;
        if (nk > most) nround += nk - most, most = nk;
      }
    size_t o_po = TAKE((size_t)nslot * sizeof(ptrdiff_t)), o_pu = TAKE((size_t)nslot * sizeof(double));
    size_t o_kr = TAKE(((size_t)nblock + 1) * I), o_ko = TAKE(((size_t)nround + 1) * SIM_W * sizeof(ptrdiff_t));
    size_t o_ku = TAKE(((size_t)nround + 1) * SIM_W * sizeof(double));
#undef TAKE
    char* mem = vd_calloc(1, top);
    if (!mem) {
      st = VD_ERR_NOMEM;
      goto done;
    }
    p->mem = mem, p->nbytes = top;
    p->nbody = nbody, p->nblock = nblock, p->nslot = nslot;
    p->part[nthread + 1] = nblock;
    p->slot_seg = (int*)(mem + o_ss), p->seg_slot = (int*)(mem + o_gs), p->par_slot = (int*)(mem + o_ps);
    p->kid_start = (int*)(mem + o_ks), p->kid_slot = (int*)(mem + o_kd), p->tip_block = (unsigned char*)(mem + o_tb);
    p->held_start = (int*)(mem + o_hs), p->held_seg = (int*)(mem + o_hg), p->held_lin = (double*)(mem + o_hl);
    p->tie_h = (double*)(mem + o_th), p->tie_g = (double*)(mem + o_tg), p->spare_dy = (double*)(mem + o_sd);
    uintptr_t a = (uintptr_t)(mem + o_bk);
    p->blk = (sim_blk*)(mem + o_bk + ((64 - (a & 63)) & 63));
    a = (uintptr_t)(mem + o_st);
    p->stat = (sim_stat*)(mem + o_st + ((64 - (a & 63)) & 63));
    a = (uintptr_t)(mem + o_kc);
    p->kid = (sim_kid*)(mem + o_kc + ((64 - (a & 63)) & 63));
    p->poff = (ptrdiff_t*)(mem + o_po), p->puse = (double*)(mem + o_pu);
    p->kround = (int*)(mem + o_kr), p->koff = (ptrdiff_t*)(mem + o_ko), p->kuse = (double*)(mem + o_ku);
    memcpy(p->tip_block, b.tips, (size_t)nblock);
    for (int t = 0; t < ns; t++) p->seg_slot[t] = -1;
    for (int s = 0; s < nslot; s++) {
      p->slot_seg[s] = b.order[s];
      if (b.order[s] >= 0) p->seg_slot[b.order[s]] = s;
    }
    // children by slot, in segment index order
    int nk = 0;
    for (int s = 0; s < nslot; s++) {
      int t = p->slot_seg[s];
      p->kid_start[s] = nk;
      p->par_slot[s] = t >= 0 && b.par[t] >= 0 ? p->seg_slot[b.par[t]] : -1;
      if (t < 0) continue;
      for (int k = b.kstart[t]; k < b.kstart[t + 1]; k++) p->kid_slot[nk++] = p->seg_slot[b.kids[k]];
    }
    p->kid_start[nslot] = nk;
    for (int s = 0; s < nslot; s++) {
      int ps = p->par_slot[s];
      p->puse[s] = ps >= 0;
      p->poff[s] = ps < 0 ? 0
                          : (ptrdiff_t)(ps / SIM_W) * (ptrdiff_t)(sizeof(sim_blk) / sizeof(double)) +
                                (ptrdiff_t)(offsetof(sim_blk, dy) / sizeof(double)) + ps % SIM_W;
    }
    // the rounds (koff and kuse are zero from the allocation)
    int nr = 0;
    for (int bk = 0; bk < nblock; bk++) {
      p->kround[bk] = nr;
      int most = 0;
      for (int l = 0; l < SIM_W; l++) {
        int s = bk * SIM_W + l, n = p->kid_start[s + 1] - p->kid_start[s];
        most = n > most ? n : most;
        for (int j = 0; j < n; j++) {
          int c = p->kid_slot[p->kid_start[s] + j];
          p->koff[SIM_W * (nr + j) + l] = (ptrdiff_t)(c / SIM_W) * (ptrdiff_t)(sizeof(sim_kid) / sizeof(double)) + c % SIM_W;
          p->kuse[SIM_W * (nr + j) + l] = 1;
        }
      }
      nr += most;
    }
    p->kround[nblock] = nr;
    // held children by slot, in segment index order
    int nh = 0;
    for (int s = 0; s < nslot; s++) {
      int t = p->slot_seg[s];
      p->held_start[s] = nh;
      if (t < 0 || !holds[t]) continue;
      for (int c = 0; c < ns; c++)
        if ((m->seg_flags[c] & VD_SIM_HELD) && m->seg_parent[c] == t) p->held_seg[nh++] = c;
    }
    p->held_start[nslot] = nh;
    // the model's data of each lane
    for (int s = 0; s < nslot; s++) {
      sim_stat* sb = &p->stat[s / SIM_W];
      int l = s % SIM_W, t = p->slot_seg[s];
      vd_quat q0 = t >= 0 ? m->seg_rest[t] : vd_quat_identity();
      sb->q0[0][l] = q0.w, sb->q0[1][l] = q0.x, sb->q0[2][l] = q0.y, sb->q0[3][l] = q0.z;
      for (int k = 0; k < 3; k++) {
        sb->cs[k][l] = t >= 0 ? m->seg_cs[3 * t + k] : 1.0;
        sb->cb[k][l] = t >= 0 ? m->seg_cb[3 * t + k] : 1.0;
      }
      sb->l0[l] = t >= 0 ? m->seg_len0[t] : 1.0, sb->lbar[l] = t >= 0 ? m->seg_lbar[t] : 1.0;
      sb->ib[l] = t >= 0 ? m->seg_inertia[2 * t] : 1.0, sb->it[l] = t >= 0 ? m->seg_inertia[2 * t + 1] : 1.0;
    }
  }
done:
  vd_free(b.par, n1 * I), vd_free(b.kstart, (n1 + 1) * I), vd_free(b.kids, n1 * I);
  vd_free(b.depth, n1 * I), vd_free(b.size, n1 * I), vd_free(b.owner, n1 * I);
  vd_free(b.pending, n1 * I), vd_free(b.order, nord * I), vd_free(b.tips, nord);
  vd_free(b.hp.v, n1 * I);
  vd_free(b.holds, n1);
  return st;
}
