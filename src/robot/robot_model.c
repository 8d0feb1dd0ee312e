// SPDX-License-Identifier: MIT
// The robot description (vd_robot): the MJCF loaded once under the MuJoCo error trap, the
// end-effector site, the finger actuators and the arm joints found, every collidable robot geom's
// shape (cylinders, ellipsoids and meshes through signed distance grids). An episode copies the
// description's model (no parsing), places its root body at the scene's base pose, limits the
// fingers to the grip force, makes its colliders of the plant from the shapes and lists the
// plant's fruits.
#include <stdio.h>
#include <string.h>

#include "robot_internal.h"

// ---------------------------------------------------------------------------------------------
// rotations

vd_quat quat_from_mat(const double* r) {
  mjtNum q[4];
  mju_mat2Quat(q, r);
  vd_quat o = {q[0], q[1], q[2], q[3]};
  return vd_quat_normalize(o);
}

vd_vec3 quat_log_v(vd_quat q) {
  if (q.w < 0) q.w = -q.w, q.x = -q.x, q.y = -q.y, q.z = -q.z;
  double s = sqrt(q.x * q.x + q.y * q.y + q.z * q.z);
  if (s < 1e-12) return vd_v3(2 * q.x, 2 * q.y, 2 * q.z);
  double a = 2 * atan2(s, q.w) / s;
  return vd_v3(a * q.x, a * q.y, a * q.z);
}

vd_quat quat_exp_v(vd_vec3 v) {
  double a = vd_norm(v);
  if (a < 1e-15) return vd_quat_identity();
  return vd_quat_axis_angle(vd_scale(v, 1.0 / a), a);
}

vd_pose robot_geom_pose(const mjModel* m, const mjData* d, int g) {
  vd_pose p;
  p.pos = vd_v3(d->geom_xpos[3 * g], d->geom_xpos[3 * g + 1], d->geom_xpos[3 * g + 2]);
  p.rot = quat_from_mat(d->geom_xmat + 9 * g);
  (void)m;
  return p;
}

void robot_site_pose(const vd_harvest* h, const mjData* d, vd_vec3* pos, vd_quat* rot) {
  int s = h->rb->ee_site;
  *pos = vd_v3(d->site_xpos[3 * s], d->site_xpos[3 * s + 1], d->site_xpos[3 * s + 2]);
  if (rot) *rot = quat_from_mat(d->site_xmat + 9 * s);
}

void robot_get_q(const vd_harvest* h, const mjData* d, double* q) {
  for (int k = 0; k < h->rb->narm; k++) q[k] = d->qpos[h->rb->arm_qpos[k]];
}

// ---------------------------------------------------------------------------------------------
// loading

// the position servo of joint j, -1 when none
static int servo_of(const mjModel* m, int j) {
  for (int a = 0; a < m->nu; a++)
    if (m->actuator_trntype[a] == mjTRN_JOINT && m->actuator_trnid[2 * a] == j) return a;
  return -1;
}

// is body b inside the subtree of body top?
static int below(const mjModel* m, int b, int top) {
  for (; b > 0; b = m->body_parentid[b])
    if (b == top) return 1;
  return top == 0;
}

// name of object k of type t for messages
static const char* name_of(const mjModel* m, int t, int k) {
  const char* n = mj_id2name(m, t, k);
  return n ? n : "(unnamed)";
}

// what the loaded model must have; errors name the MJCF and what is missing
static vd_status describe(vd_robot* h, const vd_scene* s, vd_error* err) {
  const mjModel* m = h->m;
  const char* file = s->robot_path;
  h->ee_site = mj_name2id(m, mjOBJ_SITE, s->ee_site);
  if (h->ee_site < 0)
    return vd_error_set(err, VD_ERR_VALUE, file, 0, 0,
                        "robot: no site '%s' (the end-effector site, scene robot.ee_site)", s->ee_site);
  int b = m->site_bodyid[h->ee_site];
  if (b == 0)
    return vd_error_set(err, VD_ERR_VALUE, file, 0, 0, "robot: site '%s' is on the world body",
                        s->ee_site);
  h->root_body = m->body_rootid[b];
  // fingers: two position servos of slide or hinge joints
  for (int k = 0; k < 2; k++) {
    int a = mj_name2id(m, mjOBJ_ACTUATOR, s->gripper[k]);
    if (a < 0)
      return vd_error_set(err, VD_ERR_VALUE, file, 0, 0,
                          "robot: no actuator '%s' (a finger, scene robot.gripper)", s->gripper[k]);
    int j = m->actuator_trntype[a] == mjTRN_JOINT ? m->actuator_trnid[2 * a] : -1;
    if (j < 0 || (m->jnt_type[j] != mjJNT_SLIDE && m->jnt_type[j] != mjJNT_HINGE))
      return vd_error_set(err, VD_ERR_VALUE, file, 0, 0,
                          "robot: actuator '%s' does not drive a slide or hinge joint", s->gripper[k]);
    h->grip_act[k] = a;
    h->grip_qpos[k] = m->jnt_qposadr[j];
    h->grip_dof[k] = m->jnt_dofadr[j];
    h->finger_body[k] = m->jnt_bodyid[j];
  }
  // arm: the joints on the path from the site's body to the root, each with a servo
  int jn[VD_ROBOT_MAX_JOINTS], n = 0;
  for (int bb = b; bb > 0; bb = m->body_parentid[bb]) {
    for (int j = m->body_jntadr[bb]; j >= 0 && j < m->body_jntadr[bb] + m->body_jntnum[bb]; j++) {
      if (m->jnt_type[j] == mjJNT_FREE || m->jnt_type[j] == mjJNT_BALL)
        return vd_error_set(err, VD_ERR_VALUE, file, 0, 0,
                            "robot: joint '%s' is free or ball: arm joints are hinges or slides",
                            name_of(m, mjOBJ_JOINT, j));
      if (n == VD_ROBOT_MAX_JOINTS)
        return vd_error_set(err, VD_ERR_LIMIT, file, 0, 0, "robot: more than %d arm joints",
                            VD_ROBOT_MAX_JOINTS);
      jn[n++] = j;
    }
  }
  if (!n)
    return vd_error_set(err, VD_ERR_VALUE, file, 0, 0, "robot: no joint moves site '%s'", s->ee_site);
  // MJCF order
  for (int i = 1; i < n; i++)
    for (int k = i; k > 0 && jn[k - 1] > jn[k]; k--) {
      int t = jn[k];
      jn[k] = jn[k - 1], jn[k - 1] = t;
    }
  h->narm = n;
  for (int k = 0; k < n; k++) {
    int j = jn[k], a = servo_of(m, j);
    if (a < 0)
      return vd_error_set(err, VD_ERR_VALUE, file, 0, 0, "robot: joint '%s' has no actuator",
                          name_of(m, mjOBJ_JOINT, j));
    h->arm_jnt[k] = j;
    h->arm_qpos[k] = m->jnt_qposadr[j];
    h->arm_dof[k] = m->jnt_dofadr[j];
    h->arm_act[k] = a;
    h->arm_lo[k] = m->jnt_limited[j] ? m->jnt_range[2 * j] : -1e10;
    h->arm_hi[k] = m->jnt_limited[j] ? m->jnt_range[2 * j + 1] : 1e10;
    h->qd_max[k] = m->jnt_type[j] == mjJNT_SLIDE ? 0.25 : 1.0;
  }
  return VD_OK;
}

// what the episode's scene asks of the robot: q0 within the joints' ranges, time steps that
// divide each other
static vd_status episode_checks(vd_harvest* h, vd_error* err) {
  const vd_robot* r = h->rb;
  const mjModel* m = h->m;
  const vd_scene* s = &h->scene;
  int n = r->narm;
  if (s->nq0 && s->nq0 != n)
    return vd_error_set(err, VD_ERR_VALUE, s->path, 0, 0,
                        "robot.q0: the robot has %d arm joints, q0 gives %d", n, s->nq0);
  for (int k = 0; k < n; k++) {
    h->q0[k] = s->nq0 ? s->q0[k] : m->qpos0[r->arm_qpos[k]];
    if (h->q0[k] < r->arm_lo[k] - 1e-9 || h->q0[k] > r->arm_hi[k] + 1e-9)
      return vd_error_set(err, VD_ERR_VALUE, s->path, 0, 0,
                          "robot.q0[%d]: %g is outside joint '%s' range %g..%g", k, h->q0[k],
                          name_of(m, mjOBJ_JOINT, r->arm_jnt[k]), r->arm_lo[k], r->arm_hi[k]);
  }
  // time steps: control step = nrobot robot steps, robot step = nsub plant steps
  double ts = m->opt.timestep, dt = s->sim_opt.dt;
  double ns = ts / dt, nr = s->control_dt / ts;
  if (!(ts > 0) || fabs(ns - floor(ns + 0.5)) > 1e-6 * ns || floor(ns + 0.5) < 1)
    return vd_error_set(err, VD_ERR_VALUE, s->path, 0, 0,
                        "sim.dt: %g s must divide the MJCF's timestep %g s", dt, ts);
  if (fabs(nr - floor(nr + 0.5)) > 1e-6 * nr || floor(nr + 0.5) < 1)
    return vd_error_set(err, VD_ERR_VALUE, s->path, 0, 0,
                        "control_dt: %g s must be a multiple of the MJCF's timestep %g s",
                        s->control_dt, ts);
  h->nsub = (int)floor(ns + 0.5);
  h->nrobot = (int)floor(nr + 0.5);
  return VD_OK;
}

static vd_status robot_shapes(vd_robot* r, vd_error* err);

vd_status vd_robot_load(const vd_scene* scene, vd_robot** out, vd_error* err) {
  *out = NULL;
  vd_mj_trap_install();
  vd_robot* r = vd_calloc(1, sizeof *r);
  if (!r) return vd_error_set(err, VD_ERR_NOMEM, "", 0, 0, "out of memory");
  snprintf(r->path, sizeof r->path, "%s", scene->robot_path);
  snprintf(r->ee_site_name, sizeof r->ee_site_name, "%s", scene->ee_site);
  for (int k = 0; k < 2; k++)
    snprintf(r->gripper_name[k], sizeof r->gripper_name[k], "%s", scene->gripper[k]);
  vd_status st = vd_mj_load_xml(scene->robot_path, "robot MJCF", &r->m, err);
  if (!st) st = describe(r, scene, err);
  if (!st) st = robot_shapes(r, err);
  if (st) {
    vd_robot_destroy(r);
    return st;
  }
  *out = r;
  return VD_OK;
}

void vd_robot_destroy(vd_robot* r) {
  if (!r) return;
  for (int k = 0; k < r->ngeom; k++) vd_sdf_destroy(r->geom[k].sdf);
  if (r->m) mj_deleteModel(r->m);
  vd_free(r, sizeof *r);
}

int robot_matches(const vd_robot* r, const vd_scene* s) {
  return !strcmp(r->path, s->robot_path) && !strcmp(r->ee_site_name, s->ee_site) &&
         !strcmp(r->gripper_name[0], s->gripper[0]) && !strcmp(r->gripper_name[1], s->gripper[1]);
}

vd_status robot_attach(vd_harvest* h, vd_error* err) {
  const vd_robot* rb = h->rb;
  vd_mj_trap trap;
  if (!VD_MJ_TRY(&trap)) return vd_mj_trap_status(&trap, err);
  mjModel* m = mj_copyModel(NULL, rb->m);
  vd_mj_trap_end(&trap);
  if (!m) return vd_error_set(err, VD_ERR_NOMEM, "", 0, 0, "out of memory (MuJoCo model)");
  h->m = m;
  vd_status st = episode_checks(h, err);
  if (st) return st;
  // the scene's base pose replaces the root body's; the grip force limits the fingers
  vd_quat q = vd_quat_axis_angle(vd_v3(0, 0, 1), h->scene.base_yaw);
  int r = rb->root_body;
  m->body_pos[3 * r] = h->scene.base_pos.x;
  m->body_pos[3 * r + 1] = h->scene.base_pos.y;
  m->body_pos[3 * r + 2] = h->scene.base_pos.z;
  m->body_quat[4 * r] = q.w, m->body_quat[4 * r + 1] = q.x;
  m->body_quat[4 * r + 2] = q.y, m->body_quat[4 * r + 3] = q.z;
  for (int k = 0; k < 2; k++) {
    int a = rb->grip_act[k];
    m->actuator_forcelimited[a] = 1;
    m->actuator_forcerange[2 * a] = -h->scene.method.grip_force;
    m->actuator_forcerange[2 * a + 1] = h->scene.method.grip_force;
  }
  if (!VD_MJ_TRY(&trap)) return vd_mj_trap_status(&trap, err);
  h->d = mj_makeData(m);
  h->dk = mj_makeData(m);
  vd_mj_trap_end(&trap);
  if (!h->d || !h->dk) return vd_error_set(err, VD_ERR_NOMEM, "", 0, 0, "out of memory (MuJoCo data)");
  // can the arm turn the end-effector? (a gantry cannot: IK on position only)
  mjtNum* jr = vd_malloc(sizeof(mjtNum) * 3 * (size_t)m->nv);
  if (!jr) return vd_error_set(err, VD_ERR_NOMEM, "", 0, 0, "out of memory");
  if (!VD_MJ_TRY(&trap)) {
    vd_free(jr, sizeof(mjtNum) * 3 * (size_t)m->nv);
    return vd_mj_trap_status(&trap, err);
  }
  for (int k = 0; k < rb->narm; k++) h->dk->qpos[rb->arm_qpos[k]] = h->q0[k];
  mj_kinematics(m, h->dk);
  mj_comPos(m, h->dk);
  mj_jacSite(m, h->dk, NULL, jr, rb->ee_site);
  vd_mj_trap_end(&trap);
  double s2 = 0;
  for (int k = 0; k < rb->narm; k++)
    for (int i = 0; i < 3; i++) s2 += jr[i * m->nv + rb->arm_dof[k]] * jr[i * m->nv + rb->arm_dof[k]];
  h->orient = s2 > 1e-12;
  vd_free(jr, sizeof(mjtNum) * 3 * (size_t)m->nv);
  return VD_OK;
}

// ---------------------------------------------------------------------------------------------
// colliders

// closed triangle mesh of a MuJoCo geom (cylinder, ellipsoid, mesh) in its own frame
static vd_status geom_mesh(const mjModel* m, int g, double** vert, int* nv, int** tri, int* nt,
                           vd_error* err) {
  const mjtNum* sz = m->geom_size + 3 * g;
  int type = m->geom_type[g];
  *vert = NULL, *tri = NULL, *nv = *nt = 0;
  if (type == mjGEOM_MESH) {
    int id = m->geom_dataid[g];
    int v0 = m->mesh_vertadr[id], f0 = m->mesh_faceadr[id];
    *nv = m->mesh_vertnum[id], *nt = m->mesh_facenum[id];
    *vert = vd_malloc(sizeof(double) * 3 * (size_t)*nv);
    *tri = vd_malloc(sizeof(int) * 3 * (size_t)*nt);
    if (!*vert || !*tri) return vd_error_set(err, VD_ERR_NOMEM, "", 0, 0, "out of memory");
    for (int i = 0; i < 3 * *nv; i++) (*vert)[i] = m->mesh_vert[3 * v0 + i];
    for (int i = 0; i < 3 * *nt; i++) (*tri)[i] = m->mesh_face[3 * f0 + i];
    return VD_OK;
  }
  // cylinder (radius sz0, half height sz1 on z) or ellipsoid (semi-axes sz0..2): a UV grid
  const int nu = 32, nr = type == mjGEOM_CYLINDER ? 2 : 16;
  *nv = nu * (nr + 1) + 2;
  *nt = 2 * nu * nr + 2 * nu;
  *vert = vd_malloc(sizeof(double) * 3 * (size_t)*nv);
  *tri = vd_malloc(sizeof(int) * 3 * (size_t)*nt);
  if (!*vert || !*tri) return vd_error_set(err, VD_ERR_NOMEM, "", 0, 0, "out of memory");
  double* v = *vert;
  int* t = *tri;
  int k = 0;
  for (int i = 0; i <= nr; i++) {
    for (int j = 0; j < nu; j++, k++) {
      double ph = 2 * M_PI * j / nu;
      double x, y, z;
      if (type == mjGEOM_CYLINDER) {
        x = sz[0] * cos(ph), y = sz[0] * sin(ph), z = -sz[1] + 2 * sz[1] * i / nr;
      } else {
        double th = M_PI * (i + 0.5) / (nr + 1) - 0.5 * M_PI;  // rings strictly between the poles
        x = sz[0] * cos(th) * cos(ph), y = sz[1] * cos(th) * sin(ph), z = sz[2] * sin(th);
      }
      v[3 * k] = x, v[3 * k + 1] = y, v[3 * k + 2] = z;
    }
  }
  int bottom = k, top = k + 1;
  double hz = type == mjGEOM_CYLINDER ? sz[1] : sz[2];
  v[3 * bottom] = v[3 * bottom + 1] = 0, v[3 * bottom + 2] = -hz;
  v[3 * top] = v[3 * top + 1] = 0, v[3 * top + 2] = hz;
  int n = 0;
  for (int i = 0; i < nr; i++)
    for (int j = 0; j < nu; j++) {
      int a = i * nu + j, b = i * nu + (j + 1) % nu, c = a + nu, e = b + nu;
      t[3 * n] = a, t[3 * n + 1] = b, t[3 * n + 2] = e, n++;
      t[3 * n] = a, t[3 * n + 1] = e, t[3 * n + 2] = c, n++;
    }
  for (int j = 0; j < nu; j++) {
    int a = j, b = (j + 1) % nu;
    t[3 * n] = bottom, t[3 * n + 1] = b, t[3 * n + 2] = a, n++;
    a += nr * nu, b += nr * nu;
    t[3 * n] = top, t[3 * n + 1] = a, t[3 * n + 2] = b, n++;
  }
  return VD_OK;
}

// the collision shapes of the robot's collidable geoms, in their own frames
static vd_status robot_shapes(vd_robot* r, vd_error* err) {
  const mjModel* m = r->m;
  const char* file = r->path;
  r->ngeom = 0;
  for (int g = 0; g < m->ngeom; g++) {
    int b = m->geom_bodyid[g], type = m->geom_type[g];
    if (b == 0 || m->body_rootid[b] != r->root_body) continue;
    if (!m->geom_contype[g] && !m->geom_conaffinity[g]) continue;
    if (type == mjGEOM_PLANE || type == mjGEOM_HFIELD) continue;
    if (r->ngeom == ROBOT_MAX_COLLIDERS)
      return vd_error_set(err, VD_ERR_LIMIT, file, 0, 0,
                          "robot: more than %d collidable geoms (set contype and conaffinity of "
                          "visual geoms to 0)",
                          ROBOT_MAX_COLLIDERS);
    robot_geom* c = &r->geom[r->ngeom];
    memset(c, 0, sizeof *c);
    c->geom = g, c->body = b, c->finger = -1;
    for (int k = 0; k < 2; k++)
      if (below(m, b, r->finger_body[k])) c->finger = k;
    const mjtNum* sz = m->geom_size + 3 * g;
    vd_sim_collider* sc = &c->sc;
    sc->quat = vd_quat_identity();
    c->shape.pose = vd_pose_identity();
    c->shape.id = g;
    if (type == mjGEOM_SPHERE) {
      sc->shape = VD_SIM_SPHERE, sc->size[0] = sz[0];
      c->shape.shape = VD_SHAPE_SPHERE, c->shape.radius = sz[0];
    } else if (type == mjGEOM_CAPSULE) {
      sc->shape = VD_SIM_CAPSULE, sc->size[0] = sz[0], sc->size[1] = sz[1];
      c->shape.shape = VD_SHAPE_CAPSULE, c->shape.radius = sz[0], c->shape.half_length = sz[1];
    } else if (type == mjGEOM_BOX) {
      sc->shape = VD_SIM_BOX, sc->size[0] = sz[0], sc->size[1] = sz[1], sc->size[2] = sz[2];
      c->shape.shape = VD_SHAPE_BOX, c->shape.half_size = vd_v3(sz[0], sz[1], sz[2]);
    } else {
      // cylinder, ellipsoid, mesh: a signed distance grid of the closed surface
      double* v;
      int* t;
      int nv, nt;
      vd_status st = geom_mesh(m, g, &v, &nv, &t, &nt, err);
      vd_sdf_def def = vd_sdf_def_default();
      double ext = fmax(fmax(sz[0], sz[1]), sz[2]);
      if (type != mjGEOM_MESH && ext > 0) def.cell = fmin(def.cell, ext / 8);
      if (!st) st = vd_sdf_build(v, nv, t, nt, &def, &c->sdf, err);
      vd_free(v, sizeof(double) * 3 * (size_t)nv);
      vd_free(t, sizeof(int) * 3 * (size_t)nt);
      if (st) {
        char why[512];
        snprintf(why, sizeof why, "%s", err ? err->msg : "no distance grid");
        return vd_error_set(err, st, file, 0, 0, "robot geom '%s': %s", name_of(m, mjOBJ_GEOM, g), why);
      }
      sc->shape = VD_SIM_MESH, sc->sdf = c->sdf;
      c->shape.shape = VD_SHAPE_SDF, c->shape.sdf = c->sdf;
    }
    r->ngeom++;
  }
  return VD_OK;
}

vd_status robot_colliders(vd_harvest* h, vd_error* err) {
  const vd_robot* rb = h->rb;
  h->ncol = 0;
  for (int k = 0; k < rb->ngeom; k++) {
    const robot_geom* g = &rb->geom[k];
    robot_collider* c = &h->col[h->ncol];
    memset(c, 0, sizeof *c);
    c->geom = g->geom, c->body = g->body, c->finger = g->finger;
    c->shape = g->shape;
    c->cur = c->prev = c->shape.pose = robot_geom_pose(h->m, h->d, g->geom);
    vd_sim_collider sc = g->sc;
    sc.pos = c->cur.pos, sc.quat = c->cur.rot;
    c->sim = vd_sim_add_collider(h->sd, &sc);
    if (c->sim < 0)
      return vd_error_set(err, VD_ERR_LIMIT, rb->path, 0, 0, "robot: too many colliders for the plant");
    h->ncol++;
  }
  // the fruits
  const vd_sim_model* sm = h->sm;
  int n = 0;
  for (int t = 0; t < sm->nseg; t++)
    if ((sm->seg_flags[t] & VD_SIM_FRUITSEG) && sm->seg_class[t] == VD_SIM_FRUIT) n++;
  h->fruit = n ? vd_calloc((size_t)n, sizeof *h->fruit) : NULL;
  if (n && !h->fruit) return vd_error_set(err, VD_ERR_NOMEM, "", 0, 0, "out of memory");
  h->nfruit = 0;
  for (int t = 0; t < sm->nseg; t++) {
    if (!((sm->seg_flags[t] & VD_SIM_FRUITSEG) && sm->seg_class[t] == VD_SIM_FRUIT)) continue;
    robot_fruit* f = &h->fruit[h->nfruit++];
    f->seg = t;
    f->node = sm->seg_node[2 * t + 1];
    f->instance = sm->seg_instance[t];
    f->radius = sm->node_sphere[f->node];
  }
  return VD_OK;
}

void robot_free(vd_harvest* h) {
  h->ncol = 0;
  if (h->d) mj_deleteData(h->d);
  if (h->dk) mj_deleteData(h->dk);
  if (h->m) mj_deleteModel(h->m);
  h->d = h->dk = NULL;
  h->m = NULL;
  vd_free(h->fruit, (size_t)h->nfruit * sizeof *h->fruit);
  h->fruit = NULL;
  h->nfruit = 0;
}
