// SPDX-License-Identifier: MIT
// export: the plant for robot simulators. The MJCF loads in MuJoCo (through the render module,
// no OpenGL context needed) alone and in a scene with an arm, with one body per organ and the
// geoms of its primitives, touching the arm where they overlap; leaf meshes are closed slabs of
// the asked thickness; URDF and SDF name every organ; bad settings are refused and a failed
// export leaves no file.
#include <stdlib.h>
#include <sys/stat.h>
#include <unistd.h>

#include "render_helpers.h"
#include "test.h"

// the text of a file (free with free), NULL when unreadable
static char* slurp(const char* path) {
  FILE* f = fopen(path, "rb");
  if (!f) return NULL;
  fseek(f, 0, SEEK_END);
  long n = ftell(f);
  fseek(f, 0, SEEK_SET);
  char* s = malloc((size_t)n + 1);
  if (s && fread(s, 1, (size_t)n, f) != (size_t)n) n = 0;
  if (s) s[n] = 0;
  fclose(f);
  return s;
}

// occurrences of needle in s
static int count(const char* s, const char* needle) {
  int n = 0;
  for (const char* p = s; (p = strstr(p, needle)); p += strlen(needle))
    n++;
  return n;
}

// organs (distinct label, instance) of a model and its primitives with a length
static void organs(const vd_model* m, int* norg, int* nprim) {
  int n = m->nseg + m->nsphere + m->nmesh, k = 0;
  long* key = malloc(sizeof(long) * (size_t)(n + 1));
  for (int i = 0; i < m->nseg; i++)
    key[k++] = (long)m->seg_label[i] << 32 | m->seg_instance[i];
  for (int i = 0; i < m->nsphere; i++)
    key[k++] = (long)m->sphere_label[i] << 32 | m->sphere_instance[i];
  for (int i = 0; i < m->nmesh; i++)
    key[k++] = (long)m->mesh_label[i] << 32 | m->mesh_instance[i];
  *norg = 0;
  for (int i = 0; i < k; i++) {
    int seen = 0;
    for (int j = 0; j < i && !seen; j++)
      seen = key[j] == key[i];
    *norg += !seen;
  }
  free(key);
  *nprim = m->nsphere + m->nmesh;
  for (int i = 0; i < m->nseg; i++) {
    const double* a = m->node_pos0 + 3 * m->seg_node[2 * i];
    const double* b = m->node_pos0 + 3 * m->seg_node[2 * i + 1];
    *nprim += (a[0] - b[0]) * (a[0] - b[0]) + (a[1] - b[1]) * (a[1] - b[1]) +
                  (a[2] - b[2]) * (a[2] - b[2]) >
              1e-18;
  }
}

TEST(export, mjcf_loads_with_an_arm) {
  vd_model* m = vdt_tomato(3);
  REQUIRE(m);
  int norg, nprim;
  organs(m, &norg, &nprim);
  char path[512];
  snprintf(path, sizeof path, "%s/plant.xml", vdt_tmpdir());
  vd_export_def def = vd_export_def_default();
  vd_error err = {0};
  CHECK_STATUS(vd_geom_export(m, NULL, &def, path, &err), VD_OK, err);
  // alone: the world, the plant's root body, one body per organ; a geom per primitive, a mesh
  // per spec mesh; no joints
  vd_mjcf_info mi;
  const char* alone[1] = {path};
  CHECK_STATUS(vd_render_mjcf_info(alone, 1, "plant/", &mi, &err), VD_OK, err);
  CHECK_INT(mi.nbody, 2 + norg);
  CHECK_INT(mi.nbody_prefix, norg);
  CHECK_INT(mi.ngeom, nprim);
  CHECK_INT(mi.ngeom_prefix, nprim);
  CHECK_INT(mi.nmesh, m->nmesh);
  CHECK_INT(mi.njoint, 0);
  CHECK_INT(mi.ncontact_prefix, 0);
  // beside the arm (its reference pose reaches into the plant), in a scene that includes both;
  // and the robot engineer's Lite 6 when it is there
  const char* robots[2] = {"data/robots/arm6.xml", "data/robots/lite6.xml"};
  for (int k = 0; k < 2; k++) {
    const char* robot = vdt_path(robots[k]);
    if (access(robot, R_OK) != 0) continue;
    const char* parts[2] = {robot, path};
    vd_mjcf_info both;
    CHECK_STATUS(vd_render_mjcf_info(parts, 2, "plant/", &both, &err), VD_OK, err);
    CHECK_INT(both.nbody_prefix, norg);
    CHECK_INT(both.ngeom_prefix, nprim);
    CHECK(both.njoint > 0);
    CHECK(both.ngeom > nprim);
    if (k == 0) CHECK(both.ncontact_prefix > 0);
  }
  // moved away from the arm (plant at 3 m): no contact with it
  def.pos = vd_v3(3, 0, 0);
  CHECK_STATUS(vd_geom_export(m, NULL, &def, path, &err), VD_OK, err);
  const char* arm[2] = {vdt_path("data/robots/arm6.xml"), path};
  CHECK_STATUS(vd_render_mjcf_info(arm, 2, "plant/", &mi, &err), VD_OK, err);
  CHECK_INT(mi.ncontact_prefix, 0);
  // the capsule of the first segment runs between its nodes with its mean radius
  char* text = slurp(path);
  REQUIRE(text);
  char want[256];
  const double* a = m->node_pos0 + 3 * m->seg_node[0];
  const double* b = m->node_pos0 + 3 * m->seg_node[1];
  snprintf(want, sizeof want, "size=\"%.9g\" fromto=\"%.9g %.9g %.9g %.9g %.9g %.9g\"",
           0.5 * (m->seg_radius[0] + m->seg_radius[1]), a[0], a[1], a[2], b[0], b[1], b[2]);
  CHECK(strstr(text, want) != NULL);
  CHECK(strstr(text, "<body name=\"plant\" pos=\"3 0 0\">") != NULL);
  free(text);
  // a broken file is MuJoCo's error with its file; a missing one an I/O error
  FILE* f = fopen(path, "w");
  REQUIRE(f);
  fputs("<mujoco><worldbody><geom type=\"sphere\"/></worldbody>", f);
  fclose(f);
  CHECK_STATUS(vd_render_mjcf_info(alone, 1, NULL, &mi, &err), VD_ERR_FORMAT, err);
  CHECK(strstr(err.file, "plant.xml") != NULL);
  const char* missing[2] = {"/nonexistent/x.xml", path};
  CHECK_STATUS(vd_render_mjcf_info(missing, 1, NULL, &mi, &err), VD_ERR_IO, err);
  CHECK_STATUS(vd_render_mjcf_info(missing, 2, NULL, &mi, &err), VD_ERR_IO, err);
  vd_model_destroy(m);
}

TEST(export, urdf_sdf_and_leaf_slabs) {
  vd_model* m = vdt_tomato(3);
  REQUIRE(m);
  int norg, nprim;
  organs(m, &norg, &nprim);
  char urdf[512], sdf[512], dir[512];
  snprintf(urdf, sizeof urdf, "%s/p.urdf", vdt_tmpdir());
  snprintf(sdf, sizeof sdf, "%s/p.sdf", vdt_tmpdir());
  snprintf(dir, sizeof dir, "%s/p_meshes", vdt_tmpdir());
  vd_export_def def = vd_export_def_default();
  vd_error err = {0};
  def.format = VD_EXPORT_URDF;
  CHECK_STATUS(vd_geom_export(m, NULL, &def, urdf, &err), VD_OK, err);
  def.format = VD_EXPORT_SDF;
  CHECK_STATUS(vd_geom_export(m, NULL, &def, sdf, &err), VD_OK, err);
  char* u = slurp(urdf);
  char* s = slurp(sdf);
  REQUIRE(u && s);
  // a link per organ (+ the base in URDF), a fixed joint per organ, a visual and a collision
  // per primitive
  CHECK_INT(count(u, "<link name="), norg + 1);
  CHECK_INT(count(u, "type=\"fixed\""), norg);
  CHECK_INT(count(u, "<visual "), nprim);
  CHECK_INT(count(u, "<collision "), nprim);
  CHECK_INT(count(s, "<link name="), norg);
  CHECK_INT(count(s, "<collision "), nprim);
  CHECK(strstr(s, "<static>true</static>") != NULL);
  CHECK(strstr(u, "<link name=\"fruit_") != NULL && strstr(u, "<link name=\"leaf_") != NULL);
  free(u);
  free(s);
  // the leaf meshes: closed slabs (every edge in two triangles, pointing both ways) whose volume
  // is their area times the thickness
  int checked = 0;
  for (int i = 0; i < m->nmesh && checked < 5; i++) {
    if (m->mesh_closed[i] || m->mesh_label[i] != 2) continue;
    // its file: the organ's name and its index among the organ's meshes (0 for a leaf)
    char file[700];
    const vd_label* l = vd_model_find_label(m, m->mesh_label[i]);
    snprintf(file, sizeof file, "%s/%s_%d_m0.obj", dir, l->name, m->mesh_instance[i]);
    vd_mesh slab;
    CHECK_STATUS(vd_geom_read_mesh(file, &slab, NULL, NULL, &err), VD_OK, err);
    if (!slab.ntri) continue;
    double area = 0, vol = 0;
    int t0 = m->mesh_tri[2 * i], nt = m->mesh_tri[2 * i + 1];
    for (int t = t0; t < t0 + nt; t++) {
      vd_vec3 p[3];
      for (int c = 0; c < 3; c++) {
        const double* x = m->vert_pos0 + 3 * m->tri_vert[3 * t + c];
        p[c] = vd_v3(x[0], x[1], x[2]);
      }
      area += 0.5 * vd_norm(vd_cross(vd_sub(p[1], p[0]), vd_sub(p[2], p[0])));
    }
    int open_edges = 0;
    for (int t = 0; t < slab.ntri; t++) {
      const double* a = slab.pos + 3 * slab.tri[3 * t];
      const double* b = slab.pos + 3 * slab.tri[3 * t + 1];
      const double* c = slab.pos + 3 * slab.tri[3 * t + 2];
      vol += (a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0]) +
              a[2] * (b[0] * c[1] - b[1] * c[0])) / 6;
      // each directed edge's reverse is in another triangle
      for (int e = 0; e < 3; e++) {
        int x = slab.tri[3 * t + e], y = slab.tri[3 * t + (e + 1) % 3], found = 0;
        for (int q = 0; q < slab.ntri && !found; q++)
          for (int g = 0; g < 3 && !found; g++)
            found = slab.tri[3 * q + g] == y && slab.tri[3 * q + (g + 1) % 3] == x;
        open_edges += !found;
      }
    }
    CHECK_INT(open_edges, 0);
    CHECK(vol > 0);
    // the faces lie half the thickness out along the vertex normals: a folded leaf is thinner
    CHECK(vol / (area * def.leaf_thickness) > 0.5 && vol / (area * def.leaf_thickness) < 1.05);
    vd_mesh_free(&slab);
    checked++;
  }
  CHECK(checked >= 3);
  vd_model_destroy(m);
}

TEST(export, bad_settings_leave_nothing) {
  vd_model* m = vdt_tomato(1);
  REQUIRE(m);
  vd_export_def def = vd_export_def_default();
  vd_error err = {0};
  char path[512];
  snprintf(path, sizeof path, "%s/bad.xml", vdt_tmpdir());
  def.name = "my plant";
  CHECK_STATUS(vd_geom_export(m, NULL, &def, path, &err), VD_ERR_ARG, err);
  def = vd_export_def_default(), def.leaf_thickness = 0;
  CHECK_STATUS(vd_geom_export(m, NULL, &def, path, &err), VD_ERR_ARG, err);
  def = vd_export_def_default(), def.pos.x = NAN;
  CHECK_STATUS(vd_geom_export(m, NULL, &def, path, &err), VD_ERR_ARG, err);
  CHECK(access(path, F_OK) != 0);
  // a URDF whose file cannot be written: the meshes written first are removed again
  char bad[512], dir[512];
  snprintf(bad, sizeof bad, "%s/x.urdf", vdt_tmpdir());
  snprintf(dir, sizeof dir, "%s/x_meshes", vdt_tmpdir());
  CHECK(mkdir(bad, 0700) == 0); // a folder where the file should go
  def = vd_export_def_default(), def.format = VD_EXPORT_URDF;
  CHECK(vd_geom_export(m, NULL, &def, bad, &err) != VD_OK);
  CHECK(access(dir, F_OK) != 0);
  rmdir(bad);
  vd_model_destroy(m);
}

// the flexible export: a body per rod segment that is not held, three hinge springs each, the
// rods' masses (the lumped masses of the free nodes) in total, break thresholds where the rods
// break; N links per organ gives fewer bodies with the same total
static double sum_attr(const char* s, const char* key) {
  double total = 0;
  size_t kl = strlen(key);
  for (const char* p = strstr(s, key); p; p = strstr(p + kl, key))
    total += strtod(p + kl, NULL);
  return total;
}

TEST(export, flexible_mjcf_from_the_rods) {
  vd_model* m = vdt_tomato(3);
  REQUIRE(m);
  vd_sim_def sd = vd_sim_def_default();
  vd_sim_model* sm = NULL;
  vd_error err = {0};
  CHECK_STATUS(vd_sim_build(m, &sd, &sm, &err), VD_OK, err);
  REQUIRE(sm);
  vd_export_rods rods;
  CHECK_STATUS(vd_sim_export_rods(sm, m, &rods, &err), VD_OK, err);
  int nfree = 0, nbreak = 0;
  double mfree = 0;
  for (int t = 0; t < sm->nseg; t++) {
    if (sm->seg_flags[t] & VD_SIM_FIXED) continue;
    nfree++;
    nbreak += sm->seg_spare[t] >= 0;
    int n1 = sm->seg_node[2 * t + 1];
    if (sm->node_owner[n1] == t) mfree += sm->node_mass[n1];
  }
  char path[512], coarse[512];
  snprintf(path, sizeof path, "%s/flex.xml", vdt_tmpdir());
  snprintf(coarse, sizeof coarse, "%s/flex2.xml", vdt_tmpdir());
  vd_export_def def = vd_export_def_default();
  def.rods = &rods;
  CHECK_STATUS(vd_geom_export(m, NULL, &def, path, &err), VD_OK, err);
  def.links_per_organ = 2;
  CHECK_STATUS(vd_geom_export(m, NULL, &def, coarse, &err), VD_OK, err);
  char* s = slurp(path);
  char* c = slurp(coarse);
  REQUIRE(s && c);
  CHECK_INT(count(s, "<inertial "), nfree);
  CHECK_INT(count(s, "type=\"hinge\""), 3 * nfree);
  CHECK_INT(count(s, "<numeric name=\"plant/break/"), nbreak);
  CHECK(nbreak > 0);
  CHECK_NEAR(sum_attr(s, " mass=\""), mfree, 1e-9 * mfree + 1e-12);
  CHECK_NEAR(sum_attr(c, " mass=\""), mfree, 1e-9 * mfree + 1e-12);
  CHECK(count(c, "<inertial ") < nfree / 2);
  // the plant's geoms say how they collide, so that a robot's defaults do not decide
  CHECK_INT(count(s, "contype=\"2\" conaffinity=\"1\""), count(s, "<geom "));
  // MuJoCo loads both with every joint
  vd_mjcf_info mi;
  const char* one[1] = {path};
  CHECK_STATUS(vd_render_mjcf_info(one, 1, "plant/", &mi, &err), VD_OK, err);
  CHECK_INT(mi.njoint, 3 * nfree);
  CHECK_INT(mi.ncontact, 0);
  one[0] = coarse;
  CHECK_STATUS(vd_render_mjcf_info(one, 1, "plant/", &mi, &err), VD_OK, err);
  CHECK_INT(mi.njoint, 3 * count(c, "<inertial "));
  // bad settings
  def.links_per_organ = -2;
  CHECK_STATUS(vd_geom_export(m, NULL, &def, path, &err), VD_ERR_ARG, err);
  def.links_per_organ = 0, def.damping_ratio = -1;
  CHECK_STATUS(vd_geom_export(m, NULL, &def, path, &err), VD_ERR_ARG, err);
  free(s);
  free(c);
  unlink(path);
  unlink(coarse);
  vd_sim_export_rods_free(&rods);
  vd_sim_model_destroy(sm);
  vd_model_destroy(m);
}
