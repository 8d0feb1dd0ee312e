// SPDX-License-Identifier: MIT
// Mass-spring trees (ML-Tree, Lim & Gobeawan 2024 sec. 3.1) and the substep of both models
// (Algorithms 1 and 2): build from a compiled plant, state, integrators.
//
// Integrators. With F the force on each node at the start of the substep (springs, hinges,
// damping, loads) and K_i the sum of the spring constants at node i:
//   eq. 3 (Kang et al. 2001): dv_i = (h F_i + h^2 sum_j k_ij dv*_j) / (m_i + h^2 K_i),
//                             dv*_j = h F_j / (m_j + h^2 K_j);
//   eq. 4 (Kang et al. 2000): dv_i = (h F_i + h^2 sum_j k_ij |dv_j^(t-h)| F_j / |F_j|)
//                             / (m_i + h^2 K_i);
//   implicit: (M - h dF/dv - h^2 dF/dx) dv = h (F + h dF/dx v), the linearised backward Euler of
//             Baraff & Witkin 1998, by conjugate gradients with a block-Jacobi preconditioner.
// Positions then move by h v. Eqs. 3 and 4 couple a node to its neighbours only, so a load
// travels one node per substep; the implicit solve couples the whole tree every substep.
#include <stdio.h>

#include "mss_internal.h"

vd_mss_def vd_mss_def_default(void) {
  vd_mss_def d;
  memset(&d, 0, sizeof d);
  d.springs = VD_MSS_MATERIAL;
  d.k0_green = 1e4;
  d.k0_wood = 1e5;
  d.woody_age = 1;
  d.rigid_age = INFINITY;
  d.young_green = 1e9;
  d.young_wood = 1e10;
  d.density_green = 1000;
  d.density_wood = 900;
  d.mor = 5.5e7;
  d.mor_green = 1.5e7;
  d.leaf_areal_density = 0.22;
  d.min_mass = 1e-4;
  d.damping = 1;
  d.fix_height = 0.01;
  vd_soil_preset("clamp", &d.soil);
  d.max_nodes = 1000000;
  return d;
}

vd_mss_opt vd_mss_opt_default(void) {
  vd_mss_opt o;
  memset(&o, 0, sizeof o);
  o.dt = 0.01;
  o.integrator = VD_MSS_IMPLICIT;
  o.cg_iterations = 500;
  o.cg_tolerance = 1e-8;
  o.gravity = vd_v3(0, 0, -9.81);
  o.gust_period = 2;
  o.wind_model = VD_MSS_WIND_AREA;
  o.air_density = 1.226;
  o.drag_cd = 1.2;
  o.leaf_cd = 0.1;
  o.drag = VD_MSS_DRAG_QUADRATIC;
  o.viscosity = 1.81e-5;
  o.light_k = 1;
  o.gravitropism = VD_MSS_GRAVI_NONE;
  o.gravi_k = 0.1;
  o.bastien_beta = 0.5;
  o.bastien_gamma = 1;
  o.growth_zone_age = 2;
  o.soil = 1;
  o.breaking = 1;
  o.strain_limit = 1e-4;
  o.rigid_release = 1;
  return o;
}

static int finite3(vd_vec3 v) { return isfinite(v.x) && isfinite(v.y) && isfinite(v.z); }

vd_status vd_mss_opt_check(const vd_mss_opt* o, vd_error* err) {
  const char* f = NULL;
  if (!(o->dt > 0 && o->dt <= 1e6)) f = "time step dt (s, in (0, 1e6])";
  else if (o->integrator < VD_MSS_EQ3 || o->integrator > VD_MSS_IMPLICIT) f = "integrator";
  else if (o->cg_iterations < 1) f = "conjugate-gradient iterations (>= 1)";
  else if (!(o->cg_tolerance > 0 && o->cg_tolerance < 1)) f = "conjugate-gradient tolerance (in (0, 1))";
  else if (!finite3(o->gravity)) f = "gravity (m/s^2, finite)";
  else if (!finite3(o->wind) || fabs(o->wind.x) > VD_SIM_MAX_WIND || fabs(o->wind.y) > VD_SIM_MAX_WIND ||
           fabs(o->wind.z) > VD_SIM_MAX_WIND)
    f = "wind (m/s, finite, within the largest wind)";
  else if (!isfinite(o->gust_amplitude) || !(o->gust_period > 0)) f = "gusts (amplitude finite, period > 0 s)";
  else if (o->nwind < 0 || (o->nwind > 0 && !o->wind_series)) f = "wind series";
  else if (o->wind_model < VD_MSS_WIND_PAPER || o->wind_model > VD_MSS_WIND_AREA) f = "wind model";
  else if (!(o->air_density >= 0 && isfinite(o->air_density))) f = "air density (kg/m^3 >= 0)";
  else if (!(o->drag_cd >= 0 && isfinite(o->drag_cd)) || !(o->leaf_cd >= 0 && isfinite(o->leaf_cd)))
    f = "drag coefficients (>= 0)";
  else if (o->drag < VD_MSS_DRAG_NONE || o->drag > VD_MSS_DRAG_QUADRATIC) f = "drag model";
  else if (!(o->viscosity >= 0 && isfinite(o->viscosity))) f = "viscosity (Pa s >= 0)";
  else if (o->light && (!finite3(o->light_pos) || !isfinite(o->light_k))) f = "light (position m, strength N m^2)";
  else if (o->gravitropism < VD_MSS_GRAVI_NONE || o->gravitropism > VD_MSS_GRAVI_BASTIEN) f = "gravitropism";
  else if (!isfinite(o->gravi_k)) f = "gravitropism strength (N)";
  else if (!(o->bastien_beta >= 0 && isfinite(o->bastien_beta)) || !(o->bastien_gamma >= 0 && isfinite(o->bastien_gamma)))
    f = "Bastien beta and gamma (>= 0)";
  else if (!(o->growth_zone_age >= 0)) f = "growth zone age (>= 0)";
  if (f) return vd_error_set(err, VD_ERR_VALUE, "", 0, 0, "mass-spring settings: bad %s", f);
  return VD_OK;
}

static vd_status def_check(const vd_mss_def* d, vd_error* err) {
  const char* f = NULL;
  if (d->springs < VD_MSS_PAPER || d->springs > VD_MSS_MATERIAL) f = "spring law";
  else if (!(d->k0_green > 0 && isfinite(d->k0_green)) || !(d->k0_wood > 0 && isfinite(d->k0_wood)))
    f = "spring constant k0 (N/m > 0)";
  else if (!(d->woody_age >= 0)) f = "woody age (>= 0)";
  else if (!(d->rigid_age >= 0)) f = "rigid age (>= 0, inf for none)";
  else if (!(d->young_green > 0 && isfinite(d->young_green)) || !(d->young_wood > 0 && isfinite(d->young_wood)))
    f = "Young's modulus (Pa > 0)";
  else if (!(d->density_green > 0 && isfinite(d->density_green)) ||
           !(d->density_wood > 0 && isfinite(d->density_wood)))
    f = "density (kg/m^3 > 0)";
  else if (!(d->mor > 0) || !(d->mor_green > 0)) f = "modulus of rupture (Pa > 0, inf for none)";
  else if (!(d->leaf_areal_density >= 0 && isfinite(d->leaf_areal_density))) f = "leaf areal density (kg/m^2 >= 0)";
  else if (!(d->min_mass > 0 && isfinite(d->min_mass))) f = "smallest node mass (kg > 0)";
  else if (!(d->damping >= 0 && isfinite(d->damping))) f = "damping c (>= 0)";
  else if (!(d->fix_height >= 0 && isfinite(d->fix_height))) f = "fix height (m >= 0)";
  else if (d->max_nodes < 1) f = "largest node count (>= 1)";
  if (f) return vd_error_set(err, VD_ERR_VALUE, "", 0, 0, "mass-spring model: bad %s", f);
  return vd_soil_check(&d->soil, err);
}

// ---------------------------------------------------------------------------------------------
// build

// whether a segment is part of the structure (stems, trunks, branches, roots, unknown organs)
static int structural(const vd_model* p, int j) {
  const vd_label* l = vd_model_find_label(p, p->seg_label[j]);
  vd_organ o = l ? l->organ : VD_ORGAN_OTHER;
  return o == VD_ORGAN_STEM || o == VD_ORGAN_ROOT || o == VD_ORGAN_OTHER;
}

static int is_root(const vd_model* p, int j) {
  const vd_label* l = vd_model_find_label(p, p->seg_label[j]);
  return l && l->organ == VD_ORGAN_ROOT;
}

static vd_vec3 rest_at(const vd_model* p, const double* rest, int n) {
  const double* x = rest ? rest + 3 * n : p->node_pos0 + 3 * n;
  return vd_v3(x[0], x[1], x[2]);
}

// the structure node a non-structural segment hangs from (its topmost non-structural ancestor's
// start, or the end of the structural segment it grows from), -1 if none
static int seg_attach(const vd_model* p, const int* map, int j) {
  int k = j, guard = p->nseg;
  while (p->seg_parent[k] >= 0 && !structural(p, p->seg_parent[k]) && guard-- > 0) k = p->seg_parent[k];
  int n = p->seg_node[2 * k];
  if (map[n] >= 0) return map[n];
  int par = p->seg_parent[k];
  if (par >= 0 && map[p->seg_node[2 * par + 1]] >= 0) return map[p->seg_node[2 * par + 1]];
  return -1;
}

// attachment of an organ given by its node and parent segment
static int organ_attach(const vd_model* p, const int* map, int node, int parent) {
  if (node >= 0 && node < p->nnode && map[node] >= 0) return map[node];
  if (parent < 0) return -1;
  if (structural(p, parent)) return map[p->seg_node[2 * parent + 1]];
  return seg_attach(p, map, parent);
}

// block layout: each array 8-byte aligned in one allocation
typedef struct layout {
  size_t n;
} layout;
static size_t lay(layout* l, size_t bytes) {
  size_t at = l->n;
  l->n += (bytes + 7) & ~(size_t)7;
  return at;
}

vd_status vd_mss_build(const vd_model* p, const vd_mss_def* def, const double* rest, vd_mss_model** out,
                       vd_error* err) {
  *out = NULL;
  vd_status st = def_check(def, err);
  if (st) return st;
  int npn = p->nnode, nps = p->nseg;
  // plant node -> mass-spring node: every node of a structural segment, in plant order
  int* map = vd_malloc(sizeof(int) * (size_t)(npn ? npn : 1));
  if (!map) return vd_error_set(err, VD_ERR_NOMEM, "", 0, 0, "out of memory");
  for (int i = 0; i < npn; i++) map[i] = -1;
  int ninter = 0, has_roots = 0;
  for (int j = 0; j < nps; j++)
    if (structural(p, j)) {
      map[p->seg_node[2 * j]] = map[p->seg_node[2 * j + 1]] = 0;
      ninter++;
      has_roots |= is_root(p, j);
    }
  // axes that start at one point without a parent segment (roots and trunk from an axiom, where
  // the turtle starts a node per branch) share that point's node: an alias is marked -2 - target
  for (int j = 0; j < nps; j++) {
    if (!structural(p, j) || p->seg_parent[j] >= 0) continue;
    int n = p->seg_node[2 * j];
    if (map[n] != 0) continue;
    vd_vec3 x = rest_at(p, rest, n);
    for (int k = 0; k < j; k++) {
      if (!structural(p, k) || p->seg_parent[k] >= 0) continue;
      int b = p->seg_node[2 * k];
      if (b == n || map[b] != 0) continue;
      vd_vec3 y = rest_at(p, rest, b);
      if (fabs(x.x - y.x) <= 1e-9 && fabs(x.y - y.y) <= 1e-9 && fabs(x.z - y.z) <= 1e-9) {
        map[n] = -2 - b;
        break;
      }
    }
  }
  int nn = 0;
  for (int i = 0; i < npn; i++)
    if (map[i] == 0) map[i] = nn++;
  // aliases take their point's node; the node's plant node is the one that was numbered
  unsigned char* alias = vd_calloc((size_t)(npn ? npn : 1), 1);
  if (!alias) {
    vd_free(map, sizeof(int) * (size_t)(npn ? npn : 1));
    return vd_error_set(err, VD_ERR_NOMEM, "", 0, 0, "out of memory");
  }
  for (int i = 0; i < npn; i++)
    if (map[i] <= -2) map[i] = map[-2 - map[i]], alias[i] = 1;
  if (nn > def->max_nodes) {
    vd_free(map, sizeof(int) * (size_t)(npn ? npn : 1));
    vd_free(alias, (size_t)(npn ? npn : 1));
    return vd_error_set(err, VD_ERR_LIMIT, "", 0, 0, "the mass-spring model would have %d nodes, more than %d", nn,
                        def->max_nodes);
  }
  // owners and children: internode springs 0..ninter-1 in plant segment order
  int* seg_of = vd_malloc(sizeof(int) * (size_t)(ninter ? ninter : 1));
  int* owner = vd_malloc(sizeof(int) * (size_t)(nn ? nn : 1));
  int* nchild = vd_calloc((size_t)(nn ? nn : 1), sizeof(int));
  int* first_child = vd_malloc(sizeof(int) * (size_t)(nn ? nn : 1));  // first internode from the node
  if (!seg_of || !owner || !nchild || !first_child) {
    st = vd_error_set(err, VD_ERR_NOMEM, "", 0, 0, "out of memory");
    goto done;
  }
  for (int i = 0; i < nn; i++) owner[i] = -1, first_child[i] = -1;
  {
    int s = 0;
    for (int j = 0; j < nps; j++) {
      if (!structural(p, j)) continue;
      int a = map[p->seg_node[2 * j]], b = map[p->seg_node[2 * j + 1]];
      vd_vec3 xa = rest_at(p, rest, p->seg_node[2 * j]), xb = rest_at(p, rest, p->seg_node[2 * j + 1]);
      if (!finite3(xa) || !finite3(xb)) {
        st = vd_error_set(err, VD_ERR_VALUE, "", 0, 0, "segment %d: non-finite rest position", j);
        goto done;
      }
      if (!(vd_norm(vd_sub(xb, xa)) > 1e-9)) {
        st = vd_error_set(err, VD_ERR_VALUE, "", 0, 0, "segment %d has zero length: a spring needs a rest length", j);
        goto done;
      }
      if (a == b) {
        st = vd_error_set(err, VD_ERR_VALUE, "", 0, 0, "segment %d starts and ends at node %d", j, p->seg_node[2 * j]);
        goto done;
      }
      seg_of[s] = j;
      if (owner[b] < 0) owner[b] = s;
      nchild[a]++;
      if (first_child[a] < 0 || (is_root(p, seg_of[first_child[a]]) && !is_root(p, j))) first_child[a] = s;
      s++;
    }
  }
  // springs and hinges
  int nalt = 0, nhinge = 0;
  {
    for (int s = 0; s < ninter; s++) {
      int j = seg_of[s], b = map[p->seg_node[2 * j]];
      int has_parent = owner[b] >= 0;
      int other_child = !has_parent && first_child[b] >= 0 && first_child[b] != s;
      if (def->springs == VD_MSS_PAPER) nalt += has_parent || other_child;
      else nhinge++;  // every internode gets one hinge (parent arm, sibling arm or fixed arm)
    }
  }
  int nspring = ninter + nalt;
  layout L = {0};
  size_t o_model = lay(&L, sizeof(vd_mss_model));
  size_t o_pmap = lay(&L, sizeof(int) * (size_t)(npn ? npn : 1));
  size_t o_nplant = lay(&L, sizeof(int) * (size_t)nn), o_nparent = lay(&L, sizeof(int) * (size_t)nn),
         o_nowner = lay(&L, sizeof(int) * (size_t)nn), o_nflags = lay(&L, sizeof(unsigned) * (size_t)nn),
         o_nrest = lay(&L, sizeof(vd_vec3) * (size_t)nn), o_nmass = lay(&L, sizeof(double) * (size_t)nn),
         o_nrad = lay(&L, sizeof(double) * (size_t)nn), o_nage = lay(&L, sizeof(double) * (size_t)nn),
         o_nleaf = lay(&L, sizeof(double) * (size_t)nn), o_nsoil = lay(&L, sizeof(double) * (size_t)nn),
         o_npre = lay(&L, sizeof(int) * (size_t)nn), o_norder = lay(&L, sizeof(int) * (size_t)nn),
         o_nlast = lay(&L, sizeof(int) * (size_t)nn), o_naxis = lay(&L, sizeof(int) * (size_t)nn);
  size_t o_snode = lay(&L, sizeof(int) * 2 * (size_t)nspring), o_splant = lay(&L, sizeof(int) * (size_t)nspring),
         o_sk = lay(&L, sizeof(double) * (size_t)nspring), o_sl0 = lay(&L, sizeof(double) * (size_t)nspring),
         o_srad = lay(&L, sizeof(double) * 2 * (size_t)nspring), o_smor = lay(&L, sizeof(double) * (size_t)nspring);
  size_t o_hnode = lay(&L, sizeof(int) * 3 * (size_t)nhinge), o_hk = lay(&L, sizeof(double) * (size_t)nhinge),
         o_hp = lay(&L, sizeof(vd_vec3) * (size_t)nhinge), o_hq = lay(&L, sizeof(vd_vec3) * (size_t)nhinge);
  char* blk = vd_calloc(1, L.n);
  if (!blk) {
    st = vd_error_set(err, VD_ERR_NOMEM, "", 0, 0, "out of memory (%zu bytes for the mass-spring model)", L.n);
    goto done;
  }
  vd_mss_model* m = (vd_mss_model*)(blk + o_model);
  m->nbytes = L.n;
  m->nnode = nn, m->ninter = ninter, m->nspring = nspring, m->nhinge = nhinge;
  m->nplant = npn;
  m->plant_node = (int*)(blk + o_pmap);
  memcpy(m->plant_node, map, sizeof(int) * (size_t)npn);
  m->opt = vd_mss_opt_default();
  m->springs = def->springs;
  m->rigid_age = def->rigid_age;
  m->damping = def->damping;
  m->crown = -1;
  m->node_plant = (int*)(blk + o_nplant), m->node_parent = (int*)(blk + o_nparent);
  m->node_owner = (int*)(blk + o_nowner), m->node_flags = (unsigned*)(blk + o_nflags);
  m->node_rest = (vd_vec3*)(blk + o_nrest), m->node_mass = (double*)(blk + o_nmass);
  m->node_radius = (double*)(blk + o_nrad), m->node_age = (double*)(blk + o_nage);
  m->node_leaf_area = (double*)(blk + o_nleaf), m->node_soil = (double*)(blk + o_nsoil);
  m->node_axis = (int*)(blk + o_naxis);
  m->node_pre = (int*)(blk + o_npre), m->node_order = (int*)(blk + o_norder), m->node_last = (int*)(blk + o_nlast);
  m->spring_node = (int*)(blk + o_snode), m->spring_plant = (int*)(blk + o_splant);
  m->spring_k = (double*)(blk + o_sk), m->spring_l0 = (double*)(blk + o_sl0);
  m->spring_radius = (double*)(blk + o_srad), m->spring_mor = (double*)(blk + o_smor);
  m->hinge_node = (int*)(blk + o_hnode), m->hinge_k = (double*)(blk + o_hk);
  m->hinge_p0 = (vd_vec3*)(blk + o_hp), m->hinge_q0 = (vd_vec3*)(blk + o_hq);
  // nodes
  for (int i = 0; i < npn; i++)
    if (map[i] >= 0 && !alias[i]) {
      int k = map[i];
      m->node_plant[k] = i;
      m->node_rest[k] = rest_at(p, rest, i);
      m->node_owner[k] = owner[k];
      m->node_parent[k] = -1;
      m->node_axis[k] = -1;
    }
  // internodes: k = k0 d / l (paper) or E A / l (material); masses from their volumes
  for (int s = 0; s < ninter; s++) {
    int j = seg_of[s], a = map[p->seg_node[2 * j]], b = map[p->seg_node[2 * j + 1]];
    double r0 = p->seg_radius[2 * j], r1 = p->seg_radius[2 * j + 1], l0 = vd_norm(vd_sub(m->node_rest[b], m->node_rest[a]));
    double age = p->seg_age[j];
    int woody = age >= def->woody_age || is_root(p, j);
    double rbar = 0.5 * (r0 + r1);
    m->spring_node[2 * s] = a, m->spring_node[2 * s + 1] = b;
    m->spring_plant[s] = j;
    m->spring_l0[s] = l0;
    m->spring_radius[2 * s] = r0, m->spring_radius[2 * s + 1] = r1;
    m->spring_k[s] = def->springs == VD_MSS_PAPER ? (woody ? def->k0_wood : def->k0_green) * 2 * rbar / l0
                                                  : (woody ? def->young_wood : def->young_green) * VD_PI * rbar * rbar / l0;
    m->spring_mor[s] = woody ? def->mor : def->mor_green;
    if (owner[b] == s) {
      m->node_parent[b] = a;
      m->node_radius[b] = r1;
      m->node_age[b] = age;
      m->node_axis[b] = p->seg_axis[j];
      double vol = VD_PI * l0 * (r0 * r0 + r0 * r1 + r1 * r1) / 3;
      m->node_mass[b] += vol * (woody ? def->density_wood : def->density_green);
      if (is_root(p, j)) m->node_flags[b] |= VD_MSS_ROOT;
    }
  }
  // bases: radius and age of their oldest internode
  for (int s = 0; s < ninter; s++) {
    int a = m->spring_node[2 * s];
    if (owner[a] >= 0) continue;
    m->node_radius[a] = fmax(m->node_radius[a], m->spring_radius[2 * s]);
    m->node_age[a] = fmax(m->node_age[a], p->seg_age[seg_of[s]]);
  }
  // organs that are not structure hang their mass and drag area on the node they grow from
  for (int j = 0; j < nps; j++) {
    if (structural(p, j)) continue;
    int at = seg_attach(p, map, j);
    if (at < 0) continue;
    double r0 = p->seg_radius[2 * j], r1 = p->seg_radius[2 * j + 1], l = p->seg_len0[j];
    m->node_mass[at] += def->density_green * VD_PI * l * (r0 * r0 + r0 * r1 + r1 * r1) / 3;
    m->node_leaf_area[at] += (r0 + r1) * l;
  }
  for (int k = 0; k < p->nsphere; k++) {
    int at = organ_attach(p, map, p->sphere_node[k], p->sphere_parent[k]);
    if (at < 0) continue;
    double r = p->sphere_radius[k];
    m->node_mass[at] += def->density_green * 4.0 / 3.0 * VD_PI * r * r * r;
    m->node_leaf_area[at] += VD_PI * r * r;
  }
  for (int k = 0; k < p->nmesh; k++) {
    int at = organ_attach(p, map, p->mesh_node[k], p->mesh_parent[k]);
    if (at < 0) continue;
    double area = 0;
    for (int t = p->mesh_tri[2 * k]; t < p->mesh_tri[2 * k] + p->mesh_tri[2 * k + 1]; t++) {
      const int* v = p->tri_vert + 3 * t;
      const double *x0 = p->vert_pos0 + 3 * v[0], *x1 = p->vert_pos0 + 3 * v[1], *x2 = p->vert_pos0 + 3 * v[2];
      vd_vec3 e1 = vd_v3(x1[0] - x0[0], x1[1] - x0[1], x1[2] - x0[2]);
      vd_vec3 e2 = vd_v3(x2[0] - x0[0], x2[1] - x0[1], x2[2] - x0[2]);
      area += 0.5 * vd_norm(vd_cross(e1, e2));
    }
    m->node_mass[at] += def->leaf_areal_density * area;
    m->node_leaf_area[at] += area;
  }
  for (int i = 0; i < nn; i++) m->node_mass[i] = fmax(m->node_mass[i], def->min_mass);
  // flags: buds, soil and clamps
  {
    const vd_soil* soil = &def->soil;
    int nfixed = 0, nsoil = 0;
    for (int i = 0; i < nn; i++) {
      if (!nchild[i]) m->node_flags[i] |= VD_MSS_TIP;
      double z = m->node_rest[i].z, depth = soil->ground - z;
      int base = owner[i] < 0;
      // in the soil: root nodes below the ground (a base at the ground holds through its roots)
      int in_soil = has_roots && (m->node_flags[i] & VD_MSS_ROOT) && depth > 0;
      // clamped: in a clamping soil (with the stem's base there, a pot), or a stem base at the
      // ground of a plant without roots
      int at_ground = base && z <= soil->ground + def->fix_height;
      int clamp = (in_soil && soil->method == VD_SOIL_CLAMP) || (at_ground && (!has_roots || soil->method == VD_SOIL_CLAMP));
      // the root crown: the base where the roots meet the stem, held by the soil through them
      if (!clamp && at_ground && has_roots && m->crown < 0) {
        m->node_flags[i] |= VD_MSS_CROWN;
        m->crown = i;
      }
      if (clamp) {
        m->node_flags[i] |= VD_MSS_FIXED;
        nfixed++;
      } else if (in_soil) {
        m->node_flags[i] |= VD_MSS_SOIL;
        int s = owner[i];
        double area = s >= 0 ? VD_PI * (m->spring_radius[2 * s] + m->spring_radius[2 * s + 1]) * m->spring_l0[s] : 0;
        m->node_soil[i] = vd_soil_max_force(soil, depth, m->node_radius[i], area);
        nsoil++;
      }
    }
    // the crown's anchorage: every root node's resistance, acting across its arm from the crown
    // (docs/physics.md, "Anchorage"); a crown with no soil node under it is not one
    m->ground = soil->ground;
    if (m->crown >= 0) {
      for (int i = 0; i < nn; i++) {
        if (!(m->node_flags[i] & VD_MSS_SOIL)) continue;
        m->anchor_force += m->node_soil[i];
        m->anchor_moment += m->node_soil[i] * vd_norm(vd_sub(m->node_rest[i], m->node_rest[m->crown]));
      }
      if (!nsoil) {
        m->node_flags[m->crown] &= ~VD_MSS_CROWN;
        m->crown = -1;
      }
    }
    // a plant held by nothing is clamped at its lowest base
    if (!nfixed && !nsoil) {
      int low = -1;
      for (int i = 0; i < nn; i++)
        if (owner[i] < 0 && (low < 0 || m->node_rest[i].z < m->node_rest[low].z)) low = i;
      if (low >= 0) m->node_flags[low] |= VD_MSS_FIXED;
    }
  }
  // alternate-node springs (paper) or hinges (material)
  {
    int sa = ninter, h = 0;
    for (int s = 0; s < ninter; s++) {
      int b = m->spring_node[2 * s], c = m->spring_node[2 * s + 1];
      int a = owner[b] >= 0 ? m->spring_node[2 * owner[b]] : -1, sib = -1;
      // the internodes from a crown or a clamped base hinge on the soil or the clamp (a fixed
      // arm), not on each other: the soil around the crown takes the stem's moment, not the first
      // root (the paper's alternate-node springs keep the sibling: they have no fixed arm)
      int crown = (m->node_flags[b] & (VD_MSS_CROWN | VD_MSS_FIXED)) && def->springs == VD_MSS_MATERIAL;
      if (a < 0 && !crown && first_child[b] >= 0 && first_child[b] != s) sib = first_child[b];
      int arm = a >= 0 ? a : sib >= 0 ? m->spring_node[2 * sib + 1] : -1;  // the other arm's end
      int j = seg_of[s];
      int woody = p->seg_age[j] >= def->woody_age || is_root(p, j);
      if (def->springs == VD_MSS_PAPER) {
        if (arm < 0) continue;
        double l0 = vd_norm(vd_sub(m->node_rest[c], m->node_rest[arm]));
        int other = a >= 0 ? owner[b] : sib;
        double dbar = m->spring_radius[2 * s] + m->spring_radius[2 * s + 1] + m->spring_radius[2 * other] +
                      m->spring_radius[2 * other + 1];  // mean diameter of the two internodes
        dbar *= 0.5;
        m->spring_node[2 * sa] = arm, m->spring_node[2 * sa + 1] = c;
        m->spring_plant[sa] = -1;
        m->spring_l0[sa] = l0 > 1e-9 ? l0 : 1e-9;
        m->spring_k[sa] = (woody ? def->k0_wood : def->k0_green) * dbar / m->spring_l0[sa];
        m->spring_radius[2 * sa] = m->spring_radius[2 * sa + 1] = 0.25 * dbar;
        m->spring_mor[sa] = INFINITY;
        sa++;
      } else {
        vd_vec3 q0 = vd_normalize(vd_sub(m->node_rest[c], m->node_rest[b]));
        double lq = m->spring_l0[s], lp, r = m->spring_radius[2 * s];
        vd_vec3 p0;
        if (arm >= 0) {
          int other = a >= 0 ? owner[b] : sib;
          lp = m->spring_l0[other];
          p0 = vd_normalize(vd_sub(m->node_rest[arm], m->node_rest[b]));
          if (sib >= 0) r = fmin(r, m->spring_radius[2 * sib]);
        } else {
          lp = 0;  // a fixed arm: the clamp holds half a segment (docs/physics.md)
          p0 = vd_scale(q0, -1);
        }
        double e = woody ? def->young_wood : def->young_green;
        m->hinge_node[3 * h] = arm, m->hinge_node[3 * h + 1] = b, m->hinge_node[3 * h + 2] = c;
        m->hinge_k[h] = e * VD_PI * r * r * r * r / 4 / (0.5 * (lp + lq));
        m->hinge_p0[h] = p0, m->hinge_q0[h] = q0;
        // a free base with nothing to hinge on keeps no hinge (it turns freely)
        if (arm < 0 && !(m->node_flags[b] & (VD_MSS_FIXED | VD_MSS_CROWN))) m->hinge_k[h] = 0;
        h++;
      }
    }
  }
  // pre-order of every tree of the forest
  {
    int* stack = first_child;  // reused: no longer needed
    int top = 0, pos = 0;
    // child lists through the internodes: iterate springs by start node (bases in index order)
    int* cstart = nchild;  // reused as CSR offsets
    int* clist = seg_of;   // reused: child nodes, grouped by parent
    int acc = 0;
    for (int i = 0; i < nn; i++) {
      int c = cstart[i];
      cstart[i] = acc;
      acc += c;
    }
    int* fill = owner;  // reused as fill counters (owner no longer needed: in the model)
    for (int i = 0; i < nn; i++) fill[i] = 0;
    for (int s = 0; s < ninter; s++) {
      int a = m->spring_node[2 * s], b = m->spring_node[2 * s + 1];
      if (m->node_owner[b] != s) continue;
      clist[cstart[a] + fill[a]++] = b;
    }
    for (int root = 0; root < nn; root++) {
      if (m->node_owner[root] >= 0) continue;
      stack[top++] = root;
      while (top) {
        int n = stack[--top];
        m->node_pre[n] = pos;
        m->node_order[pos++] = n;
        // children pushed in reverse so they come out in order
        for (int k = fill[n] - 1; k >= 0; k--) stack[top++] = clist[cstart[n] + k];
      }
    }
    // last descendant: children follow their parent in pre-order; a reverse pass takes the max
    for (int i = 0; i < nn; i++) m->node_last[i] = m->node_pre[i];
    for (int k = pos - 1; k >= 0; k--) {
      int n = m->node_order[k], par = m->node_parent[n];
      if (par >= 0 && m->node_owner[n] >= 0) m->node_last[par] = m->node_last[par] > m->node_last[n] ? m->node_last[par] : m->node_last[n];
    }
    // nodes not reached (owned through a loop) go last, each on its own
    for (int i = 0; i < nn && pos < nn; i++) {
      int seen = m->node_order[m->node_pre[i]] == i && m->node_pre[i] < pos;
      if (!seen) {
        m->node_pre[i] = pos;
        m->node_order[pos] = i;
        m->node_last[i] = pos++;
      }
    }
  }
  // main tip (the end of the main axis, farthest along it from its base), base and height
  {
    double* dist = m->node_soil;  // borrowed: path length from the base, before node_soil is read
    double* keep = vd_malloc(sizeof(double) * (size_t)(nn ? nn : 1));
    if (keep) memcpy(keep, m->node_soil, sizeof(double) * (size_t)nn);
    for (int k = 0; k < nn; k++) {
      int n = m->node_order[k], par = m->node_parent[n];
      dist[n] = par >= 0 && m->node_owner[n] >= 0 ? dist[par] + m->spring_l0[m->node_owner[n]] : 0;
    }
    int tip = -1;
    double best = -1;
    for (int pass = 0; pass < 2 && tip < 0; pass++)
      for (int i = 0; i < nn; i++) {
        int s = m->node_owner[i];
        if (s < 0 || (m->node_flags[i] & VD_MSS_ROOT)) continue;
        if (pass == 0 && p->seg_order[m->spring_plant[s]] != 0) continue;
        if (dist[i] > best) best = dist[i], tip = i;
      }
    if (keep) {
      memcpy(m->node_soil, keep, sizeof(double) * (size_t)nn);
      vd_free(keep, sizeof(double) * (size_t)(nn ? nn : 1));
    } else {
      st = vd_error_set(err, VD_ERR_NOMEM, "", 0, 0, "out of memory");
      vd_free(blk, L.n);
      goto done;
    }
    m->main_tip = tip;
    int base = tip;
    for (int guard = nn; base >= 0 && m->node_parent[base] >= 0 && guard-- > 0;) base = m->node_parent[base];
    m->base = base;
    double hmax = 0;
    for (int i = 0; i < nn && base >= 0; i++)
      if (!(m->node_flags[i] & VD_MSS_ROOT)) hmax = fmax(hmax, m->node_rest[i].z - m->node_rest[base].z);
    m->height0 = hmax;
    for (int i = 0; i < nn; i++) m->total_mass += m->node_mass[i];
  }
  *out = m;
done:
  vd_free(map, sizeof(int) * (size_t)(npn ? npn : 1));
  vd_free(alias, (size_t)(npn ? npn : 1));
  vd_free(seg_of, sizeof(int) * (size_t)(ninter ? ninter : 1));
  vd_free(owner, sizeof(int) * (size_t)(nn ? nn : 1));
  vd_free(nchild, sizeof(int) * (size_t)(nn ? nn : 1));
  vd_free(first_child, sizeof(int) * (size_t)(nn ? nn : 1));
  return st;
}

void vd_mss_model_destroy(vd_mss_model* m) {
  if (m) vd_free(m, m->nbytes);
}

// ---------------------------------------------------------------------------------------------
// state

int direct_symbolic(const vd_mss_model* m, mss_work* w);

vd_mss_data* vd_mss_data_create(const vd_mss_model* m) {
  int nn = m->nnode, ns = m->nspring;
  size_t n1 = (size_t)(nn ? nn : 1), s1 = (size_t)(ns ? ns : 1);
  layout L = {0};
  size_t o_d = lay(&L, sizeof(vd_mss_data));
  size_t o_pos = lay(&L, sizeof(vd_vec3) * n1), o_vel = lay(&L, sizeof(vd_vec3) * n1),
         o_force = lay(&L, sizeof(vd_vec3) * n1), o_mass = lay(&L, sizeof(double) * n1),
         o_fext = lay(&L, sizeof(vd_vec3) * n1), o_acc = lay(&L, sizeof(vd_vec3) * n1),
         o_dv = lay(&L, sizeof(vd_vec3) * n1), o_held = lay(&L, n1), o_yield = lay(&L, n1), o_rem = lay(&L, n1),
         o_rig = lay(&L, n1), o_body = lay(&L, sizeof(vd_vec3) * n1), o_sbroken = lay(&L, s1),
         o_nstress = lay(&L, sizeof(double) * n1), o_sstress = lay(&L, sizeof(double) * s1);
  // scratch
  size_t o_w = lay(&L, sizeof(mss_work));
  size_t o_wv = lay(&L, sizeof(vd_vec3) * n1 * 14), o_pre = lay(&L, sizeof(double) * 9 * n1),
         o_cd = lay(&L, sizeof(double) * n1), o_ks = lay(&L, sizeof(double) * n1), o_sc = lay(&L, sizeof(double) * s1),
         o_con = lay(&L, n1), o_elim = lay(&L, sizeof(int) * n1 * 3), o_link = lay(&L, sizeof(int) * n1 * MSS_LINKS),
         o_lblk = lay(&L, sizeof(double) * n1 * MSS_LINKS * 9), o_diag = lay(&L, sizeof(double) * n1 * 9),
         o_as = lay(&L, sizeof(int) * s1), o_ah = lay(&L, sizeof(int) * (size_t)(m->nhinge ? m->nhinge : 1));
  char* blk = vd_calloc(1, L.n);
  if (!blk) return NULL;
  vd_mss_data* d = (vd_mss_data*)(blk + o_d);
  d->nbytes = L.n;
  d->nnode = nn, d->nspring = ns;
  d->pos = (vd_vec3*)(blk + o_pos), d->vel = (vd_vec3*)(blk + o_vel), d->force = (vd_vec3*)(blk + o_force);
  d->mass = (double*)(blk + o_mass), d->fext = (vd_vec3*)(blk + o_fext), d->acc = (vd_vec3*)(blk + o_acc);
  d->dv = (vd_vec3*)(blk + o_dv);
  d->held = (unsigned char*)(blk + o_held), d->yielded = (unsigned char*)(blk + o_yield);
  d->removed = (unsigned char*)(blk + o_rem), d->rigid = (unsigned char*)(blk + o_rig);
  d->body = (vd_vec3*)(blk + o_body), d->spring_broken = (unsigned char*)(blk + o_sbroken);
  d->node_stress = (double*)(blk + o_nstress), d->spring_stress = (double*)(blk + o_sstress);
  mss_work* w = (mss_work*)(blk + o_w);
  vd_vec3* v = (vd_vec3*)(blk + o_wv);
  vd_vec3** slots[] = {&w->fint, &w->ftot, &w->cg_r, &w->cg_z, &w->cg_p, &w->cg_ap, &w->cg_x,
                       &w->cg_b, &w->dvs,  &w->pos0, &w->vel0, &w->fsub, &w->msub};
  for (size_t k = 0; k < sizeof slots / sizeof slots[0]; k++) *slots[k] = v + k * n1;
  w->pre = (double*)(blk + o_pre), w->cdrag = (double*)(blk + o_cd), w->ksum = (double*)(blk + o_ks);
  w->spring_c = (double*)(blk + o_sc), w->con = (unsigned char*)(blk + o_con);
  w->elim = (int*)(blk + o_elim), w->epos = w->elim + n1, w->nlink = w->epos + n1;
  w->link = (int*)(blk + o_link), w->lblk = (double*)(blk + o_lblk), w->diag = (double*)(blk + o_diag);
  w->anchor_spring = (int*)(blk + o_as), w->anchor_hinge = (int*)(blk + o_ah);
  w->direct = direct_symbolic(m, w);
  d->work = w;
  d->work_bytes = 0;
  for (int i = 0; i < nn; i++) {
    d->pos[i] = m->node_rest[i];
    d->mass[i] = m->node_mass[i];
  }
  d->rb.q = vd_quat_identity();
  d->uproot_tilt = 10 * VD_PI / 180;
  return d;
}

void vd_mss_data_destroy(vd_mss_data* d) {
  if (!d) return;
  vd_free(d->event, sizeof(vd_mss_event) * (size_t)d->cap_event);
  vd_free(d, d->nbytes);
}

int mss_event(vd_mss_data* d, const vd_mss_event* e) {
  if (!vd_grow((void**)&d->event, &d->cap_event, d->nevent + 1, sizeof(vd_mss_event))) return 0;
  d->event[d->nevent++] = *e;
  return 1;
}

// ---------------------------------------------------------------------------------------------
// integrators

// 3 x 3 block helpers (row-major)
static void blk_add_outer(double* b, vd_vec3 u, double s) {
  double a[3] = {u.x, u.y, u.z};
  for (int r = 0; r < 3; r++)
    for (int c = 0; c < 3; c++) b[3 * r + c] += s * a[r] * a[c];
}
static void blk_add_ident(double* b, double s) { b[0] += s, b[4] += s, b[8] += s; }

// the spring's stiffness block: k (u u^T + max(0, 1 - l0 / l) (I - u u^T)), positive semidefinite
// (the transverse part is dropped under compression, Choi & Ko 2002)
static void spring_block(const vd_mss_model* m, const vd_mss_data* d, int s, double* b, vd_vec3* u_out) {
  int i = m->spring_node[2 * s], j = m->spring_node[2 * s + 1];
  vd_vec3 e = vd_sub(d->pos[j], d->pos[i]);
  double l = v_norm(e);
  vd_vec3 u = l > 0 ? vd_scale(e, 1.0 / l) : vd_v3(0, 0, 1);
  double k = m->spring_k[s], t = l > 0 ? fmax(0.0, 1.0 - m->spring_l0[s] / l) : 0;
  memset(b, 0, 9 * sizeof(double));
  blk_add_ident(b, k * t);
  blk_add_outer(b, u, k * (1 - t));
  if (u_out) *u_out = u;
}

static vd_vec3 blk_mul(const double* b, vd_vec3 x) {
  return vd_v3(b[0] * x.x + b[1] * x.y + b[2] * x.z, b[3] * x.x + b[4] * x.y + b[5] * x.z,
               b[6] * x.x + b[7] * x.y + b[8] * x.z);
}

static void skew(double* s, vd_vec3 v) {
  s[0] = 0, s[1] = -v.z, s[2] = v.y;
  s[3] = v.z, s[4] = 0, s[5] = -v.x;
  s[6] = -v.y, s[7] = v.x, s[8] = 0;
}

// a hinge's linearisation: the error rotation changes by J (da, db, dc) with
// J = [S(p)/lp, -S(p)/lp + S(q)/lq, -S(q)/lq]; the stiffness is k J^T J
typedef struct hinge_lin {
  int a, b, c;
  double ja[9], jb[9], jc[9];
  double k;
} hinge_lin;

static int hinge_linearise(const vd_mss_model* m, const vd_mss_data* d, int h, hinge_lin* hl) {
  const int* hn = m->hinge_node + 3 * h;
  hl->a = hn[0], hl->b = hn[1], hl->c = hn[2];
  hl->k = m->hinge_k[h];
  if (!mss_hinge_on(m, d, h)) return 0;
  if ((hl->a >= 0 && d->removed[hl->a]) || d->removed[hl->b] || d->removed[hl->c]) return 0;
  if ((hl->a < 0 || d->rigid[hl->a]) && d->rigid[hl->b] && d->rigid[hl->c]) return 0;
  vd_vec3 q = vd_sub(d->pos[hl->c], d->pos[hl->b]);
  double lq = v_norm(q);
  if (!(lq > 0)) return 0;
  double sq[9];
  skew(sq, vd_scale(q, 1.0 / lq));
  memset(hl->ja, 0, sizeof hl->ja);
  for (int k = 0; k < 9; k++) hl->jc[k] = -sq[k] / lq, hl->jb[k] = sq[k] / lq;
  if (hl->a >= 0) {
    vd_vec3 pa = vd_sub(d->pos[hl->a], d->pos[hl->b]);
    double lp = v_norm(pa);
    if (lp > 0) {
      double sp[9];
      skew(sp, vd_scale(pa, 1.0 / lp));
      for (int k = 0; k < 9; k++) hl->ja[k] = sp[k] / lp, hl->jb[k] -= sp[k] / lp;
    }
  }
  return 1;
}

// b += s J_x^T J_y (3 x 3 blocks)
static void blk_add_jtj(double* out, const double* jx, const double* jy, double s) {
  for (int r = 0; r < 3; r++)
    for (int c = 0; c < 3; c++) {
      double acc = 0;
      for (int k = 0; k < 3; k++) acc += jx[3 * k + r] * jy[3 * k + c];
      out[3 * r + c] += s * acc;
    }
}

static vd_vec3 blk_tmul(const double* b, vd_vec3 x) {
  return vd_v3(b[0] * x.x + b[3] * x.y + b[6] * x.z, b[1] * x.x + b[4] * x.y + b[7] * x.z,
               b[2] * x.x + b[5] * x.y + b[8] * x.z);
}

// y = A x with A = M + h C_drag - h dF/dv - h^2 dF/dx, zero on constrained nodes
static void apply_a(const vd_mss_model* m, const vd_mss_data* d, const mss_work* w, const vd_vec3* x, vd_vec3* y) {
  double h = m->opt.dt;
  int nn = m->nnode;
  for (int i = 0; i < nn; i++) y[i] = vd_scale(x[i], d->mass[i] + h * w->cdrag[i]);
  int material = m->springs == VD_MSS_MATERIAL;
  for (int s = 0; s < m->nspring; s++) {
    if (d->spring_broken[s]) continue;
    int i = m->spring_node[2 * s], j = m->spring_node[2 * s + 1];
    if (d->rigid[i] && d->rigid[j]) continue;
    double b[9];
    vd_vec3 u;
    spring_block(m, d, s, b, &u);
    vd_vec3 dx = vd_sub(x[i], x[j]);
    vd_vec3 f = vd_scale(blk_mul(b, dx), h * h);
    double c = w->spring_c[s];
    if (material) f = vd_madd(f, u, h * c * vd_dot(u, dx));
    else f = vd_madd(f, dx, h * c);
    y[i] = vd_add(y[i], f);
    y[j] = vd_sub(y[j], f);
  }
  for (int k = 0; k < m->nhinge; k++) {
    hinge_lin hl;
    if (!hinge_linearise(m, d, k, &hl)) continue;
    vd_vec3 jx = vd_add(blk_mul(hl.jb, x[hl.b]), blk_mul(hl.jc, x[hl.c]));
    if (hl.a >= 0) jx = vd_add(jx, blk_mul(hl.ja, x[hl.a]));
    double s = h * h * hl.k;
    if (hl.a >= 0) y[hl.a] = vd_madd(y[hl.a], blk_tmul(hl.ja, jx), s);
    y[hl.b] = vd_madd(y[hl.b], blk_tmul(hl.jb, jx), s);
    y[hl.c] = vd_madd(y[hl.c], blk_tmul(hl.jc, jx), s);
  }
  for (int i = 0; i < nn; i++)
    if (w->con[i]) y[i] = vd_v3(0, 0, 0);
}

// invert a 3 x 3 (cofactors); identity scaled by 1 / trace when singular
static void blk_inverse(double* out, const double* a) {
  double c00 = a[4] * a[8] - a[5] * a[7], c01 = a[5] * a[6] - a[3] * a[8], c02 = a[3] * a[7] - a[4] * a[6];
  double det = a[0] * c00 + a[1] * c01 + a[2] * c02;
  if (!(fabs(det) > 1e-300) || !isfinite(det)) {
    double tr = a[0] + a[4] + a[8];
    memset(out, 0, 9 * sizeof(double));
    if (tr > 0) out[0] = out[4] = out[8] = 3 / tr;
    return;
  }
  double id = 1.0 / det;
  out[0] = c00 * id, out[1] = (a[2] * a[7] - a[1] * a[8]) * id, out[2] = (a[1] * a[5] - a[2] * a[4]) * id;
  out[3] = c01 * id, out[4] = (a[0] * a[8] - a[2] * a[6]) * id, out[5] = (a[2] * a[3] - a[0] * a[5]) * id;
  out[6] = c02 * id, out[7] = (a[1] * a[6] - a[0] * a[7]) * id, out[8] = (a[0] * a[4] - a[1] * a[3]) * id;
}

static void build_preconditioner(const vd_mss_model* m, const vd_mss_data* d, mss_work* w) {
  double h = m->opt.dt;
  int nn = m->nnode, material = m->springs == VD_MSS_MATERIAL;
  double* diag = w->pre;  // assembled in place, inverted at the end
  memset(diag, 0, sizeof(double) * 9 * (size_t)nn);
  for (int i = 0; i < nn; i++) blk_add_ident(diag + 9 * i, d->mass[i] + h * w->cdrag[i]);
  for (int s = 0; s < m->nspring; s++) {
    if (d->spring_broken[s]) continue;
    int i = m->spring_node[2 * s], j = m->spring_node[2 * s + 1];
    double b[9];
    vd_vec3 u;
    spring_block(m, d, s, b, &u);
    for (int k = 0; k < 9; k++) b[k] *= h * h;
    if (material) blk_add_outer(b, u, h * w->spring_c[s]);
    else blk_add_ident(b, h * w->spring_c[s]);
    for (int k = 0; k < 9; k++) diag[9 * i + k] += b[k], diag[9 * j + k] += b[k];
  }
  for (int k = 0; k < m->nhinge; k++) {
    hinge_lin hl;
    if (!hinge_linearise(m, d, k, &hl)) continue;
    double s = h * h * hl.k;
    if (hl.a >= 0) blk_add_jtj(diag + 9 * hl.a, hl.ja, hl.ja, s);
    blk_add_jtj(diag + 9 * hl.b, hl.jb, hl.jb, s);
    blk_add_jtj(diag + 9 * hl.c, hl.jc, hl.jc, s);
  }
  for (int i = 0; i < nn; i++) {
    double a[9];
    memcpy(a, diag + 9 * i, sizeof a);
    blk_inverse(diag + 9 * i, a);
  }
}

// ---------------------------------------------------------------------------------------------
// the direct solver

// Cholesky of a symmetric 3 x 3 in place (lower triangle L, upper zeroed); a pivot that is not
// positive (round-off on a singular block) is replaced by a tiny one
static void chol3(double* a) {
  double scale = fmax(fabs(a[0]), fmax(fabs(a[4]), fabs(a[8])));
  double tiny = (scale > 0 ? scale : 1) * 1e-300;
  double l00 = sqrt(fmax(a[0], tiny));
  double l10 = a[3] / l00, l20 = a[6] / l00;
  double l11 = sqrt(fmax(a[4] - l10 * l10, tiny));
  double l21 = (a[7] - l20 * l10) / l11;
  double l22 = sqrt(fmax(a[8] - l20 * l20 - l21 * l21, tiny));
  a[0] = l00, a[1] = 0, a[2] = 0;
  a[3] = l10, a[4] = l11, a[5] = 0;
  a[6] = l20, a[7] = l21, a[8] = l22;
}

// W <- W L^-T (each row of W solved against L^T)
static void trsm3(double* wm, const double* l) {
  for (int r = 0; r < 3; r++) {
    double* x = wm + 3 * r;
    double y0 = x[0] / l[0];
    double y1 = (x[1] - l[3] * y0) / l[4];
    double y2 = (x[2] - l[6] * y0 - l[7] * y1) / l[8];
    x[0] = y0, x[1] = y1, x[2] = y2;
  }
}

// L^-1 v and L^-T v
static vd_vec3 lsolve3(const double* l, vd_vec3 v) {
  double y0 = v.x / l[0];
  double y1 = (v.y - l[3] * y0) / l[4];
  double y2 = (v.z - l[6] * y0 - l[7] * y1) / l[8];
  return vd_v3(y0, y1, y2);
}
static vd_vec3 ltsolve3(const double* l, vd_vec3 v) {
  double x2 = v.z / l[8];
  double x1 = (v.y - l[7] * x2) / l[4];
  double x0 = (v.x - l[3] * x1 - l[6] * x2) / l[0];
  return vd_v3(x0, x1, x2);
}

// link from node e to the later node l (present or added); 0 when a node would need too many
static int add_link(mss_work* w, int e, int l) {
  int* lk = w->link + MSS_LINKS * e;
  for (int k = 0; k < w->nlink[e]; k++)
    if (lk[k] == l) return 1;
  if (w->nlink[e] == MSS_LINKS) return 0;
  lk[w->nlink[e]++] = l;
  return 1;
}

static int add_pair(mss_work* w, int u, int v) {
  if (u < 0 || v < 0 || u == v) return 1;
  return w->epos[u] < w->epos[v] ? add_link(w, u, v) : add_link(w, v, u);
}

// elimination order (reverse pre-order: every node before its parent) and the links with their
// fill; 0 when some node needs more than MSS_LINKS
int direct_symbolic(const vd_mss_model* m, mss_work* w) {
  int nn = m->nnode;
  for (int k = 0; k < nn; k++) w->elim[k] = m->node_order[nn - 1 - k];
  for (int k = 0; k < nn; k++) w->epos[w->elim[k]] = k, w->nlink[k] = 0;
  for (int s = 0; s < m->nspring; s++)
    if (!add_pair(w, m->spring_node[2 * s], m->spring_node[2 * s + 1])) return 0;
  for (int h = 0; h < m->nhinge; h++) {
    const int* hn = m->hinge_node + 3 * h;
    if (!add_pair(w, hn[0], hn[1]) || !add_pair(w, hn[1], hn[2]) || !add_pair(w, hn[0], hn[2])) return 0;
  }
  // eliminating a node couples every pair of its later neighbours
  for (int k = 0; k < nn; k++) {
    int n = w->elim[k];
    for (int a = 0; a < w->nlink[n]; a++)
      for (int b = a + 1; b < w->nlink[n]; b++)
        if (!add_pair(w, w->link[MSS_LINKS * n + a], w->link[MSS_LINKS * n + b])) return 0;
  }
  return 1;
}

// the block A[v][u] (u eliminated before v) or the diagonal when u == v
static double* block_at(mss_work* w, int u, int v) {
  if (u == v) return w->diag + 9 * u;
  if (w->epos[u] > w->epos[v]) {
    int t = u;
    u = v, v = t;
  }
  int* lk = w->link + MSS_LINKS * u;
  for (int k = 0; k < w->nlink[u]; k++)
    if (lk[k] == v) return w->lblk + 9 * (MSS_LINKS * u + k);
  return NULL;
}

// A[u][v] += b (and its transpose): a block is stored as A[later][earlier]
static void add_block(mss_work* w, int u, int v, const double* b) {
  double* t = block_at(w, u, v);
  if (!t) return;
  if (u == v || w->epos[u] > w->epos[v]) {
    for (int k = 0; k < 9; k++) t[k] += b[k];
  } else {
    for (int r = 0; r < 3; r++)
      for (int c = 0; c < 3; c++) t[3 * r + c] += b[3 * c + r];
  }
}


// the implicit system's velocity change by block LDL^T into w->cg_x (right-hand side w->cg_b)
static void solve_direct(const vd_mss_model* m, vd_mss_data* d, mss_work* w) {
  double h = m->opt.dt;
  int nn = m->nnode, material = m->springs == VD_MSS_MATERIAL;
  memset(w->diag, 0, sizeof(double) * 9 * (size_t)nn);
  memset(w->lblk, 0, sizeof(double) * 9 * MSS_LINKS * (size_t)nn);
  // assemble A = M + h C_drag - h dF/dv - h^2 dF/dx
  for (int i = 0; i < nn; i++) blk_add_ident(w->diag + 9 * i, d->mass[i] + h * w->cdrag[i]);
  for (int s = 0; s < m->nspring; s++) {
    if (d->spring_broken[s]) continue;
    int i = m->spring_node[2 * s], j = m->spring_node[2 * s + 1];
    if (d->rigid[i] && d->rigid[j]) continue;
    double b[9], nb[9];
    vd_vec3 u;
    spring_block(m, d, s, b, &u);
    for (int k = 0; k < 9; k++) b[k] *= h * h;
    if (material) blk_add_outer(b, u, h * w->spring_c[s]);
    else blk_add_ident(b, h * w->spring_c[s]);
    for (int k = 0; k < 9; k++) nb[k] = -b[k];
    add_block(w, i, i, b);
    add_block(w, j, j, b);
    add_block(w, i, j, nb);
  }
  for (int k = 0; k < m->nhinge; k++) {
    hinge_lin hl;
    if (!hinge_linearise(m, d, k, &hl)) continue;
    double sc = h * h * hl.k;
    int node[3] = {hl.a, hl.b, hl.c};
    const double* jac[3] = {hl.ja, hl.jb, hl.jc};
    for (int x = 0; x < 3; x++)
      for (int y = x; y < 3; y++) {
        if (node[x] < 0 || node[y] < 0) continue;
        // A[x][y] += sc J_x^T J_y; add_block wants it in (x, y) orientation
        double b[9] = {0};
        blk_add_jtj(b, jac[x], jac[y], sc);
        if (x == y) {
          add_block(w, node[x], node[x], b);
        } else {
          add_block(w, node[x], node[y], b);
        }
      }
  }
  // constrained nodes: identity rows and columns
  for (int i = 0; i < nn; i++) {
    int* lk = w->link + MSS_LINKS * i;
    for (int k = 0; k < w->nlink[i]; k++)
      if (w->con[i] || w->con[lk[k]]) memset(w->lblk + 9 * (MSS_LINKS * i + k), 0, 9 * sizeof(double));
    if (w->con[i]) {
      memset(w->diag + 9 * i, 0, 9 * sizeof(double));
      blk_add_ident(w->diag + 9 * i, 1);
    }
  }
  // block Cholesky: each node's 3 x 3 pivot is factored L L^T (never inverted: an explicit
  // inverse of a stiff, nearly singular pivot loses the small Schur complements of curved
  // branches), its links become W = A[x][n] L^-T, and its later neighbours take W_y W_x^T
  for (int e = 0; e < nn; e++) {
    int n = w->elim[e];
    double* l = w->diag + 9 * n;
    chol3(l);
    int* lk = w->link + MSS_LINKS * n;
    for (int p = 0; p < w->nlink[n]; p++) trsm3(w->lblk + 9 * (MSS_LINKS * n + p), l);
    for (int p = 0; p < w->nlink[n]; p++) {
      const double* wx = w->lblk + 9 * (MSS_LINKS * n + p);
      for (int q = 0; q < w->nlink[n]; q++) {
        int x = lk[p], y = lk[q];
        if (w->epos[x] > w->epos[y]) continue;  // each pair once, x before y
        const double* wy = w->lblk + 9 * (MSS_LINKS * n + q);
        double* tgt = block_at(w, x, y);  // x == y: the diagonal; else A[y][x]
        if (!tgt) continue;
        for (int r = 0; r < 3; r++)
          for (int c = 0; c < 3; c++)
            tgt[3 * r + c] -= wy[3 * r] * wx[3 * c] + wy[3 * r + 1] * wx[3 * c + 1] + wy[3 * r + 2] * wx[3 * c + 2];
      }
    }
  }
}

// x = A^-1 b with the factors of solve_direct (z: scratch; b, z, x distinct)
static void direct_substitute(const vd_mss_model* m, mss_work* w, const vd_vec3* b, vd_vec3* z, vd_vec3* x) {
  int nn = m->nnode;
  for (int i = 0; i < nn; i++) z[i] = b[i];
  // L y = b: y_n = L_nn^-1 z_n, then the later nodes lose W_x y_n
  for (int e = 0; e < nn; e++) {
    int n = w->elim[e];
    z[n] = lsolve3(w->diag + 9 * n, z[n]);
    int* lk = w->link + MSS_LINKS * n;
    for (int k = 0; k < w->nlink[n]; k++) z[lk[k]] = vd_sub(z[lk[k]], blk_mul(w->lblk + 9 * (MSS_LINKS * n + k), z[n]));
  }
  // L^T x = y: x_n = L_nn^-T (y_n - sum W_x^T x_x)
  for (int e = nn - 1; e >= 0; e--) {
    int n = w->elim[e];
    vd_vec3 acc = z[n];
    int* lk = w->link + MSS_LINKS * n;
    for (int k = 0; k < w->nlink[n]; k++) acc = vd_sub(acc, blk_tmul(w->lblk + 9 * (MSS_LINKS * n + k), x[lk[k]]));
    x[n] = w->con[n] ? vd_v3(0, 0, 0) : ltsolve3(w->diag + 9 * n, acc);
  }
}

// z = P^-1 r: the direct factors or block Jacobi (constrained nodes stay 0)
static void precondition(const vd_mss_model* m, mss_work* w, int direct) {
  if (direct) {
    direct_substitute(m, w, w->cg_r, w->cg_ap, w->cg_z);
    return;
  }
  for (int i = 0; i < m->nnode; i++) w->cg_z[i] = w->con[i] ? vd_v3(0, 0, 0) : blk_mul(w->pre + 9 * i, w->cg_r[i]);
}

// the implicit substep's velocity change into w->cg_x
static void solve_implicit(const vd_mss_model* m, vd_mss_data* d, mss_work* w) {
  double h = m->opt.dt;
  int nn = m->nnode, material = m->springs == VD_MSS_MATERIAL;
  // right-hand side h (F + h dF/dx v), the stiffness term assembled like A's
  for (int i = 0; i < nn; i++) w->cg_b[i] = vd_scale(w->ftot[i], h);
  for (int s = 0; s < m->nspring; s++) {
    if (d->spring_broken[s]) continue;
    int i = m->spring_node[2 * s], j = m->spring_node[2 * s + 1];
    if (d->rigid[i] && d->rigid[j]) continue;
    double b[9];
    spring_block(m, d, s, b, NULL);
    vd_vec3 f = vd_scale(blk_mul(b, vd_sub(d->vel[i], d->vel[j])), h * h);
    w->cg_b[i] = vd_sub(w->cg_b[i], f);
    w->cg_b[j] = vd_add(w->cg_b[j], f);
  }
  for (int k = 0; k < m->nhinge; k++) {
    hinge_lin hl;
    if (!hinge_linearise(m, d, k, &hl)) continue;
    vd_vec3 jv = vd_add(blk_mul(hl.jb, d->vel[hl.b]), blk_mul(hl.jc, d->vel[hl.c]));
    if (hl.a >= 0) jv = vd_add(jv, blk_mul(hl.ja, d->vel[hl.a]));
    double s = -h * h * hl.k;
    if (hl.a >= 0) w->cg_b[hl.a] = vd_madd(w->cg_b[hl.a], blk_tmul(hl.ja, jv), s);
    w->cg_b[hl.b] = vd_madd(w->cg_b[hl.b], blk_tmul(hl.jb, jv), s);
    w->cg_b[hl.c] = vd_madd(w->cg_b[hl.c], blk_tmul(hl.jc, jv), s);
  }
  (void)material;
  for (int i = 0; i < nn; i++)
    if (w->con[i]) w->cg_b[i] = vd_v3(0, 0, 0);
  // the preconditioner: the block LDL^T factors when the tree's structure allows (exact in exact
  // arithmetic: one or two iterations), else block Jacobi
  int direct = w->direct;
  if (direct) solve_direct(m, d, w);
  else build_preconditioner(m, d, w);
  // preconditioned conjugate gradients from dv = 0
  double bb = 0;
  for (int i = 0; i < nn; i++) {
    w->cg_x[i] = vd_v3(0, 0, 0);
    w->cg_r[i] = w->cg_b[i];
    bb += vd_dot(w->cg_b[i], w->cg_b[i]);
  }
  precondition(m, w, direct);
  for (int i = 0; i < nn; i++) w->cg_p[i] = w->cg_z[i];
  if (!(bb > 0)) return;
  double rz = 0;
  for (int i = 0; i < nn; i++) rz += vd_dot(w->cg_r[i], w->cg_z[i]);
  double tol2 = m->opt.cg_tolerance * m->opt.cg_tolerance * bb;
  int it = 0, conv = 0;
  for (; it < m->opt.cg_iterations; it++) {
    apply_a(m, d, w, w->cg_p, w->cg_ap);
    double pap = 0;
    for (int i = 0; i < nn; i++) pap += vd_dot(w->cg_p[i], w->cg_ap[i]);
    if (!(pap > 0)) break;
    double alpha = rz / pap, rr = 0;
    for (int i = 0; i < nn; i++) {
      w->cg_x[i] = vd_madd(w->cg_x[i], w->cg_p[i], alpha);
      w->cg_r[i] = vd_madd(w->cg_r[i], w->cg_ap[i], -alpha);
      rr += vd_dot(w->cg_r[i], w->cg_r[i]);
    }
    if (rr <= tol2) {
      conv = 1;
      it++;
      break;
    }
    double rz2 = 0;
    precondition(m, w, direct);
    for (int i = 0; i < nn; i++) rz2 += vd_dot(w->cg_r[i], w->cg_z[i]);
    double beta = rz2 / rz;
    rz = rz2;
    for (int i = 0; i < nn; i++) w->cg_p[i] = vd_madd(w->cg_z[i], w->cg_p[i], beta);
  }
  d->cg_iterations += it;
  if (!conv) mss_warn(d, VD_MSS_WARN_CG);
}

// eqs. 3 and 4: the velocity change into w->cg_x
static void solve_kang(const vd_mss_model* m, vd_mss_data* d, mss_work* w, int eq4) {
  double h = m->opt.dt, h2 = h * h;
  int nn = m->nnode;
  // sum of the spring constants at each node (hinges count as transverse springs k / l^2)
  for (int i = 0; i < nn; i++) w->ksum[i] = 0;
  for (int s = 0; s < m->nspring; s++) {
    if (d->spring_broken[s]) continue;
    int i = m->spring_node[2 * s], j = m->spring_node[2 * s + 1];
    w->ksum[i] += m->spring_k[s], w->ksum[j] += m->spring_k[s];
  }
  for (int k = 0; k < m->nhinge; k++) {
    const int* hn = m->hinge_node + 3 * k;
    int b = hn[1], c = hn[2];
    double lq = vd_norm(vd_sub(m->node_rest[c], m->node_rest[b]));
    double kt = mss_hinge_on(m, d, k) ? m->hinge_k[k] / (lq * lq) : 0;
    w->ksum[b] += kt, w->ksum[c] += kt;
  }
  // the neighbours' terms: eq. 3 predicts dv*_j = h F_j / (m_j + h^2 K_j); eq. 4 takes the last
  // substep's |dv_j| along F_j
  for (int i = 0; i < nn; i++) {
    if (w->con[i]) {
      w->cg_z[i] = vd_v3(0, 0, 0);
      continue;
    }
    if (eq4) {
      double f = v_norm(w->ftot[i]);
      w->cg_z[i] = f > 0 ? vd_scale(w->ftot[i], v_norm(d->dv[i]) / f) : vd_v3(0, 0, 0);
    } else {
      w->cg_z[i] = vd_scale(w->ftot[i], h / (d->mass[i] + h2 * w->ksum[i]));
    }
  }
  for (int i = 0; i < nn; i++) w->dvs[i] = vd_v3(0, 0, 0);
  for (int s = 0; s < m->nspring; s++) {
    if (d->spring_broken[s]) continue;
    int i = m->spring_node[2 * s], j = m->spring_node[2 * s + 1];
    double k = m->spring_k[s];
    w->dvs[i] = vd_madd(w->dvs[i], w->cg_z[j], k);
    w->dvs[j] = vd_madd(w->dvs[j], w->cg_z[i], k);
  }
  for (int k = 0; k < m->nhinge; k++) {
    const int* hn = m->hinge_node + 3 * k;
    int b = hn[1], c = hn[2];
    double lq = vd_norm(vd_sub(m->node_rest[c], m->node_rest[b]));
    double kt = mss_hinge_on(m, d, k) ? m->hinge_k[k] / (lq * lq) : 0;
    w->dvs[b] = vd_madd(w->dvs[b], w->cg_z[c], kt);
    w->dvs[c] = vd_madd(w->dvs[c], w->cg_z[b], kt);
  }
  for (int i = 0; i < nn; i++)
    w->cg_x[i] = w->con[i] ? vd_v3(0, 0, 0)
                           : vd_scale(vd_madd(vd_scale(w->ftot[i], h), w->dvs[i], h2), 1.0 / (d->mass[i] + h2 * w->ksum[i]));
}

// ---------------------------------------------------------------------------------------------
// the substep

// wrench on the rigid body from the loads and springs on its members, about its centre
static void rigid_wrench(const vd_mss_model* m, const vd_mss_data* d, const mss_work* w, vd_vec3* f, vd_vec3* tau) {
  *f = vd_v3(0, 0, 0), *tau = vd_v3(0, 0, 0);
  for (int i = 0; i < m->nnode; i++) {
    if (!d->rigid[i] || d->removed[i]) continue;
    vd_vec3 fi = vd_add(d->fext[i], w->fint[i]);
    *f = vd_add(*f, fi);
    *tau = vd_add(*tau, vd_cross(vd_sub(d->pos[i], d->rb.x), fi));
  }
}

// The ground the rigid body grows from: the one node outside it, clamped or a held root crown,
// that its members grow from; with the couplings to the outside nodes. 0 when there is none (or
// more than one: the body is then held).
static int find_anchor(const vd_mss_model* m, vd_mss_data* d, mss_work* w, mss_anchor* an, int* several) {
  const vd_rigid* b = &d->rb;
  int pivot = -1, first = -1;
  *several = 0;
  for (int i = 0; i < m->nnode; i++) {
    int par = m->node_parent[i];
    if (!d->rigid[i] || d->removed[i] || par < 0 || d->rigid[par] || d->removed[par]) continue;
    if (!((m->node_flags[par] & VD_MSS_FIXED) || (par == m->crown && mss_crown_held(m, d)))) continue;
    if (pivot >= 0 && par != pivot) *several = 1;
    if (pivot < 0) pivot = par, first = i;
  }
  if (pivot < 0 || *several) return 0;
  memset(an, 0, sizeof *an);
  an->node = pivot;
  an->pivot = d->pos[pivot];
  double r[9], rt[9];
  m3_from_quat(r, b->q);
  m3_transpose(rt, r);
  an->pivot_body = m3_mul_v(rt, vd_sub(an->pivot, b->x));
  an->axis_body = vd_normalize(vd_sub(d->body[first], an->pivot_body));
  an->spring = w->anchor_spring, an->hinge = w->anchor_hinge;
  for (int s = 0; s < m->nspring; s++) {
    int i = m->spring_node[2 * s], j = m->spring_node[2 * s + 1];
    if (d->spring_broken[s] || d->removed[i] || d->removed[j] || d->rigid[i] == d->rigid[j]) continue;
    an->spring[an->nspring++] = s;
    vd_vec3 arm = vd_sub(d->pos[d->rigid[i] ? i : j], an->pivot);
    an->stiffness += m->spring_k[s] * vd_dot(arm, arm);
  }
  for (int h = 0; h < m->nhinge; h++) {
    const int* hn = m->hinge_node + 3 * h;
    if (!mss_hinge_on(m, d, h) || (hn[0] >= 0 && d->removed[hn[0]]) || d->removed[hn[1]] || d->removed[hn[2]]) continue;
    int in = d->rigid[hn[1]] + d->rigid[hn[2]] + (hn[0] >= 0 && d->rigid[hn[0]]);
    int out = !d->rigid[hn[1]] + !d->rigid[hn[2]] + (hn[0] >= 0 && !d->rigid[hn[0]]);
    if (!in || !out) continue;
    an->hinge[an->nhinge++] = h;
    an->stiffness += m->hinge_k[h];
    if (hn[1] == pivot) an->hinge_k += m->hinge_k[h];
  }
  return 1;
}

// rigid part of a substep (Algorithm 2: before the springs); returns 1 when the soil held it
static int rigid_substep(const vd_mss_model* m, vd_mss_data* d, mss_work* w) {
  vd_rigid* b = &d->rb;
  vd_vec3 f, tau;
  // a body grown from one clamped or held node turns about it (RK4, quaternions), driven by its
  // loads and its springs and hinges to the nodes outside it (issue 26 defect 2)
  mss_anchor an;
  int several = 0;
  if (find_anchor(m, d, w, &an, &several)) {
    vd_vec3 tl = vd_v3(0, 0, 0);
    for (int i = 0; i < m->nnode; i++)
      if (d->rigid[i] && !d->removed[i]) tl = vd_add(tl, vd_cross(vd_sub(d->pos[i], an.pivot), d->fext[i]));
    mss_rigid_pinned_step(m, d, &an, tl, m->opt.dt);
    mss_rigid_sync(m, d);
    return 0;
  }
  rigid_wrench(m, d, w, &f, &tau);
  // a clamped member holds the body; soil members hold it while their capacity suffices (all of
  // it when the soil model is off)
  int clamped = 0, soil_members = 0;
  double cap_f = 0, cap_m = 0;
  for (int i = 0; i < m->nnode; i++) {
    if (!d->rigid[i] || d->removed[i]) continue;
    if ((m->node_flags[i] & VD_MSS_FIXED) || (i == m->crown && mss_crown_held(m, d))) clamped = 1;
    if (several) clamped = 1;  // grown from several held nodes: held by them
    if (m->node_flags[i] & VD_MSS_SOIL) {
      double fm = m->node_soil[i];
      soil_members = 1;
      cap_f += fm;
      cap_m += fm * v_norm(vd_sub(d->pos[i], b->x));
    }
  }
  if (clamped || (!m->opt.soil && soil_members)) {
    b->p = b->L = vd_v3(0, 0, 0);
    mss_rigid_sync(m, d);
    return 1;
  }
  // a crown whose anchorage gave way holds nothing: the root plate has failed
  if (m->crown >= 0 && d->rigid[m->crown]) soil_members = 0;
  int held = 0;
  if (soil_members) {
    // the per-node rule for a whole body: held while the wrench is within the soil's capacity
    double nf = v_norm(f), nt = v_norm(tau);
    if (nf <= cap_f && nt <= cap_m) {
      held = 1;
      b->p = b->L = vd_v3(0, 0, 0);
    } else {
      if (nf > 0) f = vd_scale(f, fmax(0.0, 1 - cap_f / nf));
      if (nt > 0) tau = vd_scale(tau, fmax(0.0, 1 - cap_m / nt));
      for (int i = 0; i < m->nnode; i++)
        if (d->rigid[i] && (m->node_flags[i] & VD_MSS_SOIL)) d->yielded[i] = 1;
    }
  }
  // a body nothing holds, stepped explicitly against stiff springs, is unstable (h^2 k / M of
  // hundreds): released, its nodes go on with the springs at the velocities they have
  // (after the crown's anchorage gave way, always: the ground holds only free nodes)
  if (!held && (m->opt.rigid_release || d->anchor_failed)) {
    for (int i = 0; i < m->nnode; i++) d->rigid[i] = 0;
    memset(b, 0, sizeof *b);
    b->q = vd_quat_identity();
    return 0;
  }
  if (!held) vd_rigid_step(b, f, tau, m->opt.dt);
  mss_rigid_sync(m, d);
  // reactions for the stress: the soil takes the wrench's force in proportion to capacity
  if (held && cap_f > 0)
    for (int i = 0; i < m->nnode; i++)
      if (d->rigid[i] && (m->node_flags[i] & VD_MSS_SOIL) && !d->removed[i])
        d->fext[i] = vd_madd(d->fext[i], f, -m->node_soil[i] / cap_f);
  return held;
}

// The stem's wrench on the root crown (the sections at the foot of its internodes that leave the
// crown, as vd_mss_stress cuts them) against the crown's anchorage; beyond it the root plate
// gives way (an event), and the crown turns freely from then on. Reads the subtree sums of the
// last vd_mss_stress.
static void anchor_check(const vd_mss_model* m, vd_mss_data* d, const mss_work* w) {
  int b = m->crown;
  vd_vec3 f = vd_v3(0, 0, 0), mo = vd_v3(0, 0, 0);
  for (int s = 0; s < m->ninter; s++) {
    int c = m->spring_node[2 * s + 1];
    if (m->spring_node[2 * s] != b || (m->node_flags[c] & VD_MSS_ROOT) || d->spring_broken[s] || d->removed[c]) continue;
    int rigid = d->rigid[b] && d->rigid[c];
    vd_vec3 fc = rigid ? w->ftot[c] : vd_scale(w->fsub[c], -1);
    vd_vec3 mc = rigid ? w->dvs[c] : vd_scale(w->msub[c], -1);
    f = vd_add(f, fc);
    mo = vd_add(mo, vd_add(mc, vd_cross(vd_sub(d->pos[c], d->pos[b]), fc)));
  }
  double nm = v_norm(mo), nf = v_norm(f);
  double load = fmax(m->anchor_moment > 0 ? nm / m->anchor_moment : nm > 0 ? INFINITY : 0,
                     m->anchor_force > 0 ? nf / m->anchor_force : nf > 0 ? INFINITY : 0);
  if (load > d->anchor_load) d->anchor_load = load;
  if (!(load > 1)) return;
  d->anchor_failed = 1;
  vd_mss_event e = {VD_MSS_ANCHOR, d->time, b, -1, load, nm, 0};
  mss_event(d, &e);
}

static double tilt_of(const vd_mss_model* m, const vd_mss_data* d) {
  int b = m->base;
  if (b < 0) return 0;
  // the first stem internode above the base
  for (int s = 0; s < m->ninter; s++) {
    if (m->spring_node[2 * s] != b || (m->node_flags[m->spring_node[2 * s + 1]] & VD_MSS_ROOT)) continue;
    int c = m->spring_node[2 * s + 1];
    if (d->removed[c]) return 0;
    vd_vec3 e0 = vd_normalize(vd_sub(m->node_rest[c], m->node_rest[b]));
    vd_vec3 e = vd_normalize(vd_sub(d->pos[c], d->pos[b]));
    return acos(fmax(-1.0, fmin(1.0, vd_dot(e0, e))));
  }
  return 0;
}

vd_status vd_mss_step(const vd_mss_model* m, vd_mss_data* d) {
  mss_work* w = d->work;
  int nn = m->nnode;
  double h = m->opt.dt;
  memcpy(w->pos0, d->pos, sizeof(vd_vec3) * (size_t)nn);
  memcpy(w->vel0, d->vel, sizeof(vd_vec3) * (size_t)nn);
  // eq. 5's coefficients c sqrt(k (m1 + m2)) with the current masses
  for (int s = 0; s < m->nspring; s++) {
    int i = m->spring_node[2 * s], j = m->spring_node[2 * s + 1];
    int on = !d->spring_broken[s] && !d->removed[i] && !d->removed[j];
    w->spring_c[s] = on ? m->damping * sqrt(m->spring_k[s] * (d->mass[i] + d->mass[j])) : 0;
  }
  // loads and internal forces at the start of the substep
  mss_external(m, d, w);
  mss_internal(m, d, w);
  // the rigid part first (Algorithm 2), then the springs' forces again at its new pose
  int rb_held = 0;
  if (d->rb.n > 0) {
    rb_held = rigid_substep(m, d, w);
    mss_internal(m, d, w);
  }
  // the soil's rule for free nodes: held while the net force is within the node's resistance
  for (int i = 0; i < nn; i++) {
    w->con[i] = !mss_free(m, d, i);
    d->held[i] = 0;
    w->ftot[i] = vd_add(d->fext[i], w->fint[i]);
    if (!w->con[i] && i == m->crown && mss_crown_held(m, d)) {
      // the crown: held while its anchorage lasts (checked after the substep)
      d->held[i] = 1;
      w->con[i] = 1;
      d->vel[i] = vd_v3(0, 0, 0);
      continue;
    }
    if (w->con[i] || !(m->node_flags[i] & VD_MSS_SOIL)) continue;
    double fm = m->opt.soil ? m->node_soil[i] : INFINITY, f = v_norm(w->ftot[i]);
    if (f <= fm) {
      d->held[i] = 1;
      w->con[i] = 1;
      d->vel[i] = vd_v3(0, 0, 0);
    } else {
      vd_vec3 fs = vd_scale(w->ftot[i], -fm / f);
      w->ftot[i] = vd_add(w->ftot[i], fs);
      d->fext[i] = vd_add(d->fext[i], fs);
      d->yielded[i] = 1;
    }
  }
  // the springs' velocity change
  if (m->opt.integrator == VD_MSS_IMPLICIT) solve_implicit(m, d, w);
  else solve_kang(m, d, w, m->opt.integrator == VD_MSS_EQ4);
  int bad = 0;
  for (int i = 0; i < nn; i++) {
    if (!mss_free(m, d, i)) continue;
    vd_vec3 dv = w->con[i] ? vd_v3(0, 0, 0) : w->cg_x[i];
    d->dv[i] = dv;
    d->vel[i] = vd_add(d->vel[i], dv);
    if (d->held[i]) d->vel[i] = vd_v3(0, 0, 0);
    d->pos[i] = vd_madd(d->pos[i], d->vel[i], h);
    if (!finite3(d->pos[i]) || !finite3(d->vel[i])) bad = 1;
  }
  // the ground of a rooted plant: stem nodes that reach it stop there (an inelastic contact
  // without sliding), so a tree that tips over lies on it
  if (m->crown >= 0 && !bad)
    for (int i = 0; i < nn; i++) {
      if ((m->node_flags[i] & VD_MSS_ROOT) || !mss_free(m, d, i) || !(d->pos[i].z < m->ground)) continue;
      d->pos[i].z = m->ground;
      d->vel[i] = vd_v3(0, 0, 0);
    }
  // strain limiting (Provot 1995): linearised implicit steps stretch internodes that turn fast
  // (the step moves nodes along tangents); parents first, each internode back within the limit,
  // the correction kept in the velocity as in position-based dynamics
  if (m->opt.strain_limit > 0 && !bad)
    for (int k = 0; k < nn; k++) {
      int c = m->node_order[k], sp = m->node_owner[c];
      if (sp < 0 || d->spring_broken[sp] || !mss_free(m, d, c) || d->held[c]) continue;
      int b = m->spring_node[2 * sp];
      vd_vec3 e = vd_sub(d->pos[c], d->pos[b]);
      double l = v_norm(e), l0 = m->spring_l0[sp], lim = m->opt.strain_limit;
      double lt = l > l0 * (1 + lim) ? l0 * (1 + lim) : l < l0 * (1 - lim) ? l0 * (1 - lim) : l;
      if (lt == l || !(l > 0)) continue;
      vd_vec3 x = vd_add(d->pos[b], vd_scale(e, lt / l));
      d->vel[c] = vd_madd(d->vel[c], vd_sub(x, d->pos[c]), 1.0 / h);
      d->pos[c] = x;
    }
  // what held and clamped nodes take: the rest of the net force (reactions, for the stress)
  for (int i = 0; i < nn; i++) {
    if (d->removed[i] || d->rigid[i]) continue;
    if (d->held[i] || (m->node_flags[i] & VD_MSS_FIXED)) d->fext[i] = vd_scale(w->fint[i], -1);
  }
  if (bad) {
    // a non-finite state is undone, and the motion stopped
    memcpy(d->pos, w->pos0, sizeof(vd_vec3) * (size_t)nn);
    for (int i = 0; i < nn; i++) d->vel[i] = d->dv[i] = vd_v3(0, 0, 0);
    d->rb.p = d->rb.L = vd_v3(0, 0, 0);
    mss_warn(d, VD_MSS_WARN_NONFINITE);
  }
  // accelerations (the stress of the rigid part reads them): a held body was stopped by the soil
  // or a clamp, which is a reaction, not an acceleration of its wood
  for (int i = 0; i < nn; i++)
    d->acc[i] = d->rigid[i] && rb_held ? vd_v3(0, 0, 0) : vd_scale(vd_sub(d->vel[i], w->vel0[i]), 1.0 / h);
  d->time += h;
  d->nstep++;
  // stress (breaking reads it) and the crown's wrench against its anchorage
  int anchor = mss_crown_held(m, d) && m->opt.soil;
  if (m->opt.breaking || anchor) vd_mss_stress(m, d);
  if (anchor) anchor_check(m, d, w);
  // uprooting: the crown's anchorage gave way, or soil nodes holding more than half the root
  // system's resistance did, and the stem's base tilted beyond the limit
  if (!d->uprooted && m->base >= 0 && m->opt.soil) {
    double total = 0, gave = 0;
    for (int i = 0; i < nn; i++)
      if ((m->node_flags[i] & VD_MSS_SOIL) && !d->removed[i]) {
        total += m->node_soil[i];
        if (d->yielded[i]) gave += m->node_soil[i];
      }
    double tilt = d->anchor_failed || (total > 0 && gave > 0.5 * total) ? tilt_of(m, d) : 0;
    if (tilt > d->uproot_tilt) {
      d->uprooted = 1;
      vd_mss_event e = {VD_MSS_UPROOT, d->time, m->base, -1, tilt, d->uproot_tilt, 0};
      mss_event(d, &e);
    }
  }
  // breaking: an internode whose stress exceeds its modulus of rupture takes its subtree with it
  if (m->opt.breaking) {
    int removed_rigid = 0;
    for (int k = 0; k < nn; k++) {
      int c = m->node_order[k], s = m->node_owner[c];
      if (s < 0 || d->removed[c] || d->spring_broken[s]) continue;
      if (!(d->spring_stress[s] > m->spring_mor[s])) continue;
      int a = m->spring_node[2 * s];
      vd_mss_event e = {VD_MSS_BREAK, d->time, a, s, d->spring_stress[s], m->spring_mor[s], 0};
      for (int q = m->node_pre[c]; q <= m->node_last[c]; q++) removed_rigid |= d->rigid[m->node_order[q]];
      e.removed = mss_remove_subtree(m, d, s);
      mss_event(d, &e);
    }
    if (removed_rigid) vd_mss_rigid_update(m, d);
  }
  return bad ? VD_ERR_VALUE : VD_OK;
}

// ---------------------------------------------------------------------------------------------
// summaries

const char* vd_mss_warning_name(vd_mss_warning w) {
  static const char* names[VD_MSS_WARN_COUNT] = {"nonfinite", "cg"};
  return w >= 0 && w < VD_MSS_WARN_COUNT ? names[w] : "?";
}

vd_vec3 vd_mss_momentum(const vd_mss_model* m, const vd_mss_data* d) {
  vd_vec3 p = d->rb.n > 0 ? d->rb.p : vd_v3(0, 0, 0);
  for (int i = 0; i < m->nnode; i++)
    if (!d->removed[i] && !d->rigid[i] && !(m->node_flags[i] & VD_MSS_FIXED)) p = vd_madd(p, d->vel[i], d->mass[i]);
  return p;
}

double vd_mss_kinetic_energy(const vd_mss_model* m, const vd_mss_data* d) {
  double e = vd_rigid_energy(&d->rb);
  for (int i = 0; i < m->nnode; i++)
    if (!d->removed[i] && !d->rigid[i]) e += 0.5 * d->mass[i] * vd_dot(d->vel[i], d->vel[i]);
  return e;
}

double vd_mss_max_displacement(const vd_mss_model* m, const vd_mss_data* d, int* node) {
  double best = 0;
  int at = -1;
  for (int i = 0; i < m->nnode; i++) {
    if (d->removed[i]) continue;
    double x = vd_norm(vd_sub(d->pos[i], m->node_rest[i]));
    if (x > best || at < 0) best = x, at = i;
  }
  if (node) *node = at;
  return best;
}

double vd_mss_height(const vd_mss_model* m, const vd_mss_data* d) {
  if (m->base < 0) return 0;
  double z0 = m->node_rest[m->base].z, h = 0;
  for (int i = 0; i < m->nnode; i++)
    if (!d->removed[i] && !(m->node_flags[i] & VD_MSS_ROOT)) h = fmax(h, d->pos[i].z - z0);
  return h;
}
