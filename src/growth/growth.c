// SPDX-License-Identifier: MIT
// The growth loop (Lim & Gobeawan 2024, Algorithms 1 and 2; growth.h): derive one age step,
// rebuild the plant and its physics, carry the state by stable ids, substeps, masses, pruning.
//
// Stable ids. Each module of the derived string has an id; a derivation step (vd_lsys_derive_step)
// tells for every new module which old module it came from, and the first module of the same
// symbol that an old module becomes keeps its id (I(l, r, a) -> I(l, r, a + 1)); every other
// module is new. A plant segment is known by (module id, its rank among the segments of that
// module) and a node by the segment that ends at it (or, for a base, the first segment that
// starts at it).
//
// Placing new nodes. A new node n hangs from its nearest old ancestor a. Its rest position is
// a's rest position plus the turtle's offset turned by the rotation between a's internode as the
// turtle drew it and as it rests now (gravitropism may have turned it); its position is a's
// position plus that rest offset turned by a's deformation (the rotation of a's internode from
// rest to now). The same rule moves leaves, fruits and their meshes with the stem node they
// hang from.
#include <math.h>
#include <stdlib.h>
#include <stdio.h>
#include <string.h>

#include "verdant/growth.h"

// ---------------------------------------------------------------------------------------------
// small helpers

static vd_quat qbetween(vd_vec3 a, vd_vec3 b) {
  double na = vd_norm(a), nb = vd_norm(b);
  if (!(na > 0) || !(nb > 0)) return vd_quat_identity();
  a = vd_scale(a, 1.0 / na), b = vd_scale(b, 1.0 / nb);
  double c = vd_dot(a, b);
  vd_vec3 ax = vd_cross(a, b);
  if (c < -1 + 1e-12) {
    vd_vec3 o = fabs(a.x) < 0.9 ? vd_v3(1, 0, 0) : vd_v3(0, 1, 0);
    vd_vec3 n = vd_normalize(vd_cross(a, o));
    vd_quat q = {0, n.x, n.y, n.z};
    return q;
  }
  vd_quat q = {1 + c, ax.x, ax.y, ax.z};
  return vd_quat_normalize(q);
}

static int finite3(vd_vec3 v) { return isfinite(v.x) && isfinite(v.y) && isfinite(v.z); }

// stable key of a plant element: module id, rank, end
static uint64_t pack_key(int64_t uid, int rank, int end) {
  return ((uint64_t)(uid + 2) << 21) ^ ((uint64_t)(rank & 0xfffff) << 1) ^ (uint64_t)(end & 1);
}

static uint64_t mix(uint64_t x) {
  x ^= x >> 33;
  x *= 0xff51afd7ed558ccdULL;
  x ^= x >> 33;
  x *= 0xc4ceb9fe1a85ec53ULL;
  x ^= x >> 33;
  return x;
}

// ---------------------------------------------------------------------------------------------
// the state carried from one plant to the next, per plant node

typedef struct carry {
  int n;               // plant nodes
  uint64_t* key;       // stable key
  vd_vec3* turtle;     // position as the turtle drew it (m)
  vd_vec3* rest;       // rest position (m)
  vd_vec3* pos;        // deformed position (m)
  vd_vec3* vel;        // velocity (m/s)
  vd_vec3* body;       // position in the rigid body's frame (m)
  double* mass;        // physics mass (kg), 0 when not a physics node
  double* stiff;       // bending stiffness measure of the segment that ends at the node, 0 for
                       // bases (seg_stiffness)
  int* parent;         // plant node at the start of the segment that ends here, -1
  unsigned char* rigid, *yielded;
  int hcap;            // hash table of keys: index + 1, 0 empty
  int* slot;
  size_t nbytes;       // size of the block
} carry;

static void carry_free(carry* c) {
  if (c->key) vd_free(c->key, c->nbytes);
  memset(c, 0, sizeof *c);
}

static int carry_alloc(carry* c, int n) {
  carry_free(c);
  int hcap = 16;
  while (hcap < 2 * n + 2) hcap *= 2;
  size_t n1 = (size_t)(n ? n : 1);
  size_t nb = n1 * (sizeof(uint64_t) + 5 * sizeof(vd_vec3) + 2 * sizeof(double) + sizeof(int) + 2) + (size_t)hcap * sizeof(int) + 64;
  char* b = vd_calloc(1, nb);
  if (!b) return 0;
  c->nbytes = nb;
  c->n = n;
  c->key = (uint64_t*)b;
  c->turtle = (vd_vec3*)(c->key + n1);
  c->rest = c->turtle + n1;
  c->pos = c->rest + n1;
  c->vel = c->pos + n1;
  c->body = c->vel + n1;
  c->mass = (double*)(c->body + n1);
  c->stiff = c->mass + n1;
  c->parent = (int*)(c->stiff + n1);
  c->slot = c->parent + n1;
  c->hcap = hcap;
  c->rigid = (unsigned char*)(c->slot + hcap);
  c->yielded = c->rigid + n1;
  return 1;
}

static void carry_index(carry* c) {
  memset(c->slot, 0, sizeof(int) * (size_t)c->hcap);
  for (int i = 0; i < c->n; i++) {
    uint64_t h = mix(c->key[i]) & (uint64_t)(c->hcap - 1);
    while (c->slot[h]) h = (h + 1) & (uint64_t)(c->hcap - 1);
    c->slot[h] = i + 1;
  }
}

static int carry_find(const carry* c, uint64_t key) {
  if (!c->n) return -1;
  uint64_t h = mix(key) & (uint64_t)(c->hcap - 1);
  while (c->slot[h]) {
    int i = c->slot[h] - 1;
    if (c->key[i] == key) return i;
    h = (h + 1) & (uint64_t)(c->hcap - 1);
  }
  return -1;
}

// ---------------------------------------------------------------------------------------------
// the grower

// The physics engine of a grower: everything the loop does differently for the mass-spring trees
// (mss, mrl) and the rods goes through one of these (the table is engine_of, at the end of the
// engines' section); the loop itself never asks which engine it runs.
typedef struct growth_engine {
  vd_status (*build)(vd_growth* g, vd_error* err);          // physics of g->plant (old freed)
  vd_status (*map)(vd_growth* g, int grown, vd_error* err); // attachments; state from the carried one
  vd_status (*step)(vd_growth* g);                          // one substep: its status (vd_sim_step)
  vd_status (*end_age)(vd_growth* g, vd_error* err);        // after the substeps: time, events, masses
  void (*read)(vd_growth* g);                               // plant nodes' positions and velocities
  void (*carry)(vd_growth* g);                              // the engine's part of the carried record
  void (*settle)(vd_growth* g);                             // stress of the state as it stands
  void (*stats)(const vd_growth* g, vd_growth_stats* out);  // the engine's part of the summary
  void (*stress)(const vd_growth* g, double* ns, double* ss); // per node and segment (NaN: none)
} growth_engine;

static const growth_engine* engine_of(vd_growth_model m);

struct vd_growth {
  vd_growth_def def;
  const growth_engine* eng;  // engine_of(def.model)
  vd_lsystem* ls;
  vd_lstring str;          // derived string
  int64_t* uid;            // module ids (str.n, capacity cap_uid)
  int64_t cap_uid, next_uid;
  int age;
  double time;
  // the plant now
  vd_plant_spec* spec;     // as the turtle drew it
  vd_model* plant;         // compiled with the rest shape
  int nnode;               // plant nodes
  uint64_t* key;           // stable key per plant node
  vd_vec3 *rest, *pos, *vel;  // per plant node (nnode)
  int* owner_seg;          // segment ending at each plant node, -1 (nnode)
  int* attach;             // physics node a plant node moves with, -1 (nnode)
  int* pmap;               // plant node -> mass-spring node, -1 (nnode)
  size_t nbytes_node;      // size of the per-node block
  // physics
  vd_mss_model* mm;
  vd_mss_data* md;
  int mss_events_seen;     // events of md already turned into growth events
  vd_sim_model* rm;
  vd_sim_data* rd;
  vd_data* rpd;            // plant state the rods write (vd_sim_to_plant)
  vd_sim_soil* soil;
  // carried
  carry c;
  vd_rigid rb;
  int uprooted;
  int anchor_failed;
  double anchor_load;
  double drawn_max;        // the largest drawn height at any age so far (m)
  // events and summaries
  vd_growth_event* ev;
  int nev, cap_ev;
  int* broken_seg;         // plant segments broken in this age step (nbroken_step)
  int nbroken_step, cap_broken;
  double momentum_error, angular_error;
  int64_t substeps, cg_iterations, unstable;
  int nbroken;
};

const char* vd_growth_model_name(vd_growth_model m) {
  static const char* n[3] = {"mss", "mrl", "rods"};
  return m >= 0 && m <= VD_GROWTH_RODS ? n[m] : "?";
}

vd_growth_def vd_growth_def_default(void) {
  vd_growth_def d;
  memset(&d, 0, sizeof d);
  d.model = VD_GROWTH_MRL;
  d.ages = 0;
  d.substeps = 50;
  d.lsys = vd_lsys_def_default();
  d.turtle = vd_turtle_def_default();
  d.mss = vd_mss_def_default();
  d.mss.rigid_age = 3;
  d.opt = vd_mss_opt_default();
  d.rods = vd_sim_def_default();
  d.rod_opt = vd_sim_opt_default();
  d.rod_opt.dt = 0.01;
  d.paper_eq8 = 0;
  d.bastien_substeps = 20;
  d.stress_free = 1;
  d.uproot_tilt = 10 * VD_PI / 180;
  return d;
}

void vd_growth_def_paper(vd_growth_def* d) {
  d->mss.springs = VD_MSS_PAPER;
  d->opt.integrator = VD_MSS_EQ3;
  d->opt.wind_model = VD_MSS_WIND_PAPER;
  d->opt.drag = VD_MSS_DRAG_STOKES;
  d->opt.drag_cd = 1;  // sec. 3.3: C_drag set to 1 (Suzuki and Arikawa 2010)
  d->opt.strain_limit = 0;
  d->opt.rigid_release = 0;
  d->paper_eq8 = 1;
  d->stress_free = 0;
  d->paper_masses = 1;
  d->paper_rigid = 1;
}

static void free_nodes(vd_growth* g) {
  if (g->key) vd_free(g->key, g->nbytes_node);
  g->key = NULL;
  g->nbytes_node = 0;
  g->nnode = 0;
}

static int alloc_nodes(vd_growth* g, int n) {
  free_nodes(g);
  size_t n1 = (size_t)(n ? n : 1);
  size_t nb = n1 * (sizeof(uint64_t) + 3 * sizeof(vd_vec3) + 3 * sizeof(int)) + 32;
  char* b = vd_calloc(1, nb);
  if (!b) return 0;
  g->nbytes_node = nb;
  g->nnode = n;
  g->key = (uint64_t*)b;
  g->rest = (vd_vec3*)(g->key + n1);
  g->pos = g->rest + n1;
  g->vel = g->pos + n1;
  g->owner_seg = (int*)(g->vel + n1);
  g->attach = g->owner_seg + n1;
  g->pmap = g->attach + n1;
  return 1;
}

static void free_physics(vd_growth* g) {
  vd_mss_data_destroy(g->md);
  vd_mss_model_destroy(g->mm);
  vd_sim_soil_destroy(g->soil);
  vd_sim_data_destroy(g->rd);
  vd_sim_model_destroy(g->rm);
  vd_data_destroy(g->rpd);
  g->md = NULL, g->mm = NULL, g->soil = NULL, g->rd = NULL, g->rm = NULL, g->rpd = NULL;
  g->mss_events_seen = 0;
}

void vd_growth_destroy(vd_growth* g) {
  if (!g) return;
  free_physics(g);
  free_nodes(g);
  carry_free(&g->c);
  vd_model_destroy(g->plant);
  vd_plant_spec_destroy(g->spec);
  vd_lstring_free(&g->str);
  vd_free(g->uid, sizeof(int64_t) * (size_t)g->cap_uid);
  vd_free(g->ev, sizeof(vd_growth_event) * (size_t)g->cap_ev);
  vd_free(g->broken_seg, sizeof(int) * (size_t)g->cap_broken);
  vd_free(g, sizeof *g);
}

int vd_growth_age(const vd_growth* g) { return g->age; }

const vd_growth_event* vd_growth_events(const vd_growth* g, int* n) {
  *n = g->nev;
  return g->ev;
}

const vd_mss_model* vd_growth_mss(const vd_growth* g, const vd_mss_data** data) {
  if (data) *data = g->md;
  return g->mm;
}

static int add_event(vd_growth* g, const vd_growth_event* e) {
  if (!vd_grow((void**)&g->ev, &g->cap_ev, g->nev + 1, sizeof *g->ev)) return 0;
  g->ev[g->nev++] = *e;
  return 1;
}

// ---------------------------------------------------------------------------------------------
// module ids

static int uid_reserve(vd_growth* g, int64_t n) {
  if (n <= g->cap_uid) return 1;
  int64_t cap = g->cap_uid ? g->cap_uid : 64;
  while (cap < n) cap *= 2;
  int64_t* u = vd_realloc(g->uid, sizeof(int64_t) * (size_t)g->cap_uid, sizeof(int64_t) * (size_t)cap);
  if (!u) return 0;
  g->uid = u;
  g->cap_uid = cap;
  return 1;
}

// ids after a derivation step: old (ids and symbols of the string before it, n_old modules)
static int uid_follow(vd_growth* g, const int64_t* old_uid, const int32_t* old_sym, int64_t n_old,
                      unsigned char* taken) {
  const vd_lstring* s = &g->str;
  if (!uid_reserve(g, s->n + 1) || !taken) return 0;
  memset(taken, 0, (size_t)(n_old ? n_old : 1));
  for (int64_t j = 0; j < s->n; j++) {
    int64_t o = s->src ? s->src[j] : -1;
    if (o >= 0 && o < n_old && !taken[o] && old_sym[o] == s->sym[j]) {
      g->uid[j] = old_uid[o];
      taken[o] = 1;
    } else {
      g->uid[j] = g->next_uid++;
    }
  }
  return 1;
}

// ---------------------------------------------------------------------------------------------
// plant geometry under a change of frames

// rotation of node a's internode from configuration x to configuration y (a base: none)
static vd_quat node_turn(const vd_plant_spec* s, const int* owner_seg, const vd_vec3* x, const vd_vec3* y, int a) {
  int sg = owner_seg[a];
  if (sg < 0) return vd_quat_identity();
  int p = s->seg[sg].node0;
  return qbetween(vd_sub(x[a], x[p]), vd_sub(y[a], y[p]));
}

// out (a copy of s) with s's nodes at to[] and its spheres and mesh vertices moved with the node
// they hang from, turned by the turn of that node's internode from s's shape to to[]
static void turn_organs(const vd_plant_spec* s, const int* owner_seg, const vd_vec3* to, vd_plant_spec* out) {
  for (int i = 0; i < s->nnode; i++) out->node[i] = to[i];
  for (int k = 0; k < s->nsphere; k++) {
    int n = s->sphere[k].node;
    if (n < 0 && s->sphere[k].parent >= 0) n = s->seg[s->sphere[k].parent].node1;
    if (n < 0) continue;
    vd_quat q = node_turn(s, owner_seg, s->node, to, n);
    out->sphere[k].center = vd_add(to[n], vd_quat_rotate(q, vd_sub(s->sphere[k].center, s->node[n])));
  }
  for (int k = 0; k < s->nmesh; k++) {
    int n = s->mesh[k].node;
    if (n < 0 && s->mesh[k].parent >= 0) n = s->seg[s->mesh[k].parent].node1;
    if (n < 0) continue;
    vd_quat q = node_turn(s, owner_seg, s->node, to, n);
    for (int v = s->mesh[k].vert_start; v < s->mesh[k].vert_start + s->mesh[k].nvert; v++)
      out->vert[v] = vd_add(to[n], vd_quat_rotate(q, vd_sub(s->vert[v], s->node[n])));
  }
}

// the physics node a plant node moves with: itself when it is one, else the nearest ancestor
static int find_attach(const vd_plant_spec* s, const int* owner_seg, const int* phys, int n) {
  for (int guard = s->nnode + 1; n >= 0 && guard-- > 0;) {
    if (phys[n]) return n;
    int sg = owner_seg[n];
    if (sg < 0) return -1;
    n = s->seg[sg].node0;
  }
  return -1;
}

// ---------------------------------------------------------------------------------------------
// rebuilding the plant

// labels from the file, like vd_lsys_grow
static vd_status turtle_plant(vd_growth* g, vd_plant_spec** out, vd_error* err) {
  vd_lstring geo = vd_lstring_empty();
  vd_plant_spec* spec = vd_plant_spec_create();
  vd_status st = spec ? VD_OK : vd_error_set(err, VD_ERR_NOMEM, "", 0, 0, "out of memory");
  // the interpretation must name modules of this string, not what they came from
  int64_t* src = g->str.src;
  g->str.src = NULL;
  if (!st) st = vd_lsys_interpret(g->ls, &g->def.lsys, &g->str, &geo, err);
  g->str.src = src;
  if (!st) st = vd_turtle_run(g->ls, &geo, &g->def.turtle, spec, err);
  // labels and instances as every front end names a plant (vd_plant_load: organs)
  vd_plant_load_def ld = vd_plant_load_def_default();
  if (!st && (st = vd_plant_load_name(g->ls, &ld, spec))) vd_error_set(err, st, "", 0, 0, "out of memory");
  // the axiom's roots and trunk start at one node (the base)
  if (!st) vd_plant_join_bases(spec);
  vd_lstring_free(&geo);
  if (st) {
    vd_plant_spec_destroy(spec);
    return st;
  }
  *out = spec;
  return VD_OK;
}

// stable keys of the plant's nodes
static void plant_keys(vd_growth* g, const vd_plant_spec* s) {
  for (int i = 0; i < s->nnode; i++) g->key[i] = 0;
  int64_t last = -2;
  int rank = 0;
  for (int j = 0; j < s->nseg; j++) {
    const vd_segment_spec* sg = &s->seg[j];
    int64_t mod = sg->module;
    rank = mod == last ? rank + 1 : 0;
    last = mod;
    int64_t uid = mod >= 0 && mod < g->str.n ? g->uid[mod] : -1 - j;
    if (!g->key[sg->node1]) g->key[sg->node1] = pack_key(uid, rank, 1);
    if (!g->key[sg->node0]) g->key[sg->node0] = pack_key(uid, rank, 0);
  }
  // nodes of no segment, and repeated keys, are new every time
  for (int i = 0; i < s->nnode; i++)
    if (!g->key[i]) g->key[i] = pack_key(-((int64_t)1 << 40), i, 0);
}

// the physics of the plant now: mass-spring model, or rods
static vd_status build_rods(vd_growth* g, vd_error* err) {
  free_physics(g);
  const vd_growth_def* def = &g->def;
  vd_sim_def rdef = def->rods;
  // one wood for every model: the rods' green stems, wood and roots take the mass-spring
  // settings' moduli, densities and drag coefficient (species presets included), issue 26
  // defect 4; their strength is read at breaking (rods_breaking)
  rdef.material[VD_SIM_GREEN].young = def->mss.young_green;
  rdef.material[VD_SIM_GREEN].density = def->mss.density_green;
  int woody_class[2] = {VD_SIM_WOOD, VD_SIM_ROOT};
  for (int k = 0; k < 2; k++) {
    rdef.material[woody_class[k]].young = def->mss.young_wood;
    rdef.material[woody_class[k]].density = def->mss.density_wood;
  }
  int stem_class[3] = {VD_SIM_GREEN, VD_SIM_WOOD, VD_SIM_ROOT};
  for (int k = 0; k < 3; k++) rdef.material[stem_class[k]].drag_cd = def->opt.drag_cd;
  int soil = def->mss.soil.method != VD_SOIL_CLAMP;
  if (soil) rdef.clamp_roots = 0;
  if (g->plant->nseg == 0) return VD_OK;  // nothing to simulate yet (an axiom that draws nothing)
  vd_status st = vd_sim_build(g->plant, &rdef, &g->rm, err);
  if (st) return st;
  vd_vec3 gr = g->rm->opt.gravity;
  g->rm->opt = def->rod_opt;
  g->rm->opt.gravity = gr;
  g->rd = vd_sim_data_create(g->rm);
  g->rpd = vd_data_create(g->plant);
  if (!g->rd || !g->rpd) return vd_error_set(err, VD_ERR_NOMEM, "", 0, 0, "out of memory");
  g->rd->time = g->time;
  if (soil) {
    vd_soil so = def->mss.soil;
    if ((st = vd_sim_soil_attach(g->rm, g->rd, &so, &g->soil, err))) return st;
  }
  return VD_OK;
}

static vd_status build_mss(vd_growth* g, vd_error* err) {
  free_physics(g);
  const vd_growth_def* def = &g->def;
  vd_mss_def mdef = def->mss;
  if (def->model == VD_GROWTH_MSS) mdef.rigid_age = INFINITY;
  vd_status st = vd_mss_build(g->plant, &mdef, NULL, &g->mm, err);
  if (st) return st;
  g->mm->opt = def->opt;
  g->md = vd_mss_data_create(g->mm);
  if (!g->md) return vd_error_set(err, VD_ERR_NOMEM, "", 0, 0, "out of memory");
  g->md->time = g->time;
  g->md->uproot_tilt = def->uproot_tilt;
  g->md->uprooted = g->uprooted;
  g->md->anchor_failed = g->anchor_failed;
  return VD_OK;
}

// total momentum of the carried state over the nodes that survive into the new plant, and the
// scale sum m |v|
static vd_vec3 carried_momentum(const vd_growth* g, double* scale) {
  vd_vec3 p = vd_v3(0, 0, 0);
  double sc = 0;
  for (int i = 0; i < g->nnode; i++) {
    int o = carry_find(&g->c, g->key[i]);
    if (o < 0 || g->c.mass[o] <= 0) continue;
    p = vd_madd(p, g->c.vel[o], g->c.mass[o]);
    sc += g->c.mass[o] * vd_norm(g->c.vel[o]);
  }
  *scale = sc;
  return p;
}

static double mss_scale(const vd_mss_model* m, const vd_mss_data* d) {
  double sc = d->rb.n > 0 ? vd_norm(d->rb.p) : 0;
  for (int i = 0; i < m->nnode; i++)
    if (!d->rigid[i] && !d->removed[i]) sc += d->mass[i] * vd_norm(d->vel[i]);
  return sc;
}

static void note_momentum(vd_growth* g, vd_vec3 before, vd_vec3 after, double scale) {
  double e = vd_norm(vd_sub(after, before)) / fmax(scale, 1e-300);
  if (scale <= 0) e = vd_norm(vd_sub(after, before)) > 0 ? INFINITY : 0;
  if (e > g->momentum_error) g->momentum_error = e;
}

// every node takes the mass of its model now (internode volume x density, leaves and organs),
// its momentum kept (v = m_old v_old / m_new); the rigid body keeps p and its angular momentum
static void mass_update(vd_growth* g) {
  vd_mss_model* m = g->mm;
  vd_mss_data* d = g->md;
  vd_vec3 p0 = vd_mss_momentum(m, d);
  double sc = mss_scale(m, d);
  int any_rigid = 0;
  for (int k = 0; k < m->nnode; k++) {
    if (d->removed[k]) continue;
    double mn = m->node_mass[k];
    if (!d->rigid[k] && !(m->node_flags[k] & VD_MSS_FIXED)) d->vel[k] = vd_scale(d->vel[k], d->mass[k] / mn);
    any_rigid |= d->rigid[k];
    d->mass[k] = mn;
  }
  if (any_rigid) vd_mss_rigid_update(m, d);
  note_momentum(g, p0, vd_mss_momentum(m, d), fmax(sc, mss_scale(m, d)));
}

// the mass-spring state from the carried one: positions, velocities (eq. 1 for new nodes),
// masses, the rigid body (eqs. 6-8 for nodes that hardened)
static vd_status map_mss(vd_growth* g, int grown, vd_error* err) {
  vd_mss_model* m = g->mm;
  vd_mss_data* d = g->md;
  double scale0;
  vd_vec3 p0 = carried_momentum(g, &scale0);
  int nn = m->nnode;
  int* old = vd_malloc(sizeof(int) * (size_t)(nn ? nn : 1));       // carried index, -1 when new
  double* share = vd_calloc((size_t)(nn ? nn : 1), sizeof(double));  // new mass grown from a node
  if (!old || !share) {
    vd_free(old, sizeof(int) * (size_t)(nn ? nn : 1));
    vd_free(share, sizeof(double) * (size_t)(nn ? nn : 1));
    return vd_error_set(err, VD_ERR_NOMEM, "", 0, 0, "out of memory");
  }
  // old nodes keep their state; new ones start with the smallest mass
  for (int k = 0; k < nn; k++) {
    int n = m->node_plant[k], o = carry_find(&g->c, g->key[n]);
    old[k] = o >= 0 && g->c.mass[o] > 0 ? o : -1;
    d->pos[k] = g->pos[n];
    d->vel[k] = g->vel[n];
    if (old[k] >= 0) {
      d->mass[k] = g->c.mass[o];
      d->rigid[k] = g->c.rigid[o];
      d->body[k] = g->c.body[o];
      d->yielded[k] = g->c.yielded[o];
    } else {
      d->mass[k] = g->def.mss.min_mass;
    }
  }
  // eq. 1: a node's momentum is shared with the new nodes that grew from it; nodes grown from a
  // clamp or from the rigid part start at rest (they bring no momentum)
  if (grown) {
    int* anchor = vd_malloc(sizeof(int) * (size_t)(nn ? nn : 1));
    if (!anchor) {
      vd_free(old, sizeof(int) * (size_t)(nn ? nn : 1));
      vd_free(share, sizeof(double) * (size_t)(nn ? nn : 1));
      return vd_error_set(err, VD_ERR_NOMEM, "", 0, 0, "out of memory");
    }
    for (int k = 0; k < nn; k++) {
      anchor[k] = -1;
      if (old[k] >= 0) continue;
      int a = m->node_parent[k], guard = nn;
      while (a >= 0 && old[a] < 0 && guard-- > 0) a = m->node_parent[a];
      if (a >= 0 && (d->rigid[a] || (m->node_flags[a] & VD_MSS_FIXED))) a = -1;
      anchor[k] = a;
      if (a >= 0) share[a] += d->mass[k];
    }
    for (int k = 0; k < nn; k++)
      if (old[k] < 0) d->vel[k] = anchor[k] >= 0 ? vd_scale(d->vel[anchor[k]], d->mass[anchor[k]] / (d->mass[anchor[k]] + share[anchor[k]])) : vd_v3(0, 0, 0);
    for (int k = 0; k < nn; k++)
      if (share[k] > 0) d->vel[k] = vd_scale(d->vel[k], d->mass[k] / (d->mass[k] + share[k]));
    vd_free(anchor, sizeof(int) * (size_t)(nn ? nn : 1));
  } else {
    for (int k = 0; k < nn; k++)
      if (old[k] < 0) d->vel[k] = vd_v3(0, 0, 0);
  }
  vd_free(old, sizeof(int) * (size_t)(nn ? nn : 1));
  vd_free(share, sizeof(double) * (size_t)(nn ? nn : 1));
  // the rigid body as it was, refitted to the members that survive (they carry their rigid
  // velocities; members cut with a branch took their momentum away)
  d->rb = g->rb;
  int nr = 0;
  for (int k = 0; k < nn; k++) nr += d->rigid[k];
  if (nr == 0) {
    memset(&d->rb, 0, sizeof d->rb);
    d->rb.q = vd_quat_identity();
  } else {
    vd_mss_rigid_refit(m, d, vd_rigid_omega(&g->rb));
  }
  vd_vec3 p1 = vd_mss_momentum(m, d);
  note_momentum(g, p0, p1, fmax(scale0, mss_scale(m, d)));
  // the masses of this year from the first substep: new nodes, this year's leaves and the
  // wood laid down (the seed's own rule keeps last year's until the end of the step)
  if (!g->def.paper_masses) mass_update(g);
  // nodes that hardened join the rigid body (Algorithm 2)
  if (g->def.model == VD_GROWTH_MRL) {
    unsigned char* join = (unsigned char*)d->held;  // scratch, cleared by the next substep
    int any = 0;
    for (int k = 0; k < nn; k++) {
      // the hardened wood above the ground: roots stay with the soil that holds each of them up
      // to its own resistance, clamped nodes and a held root crown are the ground's (the body
      // turns about them), issue 26 defects 2 and 5
      // (paper_rigid: the seed's, every node old enough, held while its soil or clamp holds)
      unsigned ground = g->def.paper_rigid ? 0u : VD_MSS_ROOT | VD_MSS_FIXED | VD_MSS_SOIL | VD_MSS_CROWN;
      join[k] = !d->rigid[k] && !d->removed[k] && !(m->node_flags[k] & ground) && m->node_age[k] >= m->rigid_age;
      any |= join[k];
    }
    if (any) {
      double lc[6];
      vd_vec3 pa = vd_mss_momentum(m, d);
      double sc = mss_scale(m, d);
      vd_mss_rigid_join(m, d, join, g->def.paper_eq8, lc);
      note_momentum(g, pa, vd_mss_momentum(m, d), sc);
      vd_vec3 lt = vd_v3(lc[0], lc[1], lc[2]), le = vd_v3(lc[3], lc[4], lc[5]);
      double ref = fmax(vd_norm(lt), 1e-300);
      double e = vd_norm(vd_sub(le, lt)) / ref;
      if (vd_norm(lt) == 0) e = vd_norm(le) > 0 ? INFINITY : 0;
      if (e > g->angular_error) g->angular_error = e;
    }
    memset(join, 0, (size_t)nn);
  }
  return VD_OK;
}

// rods: positions from the carried deformation (each rod segment turned like its plant segment),
// velocities zero
static void map_rods(vd_growth* g) {
  const vd_sim_model* m = g->rm;
  vd_sim_data* d = g->rd;
  const vd_plant_spec* s = g->spec;
  int ns = m->nseg;
  // rotation of each rod segment: that of its plant segment's chord, else its parent's
  vd_quat* rot = vd_malloc(sizeof(vd_quat) * (size_t)(ns ? ns : 1));
  unsigned char* placed = vd_calloc((size_t)(m->nnode_all ? m->nnode_all : 1), 1);
  if (!rot || !placed) {
    vd_free(rot, sizeof(vd_quat) * (size_t)(ns ? ns : 1));
    vd_free(placed, (size_t)(m->nnode_all ? m->nnode_all : 1));
    return;  // the state stays at rest
  }
  for (int k = ns - 1; k >= 0; k--) {  // seg_order is children first: backwards, parents first
    int t = m->seg_order[k], j = m->seg_plant[t], par = m->seg_parent[t];
    if (j >= 0 && j < s->nseg) {
      int a = s->seg[j].node0, b = s->seg[j].node1;
      rot[t] = qbetween(vd_sub(g->rest[b], g->rest[a]), vd_sub(g->pos[b], g->pos[a]));
    } else {
      rot[t] = par >= 0 ? rot[par] : vd_quat_identity();
    }
    int na = m->seg_node[2 * t], nb = m->seg_node[2 * t + 1];
    if (!placed[na]) {
      if (!m->node_fixed[na] && j >= 0 && j < s->nseg) {
        int a = s->seg[j].node0;
        d->node_pos[na] = vd_add(g->pos[a], vd_quat_rotate(rot[t], vd_sub(m->node_pos0[na], g->rest[a])));
      }
      placed[na] = 1;
    }
    // clamped nodes and segments stay where they are held
    if (m->seg_flags[t] & VD_SIM_FIXED) {
      rot[t] = vd_quat_identity();
      placed[nb] = 1;
      continue;
    }
    if (!m->node_fixed[nb])
      d->node_pos[nb] = vd_add(d->node_pos[na], vd_quat_rotate(rot[t], vd_sub(m->node_pos0[nb], m->node_pos0[na])));
    placed[nb] = 1;
    d->seg_quat[t] = vd_quat_normalize(vd_quat_mul(rot[t], m->seg_quat0[t]));
  }
  for (int i = 0; i < m->nnode_all; i++)
    if (!finite3(d->node_pos[i])) d->node_pos[i] = m->node_pos0[i];
  vd_free(rot, sizeof(vd_quat) * (size_t)(ns ? ns : 1));
  vd_free(placed, (size_t)(m->nnode_all ? m->nnode_all : 1));
}

// a measure of a segment's bending stiffness, for the share that is new after a year: E r^4 with
// the wood's or green stem's modulus (material springs, rods), k0 d with the paper's springs
static double seg_stiffness(const vd_growth* g, const vd_plant_spec* s, int j) {
  const vd_segment_spec* sg = &s->seg[j];
  const vd_label* l = vd_plant_find_label(s, sg->label);
  int woody = sg->age >= g->def.mss.woody_age || (l && l->organ == VD_ORGAN_ROOT);
  double r = sg->r1;
  if (g->def.model == VD_GROWTH_RODS) return r * r * r * r;
  if (g->def.mss.springs == VD_MSS_PAPER) return (woody ? g->def.mss.k0_wood : g->def.mss.k0_green) * r;
  return (woody ? g->def.mss.young_wood : g->def.mss.young_green) * r * r * r * r;
}

// unit vector a turned toward unit vector b by the fraction f of the angle between them
static vd_vec3 slerp_dir(vd_vec3 a, vd_vec3 b, double f) {
  double c = fmax(-1.0, fmin(1.0, vd_dot(a, b))), th = acos(c);
  if (!(th > 1e-12)) return a;
  double s = sin(th);
  if (!(s > 1e-12)) return a;  // opposite: no defined turn
  return vd_normalize(vd_add(vd_scale(a, sin((1 - f) * th) / s), vd_scale(b, sin(f * th) / s)));
}

// Stress-free secondary growth: the wood a year adds (and the lignification of green shoots) is
// laid down without stress on the tree as it stands, so the old deformation stays carried by the
// old stiffness only. Each old internode's rest direction turns toward its deformed direction by
// the share of its bending stiffness that is new, f = 1 - EI_old / EI_new, in the frame its parent
// internode carries (as the hinges see it); lengths are kept, parents before children. Without
// it the deformation carried into a stiffer tree would load it as if the new wood had been there
// when it bent (docs/physics.md, "growth").
static void stress_free_growth(vd_growth* g, const vd_plant_spec* spec, const unsigned char* old) {
  int n = spec->nnode;
  unsigned char* done = vd_calloc((size_t)(n ? n : 1), 1);
  vd_vec3* r0 = vd_malloc(sizeof(vd_vec3) * (size_t)(n ? n : 1));
  if (!done || !r0) {
    vd_free(done, (size_t)(n ? n : 1));
    vd_free(r0, sizeof(vd_vec3) * (size_t)(n ? n : 1));
    return;  // out of memory: the rest shape stays (elastic carry)
  }
  memcpy(r0, g->rest, sizeof(vd_vec3) * (size_t)n);
  for (int i = 0; i < n; i++) done[i] = !old[i] || g->owner_seg[i] < 0;
  for (int more = 1; more;) {
    more = 0;
    for (int i = 0; i < n; i++) {
      if (done[i]) continue;
      int par = spec->seg[g->owner_seg[i]].node0;
      if (!done[par] && old[par]) continue;
      int o = carry_find(&g->c, g->key[i]);
      double sn = seg_stiffness(g, spec, g->owner_seg[i]), so = o >= 0 ? g->c.stiff[o] : sn;
      double f = sn > so && so > 0 ? 1 - so / sn : 0;
      vd_vec3 e0 = vd_sub(r0[i], r0[par]), x = vd_sub(g->pos[i], g->pos[par]);
      double l = vd_norm(e0);
      if (l > 0 && vd_norm(x) > 0 && old[par]) {
        vd_vec3 q0 = vd_scale(e0, 1.0 / l), q = vd_normalize(x), dir;
        int pp = g->owner_seg[par] >= 0 ? spec->seg[g->owner_seg[par]].node0 : -1;
        if (pp >= 0 && old[pp]) {
          // in the frame the parent internode carries (as the hinges do): the deviation from the
          // carried rest direction t shrinks to (1 - f) of itself
          vd_vec3 p0 = vd_sub(r0[pp], r0[par]), p1 = vd_sub(g->rest[pp], g->rest[par]), pc = vd_sub(g->pos[pp], g->pos[par]);
          vd_vec3 t = vd_quat_rotate(qbetween(p0, pc), q0);
          dir = vd_quat_rotate(vd_quat_conj(qbetween(p1, pc)), slerp_dir(t, q, f));
        } else {
          dir = slerp_dir(q0, q, f);
        }
        g->rest[i] = vd_add(g->rest[par], vd_scale(dir, l));
      }
      done[i] = 1;
      more = 1;
    }
  }
  vd_free(done, (size_t)(n ? n : 1));
  vd_free(r0, sizeof(vd_vec3) * (size_t)(n ? n : 1));
}

// the plant from the string now, the carried state mapped onto it, its physics built
static vd_status rebuild(vd_growth* g, int grown, vd_error* err) {
  vd_plant_spec* spec = NULL;
  vd_status st = turtle_plant(g, &spec, err);
  if (st) return st;
  vd_plant_spec_destroy(g->spec);
  g->spec = spec;
  if (!alloc_nodes(g, spec->nnode)) return vd_error_set(err, VD_ERR_NOMEM, "", 0, 0, "out of memory");
  plant_keys(g, spec);
  for (int i = 0; i < spec->nnode; i++) g->owner_seg[i] = -1;
  for (int j = 0; j < spec->nseg; j++) g->owner_seg[spec->seg[j].node1] = j;
  // old nodes keep rest, position and velocity; a new node is placed on its parent node as the
  // turtle drew it, turned by the parent internode's turn from the turtle to the rest shape, then
  // by its turn from rest to now (the smallest rotations: what the hinges carry), so that a new
  // branch enters without bending its joints
  unsigned char* placed = vd_malloc((size_t)(spec->nnode ? spec->nnode : 1));
  if (!placed) return vd_error_set(err, VD_ERR_NOMEM, "", 0, 0, "out of memory");
  for (int i = 0; i < spec->nnode; i++) {
    int o = carry_find(&g->c, g->key[i]);
    placed[i] = o >= 0;
    if (o >= 0) g->rest[i] = g->c.rest[o], g->pos[i] = g->c.pos[o], g->vel[i] = g->c.vel[o];
  }
  if (grown && g->def.stress_free) stress_free_growth(g, spec, placed);
  for (int more = 1; more;) {
    more = 0;
    for (int i = 0; i < spec->nnode; i++) {
      int sg = g->owner_seg[i];
      if (placed[i] || sg < 0) continue;
      int par = spec->seg[sg].node0;
      if (!placed[par]) continue;
      int pp = g->owner_seg[par] >= 0 ? spec->seg[g->owner_seg[par]].node0 : -1;
      vd_quat gq = pp >= 0 ? qbetween(vd_sub(spec->node[par], spec->node[pp]), vd_sub(g->rest[par], g->rest[pp])) : vd_quat_identity();
      vd_quat dq = pp >= 0 ? qbetween(vd_sub(g->rest[par], g->rest[pp]), vd_sub(g->pos[par], g->pos[pp])) : vd_quat_identity();
      g->rest[i] = vd_add(g->rest[par], vd_quat_rotate(gq, vd_sub(spec->node[i], spec->node[par])));
      g->pos[i] = vd_add(g->pos[par], vd_quat_rotate(dq, vd_sub(g->rest[i], g->rest[par])));
      g->vel[i] = g->vel[par];
      placed[i] = 1;
      more = 1;
    }
  }
  // new bases start where the turtle put them, at rest
  for (int i = 0; i < spec->nnode; i++)
    if (!placed[i]) g->rest[i] = g->pos[i] = spec->node[i], g->vel[i] = vd_v3(0, 0, 0);
  vd_free(placed, (size_t)(spec->nnode ? spec->nnode : 1));
  // the model at rest: the spec's nodes at their rest positions, organs turned with their node
  vd_plant_spec* rs = vd_plant_spec_copy(spec);
  if (!rs) return vd_error_set(err, VD_ERR_NOMEM, "", 0, 0, "out of memory");
  // spheres and mesh vertices: turtle -> rest with the turn of their node's internode
  turn_organs(spec, g->owner_seg, g->rest, rs);
  vd_model_destroy(g->plant);
  g->plant = NULL;
  st = vd_plant_compile(rs, &g->plant, err);
  vd_plant_spec_destroy(rs);
  if (st) return st;
  if ((st = g->eng->build(g, err))) return st;
  for (int i = 0; i < spec->nnode; i++) g->pmap[i] = -1;
  return g->eng->map(g, grown, err);
}

// attachments: plant node -> mass-spring node; the state from the carried one
static vd_status attach_mss(vd_growth* g, int grown, vd_error* err) {
  const vd_plant_spec* spec = g->spec;
  int* phys = g->attach;  // flags first, then each node's attachment (read before written)
  for (int i = 0; i < spec->nnode; i++) {
    g->pmap[i] = i < g->mm->nplant ? g->mm->plant_node[i] : -1;
    phys[i] = g->pmap[i] >= 0;
  }
  int* at = vd_malloc(sizeof(int) * (size_t)(spec->nnode ? spec->nnode : 1));
  if (!at) return vd_error_set(err, VD_ERR_NOMEM, "", 0, 0, "out of memory");
  for (int i = 0; i < spec->nnode; i++) at[i] = find_attach(spec, g->owner_seg, phys, i);
  memcpy(g->attach, at, sizeof(int) * (size_t)spec->nnode);
  vd_free(at, sizeof(int) * (size_t)(spec->nnode ? spec->nnode : 1));
  return map_mss(g, grown, err);
}

// rods: every plant node is its own; the rod state from the carried one
static vd_status attach_rods(vd_growth* g, int grown, vd_error* err) {
  (void)grown, (void)err;
  for (int i = 0; i < g->spec->nnode; i++) g->attach[i] = i;
  if (g->rm) map_rods(g);
  return VD_OK;
}

// ---------------------------------------------------------------------------------------------
// the state after the physics: positions of every plant node, the carried record

// the plant's node positions and velocities from the physics
static void read_mss(vd_growth* g) {
  const vd_plant_spec* s = g->spec;
  const vd_mss_data* d = g->md;
  for (int i = 0; i < s->nnode; i++) {
    int k = g->pmap[i];
    if (k < 0) continue;
    g->pos[i] = d->pos[k];
    g->vel[i] = d->vel[k];
  }
  // the rest follow the node they hang from
  for (int i = 0; i < s->nnode; i++) {
    int a = g->attach[i];
    if (g->pmap[i] >= 0 || a < 0) continue;
    vd_quat q = node_turn(s, g->owner_seg, g->rest, g->pos, a);
    g->pos[i] = vd_add(g->pos[a], vd_quat_rotate(q, vd_sub(g->rest[i], g->rest[a])));
    g->vel[i] = g->vel[a];
  }
}

static void read_rods(vd_growth* g) {
  const vd_plant_spec* s = g->spec;
  if (!g->rm) return;  // no rods: the plant stays where it is
  vd_sim_to_plant(g->rm, g->rd, g->plant, g->rpd);
  for (int i = 0; i < s->nnode; i++) {
    g->pos[i] = vd_v3(g->rpd->node_pos[3 * i], g->rpd->node_pos[3 * i + 1], g->rpd->node_pos[3 * i + 2]);
    g->vel[i] = vd_v3(0, 0, 0);
  }
}

static vd_status carry_out(vd_growth* g, vd_error* err) {
  const vd_plant_spec* s = g->spec;
  g->eng->read(g);
  if (!carry_alloc(&g->c, s->nnode)) return vd_error_set(err, VD_ERR_NOMEM, "", 0, 0, "out of memory");
  for (int i = 0; i < s->nnode; i++) {
    g->c.key[i] = g->key[i];
    g->c.turtle[i] = s->node[i];
    g->c.rest[i] = g->rest[i];
    g->c.pos[i] = g->pos[i];
    g->c.vel[i] = g->vel[i];
    g->c.parent[i] = g->owner_seg[i] >= 0 ? s->seg[g->owner_seg[i]].node0 : -1;
    g->c.stiff[i] = g->owner_seg[i] >= 0 ? seg_stiffness(g, s, g->owner_seg[i]) : 0;
  }
  g->eng->carry(g);
  carry_index(&g->c);
  return VD_OK;
}

// the mass-spring part of the carried record: masses, the rigid part, the soil's state
static void carry_mss(vd_growth* g) {
  for (int i = 0; i < g->spec->nnode; i++) {
    int k = g->pmap[i];
    // the node's own plant node carries it (not the aliases of a shared base)
    if (k >= 0 && !g->md->removed[k] && g->mm->node_plant[k] == i) {
      g->c.mass[i] = g->md->mass[k];
      g->c.rigid[i] = g->md->rigid[k];
      g->c.body[i] = g->md->body[k];
      g->c.yielded[i] = g->md->yielded[k];
    }
  }
  g->rb = g->md->rb;
  g->uprooted = g->md->uprooted;
  g->anchor_failed = g->md->anchor_failed;
  g->anchor_load = fmax(g->anchor_load, g->md->anchor_load);
}

static void carry_rods(vd_growth* g) { (void)g; }  // the rods carry positions only

// ---------------------------------------------------------------------------------------------
// create, step

static vd_status check_def(const vd_growth_def* d, vd_error* err) {
  if (d->model < VD_GROWTH_MSS || d->model > VD_GROWTH_RODS)
    return vd_error_set(err, VD_ERR_VALUE, "", 0, 0, "growth: unknown model");
  if (d->substeps < 1)
    return vd_error_set(err, VD_ERR_VALUE, "", 0, 0, "growth: substeps must be at least 1 (got %d)", d->substeps);
  if (d->bastien_substeps < 1)
    return vd_error_set(err, VD_ERR_VALUE, "", 0, 0, "growth: gravitropism substeps must be at least 1");
  if (!(d->uproot_tilt > 0 && d->uproot_tilt < VD_PI))
    return vd_error_set(err, VD_ERR_VALUE, "", 0, 0, "growth: uprooting tilt must be in (0, 180) degrees");
  vd_status st = vd_mss_opt_check(&d->opt, err);
  if (st) return st;
  if (d->model == VD_GROWTH_RODS && !(d->rod_opt.dt > 0))
    return vd_error_set(err, VD_ERR_VALUE, "", 0, 0, "growth: rods time step must be > 0 s");
  return VD_OK;
}

// a light inside the plant (its box) makes the 1/d^2 pull meaningless
static vd_status check_light(const vd_growth* g, vd_error* err) {
  if (!g->def.opt.light || !g->spec->nnode) return VD_OK;
  vd_vec3 lo = g->pos[0], hi = g->pos[0];
  for (int i = 1; i < g->spec->nnode; i++) lo = vd_vmin(lo, g->pos[i]), hi = vd_vmax(hi, g->pos[i]);
  vd_vec3 l = g->def.opt.light_pos;
  if (l.x >= lo.x && l.x <= hi.x && l.y >= lo.y && l.y <= hi.y && l.z >= lo.z && l.z <= hi.z)
    return vd_error_set(err, VD_ERR_VALUE, "", 0, 0,
                        "the light point (%g, %g, %g) m is inside the plant (its box spans (%g, %g, %g) to (%g, %g, %g) m "
                        "at age %d): put it outside",
                        l.x, l.y, l.z, lo.x, lo.y, lo.z, hi.x, hi.y, hi.z, g->age);
  return VD_OK;
}

vd_status vd_growth_create(vd_lsystem* ls, const vd_growth_def* def, vd_growth** out, vd_error* err) {
  *out = NULL;
  vd_status st = check_def(def, err);
  if (st) return st;
  vd_growth* g = vd_calloc(1, sizeof *g);
  if (!g) return vd_error_set(err, VD_ERR_NOMEM, "", 0, 0, "out of memory");
  g->def = *def;
  g->eng = engine_of(def->model);
  g->ls = ls;
  g->str = vd_lstring_empty();
  g->rb.q = vd_quat_identity();
  st = vd_lsys_derive_begin(ls, &g->def.lsys, &g->str, err);
  if (!st && !uid_reserve(g, g->str.n + 1)) st = vd_error_set(err, VD_ERR_NOMEM, "", 0, 0, "out of memory");
  if (!st) {
    for (int64_t j = 0; j < g->str.n; j++) g->uid[j] = g->next_uid++;
    st = rebuild(g, 0, err);
  }
  if (!st) st = check_light(g, err);
  if (!st) st = carry_out(g, err);
  if (st) {
    vd_growth_destroy(g);
    return st;
  }
  *out = g;
  return VD_OK;
}

// cut the modules of broken internodes and everything after them in their branch
static vd_status prune(vd_growth* g, vd_error* err) {
  vd_lstring* s = &g->str;
  size_t n0 = (size_t)(s->n ? s->n : 1);
  unsigned char* del = vd_calloc(n0, 1);
  if (!del) return vd_error_set(err, VD_ERR_NOMEM, "", 0, 0, "out of memory");
  for (int k = 0; k < g->nbroken_step; k++) {
    int j = g->broken_seg[k];
    if (j < 0 || j >= g->spec->nseg) continue;
    int64_t i = g->spec->seg[j].module;
    if (i < 0 || i >= s->n) continue;
    int depth = 0;
    for (int64_t q = i; q < s->n; q++) {
      if (s->sym[q] == VD_SYM_SB) depth++;
      else if (s->sym[q] == VD_SYM_EB && depth-- == 0) break;
      del[q] = 1;
    }
  }
  int64_t w = 0, wv = 0;
  for (int64_t i = 0; i < s->n; i++) {
    if (del[i]) continue;
    int64_t a = s->par[i], np = s->par[i + 1] - a;
    s->sym[w] = s->sym[i];
    if (s->src) s->src[w] = s->src[i];
    memmove(s->val + wv, s->val + a, sizeof(double) * (size_t)np);
    g->uid[w] = g->uid[i];
    s->par[w] = wv;
    wv += np;
    w++;
  }
  s->n = w;
  s->par[w] = wv;
  vd_free(del, n0);
  return VD_OK;
}

// growth events from the physics' events since the last look
static void collect_events(vd_growth* g) {
  if (!g->md) return;
  const vd_mss_model* m = g->mm;
  for (int k = g->mss_events_seen; k < g->md->nevent; k++) {
    const vd_mss_event* e = &g->md->event[k];
    vd_growth_event ge;
    memset(&ge, 0, sizeof ge);
    ge.kind = e->kind;
    ge.age = g->age;
    ge.time = e->time;
    ge.node = e->node >= 0 ? m->node_plant[e->node] : -1;
    ge.segment = e->spring >= 0 ? m->spring_plant[e->spring] : -1;
    ge.stress = e->stress;
    ge.limit = e->limit;
    ge.removed = e->removed;
    if (ge.segment >= 0) {
      const vd_label* l = vd_model_find_label(g->plant, g->plant->seg_label[ge.segment]);
      snprintf(ge.label, sizeof ge.label, "%s", l ? l->name : "");
      if (vd_grow((void**)&g->broken_seg, &g->cap_broken, g->nbroken_step + 1, sizeof(int)))
        g->broken_seg[g->nbroken_step++] = ge.segment;
      g->nbroken++;
    }
    if (e->kind == VD_MSS_UPROOT) snprintf(ge.label, sizeof ge.label, "%s", "uproot");
    if (e->kind == VD_MSS_ANCHOR) snprintf(ge.label, sizeof ge.label, "%s", "anchorage");
    add_event(g, &ge);
  }
  g->mss_events_seen = g->md->nevent;
}

// rods: internodes whose bending stress exceeds the modulus of rupture break at the end of the step
static void rods_breaking(vd_growth* g) {
  if (!g->def.opt.breaking) return;
  const vd_model* p = g->plant;
  double* st = vd_malloc(sizeof(double) * (size_t)(p->nseg ? p->nseg : 1));
  if (!st) return;
  vd_sim_plant_stress(g->rm, g->rd, p, st);
  for (int j = 0; j < p->nseg; j++) {
    const vd_label* l = vd_model_find_label(p, p->seg_label[j]);
    if (!l || (l->organ != VD_ORGAN_STEM && l->organ != VD_ORGAN_OTHER && l->organ != VD_ORGAN_ROOT)) continue;
    int woody = p->seg_age[j] >= g->def.mss.woody_age || l->organ == VD_ORGAN_ROOT;
    double mor = woody ? g->def.mss.mor : g->def.mss.mor_green;
    if (!(isfinite(st[j]) && st[j] > mor)) continue;
    // one break per branch: skip segments whose ancestor broke already
    int skip = 0;
    for (int a = p->seg_parent[j], guard = p->nseg; a >= 0 && !skip && guard-- > 0; a = p->seg_parent[a])
      for (int k = 0; k < g->nbroken_step && !skip; k++) skip = g->broken_seg[k] == a;
    if (skip || !vd_grow((void**)&g->broken_seg, &g->cap_broken, g->nbroken_step + 1, sizeof(int))) continue;
    g->broken_seg[g->nbroken_step++] = j;
    vd_growth_event ge;
    memset(&ge, 0, sizeof ge);
    ge.kind = VD_MSS_BREAK;
    ge.age = g->age;
    ge.time = g->rd->time;
    ge.node = p->seg_node[2 * j];
    ge.segment = j;
    ge.stress = st[j];
    ge.limit = mor;
    snprintf(ge.label, sizeof ge.label, "%s", l->name);
    add_event(g, &ge);
    g->nbroken++;
  }
  vd_free(st, sizeof(double) * (size_t)(p->nseg ? p->nseg : 1));
}

// the end of an age step on a mass-spring tree: masses from the volumes with momentum kept,
// gravitropism of the rest shape
static vd_status end_mss(vd_growth* g, vd_error* err) {
  vd_mss_model* m = g->mm;
  vd_mss_data* d = g->md;
  mass_update(g);
  if (m->opt.gravitropism == VD_MSS_GRAVI_BASTIEN) {
    vd_vec3* rest = vd_malloc(sizeof(vd_vec3) * (size_t)(m->nnode ? m->nnode : 1));
    vd_vec3* old = vd_malloc(sizeof(vd_vec3) * (size_t)(g->spec->nnode ? g->spec->nnode : 1));
    if (!rest || !old) {
      vd_free(rest, sizeof(vd_vec3) * (size_t)(m->nnode ? m->nnode : 1));
      vd_free(old, sizeof(vd_vec3) * (size_t)(g->spec->nnode ? g->spec->nnode : 1));
      return vd_error_set(err, VD_ERR_NOMEM, "", 0, 0, "out of memory");
    }
    vd_mss_bastien(m, d, 1.0, g->def.bastien_substeps, rest);
    memcpy(old, g->rest, sizeof(vd_vec3) * (size_t)g->spec->nnode);
    for (int i = 0; i < g->spec->nnode; i++)
      if (g->pmap[i] >= 0) g->rest[i] = rest[g->pmap[i]];
    for (int i = 0; i < g->spec->nnode; i++) {
      int a = g->attach[i];
      if (g->pmap[i] >= 0 || a < 0) continue;
      vd_quat q = node_turn(g->spec, g->owner_seg, old, g->rest, a);
      g->rest[i] = vd_add(g->rest[a], vd_quat_rotate(q, vd_sub(old[i], old[a])));
    }
    vd_free(rest, sizeof(vd_vec3) * (size_t)(m->nnode ? m->nnode : 1));
    vd_free(old, sizeof(vd_vec3) * (size_t)(g->spec->nnode ? g->spec->nnode : 1));
  }
  return VD_OK;
}

static double drawn_height(const vd_growth* g);

vd_status vd_growth_step(vd_growth* g, vd_error* err) {
  vd_status st = VD_OK;
  // one derivation step; the module ids follow it
  {
    int64_t n_old = g->str.n;
    int64_t* old_uid = vd_malloc(sizeof(int64_t) * (size_t)(n_old ? n_old : 1));
    int32_t* old_sym = vd_malloc(sizeof(int32_t) * (size_t)(n_old ? n_old : 1));
    unsigned char* taken = vd_malloc((size_t)(n_old ? n_old : 1));
    if (!old_uid || !old_sym || !taken) st = vd_error_set(err, VD_ERR_NOMEM, "", 0, 0, "out of memory");
    if (!st && old_uid && old_sym && taken) {
      if (n_old && g->uid && g->str.sym) {
        memcpy(old_uid, g->uid, sizeof(int64_t) * (size_t)n_old);
        memcpy(old_sym, g->str.sym, sizeof(int32_t) * (size_t)n_old);
      }
      st = vd_lsys_derive_step(g->ls, &g->def.lsys, &g->str, err);
    }
    if (!st && (!old_uid || !old_sym || !uid_follow(g, old_uid, old_sym, n_old, taken)))
      st = vd_error_set(err, VD_ERR_NOMEM, "", 0, 0, "out of memory");
    vd_free(old_uid, sizeof(int64_t) * (size_t)(n_old ? n_old : 1));
    vd_free(old_sym, sizeof(int32_t) * (size_t)(n_old ? n_old : 1));
    vd_free(taken, (size_t)(n_old ? n_old : 1));
    if (st) return st;
  }
  g->age++;
  g->nbroken_step = 0;
  if ((st = rebuild(g, 1, err))) return st;
  g->drawn_max = fmax(g->drawn_max, drawn_height(g));
  if ((st = check_light(g, err))) return st;
  // the substeps
  for (int k = 0; k < g->def.substeps; k++) {
    if (g->eng->step(g)) g->unstable++;
    g->substeps++;
  }
  if ((st = g->eng->end_age(g, err))) return st;
  if ((st = carry_out(g, err))) return st;
  // broken branches leave the L-string, and the plant is rebuilt without them
  if (g->nbroken_step) {
    if ((st = prune(g, err))) return st;
    if ((st = rebuild(g, 0, err))) return st;
    if ((st = carry_out(g, err))) return st;
  }
  // stress of the tree as it stands now (also without breaking, and after a rebuild)
  g->eng->settle(g);
  return VD_OK;
}

// ---------------------------------------------------------------------------------------------
// results

// the highest stem node above the stem's base as the turtle draws the string now (m)
static double drawn_height(const vd_growth* g) {
  if (!g->spec) return 0;
  const vd_plant_spec* s = g->spec;
  double z0 = HUGE_VAL, z1 = -HUGE_VAL;
  for (int j = 0; j < s->nseg; j++) {
    const vd_label* l = vd_plant_find_label(s, s->seg[j].label);
    vd_organ o = l ? l->organ : VD_ORGAN_OTHER;
    if (o != VD_ORGAN_STEM && o != VD_ORGAN_OTHER) continue;
    for (int e = 0; e < 2; e++) {
      double z = s->node[e ? s->seg[j].node1 : s->seg[j].node0].z;
      z0 = fmin(z0, z), z1 = fmax(z1, z);
    }
  }
  return z0 < HUGE_VAL ? z1 - z0 : 0;
}

void vd_growth_get_stats(const vd_growth* g, vd_growth_stats* out) {
  memset(out, 0, sizeof *out);
  out->age = g->age;
  out->time = g->time;
  out->nnode = g->spec->nnode;
  out->nseg = g->spec->nseg;
  out->momentum_error = g->momentum_error;
  out->angular_error = g->angular_error;
  out->substeps = g->substeps;
  out->nbroken = g->nbroken;
  out->uprooted = g->uprooted;
  out->anchor_failed = g->anchor_failed;
  out->anchor_load = g->anchor_load;
  out->drawn_height = fmax(g->drawn_max, drawn_height(g));
  g->eng->stats(g, out);
  // judged against the drawn height, which no lean of the rest shape moves
  double h0 = out->drawn_height > 0 ? out->drawn_height : out->height0;
  out->diverged = !isfinite(out->height) || !isfinite(out->max_displacement) ||
                  (h0 > 0 && (out->height > 1.5 * h0 || out->max_displacement > 2 * h0));
  out->collapsed = out->diverged || (h0 > 0 && out->height < VD_GROWTH_COLLAPSE * h0);
}

static void stats_mss(const vd_growth* g, vd_growth_stats* out) {
  const vd_mss_model* m = g->mm;
  const vd_mss_data* d = g->md;
  out->nphys = m->nnode;
  out->nrigid = d->rb.n;
  out->height = vd_mss_height(m, d);
  out->height0 = m->height0;
  out->max_displacement = vd_mss_max_displacement(m, d, NULL);
  out->tip_displacement = m->main_tip >= 0 ? vd_norm(vd_sub(d->pos[m->main_tip], m->node_rest[m->main_tip])) : 0;
  for (int s = 0; s < m->ninter; s++) out->max_stress = fmax(out->max_stress, d->spring_stress[s]);
  for (int k = 0; k < m->nnode; k++) out->total_mass += d->removed[k] ? 0 : d->mass[k];
  out->kinetic_energy = vd_mss_kinetic_energy(m, d);
  out->cg_iterations = d->cg_iterations;
  out->unstable = d->warning[VD_MSS_WARN_NONFINITE];
  out->uprooted = d->uprooted;
  out->anchor_failed = d->anchor_failed;
  out->anchor_load = fmax(g->anchor_load, d->anchor_load);
}

static void stats_rods(const vd_growth* g, vd_growth_stats* out) {
  if (g->rm) {
    const vd_sim_model* m = g->rm;
    const vd_sim_data* d = g->rd;
    out->nphys = m->nnode;
    out->max_displacement = vd_sim_max_displacement(m, d, NULL);
    out->tip_displacement = m->main_tip >= 0 ? vd_norm(vd_sub(d->node_pos[m->main_tip], m->node_pos0[m->main_tip])) : 0;
    out->total_mass = m->total_mass;
    out->kinetic_energy = vd_sim_kinetic_energy(m, d);
    out->unstable = g->unstable;
    // heights from the plant's stem nodes
    double z0 = HUGE_VAL, zr = -HUGE_VAL, zn = -HUGE_VAL;
    for (int j = 0; j < g->plant->nseg; j++) {
      const vd_label* l = vd_model_find_label(g->plant, g->plant->seg_label[j]);
      if (l && l->organ == VD_ORGAN_ROOT) continue;
      for (int e = 0; e < 2; e++) {
        int n = g->plant->seg_node[2 * j + e];
        z0 = fmin(z0, g->rest[n].z);
        zr = fmax(zr, g->rest[n].z);
        zn = fmax(zn, g->pos[n].z);
      }
    }
    if (z0 < HUGE_VAL) out->height0 = zr - z0, out->height = zn - z0;
    double* st = vd_malloc(sizeof(double) * (size_t)(g->plant->nseg ? g->plant->nseg : 1));
    if (st) {
      vd_sim_plant_stress(m, d, g->plant, st);
      for (int j = 0; j < g->plant->nseg; j++)
        if (isfinite(st[j])) out->max_stress = fmax(out->max_stress, st[j]);
      vd_free(st, sizeof(double) * (size_t)(g->plant->nseg ? g->plant->nseg : 1));
    }
  }
}

vd_status vd_growth_plant(const vd_growth* g, vd_plant_spec** out, vd_error* err) {
  *out = NULL;
  const vd_plant_spec* s = g->spec;
  vd_plant_spec* p = vd_plant_spec_copy(s);
  if (!p) return vd_error_set(err, VD_ERR_NOMEM, "", 0, 0, "out of memory");
  // nodes where they are; organs and up vectors turned with the node they hang from
  turn_organs(s, g->owner_seg, g->pos, p);
  for (int j = 0; j < s->nseg; j++) {
    vd_quat q = node_turn(s, g->owner_seg, s->node, g->pos, s->seg[j].node1);
    vd_vec3 u = vd_quat_rotate(q, s->seg[j].up);
    vd_vec3 ax = vd_normalize(vd_sub(g->pos[s->seg[j].node1], g->pos[s->seg[j].node0]));
    u = vd_madd(u, ax, -vd_dot(u, ax));
    if (vd_norm(u) > 1e-9) p->seg[j].up = vd_normalize(u);
  }
  // stress per node and per segment (NaN where there is none)
  double* ns = vd_malloc(sizeof(double) * (size_t)(s->nnode ? s->nnode : 1));
  double* ss = vd_malloc(sizeof(double) * (size_t)(s->nseg ? s->nseg : 1));
  if (!ns || !ss) {
    vd_free(ns, sizeof(double) * (size_t)(s->nnode ? s->nnode : 1));
    vd_free(ss, sizeof(double) * (size_t)(s->nseg ? s->nseg : 1));
    vd_plant_spec_destroy(p);
    return vd_error_set(err, VD_ERR_NOMEM, "", 0, 0, "out of memory");
  }
  vd_status st = VD_OK;
  {
    for (int i = 0; i < s->nnode; i++) ns[i] = NAN;
    for (int j = 0; j < s->nseg; j++) ss[j] = NAN;
    g->eng->stress(g, ns, ss);
    if (vd_plant_set_stress(p, ns, ss)) st = vd_error_set(err, VD_ERR_NOMEM, "", 0, 0, "out of memory");
  }
  vd_free(ns, sizeof(double) * (size_t)(s->nnode ? s->nnode : 1));
  vd_free(ss, sizeof(double) * (size_t)(s->nseg ? s->nseg : 1));
  if (st) {
    vd_plant_spec_destroy(p);
    return st;
  }
  *out = p;
  return VD_OK;
}

static void stress_mss(const vd_growth* g, double* ns, double* ss) {
  const vd_mss_model* m = g->mm;
  const vd_mss_data* d = g->md;
  for (int i = 0; i < g->spec->nnode; i++)
    if (g->pmap[i] >= 0) ns[i] = d->node_stress[g->pmap[i]];
  for (int q = 0; q < m->ninter; q++) ss[m->spring_plant[q]] = d->spring_stress[q];
}

static void stress_rods(const vd_growth* g, double* ns, double* ss) {
  const vd_plant_spec* s = g->spec;
  if (!g->rm) return;
  vd_sim_plant_stress(g->rm, g->rd, g->plant, ss);
  for (int j = 0; j < s->nseg; j++) {
    if (!isfinite(ss[j])) continue;
    int n = s->seg[j].node1;
    ns[n] = isfinite(ns[n]) ? fmax(ns[n], ss[j]) : ss[j];
  }
}

// ---------------------------------------------------------------------------------------------
// the engines' substeps and age ends, and the one table the loop dispatches through

static vd_status step_mss(vd_growth* g) { return vd_mss_step(g->mm, g->md); }

static vd_status step_rods(vd_growth* g) {
  if (!g->rm) return VD_OK;
  vd_status st = vd_sim_step(g->rm, g->rd);
  vd_sim_soil_update(g->rm, g->rd, g->soil);
  return st;
}

static vd_status end_age_mss(vd_growth* g, vd_error* err) {
  g->time = g->md->time;
  collect_events(g);
  return end_mss(g, err);
}

static vd_status end_age_rods(vd_growth* g, vd_error* err) {
  (void)err;
  if (!g->rm) {
    g->time += g->def.substeps * g->def.rod_opt.dt;
    return VD_OK;
  }
  g->time = g->rd->time;
  rods_breaking(g);
  return VD_OK;
}

static void settle_mss(vd_growth* g) { vd_mss_stress_now(g->mm, g->md); }

static void settle_rods(vd_growth* g) { (void)g; }  // the rods' stress is computed when read

static const growth_engine engine_mss = {build_mss, attach_mss, step_mss, end_age_mss, read_mss,
                                         carry_mss, settle_mss, stats_mss, stress_mss};
static const growth_engine engine_rods = {build_rods, attach_rods, step_rods, end_age_rods, read_rods,
                                          carry_rods, settle_rods, stats_rods, stress_rods};

static const growth_engine* engine_of(vd_growth_model m) { return m == VD_GROWTH_RODS ? &engine_rods : &engine_mss; }
