// SPDX-License-Identifier: MIT
// Solids: the closed primitives of a plant as the polyhedra vd_geom_tessellate makes of them,
// with exact point-inside tests. A frustum of s slices is a prism whose section at height z is
// the regular s-gon of circumradius r(z); a UV sphere is, within each longitude wedge, the
// polygon of its latitude chords; both are tested in O(1) after a cheap circumscribed/inscribed
// pre-test, so only points in the thin band between circle and polygon pay for an atan2.
// Closed meshes use the generalised winding number (van Oosterom & Strackee 1983 solid angles).
#include <math.h>
#include <string.h>

#include "geom_internal.h"

// ---------------------------------------------------------------------------------------------
// build

static vd_vec3 get3(const double* a, int i) {
  return vd_v3(a[3 * i], a[3 * i + 1], a[3 * i + 2]);
}

static void box_point(vd_solid* s, vd_vec3 p, double pad) {
  double v[3] = {p.x, p.y, p.z};
  for (int k = 0; k < 3; k++) {
    if (v[k] - pad < s->lo[k]) s->lo[k] = v[k] - pad;
    if (v[k] + pad > s->hi[k]) s->hi[k] = v[k] + pad;
  }
}

// box of a disc: centre c, unit normal a, radius r (extent r sqrt(1 - a_k^2) along axis k)
static void box_disc(vd_solid* s, vd_vec3 c, vd_vec3 a, double r, double pad) {
  double av[3] = {a.x, a.y, a.z}, cv[3] = {c.x, c.y, c.z};
  for (int k = 0; k < 3; k++) {
    double e = r * sqrt(fmax(0.0, 1.0 - av[k] * av[k])) + pad;
    if (cv[k] - e < s->lo[k]) s->lo[k] = cv[k] - e;
    if (cv[k] + e > s->hi[k]) s->hi[k] = cv[k] + e;
  }
}

static void solid_init(vd_solid* s, int kind, int prim, int label, int instance) {
  memset(s, 0, sizeof *s);  // NOLINT(clang-analyzer-core.NonNullParamChecker): solids exist whenever ns > 0
  s->kind = kind, s->prim = prim, s->label = label, s->instance = instance;
  s->joined[0] = s->joined[1] = -1;
  s->q = vd_quat_identity();
  for (int k = 0; k < 9; k++)
    s->rot[k] = k % 4 == 0;
  for (int k = 0; k < 3; k++)
    s->lo[k] = INFINITY, s->hi[k] = -INFINITY;
}

// solid k: the frustum of segment i from c0 to c1 (radii r0, r1) in the segment's frame
static void seg_solid(vd_solids* out, int k, const vd_model* m, int slices, int i, const double* seg_quat, vd_vec3 c0,
                      vd_vec3 c1, double r0, double r1) {
  vd_solid* s = &out->solid[k];
  solid_init(s, VD_PRIM_SEGMENT, i, m->seg_label[i], m->seg_instance[i]);
  vd_quat q = {seg_quat[4 * i], seg_quat[4 * i + 1], seg_quat[4 * i + 2], seg_quat[4 * i + 3]};
  vd_vec3 axis = vd_quat_rotate(q, vd_v3(0, 0, 1));
  s->c = c0;
  s->q = q;
  vd_vec3 ax[3] = {vd_quat_rotate(q, vd_v3(1, 0, 0)), vd_quat_rotate(q, vd_v3(0, 1, 0)), axis};
  for (int r = 0; r < 3; r++)
    s->rot[3 * r] = ax[r].x, s->rot[3 * r + 1] = ax[r].y, s->rot[3 * r + 2] = ax[r].z;
  s->len = vd_dot(vd_sub(c1, c0), axis);
  s->r0 = r0, s->r1 = r1;
  s->slices = geom_seg_slices(m, slices, i);
  s->cos_half = cos(VD_PI / s->slices);
  box_disc(s, c0, axis, s->r0, out->eps);
  box_disc(s, c1, axis, s->r1, out->eps);
}

vd_status vd_solids_build(const vd_model* m, const vd_data* d, const vd_mesh_def* def,
                          vd_solids* out, vd_error* err) {
  if (!out) return vd_error_set(err, VD_ERR_ARG, "", 0, 0, "solids: null output");
  memset(out, 0, sizeof *out);
  if (!m) return vd_error_set(err, VD_ERR_ARG, "", 0, 0, "solids: null model");
  vd_mesh_def md = def ? *def : vd_mesh_def_default();
  if (md.slices != 0 && md.slices < 3)
    return vd_error_set(err, VD_ERR_ARG, "", 0, 0, "mesh def: slices must be 0 or >= 3");
  if (md.sphere_stacks != 0 && md.sphere_stacks < 2)
    return vd_error_set(err, VD_ERR_ARG, "", 0, 0, "mesh def: sphere_stacks must be 0 or >= 2");
  if (d && (d->nnode != m->nnode || d->nseg != m->nseg || d->nsphere != m->nsphere ||
            d->nvert != m->nvert))
    return vd_error_set(err, VD_ERR_ARG, "", 0, 0, "solids: data does not match the model");
  const double* node_pos = d ? d->node_pos : m->node_pos0;
  const double* seg_quat = d ? d->seg_quat : m->seg_quat0;
  const double* sphere_pos = d ? d->sphere_pos : m->sphere_pos0;
  const double* vert_pos = d ? d->vert_pos : m->vert_pos0;

  // sizes first, then one block
  int nclosed = 0, ntri = 0;
  for (int i = 0; i < m->nmesh; i++)
    if (m->mesh_closed[i]) nclosed++, ntri += m->mesh_tri[2 * i + 1];
  // a segment broken at a known point into two parts has a second solid (its stump)
  int nstump = 0;
  for (int i = 0; i < m->nseg; i++) {
    double f;
    nstump += geom_seg_cut(d, i, &f) == (GEOM_PART_OFF | GEOM_PART_STUB);
  }
  int ns = m->nseg + nstump + m->nsphere + nclosed;
  size_t nbytes = (size_t)ns * sizeof(vd_solid) + (size_t)ntri * 9 * sizeof(double) +
                  ((size_t)m->nseg * 3 + (size_t)m->nsphere + (size_t)m->nmesh) * sizeof(int);
  char* block = nbytes ? vd_malloc(nbytes) : NULL;
  double* box = ns ? vd_malloc((size_t)ns * 6 * sizeof(double)) : NULL;
  if ((nbytes && !block) || (ns && !box)) {
    vd_free(block, nbytes);
    vd_free(box, (size_t)ns * 6 * sizeof(double));
    return vd_error_set(err, VD_ERR_NOMEM, "", 0, 0, "out of memory building solids");
  }
  out->nbytes = nbytes;
  out->nsolid = ns;
  out->ntri = ntri;
  out->nseg = m->nseg, out->nsphere = m->nsphere, out->nmesh = m->nmesh;
  char* p = block;
  out->solid = (vd_solid*)p, p += (size_t)ns * sizeof(vd_solid);
  out->tri = (double*)p, p += (size_t)ntri * 9 * sizeof(double);
  out->seg_solid = (int*)p, p += (size_t)m->nseg * sizeof(int);
  int* cont = (int*)p;
  p += (size_t)m->nseg * sizeof(int);
  int* joined = (int*)p;
  p += (size_t)m->nseg * sizeof(int);
  out->sphere_solid = (int*)p, p += (size_t)m->nsphere * sizeof(int);
  out->mesh_solid = (int*)p;
  if (!ntri) out->tri = NULL;

  // boundary tolerance: 1e-9 of the plant's scale, at least 1e-9 m
  double scale = 1;
  for (int i = 0; i < 3 * m->nnode; i++)
    scale = fmax(scale, fabs(node_pos[i]));
  for (int i = 0; i < 3 * m->nsphere; i++)
    scale = fmax(scale, fabs(sphere_pos[i]));
  for (int i = 0; i < 3 * m->nvert; i++)
    scale = fmax(scale, fabs(vert_pos[i]));
  double eps = 1e-9 * scale;
  out->eps = eps;

  // frustums, in the frame and with the sides the tessellation uses
  int k = 0, kstump = m->nseg;
  if (m->nseg) geom_joints(m, d, md.slices, cont, joined);
  for (int i = 0; i < m->nseg; i++, k++) {
    out->seg_solid[i] = k;  // NOLINT(clang-analyzer-core.NullDereference): arrays carved from one block sized by these counts
    vd_vec3 c0 = get3(node_pos, m->seg_node[2 * i]), c1 = get3(node_pos, m->seg_node[2 * i + 1]);
    double r0 = m->seg_radius[2 * i], r1 = m->seg_radius[2 * i + 1], f;
    int parts = geom_seg_cut(d, i, &f);
    if (parts == GEOM_WHOLE) {
      seg_solid(out, k, m, md.slices, i, seg_quat, c0, c1, r0, r1);
      continue;
    }
    // broken at a known point: the part that came off, and the stump (a second solid when both
    // exist, each the other's neighbour so that neither removes the other's points)
    const double* cut = d->seg_cut + 7 * i;  // NOLINT(clang-analyzer-core.NullDereference): d exists when a segment is cut
    double rf = r0 + f * (r1 - r0);
    vd_vec3 a = vd_v3(cut[1], cut[2], cut[3]), b = vd_v3(cut[4], cut[5], cut[6]);
    if (parts & GEOM_PART_OFF)
      seg_solid(out, k, m, md.slices, i, seg_quat, b, c1, rf, r1);
    else
      seg_solid(out, k, m, md.slices, i, seg_quat, c0, a, r0, rf);
    if (parts == (GEOM_PART_OFF | GEOM_PART_STUB)) {
      seg_solid(out, kstump, m, md.slices, i, seg_quat, c0, a, r0, rf);
      out->solid[k].joined[0] = kstump, out->solid[kstump].joined[0] = k;
      kstump++;
    }
  }
  k = kstump;
  // tube neighbours: a segment and the one continuing it through a shared ring
  for (int i = 0; i < m->nseg; i++)
    if (cont[i] >= 0) {
      out->solid[out->seg_solid[i]].joined[1] = out->seg_solid[cont[i]];
      out->solid[out->seg_solid[cont[i]]].joined[0] = out->seg_solid[i];
    }
  // spheres: world-aligned UV spheres
  for (int i = 0; i < m->nsphere; i++, k++) {
    vd_solid* s = &out->solid[k];
    solid_init(s, VD_PRIM_SPHERE, i, m->sphere_label[i], m->sphere_instance[i]);
    out->sphere_solid[i] = k;  // NOLINT(clang-analyzer-core.NullDereference): arrays carved from one block sized by these counts
    s->c = get3(sphere_pos, i);
    s->r0 = s->r1 = m->sphere_radius[i];
    s->slices = md.slices > 0 ? md.slices : m->sphere_slices[i];
    s->stacks = md.sphere_stacks > 0 ? md.sphere_stacks : (s->slices / 2 < 2 ? 2 : s->slices / 2);
    s->cos_half = cos(VD_PI / s->slices);
    s->cos_stack = cos(VD_PI / (2.0 * s->stacks));
    box_point(s, vd_sub(s->c, vd_v3(s->r0, s->r0, s->r0)), eps);
    box_point(s, vd_add(s->c, vd_v3(s->r0, s->r0, s->r0)), eps);
  }
  // closed meshes: their triangles copied
  int tk = 0;
  for (int i = 0; i < m->nmesh; i++) {
    out->mesh_solid[i] = -1;
    if (!m->mesh_closed[i]) continue;
    vd_solid* s = &out->solid[k];
    solid_init(s, VD_PRIM_MESH, i, m->mesh_label[i], m->mesh_instance[i]);
    out->mesh_solid[i] = k++;
    s->tri_start = tk;
    s->ntri = m->mesh_tri[2 * i + 1];
    for (int t = m->mesh_tri[2 * i]; t < m->mesh_tri[2 * i] + s->ntri; t++, tk++)
      for (int c = 0; c < 3; c++) {
        vd_vec3 v = get3(vert_pos, m->tri_vert[3 * t + c]);
        out->tri[9 * tk + 3 * c] = v.x, out->tri[9 * tk + 3 * c + 1] = v.y;
        out->tri[9 * tk + 3 * c + 2] = v.z;
        box_point(s, v, eps);
      }
  }
  // a BVH over the boxes
  for (int i = 0; i < ns; i++)
    for (int c = 0; c < 3; c++) {
      box[6 * i + c] = out->solid[i].lo[c];  // NOLINT(clang-analyzer-core.NullDereference): arrays carved from one block sized by these counts
      box[6 * i + 3 + c] = out->solid[i].hi[c];
    }
  vd_bvh_def bd = vd_bvh_def_default();
  bd.leaf_size = 2;
  vd_status st = vd_bvh_build(box, ns, &bd, &out->bvh, err);
  vd_free(box, (size_t)ns * 6 * sizeof(double));
  if (st) vd_solids_free(out);
  return st;
}

void vd_solids_free(vd_solids* so) {
  if (!so) return;
  vd_bvh_free(&so->bvh);
  vd_free(so->solid, so->nbytes);
  memset(so, 0, sizeof *so);
}

// ---------------------------------------------------------------------------------------------
// point-inside tests

// sector of angle atan2(y, x) among n equal sectors starting at angle 0
static int sector(double y, double x, int n) {
  double th = atan2(y, x);
  if (th < 0) th += 2.0 * VD_PI;
  int k = (int)(th * n / (2.0 * VD_PI));
  return k < 0 ? 0 : k >= n ? n - 1 : k;
}

static int in_frustum(const vd_solid* s, vd_vec3 p, double eps) {
  vd_vec3 d = vd_sub(p, s->c);
  const double* R = s->rot;
  vd_vec3 v = vd_v3(R[0] * d.x + R[1] * d.y + R[2] * d.z, R[3] * d.x + R[4] * d.y + R[5] * d.z,
                    R[6] * d.x + R[7] * d.y + R[8] * d.z);
  if (v.z < -eps || v.z > s->len + eps) return 0;
  double f = s->len > 0 ? v.z / s->len : 0.5;
  f = f < 0 ? 0 : f > 1 ? 1 : f;
  double rz = s->r0 + (s->r1 - s->r0) * f;
  double rho2 = v.x * v.x + v.y * v.y;
  // outside the circumscribed circle, inside the inscribed one, else the polygon's side
  if (rho2 > (rz + eps) * (rz + eps)) return 0;
  double half = VD_PI / s->slices, ri = rz * s->cos_half;
  if (rho2 <= ri * ri) return 1;
  int k = sector(v.y, v.x, s->slices);
  double tm = (2 * k + 1) * half;
  return v.x * cos(tm) + v.y * sin(tm) <= ri + eps;
}

// within the longitude wedge of a point, a UV sphere is the polygon of its latitude chords in
// the (rho, z) half-plane: vertices (r sin(phi_j) cos(half), r cos(phi_j)), j = 0..stacks, from
// the top pole down the outside to the bottom pole (clockwise, inside on the right)
static int in_sphere(const vd_solid* s, vd_vec3 p, double eps) {
  vd_vec3 v = vd_sub(p, s->c);
  double r = s->r0, d2 = vd_dot(v, v);
  if (d2 > (r + eps) * (r + eps)) return 0;
  double half = VD_PI / s->slices, ch = s->cos_half;
  double ri = r * ch * s->cos_stack;
  if (d2 <= ri * ri) return 1;
  int k = sector(v.y, v.x, s->slices);
  double tm = (2 * k + 1) * half;
  double rho = v.x * cos(tm) + v.y * sin(tm);
  double px = 0, pz = r;
  for (int j = 1; j <= s->stacks; j++) {
    double phi = VD_PI * (double)j / (double)s->stacks;
    double qx = j == s->stacks ? 0 : r * sin(phi) * ch, qz = j == s->stacks ? -r : r * cos(phi);
    double ex = qx - px, ez = qz - pz;
    double cross = ex * (v.z - pz) - ez * (rho - px);
    if (cross > eps * sqrt(ex * ex + ez * ez)) return 0;
    px = qx, pz = qz;
  }
  return 1;
}

// generalised winding number of a closed triangle mesh; a point on a face counts as inside
static int in_mesh(const vd_solids* so, const vd_solid* s, vd_vec3 p, double eps) {
  double w = 0;
  for (int t = s->tri_start; t < s->tri_start + s->ntri; t++) {
    const double* tv = so->tri + 9 * (size_t)t;
    vd_vec3 a = vd_sub(vd_v3(tv[0], tv[1], tv[2]), p), b = vd_sub(vd_v3(tv[3], tv[4], tv[5]), p);
    vd_vec3 c = vd_sub(vd_v3(tv[6], tv[7], tv[8]), p);
    double la = vd_norm(a), lb = vd_norm(b), lc = vd_norm(c);
    if (la <= eps || lb <= eps || lc <= eps) return 1;
    double num = vd_dot(a, vd_cross(b, c));
    double den = la * lb * lc + vd_dot(a, b) * lc + vd_dot(a, c) * lb + vd_dot(b, c) * la;
    // in the triangle's plane and inside it: on the boundary
    if (fabs(num) <= eps * vd_norm(vd_cross(vd_sub(b, a), vd_sub(c, a))) && den < 0) return 1;
    w += 2.0 * atan2(num, den);
  }
  return w / (4.0 * VD_PI) > 0.5;
}

int vd_solid_contains(const vd_solids* so, int i, vd_vec3 p) {
  const vd_solid* s = &so->solid[i];
  double pv[3] = {p.x, p.y, p.z};
  for (int k = 0; k < 3; k++)
    if (pv[k] < s->lo[k] || pv[k] > s->hi[k]) return 0;
  switch (s->kind) {
    case VD_PRIM_SEGMENT: return in_frustum(s, p, so->eps);
    case VD_PRIM_SPHERE: return in_sphere(s, p, so->eps);
    default: return in_mesh(so, s, p, so->eps);
  }
}

int vd_solids_own(const vd_solids* so, int kind, int prim) {
  if (kind == VD_PRIM_SEGMENT && prim >= 0 && prim < so->nseg) return so->seg_solid[prim];
  if (kind == VD_PRIM_SPHERE && prim >= 0 && prim < so->nsphere) return so->sphere_solid[prim];
  if (kind == VD_PRIM_MESH && prim >= 0 && prim < so->nmesh) return so->mesh_solid[prim];
  return -1;
}

int vd_solids_inside(const vd_solids* so, vd_vec3 p, int kind, int prim) {
  if (!so || so->nsolid == 0) return -1;
  // the point's own solid and its tube neighbours are not tested
  int own = vd_solids_own(so, kind, prim);
  int skip1 = own >= 0 ? so->solid[own].joined[0] : -1;
  int skip2 = own >= 0 ? so->solid[own].joined[1] : -1;
  double pv[3] = {p.x, p.y, p.z};
  int stack[256];
  int sp = 0;
  stack[sp++] = 0;
  while (sp) {
    const vd_bvh_node* nd = &so->bvh.node[stack[--sp]];
    if (pv[0] < nd->lo[0] || pv[0] > nd->hi[0] || pv[1] < nd->lo[1] || pv[1] > nd->hi[1] ||
        pv[2] < nd->lo[2] || pv[2] > nd->hi[2])
      continue;
    if (nd->count) {
      for (int i = nd->first; i < nd->first + nd->count; i++) {
        int s = so->bvh.item[i];
        if (s == own || s == skip1 || s == skip2) continue;
        if (vd_solid_contains(so, s, p)) return s;
      }
    } else if (sp + 2 <= 256) {
      stack[sp++] = nd->first + 1;
      stack[sp++] = nd->first;
    }
  }
  return -1;
}
