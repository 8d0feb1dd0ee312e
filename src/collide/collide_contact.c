// SPDX-License-Identifier: MIT
// Collision geometry: colliders with moving poses, point and tapered-capsule queries against
// them, the narrow phase between plant primitives, a sweep-and-prune broad phase, neighbour
// exclusion from the plant's topology, and contact lists in an arena.
//
// A tapered capsule against a convex shape is a convex problem along the axis: the signed
// distance of a convex set is convex, composed with the affine axis map it stays convex, and the
// radius r(t) is linear. So the deepest axis point is found by bisection on the sign of the
// derivative (any subgradient will do), which is exact to round-off for every convex collider;
// a flat minimum (an axis parallel to a face) takes the middle of its flat part, so a capsule
// lying on the ground is pushed at its middle, not at an arbitrary end.
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "collide_internal.h"

// bisection steps: 2^-52 of the axis is at double round-off
#define BISECT_STEPS 52

vd_pose vd_pose_identity(void) {
  vd_pose p = {{0, 0, 0}, {1, 0, 0, 0}};
  return p;
}

vd_collide_def vd_collide_def_default(void) {
  vd_collide_def d;
  d.margin = 0.001;
  d.max_contacts = 1000000;
  return d;
}

// ---------------------------------------------------------------------------------------------
// colliders

static vd_collider collider_zero(vd_shape shape) {
  vd_collider c;
  memset(&c, 0, sizeof c);
  c.shape = shape;
  c.pose = vd_pose_identity();
  return c;
}

// unit vector orthogonal to unit v (deterministic: from the world axis least aligned with v)
static vd_vec3 any_perp(vd_vec3 v) {
  double ax = fabs(v.x), ay = fabs(v.y), az = fabs(v.z);
  vd_vec3 a =
      (ax <= ay && ax <= az) ? vd_v3(1, 0, 0) : (ay <= az ? vd_v3(0, 1, 0) : vd_v3(0, 0, 1));
  return vd_normalize(vd_madd(a, v, -vd_dot(a, v)));
}

// rotation taking local +z to the unit vector n
static vd_quat quat_z_to(vd_vec3 n) {
  vd_vec3 z = vd_normalize(n);
  vd_vec3 x = any_perp(z);
  return vd_quat_normalize(vd_quat_from_axes(x, vd_cross(z, x), z));
}

vd_collider vd_collider_plane(vd_vec3 point, vd_vec3 n) {
  vd_collider c = collider_zero(VD_SHAPE_PLANE);
  c.pose.pos = point;
  c.pose.rot = quat_z_to(n);
  return c;
}

vd_collider vd_collider_sphere(vd_vec3 center, double r) {
  vd_collider c = collider_zero(VD_SHAPE_SPHERE);
  c.pose.pos = center;
  c.radius = r;
  return c;
}

vd_collider vd_collider_capsule(vd_vec3 a, vd_vec3 b, double r) {
  vd_collider c = collider_zero(VD_SHAPE_CAPSULE);
  vd_vec3 d = vd_sub(b, a);
  c.pose.pos = vd_scale(vd_add(a, b), 0.5);
  c.pose.rot = vd_norm(d) > 0 ? quat_z_to(d) : vd_quat_identity();
  c.half_length = 0.5 * vd_norm(d);
  c.radius = r;
  return c;
}

vd_collider vd_collider_box(vd_pose pose, vd_vec3 half_size) {
  vd_collider c = collider_zero(VD_SHAPE_BOX);
  c.pose = pose;
  c.half_size = half_size;
  return c;
}

vd_collider vd_collider_sdf(vd_pose pose, const vd_sdf* sdf) {
  vd_collider c = collider_zero(VD_SHAPE_SDF);
  c.pose = pose;
  c.sdf = sdf;
  return c;
}

void vd_collider_set_pose(vd_collider* c, vd_pose pose) {
  c->pose = pose;
}

// a pose as a rotation matrix, built once per query (cheaper than quaternion rotations)
typedef struct frame {
  double R[9]; // columns: the local axes in world (row-major)
  vd_vec3 pos; // origin (m)
} frame;

static frame frame_of(const vd_pose* p) {
  frame f;
  vd_quat q = p->rot;
  double w = q.w, x = q.x, y = q.y, z = q.z;
  f.R[0] = 1 - 2 * (y * y + z * z), f.R[1] = 2 * (x * y - w * z), f.R[2] = 2 * (x * z + w * y);
  f.R[3] = 2 * (x * y + w * z), f.R[4] = 1 - 2 * (x * x + z * z), f.R[5] = 2 * (y * z - w * x);
  f.R[6] = 2 * (x * z - w * y), f.R[7] = 2 * (y * z + w * x), f.R[8] = 1 - 2 * (x * x + y * y);
  f.pos = p->pos;
  return f;
}
static vd_vec3 f_rotate(const frame* f, vd_vec3 v) {
  const double* R = f->R;
  return vd_v3(R[0] * v.x + R[1] * v.y + R[2] * v.z, R[3] * v.x + R[4] * v.y + R[5] * v.z,
               R[6] * v.x + R[7] * v.y + R[8] * v.z);
}
static vd_vec3 f_local(const frame* f, vd_vec3 x) {
  const double* R = f->R;
  vd_vec3 v = vd_sub(x, f->pos);
  return vd_v3(R[0] * v.x + R[3] * v.y + R[6] * v.z, R[1] * v.x + R[4] * v.y + R[7] * v.z,
               R[2] * v.x + R[5] * v.y + R[8] * v.z);
}
static vd_vec3 to_world(const vd_pose* p, vd_vec3 x) {
  return vd_add(p->pos, vd_quat_rotate(p->rot, x));
}

void vd_collider_bounds(const vd_collider* c, vd_vec3* lo, vd_vec3* hi) {
  vd_vec3 h;
  switch (c->shape) {
  case VD_SHAPE_SPHERE:
    *lo = vd_sub(c->pose.pos, vd_v3(c->radius, c->radius, c->radius));
    *hi = vd_add(c->pose.pos, vd_v3(c->radius, c->radius, c->radius));
    return;
  case VD_SHAPE_CAPSULE: {
    vd_vec3 a = to_world(&c->pose, vd_v3(0, 0, -c->half_length));
    vd_vec3 b = to_world(&c->pose, vd_v3(0, 0, c->half_length));
    *lo = vd_sub(vd_vmin(a, b), vd_v3(c->radius, c->radius, c->radius));
    *hi = vd_add(vd_vmax(a, b), vd_v3(c->radius, c->radius, c->radius));
    return;
  }
  case VD_SHAPE_BOX:
  case VD_SHAPE_SDF: {
    // the eight corners of the box (or of the grid) in world
    vd_vec3 l, u;
    if (c->shape == VD_SHAPE_BOX) {
      h = c->half_size;
      l = vd_scale(h, -1), u = h;
    } else {
      const vd_sdf* g = c->sdf;
      l = g->origin;
      u = vd_add(g->origin, vd_scale(vd_v3(g->nx - 1, g->ny - 1, g->nz - 1), g->cell));
    }
    for (int k = 0; k < 8; k++) {
      vd_vec3 p = vd_v3(k & 1 ? u.x : l.x, k & 2 ? u.y : l.y, k & 4 ? u.z : l.z);
      vd_vec3 w = to_world(&c->pose, p);
      *lo = k ? vd_vmin(*lo, w) : w;
      *hi = k ? vd_vmax(*hi, w) : w;
    }
    return;
  }
  default:
    *lo = vd_v3(-HUGE_VAL, -HUGE_VAL, -HUGE_VAL);
    *hi = vd_v3(HUGE_VAL, HUGE_VAL, HUGE_VAL);
    return;
  }
}

// ---------------------------------------------------------------------------------------------
// signed distances in the shape's frame

// signed distance of local point p and the unit outward normal n (the gradient)
static double shape_sd(const vd_collider* c, vd_vec3 p, vd_vec3* n) {
  switch (c->shape) {
  case VD_SHAPE_PLANE:
    *n = vd_v3(0, 0, 1);
    return p.z;
  case VD_SHAPE_SPHERE: {
    double d = len3(p);
    *n = d > 0 ? vd_scale(p, 1.0 / d) : vd_v3(0, 0, 1);
    return d - c->radius;
  }
  case VD_SHAPE_CAPSULE: {
    double h = c->half_length, z = p.z < -h ? -h : (p.z > h ? h : p.z);
    vd_vec3 v = vd_v3(p.x, p.y, p.z - z);
    double d = len3(v);
    *n = d > 0 ? vd_scale(v, 1.0 / d) : vd_v3(1, 0, 0);
    return d - c->radius;
  }
  case VD_SHAPE_BOX: {
    double pc[3] = {p.x, p.y, p.z}, hc[3] = {c->half_size.x, c->half_size.y, c->half_size.z};
    double q[3], s[3], out = 0;
    for (int a = 0; a < 3; a++) {
      s[a] = pc[a] < 0 ? -1 : 1;
      q[a] = fabs(pc[a]) - hc[a];
      if (q[a] > 0) out += q[a] * q[a];
    }
    if (out > 0) {
      // outside: distance to the nearest point of the box
      double d = sqrt(out);
      double g[3];
      for (int a = 0; a < 3; a++)
        g[a] = q[a] > 0 ? s[a] * q[a] / d : 0;
      *n = vd_v3(g[0], g[1], g[2]);
      return d;
    }
    // inside (or on it): the nearest face, the first axis on ties
    int a = 0;
    for (int k = 1; k < 3; k++)
      if (q[k] > q[a]) a = k;
    double g[3] = {0, 0, 0};
    g[a] = s[a];
    *n = vd_v3(g[0], g[1], g[2]);
    return q[a];
  }
  case VD_SHAPE_SDF: {
    vd_vec3 g;
    double d = vd_sdf_eval(c->sdf, p, &g);
    double len = len3(g);
    *n = len > 0 ? vd_scale(g, 1.0 / len) : vd_v3(0, 0, 1);
    return d;
  }
  default:
    // cppcheck-suppress incorrectStringBooleanError ; the string is the failed assert's message
    VD_ASSERT(0 && "unknown collider shape");
    *n = vd_v3(0, 0, 1);
    return HUGE_VAL;
  }
}

static vd_collide_hit hit_from_local(const frame* f, vd_vec3 pw, double sd, vd_vec3 nl, double r,
                                     double t) {
  vd_collide_hit h;
  h.normal = f_rotate(f, nl);
  h.point = vd_madd(pw, h.normal, -sd);
  h.dist = sd - r;
  h.t = t;
  return h;
}

static vd_collide_hit sphere_query(const vd_collider* c, const frame* f, vd_vec3 p, double r) {
  vd_vec3 n;
  double sd = shape_sd(c, f_local(f, p), &n);
  return hit_from_local(f, p, sd, n, r, 0);
}

vd_collide_hit vd_collide_point(const vd_collider* c, vd_vec3 p) {
  return vd_collide_sphere(c, p, 0);
}

vd_collide_hit vd_collide_sphere(const vd_collider* c, vd_vec3 p, double r) {
  VD_ASSERT(c);
  frame f = frame_of(&c->pose);
  return sphere_query(c, &f, p, r);
}

// derivative of f(t) = sd(a + t d) - (ra + t dr) along the axis (a subgradient at kinks)
static double axis_slope(const vd_collider* c, vd_vec3 a, vd_vec3 d, double dr, double t) {
  vd_vec3 n;
  shape_sd(c, vd_madd(a, d, t), &n);
  return vd_dot(n, d) - dr;
}

// the deepest axis parameter of a convex shape: the minimiser of the convex f, the middle of the
// flat part when f is flat (slopes within tol of zero)
static double convex_argmin(const vd_collider* c, vd_vec3 a, vd_vec3 d, double dr) {
  double tol = 1e-12 * (len3(d) + fabs(dr));
  if (!(tol > 0)) return 0.5; // the axis is a point with one radius
  // the lowest t with slope >= -tol, and the highest with slope <= tol
  double lo_end, hi_end;
  if (axis_slope(c, a, d, dr, 0) >= -tol) {
    lo_end = 0;
  } else if (axis_slope(c, a, d, dr, 1) < -tol) {
    return 1;
  } else {
    double l = 0, h = 1;
    for (int i = 0; i < BISECT_STEPS; i++) {
      double m = 0.5 * (l + h);
      if (axis_slope(c, a, d, dr, m) >= -tol)
        h = m;
      else
        l = m;
    }
    lo_end = h;
  }
  if (axis_slope(c, a, d, dr, 1) <= tol) {
    hi_end = 1;
  } else if (axis_slope(c, a, d, dr, lo_end) > tol) {
    return lo_end;
  } else {
    double l = lo_end, h = 1;
    for (int i = 0; i < BISECT_STEPS; i++) {
      double m = 0.5 * (l + h);
      if (axis_slope(c, a, d, dr, m) <= tol)
        l = m;
      else
        h = m;
    }
    hi_end = l;
  }
  return 0.5 * (lo_end + hi_end);
}

// the deepest axis parameter against a sphere at the origin, in closed form: f(t) = |a + t d|
// - t dr (+ constants) has f' = 0 where (t - t0) |d|^2 / |a + t d| = dr, t0 the foot of the
// perpendicular from the centre, so t = t0 + dr h / (|d| sqrt(|d|^2 - dr^2)), h the distance
// from the centre to the axis line; clamped to the axis (f is convex)
static double sphere_argmin(vd_vec3 a, vd_vec3 d, double dr) {
  double dd = vd_dot(d, d);
  if (!(dd > 0)) return 0.5;
  if (dr * dr >= dd) return dr > 0 ? 1 : 0; // one end's sphere holds the whole capsule
  double t0 = -vd_dot(a, d) / dd;
  vd_vec3 foot = vd_madd(a, d, t0);
  double h = len3(foot);
  double t = t0 + dr * h / (sqrt(dd) * sqrt(dd - dr * dr));
  return t < 0 ? 0 : (t > 1 ? 1 : t);
}

// f along the axis of a capsule in the collider's frame
static double axis_f(const vd_collider* c, vd_vec3 a, vd_vec3 d, double ra, double dr, double t) {
  vd_vec3 n;
  return shape_sd(c, vd_madd(a, d, t), &n) - (ra + t * dr);
}

// the deepest axis parameter against a distance grid: samples every half cell, then a
// golden-section search around the best sample
static double sdf_argmin(const vd_collider* c, vd_vec3 a, vd_vec3 d, double ra, double dr) {
  double len = len3(d);
  int m = (int)ceil(len / (0.5 * c->sdf->cell));
  if (m < 1) m = 1;
  if (m > 4096) m = 4096;
  int best = 0;
  double fb = axis_f(c, a, d, ra, dr, 0);
  for (int i = 1; i <= m; i++) {
    double f = axis_f(c, a, d, ra, dr, (double)i / m);
    if (f < fb) fb = f, best = i;
  }
  double l = (double)(best > 0 ? best - 1 : 0) / m, h = (double)(best < m ? best + 1 : m) / m;
  const double g = 0.6180339887498949;
  double x1 = h - g * (h - l), x2 = l + g * (h - l);
  double f1 = axis_f(c, a, d, ra, dr, x1), f2 = axis_f(c, a, d, ra, dr, x2);
  for (int i = 0; i < 24; i++) {
    if (f1 <= f2) {
      h = x2, x2 = x1, f2 = f1;
      x1 = h - g * (h - l);
      f1 = axis_f(c, a, d, ra, dr, x1);
    } else {
      l = x1, x1 = x2, f1 = f2;
      x2 = l + g * (h - l);
      f2 = axis_f(c, a, d, ra, dr, x2);
    }
  }
  double t = f1 <= f2 ? x1 : x2;
  return fmin(f1, f2) < fb ? t : (double)best / m;
}

static vd_collide_hit capsule_query(const vd_collider* c, const frame* f, vd_vec3 a, vd_vec3 b,
                                    double ra, double rb) {
  // the axis in the collider's frame
  vd_vec3 al = f_local(f, a), bl = f_local(f, b);
  vd_vec3 d = vd_sub(bl, al);
  double dr = rb - ra;
  double t;
  if (c->shape == VD_SHAPE_PLANE) {
    // linear along the axis: the lower end, the middle when level
    double f0 = al.z - ra, f1 = bl.z - rb, tol = 1e-12 * (len3(d) + fabs(dr));
    t = f0 < f1 - tol ? 0 : (f1 < f0 - tol ? 1 : 0.5);
  } else if (c->shape == VD_SHAPE_SPHERE) {
    t = sphere_argmin(al, d, dr);
  } else if (c->shape == VD_SHAPE_SDF) {
    t = sdf_argmin(c, al, d, ra, dr);
  } else {
    t = convex_argmin(c, al, d, dr);
  }
  // the hit at the deepest axis point
  vd_vec3 n;
  double sd = shape_sd(c, vd_madd(al, d, t), &n);
  return hit_from_local(f, vd_madd(a, vd_sub(b, a), t), sd, n, ra + t * dr, t);
}

vd_collide_hit vd_collide_capsule(const vd_collider* c, vd_vec3 a, vd_vec3 b, double ra,
                                  double rb) {
  VD_ASSERT(c);
  frame f = frame_of(&c->pose);
  return capsule_query(c, &f, a, b, ra, rb);
}

// ---------------------------------------------------------------------------------------------
// narrow phase between plant primitives

// closest points of segments p1-q1 and p2-q2 at parameters *s and *t (Ericson, Real-Time
// Collision Detection, 5.1.9); parallel overlapping segments take the middle of the overlap
static void segment_closest(vd_vec3 p1, vd_vec3 q1, vd_vec3 p2, vd_vec3 q2, double* s, double* t) {
  vd_vec3 d1 = vd_sub(q1, p1), d2 = vd_sub(q2, p2), r = vd_sub(p1, p2);
  double a = vd_dot(d1, d1), e = vd_dot(d2, d2), f = vd_dot(d2, r);
  const double tiny = 1e-24;
#define CLAMP01(x) ((x) < 0 ? 0 : ((x) > 1 ? 1 : (x)))
  if (a <= tiny && e <= tiny) {
    *s = *t = 0;
    return;
  }
  if (a <= tiny) {
    *s = 0;
    *t = CLAMP01(f / e);
    return;
  }
  double c = vd_dot(d1, r);
  if (e <= tiny) {
    *t = 0;
    *s = CLAMP01(-c / a);
    return;
  }
  double b = vd_dot(d1, d2), den = a * e - b * b;
  double ss;
  if (den > 1e-12 * a * e) {
    ss = CLAMP01((b * f - c * e) / den);
  } else {
    // parallel: the middle of the overlap of segment 2's projection with [0, 1], else the end
    double s0 = -c / a, s1 = (b - c) / a;
    double lo = fmax(fmin(s0, s1), 0), hi = fmin(fmax(s0, s1), 1);
    ss = lo <= hi ? 0.5 * (lo + hi) : CLAMP01(fmin(s0, s1) > 1 ? 1 : 0);
  }
  double tt = (b * ss + f) / e;
  if (tt < 0) {
    tt = 0;
    ss = CLAMP01(-c / a);
  } else if (tt > 1) {
    tt = 1;
    ss = CLAMP01((b - c) / a);
  }
  *s = ss;
  *t = tt;
#undef CLAMP01
}

static vd_vec3 vec_at(const double* a, int i) {
  return vd_v3(a[3 * i], a[3 * i + 1], a[3 * i + 2]);
}

int vd_collide_pair(const vd_collide_prims* P, int i, int j, double margin, vd_contact* out) {
  VD_ASSERT(P && out && i != j);
  if (i > j) {
    int k = i;
    i = j, j = k;
  }
  int nc = P->ncapsule;
  vd_contact c;
  memset(&c, 0, sizeof c);
  c.a = i, c.b = j;
  if (j < nc) {
    // capsule-capsule: closest axis points, radii taken there (exact for uniform radii)
    vd_vec3 a0 = vec_at(P->node_pos, P->capsule_node[2 * i]);
    vd_vec3 a1 = vec_at(P->node_pos, P->capsule_node[2 * i + 1]);
    vd_vec3 b0 = vec_at(P->node_pos, P->capsule_node[2 * j]);
    vd_vec3 b1 = vec_at(P->node_pos, P->capsule_node[2 * j + 1]);
    segment_closest(a0, a1, b0, b1, &c.ta, &c.tb);
    vd_vec3 pa = vd_madd(a0, vd_sub(a1, a0), c.ta), pb = vd_madd(b0, vd_sub(b1, b0), c.tb);
    double ra =
        P->capsule_radius[2 * i] + c.ta * (P->capsule_radius[2 * i + 1] - P->capsule_radius[2 * i]);
    double rb =
        P->capsule_radius[2 * j] + c.tb * (P->capsule_radius[2 * j + 1] - P->capsule_radius[2 * j]);
    vd_vec3 v = vd_sub(pa, pb);
    double d = len3(v);
    c.dist = d - ra - rb;
    if (!(c.dist < margin)) return 0;
    double scale = vd_norm(vd_sub(a1, a0)) + vd_norm(vd_sub(b1, b0));
    if (d > 1e-12 * scale) {
      c.normal = vd_scale(v, 1.0 / d);
    } else {
      // axes cross: the common perpendicular, or any perpendicular when parallel
      vd_vec3 x = vd_cross(vd_sub(a1, a0), vd_sub(b1, b0));
      c.normal = vd_norm(x) > 0 ? vd_normalize(x) : any_perp(vd_normalize(vd_sub(a1, a0)));
    }
    c.pa = vd_madd(pa, c.normal, -ra);
    c.pb = vd_madd(pb, c.normal, rb);
    *out = c;
    return 1;
  }
  vd_vec3 cj = vec_at(P->sphere_pos, j - nc);
  double rj = P->sphere_radius[j - nc];
  vd_collider sph = vd_collider_sphere(cj, rj);
  vd_collide_hit h;
  if (i < nc) {
    // capsule-sphere: the sphere as a collider
    vd_vec3 a0 = vec_at(P->node_pos, P->capsule_node[2 * i]);
    vd_vec3 a1 = vec_at(P->node_pos, P->capsule_node[2 * i + 1]);
    double r0 = P->capsule_radius[2 * i], r1 = P->capsule_radius[2 * i + 1];
    h = vd_collide_capsule(&sph, a0, a1, r0, r1);
    c.ta = h.t;
    c.pa = vd_madd(vd_madd(a0, vd_sub(a1, a0), h.t), h.normal, -(r0 + h.t * (r1 - r0)));
  } else {
    // sphere-sphere
    vd_vec3 ci = vec_at(P->sphere_pos, i - nc);
    double ri = P->sphere_radius[i - nc];
    h = vd_collide_sphere(&sph, ci, ri);
    c.pa = vd_madd(ci, h.normal, -ri);
  }
  c.dist = h.dist;
  if (!(c.dist < margin)) return 0;
  c.normal = h.normal;
  c.pb = h.point;
  *out = c;
  return 1;
}

// ---------------------------------------------------------------------------------------------
// contact lists in the arena

typedef struct cbuf {
  vd_contact* c;
  int n, cap;
} cbuf;

// append one contact, doubling the arena array when full; 0 when the arena is out of memory
static int cbuf_push(vd_arena* ar, cbuf* b, const vd_contact* c) {
  if (b->n == b->cap) {
    int cap = b->cap ? 2 * b->cap : 64;
    vd_contact* p = vd_arena_alloc(ar, (size_t)cap * sizeof *p);
    if (!p) return 0;
    if (b->n) memcpy(p, b->c, (size_t)b->n * sizeof *p);
    b->c = p, b->cap = cap;
  }
  b->c[b->n++] = *c;
  return 1;
}

// primitive i's own extra margin (m)
static double prim_margin(const vd_collide_prims* P, int i) { return P->margin ? P->margin[i] : 0; }

// bounding box of primitive i, grown by g on every side
static void prim_bounds(const vd_collide_prims* P, int i, double g, vd_vec3* lo, vd_vec3* hi) {
  if (i < P->ncapsule) {
    vd_vec3 a = vec_at(P->node_pos, P->capsule_node[2 * i]);
    vd_vec3 b = vec_at(P->node_pos, P->capsule_node[2 * i + 1]);
    double r0 = P->capsule_radius[2 * i], r1 = P->capsule_radius[2 * i + 1];
    double r = (r0 > r1 ? r0 : r1) + g;
    *lo = vd_sub(vd_vmin(a, b), vd_v3(r, r, r));
    *hi = vd_add(vd_vmax(a, b), vd_v3(r, r, r));
  } else {
    vd_vec3 c = vec_at(P->sphere_pos, i - P->ncapsule);
    double r = P->sphere_radius[i - P->ncapsule] + g;
    *lo = vd_sub(c, vd_v3(r, r, r));
    *hi = vd_add(c, vd_v3(r, r, r));
  }
}

// is j in i's excluded row (rows ascending)?
static int excluded(const vd_collide_prims* P, int i, int j) {
  if (!P->exclude_start || !P->exclude) return 0;
  int l = P->exclude_start[i], h = P->exclude_start[i + 1];
  while (l < h) {
    int m = l + (h - l) / 2;
    if (P->exclude[m] == j) return 1;
    if (P->exclude[m] < j)
      l = m + 1;
    else
      h = m;
  }
  return 0;
}

static vd_status check_prims(const vd_collide_prims* P, const vd_collide_def* def, vd_arena* arena,
                             vd_contact_list* out, vd_error* err) {
  if (!P || !arena || !out)
    return vd_error_set(err, VD_ERR_ARG, "", 0, 0, "collide: null argument");
  if (P->ncapsule < 0 || P->nsphere < 0 || P->nnode < 0)
    return vd_error_set(err, VD_ERR_ARG, "", 0, 0, "collide: negative size");
  if ((P->ncapsule && (!P->node_pos || !P->capsule_node || !P->capsule_radius)) ||
      (P->nsphere && (!P->sphere_pos || !P->sphere_radius)))
    return vd_error_set(err, VD_ERR_ARG, "", 0, 0, "collide: missing primitive arrays");
  for (int i = 0; i < 2 * P->ncapsule; i++)
    if (P->capsule_node[i] < 0 || P->capsule_node[i] >= P->nnode)
      return vd_error_set(err, VD_ERR_ARG, "", 0, 0, "collide: capsule %d: node out of range",
                          i / 2);
  if (P->exclude_start && P->exclude_rows != P->ncapsule + P->nsphere)
    return vd_error_set(err, VD_ERR_ARG, "", 0, 0,
                        "collide: the exclusion has %d rows for %d primitives", P->exclude_rows,
                        P->ncapsule + P->nsphere);
  for (int i = 0; P->margin && i < P->ncapsule + P->nsphere; i++)
    if (!(P->margin[i] >= 0 && isfinite(P->margin[i])))
      return vd_error_set(err, VD_ERR_ARG, "", 0, 0, "collide: primitive %d: margin must be >= 0 m",
                          i);
  if (def && !(def->margin >= 0 && isfinite(def->margin)))
    return vd_error_set(err, VD_ERR_ARG, "", 0, 0, "collide: margin must be >= 0 m");
  if (def && def->max_contacts < 0)
    return vd_error_set(err, VD_ERR_ARG, "", 0, 0, "collide: max_contacts must be >= 0");
  memset(out, 0, sizeof *out);
  return VD_OK;
}

// a sort key: ordered by k; equal keys keep their input order (the sort is stable)
typedef struct rkey {
  uint64_t k; // sweep: the box's low end as ordered bits; contacts and pairs: a << 32 | b
  int v;      // sweep: the primitive; contacts: the contact's index
} rkey;

// the bits of a double as an unsigned integer in the same order (negatives flipped)
static uint64_t ordered_bits(double x) {
  uint64_t u;
  memcpy(&u, &x, sizeof u);
  return (u >> 63) ? ~u : u | ((uint64_t)1 << 63);
}

// least-significant-digit radix sort (8 passes of 8 bits, passes with a single digit skipped)
// of n keys with tmp (n keys) as scratch; returns the sorted array (a or tmp). Branch-free,
// linear, stable, and both arrays come from the caller's arena: no heap in a step
static rkey* sort_keys(rkey* a, rkey* tmp, int n) {
  uint32_t count[8][256];
  memset(count, 0, sizeof count);
  for (int i = 0; i < n; i++)
    for (int d = 0; d < 8; d++)
      count[d][(a[i].k >> (8 * d)) & 255]++;
  rkey *src = a, *dst = tmp;
  for (int d = 0; d < 8; d++) {
    uint32_t* c = count[d];
    if (n == 0 || c[(src[0].k >> (8 * d)) & 255] == (uint32_t)n) continue; // one digit only
    uint32_t sum = 0;
    for (int q = 0; q < 256; q++) {
      uint32_t x = c[q];
      c[q] = sum, sum += x;
    }
    for (int i = 0; i < n; i++)
      dst[c[(src[i].k >> (8 * d)) & 255]++] = src[i];
    rkey* x = src;
    src = dst, dst = x;
  }
  return src;
}

// the contact list ordered by (a, b), copied into a fresh arena array; 0 when out of memory
static int sort_contacts(vd_arena* ar, cbuf* b) {
  if (b->n < 2) return 1;
  rkey* k = vd_arena_alloc(ar, (size_t)b->n * sizeof *k);
  rkey* tmp = vd_arena_alloc(ar, (size_t)b->n * sizeof *tmp);
  vd_contact* out = vd_arena_alloc(ar, (size_t)b->n * sizeof *out);
  if (!k || !tmp || !out) return 0;
  for (int i = 0; i < b->n; i++)
    k[i].k = (uint64_t)(uint32_t)b->c[i].a << 32 | (uint32_t)b->c[i].b, k[i].v = i;
  rkey* s = sort_keys(k, tmp, b->n);
  for (int i = 0; i < b->n; i++)
    out[i] = b->c[s[i].v];
  b->c = out, b->cap = b->n;
  return 1;
}

static double comp(vd_vec3 v, int a) {
  return a == 0 ? v.x : (a == 1 ? v.y : v.z);
}

// a growable array of candidate pairs (a < b) in the arena
typedef struct pbuf {
  int* p; // (n x 2)
  int n, cap;
} pbuf;

static int pbuf_push(vd_arena* ar, pbuf* b, int i, int j) {
  if (b->n == b->cap) {
    int cap = b->cap ? 2 * b->cap : 256;
    int* p = vd_arena_alloc(ar, (size_t)cap * 2 * sizeof *p);
    if (!p) return 0;
    if (b->n) memcpy(p, b->p, (size_t)b->n * 2 * sizeof *p);
    b->p = p, b->cap = cap;
  }
  b->p[2 * b->n] = i, b->p[2 * b->n + 1] = j;
  b->n++;
  return 1;
}

// the broad phase: pairs of primitives that take part, are not excluded and whose boxes, grown
// by grow / 2 each, overlap; sweep and prune along the axis where the box centres spread most
static vd_status broad_phase(const vd_collide_prims* P, double grow, vd_arena* arena, pbuf* out,
                             vd_error* err) {
  const char* oom = "collide: arena out of memory";
  int n = P->ncapsule + P->nsphere;
  out->p = NULL, out->n = out->cap = 0;
  if (n < 2) return VD_OK;
  vd_vec3* lo = vd_arena_alloc(arena, (size_t)n * sizeof *lo);
  vd_vec3* hi = vd_arena_alloc(arena, (size_t)n * sizeof *hi);
  rkey* key = vd_arena_alloc(arena, (size_t)n * sizeof *key);
  rkey* tmp = vd_arena_alloc(arena, (size_t)n * sizeof *tmp);
  double* start = vd_arena_alloc(arena, (size_t)n * sizeof *start);
  if (!lo || !hi || !key || !tmp || !start)
    return vd_error_set(err, VD_ERR_NOMEM, "", 0, 0, "%s", oom);
  int m = 0;
  vd_vec3 cmin = vd_v3(HUGE_VAL, HUGE_VAL, HUGE_VAL), cmax = vd_scale(cmin, -1);
  for (int i = 0; i < n; i++) {
    if (P->skip && P->skip[i]) continue;
    prim_bounds(P, i, 0.5 * grow + prim_margin(P, i), &lo[i], &hi[i]);
    vd_vec3 c = vd_scale(vd_add(lo[i], hi[i]), 0.5);
    cmin = vd_vmin(cmin, c), cmax = vd_vmax(cmax, c);
    key[m++].v = i;
  }
  vd_vec3 spread = vd_sub(cmax, cmin);
  int ax = spread.x >= spread.y && spread.x >= spread.z ? 0 : (spread.y >= spread.z ? 1 : 2);
  for (int k = 0; k < m; k++)
    key[k].k = ordered_bits(comp(lo[key[k].v], ax));
  key = sort_keys(key, tmp, m);
  for (int k = 0; k < m; k++)
    start[k] = comp(lo[key[k].v], ax);
  for (int k = 0; k < m; k++) {
    int i = key[k].v;
    double end = comp(hi[i], ax);
    for (int q = k + 1; q < m && start[q] <= end; q++) {
      int j = key[q].v;
      // boxes overlap on the other two axes (all six tests at once), the pair is not excluded
      int apart = (lo[i].x > hi[j].x) | (lo[j].x > hi[i].x) | (lo[i].y > hi[j].y) |
                  (lo[j].y > hi[i].y) | (lo[i].z > hi[j].z) | (lo[j].z > hi[i].z);
      if (apart) continue;
      int a = i < j ? i : j, b = i < j ? j : i;
      if (excluded(P, a, b)) continue;
      if (!pbuf_push(arena, out, a, b)) return vd_error_set(err, VD_ERR_NOMEM, "", 0, 0, "%s", oom);
    }
  }
  return VD_OK;
}

// the narrow phase over candidate pairs, contacts sorted by (a, b); boxes: test the current
// boxes first (pairs kept from an earlier broad phase)
static vd_status narrow_phase(const vd_collide_prims* P, const int* pair, int npair,
                              const vd_collide_def* def, int boxes, vd_arena* arena,
                              vd_contact_list* out, vd_error* err) {
  cbuf buf = {NULL, 0, 0};
  for (int k = 0; k < npair; k++) {
    int a = pair[2 * k], b = pair[2 * k + 1];
    if (P->skip && (P->skip[a] || P->skip[b])) continue;
    double ea = prim_margin(P, a), eb = prim_margin(P, b);
    if (boxes) {
      vd_vec3 la, ha, lb, hb;
      prim_bounds(P, a, 0.5 * def->margin + ea, &la, &ha);
      prim_bounds(P, b, 0.5 * def->margin + eb, &lb, &hb);
      if (la.x > hb.x || lb.x > ha.x || la.y > hb.y || lb.y > ha.y || la.z > hb.z || lb.z > ha.z)
        continue;
    }
    out->ntested++;  // NOLINT(clang-analyzer-core.uninitialized.Assign): check_prims zeroes *out
    vd_contact c;
    if (!vd_collide_pair(P, a, b, def->margin + ea + eb, &c)) continue;
    if (buf.n >= def->max_contacts) {
      out->ndropped++;
      continue;
    }
    if (!cbuf_push(arena, &buf, &c))
      return vd_error_set(err, VD_ERR_NOMEM, "", 0, 0, "collide: arena out of memory");
  }
  // fixed order whatever the sweep met first
  if (!sort_contacts(arena, &buf))
    return vd_error_set(err, VD_ERR_NOMEM, "", 0, 0, "collide: arena out of memory");
  out->n = buf.n;
  out->c = buf.c;
  return VD_OK;
}

vd_status vd_collide_self(const vd_collide_prims* P, const vd_collide_def* def_in, vd_arena* arena,
                          vd_contact_list* out, vd_error* err) {
  vd_status st = check_prims(P, def_in, arena, out, err);
  if (st) return st;
  vd_collide_def def = def_in ? *def_in : vd_collide_def_default();
  pbuf pairs;
  if ((st = broad_phase(P, def.margin, arena, &pairs, err))) return st;
  return narrow_phase(P, pairs.p, pairs.n, &def, 0, arena, out, err);
}

vd_status vd_collide_self_pairs(const vd_collide_prims* P, double grow, vd_arena* arena,
                                vd_pair_list* out, vd_error* err) {
  vd_contact_list dummy;
  if (!out) return vd_error_set(err, VD_ERR_ARG, "", 0, 0, "collide: null argument");
  memset(out, 0, sizeof *out);
  vd_status st = check_prims(P, NULL, arena, &dummy, err);
  if (st) return st;
  if (!(grow >= 0) || !isfinite(grow))
    return vd_error_set(err, VD_ERR_ARG, "", 0, 0, "collide: grow must be >= 0 m");
  pbuf pairs;
  if ((st = broad_phase(P, grow, arena, &pairs, err))) return st;
  // ascending (a, b): two stable counting sorts, by b then by a, back into the sweep's buffer
  // (primitive indices are small integers; 8 bytes a pair of scratch, no 64-bit keys)
  if (pairs.n > 1) {
    int n = P->ncapsule + P->nsphere;
    int* tmp = vd_arena_alloc(arena, (size_t)pairs.n * 2 * sizeof *tmp);
    int* cnt = vd_arena_alloc(arena, ((size_t)n + 1) * sizeof *cnt);
    if (!tmp || !cnt)
      return vd_error_set(err, VD_ERR_NOMEM, "", 0, 0, "collide: arena out of memory");
    for (int pass = 1; pass >= 0; pass--) {
      const int* src = pass ? pairs.p : tmp;
      int* dst = pass ? tmp : pairs.p;
      memset(cnt, 0, ((size_t)n + 1) * sizeof *cnt);
      for (int i = 0; i < pairs.n; i++)
        cnt[src[2 * i + pass] + 1]++;
      for (int v = 0; v < n; v++)
        cnt[v + 1] += cnt[v];
      for (int i = 0; i < pairs.n; i++) {
        int o = cnt[src[2 * i + pass]]++;
        dst[2 * o] = src[2 * i], dst[2 * o + 1] = src[2 * i + 1];
      }
    }
  }
  out->n = pairs.n;
  out->pair = pairs.p;
  return VD_OK;
}

vd_status vd_collide_pairs(const vd_collide_prims* P, const vd_pair_list* pairs,
                           const vd_collide_def* def_in, vd_arena* arena, vd_contact_list* out,
                           vd_error* err) {
  vd_status st = check_prims(P, def_in, arena, out, err);
  if (st) return st;
  if (!pairs || (pairs->n > 0 && !pairs->pair) || pairs->n < 0)
    return vd_error_set(err, VD_ERR_ARG, "", 0, 0, "collide: bad pair list");
  int n = P->ncapsule + P->nsphere;
  for (int k = 0; k < 2 * pairs->n; k++)
    if (pairs->pair[k] < 0 || pairs->pair[k] >= n ||
        (k % 2 && pairs->pair[k] == pairs->pair[k - 1]))
      return vd_error_set(err, VD_ERR_ARG, "", 0, 0, "collide: pair %d: bad primitive", k / 2);
  vd_collide_def def = def_in ? *def_in : vd_collide_def_default();
  return narrow_phase(P, pairs->pair, pairs->n, &def, 1, arena, out, err);
}

vd_status vd_collide_colliders(const vd_collide_prims* P, const vd_collider* col, int ncol,
                               const vd_collide_def* def_in, vd_arena* arena, vd_contact_list* out,
                               vd_error* err) {
  vd_status st = check_prims(P, def_in, arena, out, err);
  if (st) return st;
  if (ncol < 0 || (ncol > 0 && !col))
    return vd_error_set(err, VD_ERR_ARG, "", 0, 0, "collide: bad collider array");
  for (int k = 0; k < ncol; k++)
    if ((int)col[k].shape < 0 || col[k].shape >= VD_SHAPE_COUNT ||
        (col[k].shape == VD_SHAPE_SDF && !col[k].sdf))
      return vd_error_set(err, VD_ERR_ARG, "", 0, 0, "collide: collider %d: bad shape", k);
  vd_collide_def def = def_in ? *def_in : vd_collide_def_default();
  int n = P->ncapsule + P->nsphere;
  // the primitives' boxes, grown by the margin, once for all colliders
  vd_vec3* plo = vd_arena_alloc(arena, (size_t)(n ? n : 1) * sizeof *plo);
  vd_vec3* phi = vd_arena_alloc(arena, (size_t)(n ? n : 1) * sizeof *phi);
  if (!plo || !phi)
    return vd_error_set(err, VD_ERR_NOMEM, "", 0, 0, "collide: arena out of memory");
  for (int i = 0; i < n; i++)
    prim_bounds(P, i, def.margin + prim_margin(P, i), &plo[i], &phi[i]);
  cbuf buf = {NULL, 0, 0};
  for (int k = 0; k < ncol; k++) {
    const vd_collider* c = &col[k];
    frame f = frame_of(&c->pose);
    vd_vec3 clo, chi;
    vd_collider_bounds(c, &clo, &chi);
    for (int i = 0; i < n; i++) {
      if (P->skip && P->skip[i]) continue;
      vd_vec3 lo = plo[i], hi = phi[i];
      if (lo.x > chi.x || clo.x > hi.x || lo.y > chi.y || clo.y > hi.y || lo.z > chi.z ||
          clo.z > hi.z)
        continue;
      out->ntested++;
      // the primitive against the collider
      vd_contact ct;
      memset(&ct, 0, sizeof ct);
      ct.a = i, ct.b = k, ct.collider = 1;
      vd_collide_hit h;
      if (i < P->ncapsule) {
        vd_vec3 a0 = vec_at(P->node_pos, P->capsule_node[2 * i]);
        vd_vec3 a1 = vec_at(P->node_pos, P->capsule_node[2 * i + 1]);
        double r0 = P->capsule_radius[2 * i], r1 = P->capsule_radius[2 * i + 1];
        // far from the shape: the distance at the axis' middle less half the axis bounds every
        // point's (signed distances are 1-Lipschitz; a trilinear grid's at most sqrt(3))
        vd_vec3 nm;
        double half = 0.5 * len3(vd_sub(a1, a0)),
               lip = c->shape == VD_SHAPE_SDF ? 1.7320508075688772 : 1;
        double sd_mid = shape_sd(c, f_local(&f, vd_scale(vd_add(a0, a1), 0.5)), &nm);
        double slack = c->shape == VD_SHAPE_SDF ? 0.1 * c->sdf->cell : 0; // swept values' error
        if (sd_mid - lip * half - (r0 > r1 ? r0 : r1) - slack >= def.margin + prim_margin(P, i))
          continue;
        h = capsule_query(c, &f, a0, a1, r0, r1);
        ct.ta = h.t;
        ct.pa = vd_madd(vd_madd(a0, vd_sub(a1, a0), h.t), h.normal, -(r0 + h.t * (r1 - r0)));
      } else {
        vd_vec3 ci = vec_at(P->sphere_pos, i - P->ncapsule);
        double ri = P->sphere_radius[i - P->ncapsule];
        h = sphere_query(c, &f, ci, ri);
        ct.pa = vd_madd(ci, h.normal, -ri);
      }
      if (!(h.dist < def.margin + prim_margin(P, i))) continue;
      ct.dist = h.dist;
      ct.normal = h.normal;
      ct.pb = h.point;
      if (buf.n >= def.max_contacts) {
        out->ndropped++;
        continue;
      }
      if (!cbuf_push(arena, &buf, &ct))
        return vd_error_set(err, VD_ERR_NOMEM, "", 0, 0, "collide: arena out of memory");
    }
  }
  if (!sort_contacts(arena, &buf))
    return vd_error_set(err, VD_ERR_NOMEM, "", 0, 0, "collide: arena out of memory");
  out->n = buf.n;
  out->c = buf.c;
  return VD_OK;
}

// ---------------------------------------------------------------------------------------------
// neighbour exclusion from the topology

static int cmp_int(const void* a, const void* b) {
  int x = *(const int*)a, y = *(const int*)b;
  return (x > y) - (x < y);
}

vd_status vd_collide_exclusion_build(int nnode, int ncap, const int* cap_node, int nsph,
                                     const int* sph_node, int hops, vd_collide_exclusion* out,
                                     vd_error* err) {
  if (!out) return vd_error_set(err, VD_ERR_ARG, "", 0, 0, "exclusion: null argument");
  memset(out, 0, sizeof *out);
  if (nnode < 0 || ncap < 0 || nsph < 0 || hops < 0 || (ncap && !cap_node))
    return vd_error_set(err, VD_ERR_ARG, "", 0, 0, "exclusion: bad argument");
  for (int i = 0; i < 2 * ncap; i++)
    if (cap_node[i] < 0 || cap_node[i] >= nnode)
      return vd_error_set(err, VD_ERR_ARG, "", 0, 0, "exclusion: capsule %d: node out of range",
                          i / 2);
  for (int i = 0; sph_node && i < nsph; i++)
    if (sph_node[i] < -1 || sph_node[i] >= nnode)
      return vd_error_set(err, VD_ERR_ARG, "", 0, 0, "exclusion: sphere %d: node out of range", i);
  int n = ncap + nsph;
  // node -> primitives touching it, and node -> neighbour nodes (CSR, counted then filled)
  size_t I = sizeof(int);
  int* pstart = vd_calloc((size_t)nnode + 1, I);
  int* prim = vd_malloc(((size_t)2 * ncap + (size_t)nsph + 1) * I);
  int* nstart = vd_calloc((size_t)nnode + 1, I);
  int* nbr = vd_malloc(((size_t)2 * ncap + 1) * I);
  int* mark = vd_malloc(((size_t)nnode + 1) * I);
  int* depth = vd_malloc(((size_t)nnode + 1) * I);
  int* queue = vd_malloc(((size_t)nnode + 1) * I);
  int* pmark = vd_malloc(((size_t)n + 1) * I);
  int* row = vd_malloc(((size_t)n + 1) * I);
  int* all = NULL;
  int nall = 0, cap_all = 0;
  int64_t* start64 = vd_malloc(((size_t)n + 1) * sizeof(int64_t));
  vd_status st = VD_OK;
  if (!pstart || !prim || !nstart || !nbr || !mark || !depth || !queue || !pmark || !row ||
      !start64) {
    st = vd_error_set(err, VD_ERR_NOMEM, "", 0, 0, "out of memory building the exclusion");
    goto done;
  }
  for (int i = 0; i < ncap; i++) {
    pstart[cap_node[2 * i] + 1]++;
    if (cap_node[2 * i + 1] != cap_node[2 * i]) pstart[cap_node[2 * i + 1] + 1]++;
    nstart[cap_node[2 * i] + 1]++, nstart[cap_node[2 * i + 1] + 1]++;
  }
  for (int i = 0; sph_node && i < nsph; i++)
    if (sph_node[i] >= 0) pstart[sph_node[i] + 1]++;
  for (int v = 0; v < nnode; v++)
    pstart[v + 1] += pstart[v], nstart[v + 1] += nstart[v];
  for (int v = 0; v < nnode; v++)
    mark[v] = pstart[v], depth[v] = nstart[v];
  for (int i = 0; i < ncap; i++) {
    int a = cap_node[2 * i], b = cap_node[2 * i + 1];
    prim[mark[a]++] = i;
    if (b != a) prim[mark[b]++] = i;
    nbr[depth[a]++] = b, nbr[depth[b]++] = a;
  }
  for (int i = 0; sph_node && i < nsph; i++)
    if (sph_node[i] >= 0) prim[mark[sph_node[i]]++] = ncap + i;
  for (int v = 0; v < nnode; v++)
    mark[v] = -1;
  for (int i = 0; i < n; i++)
    pmark[i] = -1;

  // per primitive: nodes within `hops` of its own (breadth-first), the primitives on them
  for (int p = 0; p < n; p++) {
    start64[p] = nall;
    int qn = 0;
    int own[2] = {-1, -1};
    if (p < ncap)
      own[0] = cap_node[2 * p], own[1] = cap_node[2 * p + 1];
    else if (sph_node)
      own[0] = sph_node[p - ncap];
    for (int k = 0; k < 2; k++)
      if (own[k] >= 0 && mark[own[k]] != p)
        mark[own[k]] = p, depth[own[k]] = 0, queue[qn++] = own[k];
    int nrow = 0;
    for (int qh = 0; qh < qn; qh++) {
      int v = queue[qh];
      for (int e = pstart[v]; e < pstart[v + 1]; e++) {
        int q = prim[e];
        if (q != p && pmark[q] != p) pmark[q] = p, row[nrow++] = q;
      }
      if (depth[v] == hops) continue;
      for (int e = nstart[v]; e < nstart[v + 1]; e++) {
        int w = nbr[e];
        if (mark[w] != p) mark[w] = p, depth[w] = depth[v] + 1, queue[qn++] = w;
      }
    }
    // ascending row appended to the whole list
    qsort(row, (size_t)nrow, sizeof *row, cmp_int);
    if (nrow && !vd_grow((void**)&all, &cap_all, nall + nrow, sizeof(int))) {
      st = vd_error_set(err, VD_ERR_NOMEM, "", 0, 0, "out of memory building the exclusion");
      goto done;
    }
    if (nrow) memcpy(all + nall, row, (size_t)nrow * I);
    nall += nrow;
  }
  start64[n] = nall;
  // the result in one allocation
  {
    size_t head = (sizeof(int) * ((size_t)n + 1) + 15) & ~(size_t)15;
    out->nbytes = head + (size_t)nall * I + I;
    char* block = vd_malloc(out->nbytes);
    if (!block) {
      st = vd_error_set(err, VD_ERR_NOMEM, "", 0, 0, "out of memory building the exclusion");
      out->nbytes = 0;
      goto done;
    }
    out->start = (int*)block;
    out->exclude = (int*)(block + head);
    for (int i = 0; i <= n; i++)
      out->start[i] = (int)start64[i];
    if (nall) memcpy(out->exclude, all, (size_t)nall * I);
    out->nprim = n;
    out->nexclude = nall;
  }
done:
  vd_free(pstart, ((size_t)nnode + 1) * I);
  vd_free(prim, ((size_t)2 * ncap + (size_t)nsph + 1) * I);
  vd_free(nstart, ((size_t)nnode + 1) * I);
  vd_free(nbr, ((size_t)2 * ncap + 1) * I);
  vd_free(mark, ((size_t)nnode + 1) * I);
  vd_free(depth, ((size_t)nnode + 1) * I);
  vd_free(queue, ((size_t)nnode + 1) * I);
  vd_free(pmark, ((size_t)n + 1) * I);
  vd_free(row, ((size_t)n + 1) * I);
  vd_free(all, (size_t)cap_all * I);
  vd_free(start64, ((size_t)n + 1) * sizeof(int64_t));
  return st;
}

vd_status vd_collide_exclusion_add_touching(vd_collide_exclusion* ex, const vd_collide_prims* rest,
                                            double margin, vd_error* err) {
  if (!ex || !rest || !ex->start)
    return vd_error_set(err, VD_ERR_ARG, "", 0, 0, "exclusion: null argument");
  int n = ex->nprim;
  if (rest->ncapsule + rest->nsphere != n)
    return vd_error_set(err, VD_ERR_ARG, "", 0, 0, "exclusion: %d rows for %d primitives", n,
                        rest->ncapsule + rest->nsphere);
  // the pairs touching in the rest state, the existing exclusion applied
  vd_collide_prims P = *rest;
  vd_collide_prims_set_exclusion(&P, ex);
  vd_collide_def def = vd_collide_def_default();
  def.margin = margin;
  vd_arena arena;
  vd_arena_init(&arena, 0);
  vd_contact_list L;
  vd_status st = vd_collide_self(&P, &def, &arena, &L, err);
  if (st || L.n == 0) {
    vd_arena_free(&arena);
    return st;
  }
  // the merged rows: old entries plus both directions of every new pair, ascending
  size_t I = sizeof(int);
  int* cnt = vd_calloc((size_t)n + 1, I);
  size_t nall = (size_t)ex->nexclude + 2 * (size_t)L.n;
  size_t head = (I * ((size_t)n + 1) + 15) & ~(size_t)15;
  size_t nbytes = head + nall * I + I;
  char* block = vd_malloc(nbytes);
  if (!cnt || !block) {
    vd_free(cnt, ((size_t)n + 1) * I);
    vd_free(block, nbytes);
    vd_arena_free(&arena);
    return vd_error_set(err, VD_ERR_NOMEM, "", 0, 0, "out of memory extending the exclusion");
  }
  int* start = (int*)block;
  int* exc = (int*)(block + head);
  for (int i = 0; i < n; i++)
    cnt[i] = ex->start[i + 1] - ex->start[i];
  for (int k = 0; k < L.n; k++)
    cnt[L.c[k].a]++, cnt[L.c[k].b]++;
  start[0] = 0;
  for (int i = 0; i < n; i++)
    start[i + 1] = start[i] + cnt[i];
  for (int i = 0; i < n; i++) {
    int o = start[i];
    for (int e = ex->start[i]; e < ex->start[i + 1]; e++)
      exc[o++] = ex->exclude[e];
    cnt[i] = o; // next free slot of row i
  }
  for (int k = 0; k < L.n; k++) {
    exc[cnt[L.c[k].a]++] = L.c[k].b;
    exc[cnt[L.c[k].b]++] = L.c[k].a;
  }
  for (int i = 0; i < n; i++)
    qsort(exc + start[i], (size_t)(start[i + 1] - start[i]), I, cmp_int);
  vd_free(cnt, ((size_t)n + 1) * I);
  vd_arena_free(&arena);
  vd_free(ex->start, ex->nbytes);
  ex->start = start, ex->exclude = exc;
  ex->nexclude = (int)nall;
  ex->nbytes = nbytes;
  return VD_OK;
}

void vd_collide_exclusion_free(vd_collide_exclusion* ex) {
  if (!ex) return;
  if (ex->start) vd_free(ex->start, ex->nbytes);
  memset(ex, 0, sizeof *ex);
}

void vd_collide_prims_set_exclusion(vd_collide_prims* prims, const vd_collide_exclusion* ex) {
  prims->exclude_start = ex ? ex->start : NULL;
  prims->exclude = ex ? ex->exclude : NULL;
  prims->exclude_rows = ex ? ex->nprim : 0;
}
