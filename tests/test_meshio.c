// SPDX-License-Identifier: MIT
// meshio: reading meshes back (vd_geom_read_mesh): the OBJ and PLY files the writers make give
// the same triangles, labels, instances and label names; foreign OBJ forms (polygons, v/t/n,
// negative indices, groups and objects) read; bad files name the file and line; a PLY without
// faces is a point cloud, not a mesh.
#include <stdlib.h>

#include "render_helpers.h"
#include "test.h"

// write text to a file in the scratch folder; returns its path (static buffer of 8)
static const char* scratch(const char* name, const char* text, size_t len) {
  static char buf[8][512];
  static int k;
  char* p = buf[k++ & 7];
  snprintf(p, 512, "%s/%s", vdt_tmpdir(), name);
  FILE* f = fopen(p, "wb");
  if (f) {
    fwrite(text, 1, len, f);
    fclose(f);
  }
  return p;
}

// the label of each written triangle, as a multiset over (label, instance, rounded centroid)
static int same_triangles(const vd_mesh* a, const vd_mesh* b, double tol) {
  if (a->ntri != b->ntri) return 0;
  // both writers keep the triangles' order within each (label, instance) group; the OBJ sorts by
  // group: match by sorting both on (label, instance, index within the group)
  int* ia = malloc(sizeof(int) * (size_t)a->ntri);
  int* ib = malloc(sizeof(int) * (size_t)b->ntri);
  if (!ia || !ib) return free(ia), free(ib), 0;
  int n = 0;
  for (int pass = 0; pass < 2; pass++) {
    const vd_mesh* m = pass ? b : a;
    int* idx = pass ? ib : ia;
    n = 0;
    // a stable order: by (label, instance), then by index
    for (int t = 0; t < m->ntri; t++)
      idx[n++] = t;
    for (int i = 1; i < n; i++)
      for (int j = i; j > 0; j--) {
        int x = idx[j - 1], y = idx[j];
        int kx = m->tri_label[x] * 70000 + m->tri_instance[x];
        int ky = m->tri_label[y] * 70000 + m->tri_instance[y];
        if (kx <= ky) break;
        idx[j - 1] = y, idx[j] = x;
      }
  }
  int ok = 1;
  for (int i = 0; i < n && ok; i++) {
    int x = ia[i], y = ib[i];
    ok = a->tri_label[x] == b->tri_label[y] && a->tri_instance[x] == b->tri_instance[y];
    for (int c = 0; c < 3 && ok; c++)
      for (int k = 0; k < 3 && ok; k++) {
        double pa = a->pos[3 * a->tri[3 * x + c] + k], pb = b->pos[3 * b->tri[3 * y + c] + k];
        double na = a->normal[3 * a->tri[3 * x + c] + k], nb = b->normal[3 * b->tri[3 * y + c] + k];
        ok = fabs(pa - pb) <= tol && fabs(na - nb) <= 1e-5;
      }
  }
  free(ia);
  free(ib);
  return ok;
}

TEST(meshio, round_trip) {
  vd_model* m = vdt_tomato(3);
  REQUIRE(m);
  vd_mesh mesh;
  vd_error err = {0};
  CHECK_STATUS(vd_geom_tessellate(m, NULL, NULL, &mesh, &err), VD_OK, err);
  char obj[512], ply[512], asc[512];
  snprintf(obj, sizeof obj, "%s/t.obj", vdt_tmpdir());
  snprintf(ply, sizeof ply, "%s/t.ply", vdt_tmpdir());
  snprintf(asc, sizeof asc, "%s/ta.ply", vdt_tmpdir());
  CHECK_STATUS(vd_geom_write_obj(&mesh, m->labels, m->nlabel, obj, &err), VD_OK, err);
  CHECK_STATUS(vd_geom_write_ply(&mesh, m->labels, m->nlabel, ply, 1, &err), VD_OK, err);
  CHECK_STATUS(vd_geom_write_ply(&mesh, m->labels, m->nlabel, asc, 0, &err), VD_OK, err);
  const char* paths[3] = {obj, ply, asc};
  for (int k = 0; k < 3; k++) {
    CHECK(vd_geom_is_mesh_file(paths[k]));
    vd_mesh back;
    vd_label* lab = NULL;
    int nlab = 0;
    CHECK_STATUS(vd_geom_read_mesh(paths[k], &back, &lab, &nlab, &err), VD_OK, err);
    // float PLY positions, %.9g OBJ: the same triangles within float precision
    CHECK(same_triangles(&mesh, &back, 1e-6));
    CHECK_INT(nlab, m->nlabel);
    for (int i = 0; i < nlab && i < m->nlabel; i++) {
      CHECK_INT(lab[i].id, m->labels[i].id);
      CHECK_STR(lab[i].name, m->labels[i].name);
    }
    vd_mesh_free(&back);
    vd_free(lab, sizeof(vd_label) * (size_t)(nlab ? nlab : 1));
  }
  vd_mesh_free(&mesh);
  vd_model_destroy(m);
}

TEST(meshio, foreign_obj) {
  // a quad with texture and normal indices in group "top", then a triangle by negative indices
  // in object "second", group "side"; faces before any group have label 0
  const char* text = "# not verdant\nmtllib x.mtl\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvt 0 0\n"
                     "vn 0 0 1\nf 1 2 3\ng top\nusemtl top\nf 1/1/1 2/1/1 3/1/1 4/1/1\n"
                     "o second\ng side\nf -4 -3 -2\n";
  const char* p = scratch("foreign.obj", text, strlen(text));
  vd_mesh m;
  vd_label* lab = NULL;
  int nlab = 0;
  vd_error err = {0};
  CHECK_STATUS(vd_geom_read_mesh(p, &m, &lab, &nlab, &err), VD_OK, err);
  CHECK_INT(m.ntri, 4);
  CHECK_INT(nlab, 2);
  if (nlab == 2) {
    CHECK_STR(lab[0].name, "top");
    CHECK_STR(lab[1].name, "side");
  }
  if (m.ntri == 4) {
    CHECK_INT(m.tri_label[0], 0);
    CHECK_INT(m.tri_label[1], 1);
    CHECK_INT(m.tri_label[2], 1);
    CHECK_INT(m.tri_label[3], 2);
    CHECK_INT(m.tri_instance[3], 1);
    // the quad's fan: (1 2 3), (1 3 4); the file's normal (0 0 1) everywhere
    CHECK_NEAR(m.pos[3 * m.tri[3 * 2 + 2] + 1], 1, 0);
    for (int t = 0; t < 4; t++)
      CHECK_NEAR(m.normal[3 * m.tri[3 * t] + 2], 1, 1e-12);
  }
  vd_mesh_free(&m);
  vd_free(lab, sizeof(vd_label) * (size_t)(nlab ? nlab : 1));
}

TEST(meshio, bad_files) {
  struct {
    const char* name;
    const char* text;
    vd_status st;
    int line;
  } bad[] = {
      {"idx.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 4\n", VD_ERR_FORMAT, 4},
      {"two.obj", "v 0 0 0\nv 1 0 0\nf 1 2\n", VD_ERR_FORMAT, 3},
      {"nan.obj", "v 0 0 0\nv nan 0 0\nv 0 1 0\nf 1 2 3\n", VD_ERR_FORMAT, 2},
      {"none.obj", "v 0 0 0\n", VD_ERR_FORMAT, 0},
      {"cloud.ply", "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\n"
                    "property float z\nend_header\n0 0 0\n",
       VD_ERR_FORMAT, 0},
      {"short.ply", "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
                    "property float z\nelement face 1\nproperty list uchar int vertex_indices\n"
                    "end_header\n0 0 0\n1 0 0\n",
       VD_ERR_FORMAT, 11},
      {"range.ply", "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
                    "property float z\nelement face 1\nproperty list uchar int vertex_indices\n"
                    "end_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 3\n",
       VD_ERR_FORMAT, 13},
      {"big.ply", "ply\nformat binary_little_endian 1.0\nelement vertex 1000000\nproperty float x\n"
                  "property float y\nproperty float z\nelement face 1\n"
                  "property list uchar int vertex_indices\nend_header\n",
       VD_ERR_FORMAT, 0},
      {"be.ply", "ply\nformat binary_big_endian 1.0\nend_header\n", VD_ERR_UNSUPPORTED, 2},
  };
  for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
    const char* p = scratch(bad[i].name, bad[i].text, strlen(bad[i].text));
    vd_mesh m;
    vd_error err = {0};
    CHECK_STATUS(vd_geom_read_mesh(p, &m, NULL, NULL, &err), bad[i].st, err);
    if (bad[i].line) CHECK_INT(err.line, bad[i].line);
    CHECK(strstr(err.file, bad[i].name) != NULL);
    CHECK(m.ntri == 0 && m.pos == NULL);
  }
  // a point cloud PLY is not a mesh file; a missing file is an I/O error
  CHECK(!vd_geom_is_mesh_file(scratch("c.ply", bad[4].text, strlen(bad[4].text))));
  vd_mesh m;
  vd_error err = {0};
  CHECK_STATUS(vd_geom_read_mesh("/nonexistent/x.obj", &m, NULL, NULL, &err), VD_ERR_IO, err);
  CHECK_STATUS(vd_geom_read_mesh("x.stl", &m, NULL, NULL, &err), VD_ERR_ARG, err);
}
