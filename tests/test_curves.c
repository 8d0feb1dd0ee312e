// SPDX-License-Identifier: MIT
// curves: hand-drawn branch polylines to a plant spec (seed 000 sec. 3.5): expected nodes and
// segments of small hand-made files, the effect of sigma_distance, sigma_connect and the sampling
// step, markers as key nodes, leaf and fruit placement, labels, the bundled tomato, malformed
// files (VD_ERR_FORMAT naming the field), determinism and out-of-memory behaviour.
#include <stdlib.h>

#include "test.h"
#include "verdant/plant.h"

// parse text and build a new spec with def (NULL: the file's)
static vd_status build_text(const char* text, const vd_curves_def* def, vd_plant_spec** out,
                            vd_curves_stats* stats, vd_error* err) {
  *out = NULL;
  vd_curves* c;
  vd_status st = vd_curves_parse(text, strlen(text), "test.json", &c, err);
  if (st) return st;
  *out = vd_plant_spec_create();
  st = vd_curves_build(c, def, *out, stats, err);
  vd_curves_destroy(c);
  if (st) {
    vd_plant_spec_destroy(*out);
    *out = NULL;
  }
  return st;
}

static double node_z(const vd_plant_spec* s, int seg, int end) {
  return s->node[end ? s->seg[seg].node1 : s->seg[seg].node0].z;
}

// a 0.2 m stem with a 0.1 m horizontal branch from its middle
static const char* two_curves =
    "{\"format\": \"verdant-curves\", \"version\": 1, \"units\": \"m\",\n"
    " \"settings\": {\"distance\": 0.05, \"sample_step\": 0.001},\n"
    " \"curves\": [\n"
    "  {\"name\": \"main\", \"points\": [[0,0,0],[0,0,0.2]], \"radius\": [0.005, 0.003]},\n"
    "  {\"name\": \"side\", \"label\": \"branch\", \"points\": [[0,0,0.1],[0.1,0,0.1]]}\n"
    " ]}";

TEST(curves, two_curves) {
  vd_plant_spec* s;
  vd_curves_stats st;
  vd_error err = {0};
  CHECK_STATUS(build_text(two_curves, NULL, &s, &st, &err), VD_OK, err);
  REQUIRE(s);
  // dense samples: 201 on the stem, 101 on the branch; the branch starts on a stem sample
  CHECK_INT(st.ncurve, 2);
  CHECK_INT(st.nsample, 302);
  CHECK_INT(st.nconnect, 1);
  CHECK_INT(st.ngap, 0);
  // stem nodes at z = 0, 0.05, 0.1 (junction), 0.15, 0.2; branch nodes at x = 0.05, 0.1
  CHECK_INT(s->nnode, 7);
  CHECK_INT(s->nseg, 6);
  CHECK_INT(st.nnode, 7);
  CHECK_INT(st.nseg, 6);
  double zs[4] = {0, 0.05, 0.1, 0.15};
  for (int i = 0; i < 4; i++) {
    CHECK_NEAR(node_z(s, i, 0), zs[i], 1e-12);
    CHECK_NEAR(node_z(s, i, 1), zs[i] + 0.05, 1e-12);
    CHECK_INT(s->seg[i].parent, i - 1);
    CHECK_INT(s->seg[i].label, 1);
    CHECK_INT(s->seg[i].axis, 0);
    CHECK_INT(s->seg[i].order, 0);
    CHECK_INT(s->seg[i].instance, 1);
    // radius linear from 5 mm to 3 mm along the stem
    CHECK_NEAR(s->seg[i].r0, 0.005 - 0.002 * zs[i] / 0.2, 1e-12);
    CHECK_NEAR(s->seg[i].r1, 0.005 - 0.002 * (zs[i] + 0.05) / 0.2, 1e-12);
    CHECK(s->seg[i].flags & VD_SEG_GC);
    CHECK_INT((s->seg[i].flags & VD_SEG_TIP) != 0, i == 3);
  }
  // the branch: in preorder after the stem's segment ending at the junction
  int b0 = -1;
  for (int i = 0; i < s->nseg; i++)
    if (s->seg[i].label == 2 && b0 < 0) b0 = i;
  REQUIRE(b0 >= 0);
  CHECK_INT(s->seg[b0].parent, 1); // the stem segment ending at z = 0.1
  CHECK_INT(s->seg[b0].node0, s->seg[1].node1);
  CHECK_NEAR(s->node[s->seg[b0].node1].x, 0.05, 1e-12);
  CHECK_NEAR(s->node[s->seg[b0 + 1].node1].x, 0.1, 1e-12);
  CHECK_INT(s->seg[b0 + 1].parent, b0);
  CHECK_INT(s->seg[b0].order, 1);
  CHECK_INT(s->seg[b0].axis, 1);
  CHECK_INT(s->seg[b0].instance, 2);
  CHECK_NEAR(s->seg[b0].r0, 0.002, 1e-15); // the default radius
  CHECK(!(s->seg[b0].flags & VD_SEG_GC));  // the stem goes on through the junction
  CHECK(s->seg[b0 + 1].flags & VD_SEG_TIP);
  // up vectors: unit and normal to their segments
  for (int i = 0; i < s->nseg; i++) {
    vd_vec3 d = vd_sub(s->node[s->seg[i].node1], s->node[s->seg[i].node0]);
    CHECK_NEAR(vd_norm(s->seg[i].up), 1, 1e-12);
    CHECK_NEAR(vd_dot(s->seg[i].up, d), 0, 1e-12);
  }
  // labels named, the spec compiles
  CHECK_STR(vd_plant_find_label(s, 1)->name, "stem");
  CHECK_STR(vd_plant_find_label(s, 2)->name, "branch");
  vd_model* m = NULL;
  CHECK_STATUS(vd_plant_compile(s, &m, &err), VD_OK, err);
  vd_model_destroy(m);
  vd_plant_spec_destroy(s);
}

// replace the first occurrence of `from` in a copy of text
static char* edit(const char* text, const char* from, const char* to) {
  static char buf[8192];
  const char* p = strstr(text, from);
  if (!p) return NULL;
  snprintf(buf, sizeof buf, "%.*s%s%s", (int)(p - text), text, to, p + strlen(from));
  return buf;
}

TEST(curves, sigma_effects) {
  vd_error err = {0};
  vd_plant_spec* s;
  vd_curves* c;
  REQUIRE(vd_curves_parse(two_curves, strlen(two_curves), "t", &c, &err) == VD_OK);
  vd_curves_def def = vd_curves_file_def(c);
  CHECK_NEAR(def.distance, 0.05, 0);
  CHECK_NEAR(def.connect, 0.01, 0); // the default
  // sigma_distance 0.01 / 0.02 / 0.1 m: 20 / 10 / 2 stem and 10 / 5 / 1 branch segments
  double sig[3] = {0.01, 0.02, 0.1};
  for (int k = 0; k < 3; k++) {
    def.distance = sig[k];
    s = vd_plant_spec_create();
    vd_curves_stats st;
    CHECK_STATUS(vd_curves_build(c, &def, s, &st, &err), VD_OK, err);
    int nstem = 0, nbranch = 0;
    for (int i = 0; i < s->nseg; i++)
      s->seg[i].label == 1 ? nstem++ : nbranch++;
    CHECK_INT(nstem, (int)(0.2 / sig[k] + 0.5));
    CHECK_INT(nbranch, (int)(0.1 / sig[k] + 0.5));
    CHECK_INT(s->nnode, nstem + nbranch + 1);
    vd_plant_spec_destroy(s);
  }
  // the sampling step does not move the kept nodes when it divides sigma
  def.distance = 0.05;
  def.sample_step = 0.0005;
  s = vd_plant_spec_create();
  CHECK_STATUS(vd_curves_build(c, &def, s, NULL, &err), VD_OK, err);
  CHECK_INT(s->nseg, 6);
  CHECK_NEAR(s->node[s->seg[1].node1].z, 0.1, 1e-12);
  vd_plant_spec_destroy(s);
  vd_curves_destroy(c);

  // half-sigma rule: a tip 0.03 m past the last kept node stays, 0.02 m past it replaces it
  const char* longer = edit(two_curves, "[0,0,0.2]]", "[0,0,0.23]]");
  CHECK_STATUS(build_text(longer, NULL, &s, NULL, &err), VD_OK, err);
  REQUIRE(s);
  CHECK_INT(s->nseg, 7); // 0 .05 .1 .15 .2 .23 + 2 branch
  vd_plant_spec_destroy(s);
  const char* shorter = edit(two_curves, "[0,0,0.2]]", "[0,0,0.22]]");
  CHECK_STATUS(build_text(shorter, NULL, &s, NULL, &err), VD_OK, err);
  REQUIRE(s);
  CHECK_INT(s->nseg, 6); // 0 .05 .1 .15 .22 + 2 branch: the node at 0.2 gave way
  CHECK_NEAR(s->node[s->seg[3].node1].z, 0.22, 1e-12);
  CHECK_NEAR(s->node[s->seg[3].node0].z, 0.15, 1e-12);
  vd_plant_spec_destroy(s);

  // sigma_connect: a branch starting 4 mm off the stem joins through a gap segment within
  // connect = 0.01 m, and is rejected with connect = 0.003 m
  const char* gap = edit(two_curves, "[[0,0,0.1],[0.1,0,0.1]]", "[[0.004,0,0.1],[0.1,0,0.1]]");
  vd_curves_stats st;
  CHECK_STATUS(build_text(gap, NULL, &s, &st, &err), VD_OK, err);
  REQUIRE(s);
  CHECK_INT(st.ngap, 1);
  CHECK_INT(s->nseg, 6); // the branch end was not a key node: the gap folds into its first segment
  vd_plant_spec_destroy(s);
  REQUIRE(vd_curves_parse(gap, strlen(gap), "gap.json", &c, &err) == VD_OK);
  def = vd_curves_file_def(c);
  def.connect = 0.003;
  s = vd_plant_spec_create();
  err = (vd_error){0};
  CHECK_STATUS(vd_curves_build(c, &def, s, NULL, &err), VD_ERR_VALUE, err);
  CHECK(strstr(err.msg, "curves[1] (side)") != NULL);
  vd_plant_spec_destroy(s);
  vd_curves_destroy(c);
}

TEST(curves, root_inside_a_curve) {
  // the root at the junction: the stem runs both ways from it, three root segments
  const char* text = edit(two_curves, "\"curves\"", "\"root\": [0, 0, 0.1], \"curves\"");
  REQUIRE(text);
  vd_plant_spec* s;
  vd_error err = {0};
  CHECK_STATUS(build_text(text, NULL, &s, NULL, &err), VD_OK, err);
  REQUIRE(s);
  CHECK_INT(s->nseg, 6);
  int roots = 0, down = 0;
  for (int i = 0; i < s->nseg; i++) {
    roots += s->seg[i].parent < 0;
    if (s->seg[i].parent < 0) CHECK_NEAR(s->node[s->seg[i].node0].z, 0.1, 1e-12);
    down += s->node[s->seg[i].node1].z < s->node[s->seg[i].node0].z - 1e-9;
  }
  CHECK_INT(roots, 3);
  CHECK_INT(down, 2); // 0.1 -> 0.05 -> 0
  vd_plant_spec_destroy(s);
}

TEST(curves, connection_order) {
  // a peduncle from the stem, and a pedicel drawn from the peduncle's tip 8 mm from the stem:
  // it joins the peduncle (nearest gap first), not the stem
  const char* text =
      "{\"format\": \"verdant-curves\", \"version\": 1,\n"
      " \"settings\": {\"distance\": 0.01},\n"
      " \"curves\": [\n"
      "  {\"points\": [[0,0,0],[0,0,0.3]]},\n"
      "  {\"label\": \"pedicel\", \"points\": [[0.008,0,0.2],[0.008,0,0.17]]},\n"
      "  {\"label\": \"peduncle\", \"points\": [[0,0,0.1],[0.008,0,0.15],[0.008,0,0.2]]}\n"
      " ]}";
  vd_plant_spec* s;
  vd_curves_stats st;
  vd_error err = {0};
  CHECK_STATUS(build_text(text, NULL, &s, &st, &err), VD_OK, err);
  REQUIRE(s);
  CHECK_INT(st.nconnect, 2);
  CHECK_INT(st.ngap, 0);
  // the pedicel's first segment hangs from the peduncle's last one
  int ped = -1, pdc_last = -1;
  for (int i = 0; i < s->nseg; i++) {
    if (s->seg[i].label == 3) pdc_last = i; // peduncle: label 3 (third name seen)
    if (s->seg[i].label == 2 && ped < 0) ped = i;
  }
  REQUIRE(ped >= 0 && pdc_last >= 0);
  CHECK_STR(vd_plant_find_label(s, 2)->name, "pedicel");
  CHECK_INT(s->seg[ped].parent, pdc_last);
  CHECK_INT(s->seg[ped].order, 2);
  // continuing the peduncle's tip, the pedicel joins it smoothly
  CHECK(s->seg[ped].flags & VD_SEG_GC);
  vd_plant_spec_destroy(s);
  // reversed drawing: the pedicel drawn tip first still joins by its nearer end
  const char* rev = edit(text, "[[0.008,0,0.2],[0.008,0,0.17]]", "[[0.008,0,0.17],[0.008,0,0.2]]");
  CHECK_STATUS(build_text(rev, NULL, &s, &st, &err), VD_OK, err);
  REQUIRE(s);
  CHECK_INT(st.ngap, 0);
  int last = s->nseg - 1;
  CHECK_NEAR(s->node[s->seg[last].node1].z, 0.17, 1e-12);
  vd_plant_spec_destroy(s);
}

TEST(curves, markers) {
  const char* text =
      "{\"format\": \"verdant-curves\", \"version\": 1,\n"
      " \"labels\": [{\"id\": 7, \"name\": \"stem\"}, {\"id\": 9, \"name\": \"fruit\"}],\n"
      " \"settings\": {\"distance\": 0.05},\n"
      " \"root\": [0, 0.002, 0],\n"
      " \"curves\": [{\"points\": [[0,0,0],[0,0,0.2]], \"radius\": 0.004}],\n"
      " \"fruits\": [{\"at\": [0.002,0,0.07], \"radius\": 0.01},\n"
      "            {\"at\": [0,0,0.2], \"label\": \"bud\"}],\n"
      " \"leaves\": [{\"at\": [0,0,0.13], \"direction\": [1,0,0], \"length\": 0.04,\n"
      "              \"width\": 0.02, \"label\": 4},\n"
      "            {\"at\": [0,0,0.2], \"template\": \"mine\"}],\n"
      " \"templates\": {\"mine\": {\"vertices\": [[0,0,0],[1,0,0],[0,1,0]],\n"
      "                          \"triangles\": [[0,1,2]]}}\n"
      "}";
  vd_plant_spec* s;
  vd_curves_stats st;
  vd_error err = {0};
  CHECK_STATUS(build_text(text, NULL, &s, &st, &err), VD_OK, err);
  REQUIRE(s);
  CHECK_INT(st.nfruit, 2);
  CHECK_INT(st.nleaf, 2);
  // marked nodes are kept: 0 -> 0.07 (the node at 0.05 gave way, 0.02 m before a key node)
  // -> 0.12 -> 0.13 (the leaf; 0.12 gave way) ... checked through node heights
  double z[16];
  int nz = 0;
  for (int i = 0; i < s->nnode && nz < 16; i++)
    z[nz++] = s->node[i].z;
  double expect[] = {0, 0.07, 0.13, 0.2};
  CHECK_INT(nz, 4);
  for (int i = 0; i < 4 && i < nz; i++)
    CHECK_NEAR(z[i], expect[i], 1e-12);
  // the fruit hangs below its node, touching it; the bud continues the stem's tip upwards
  CHECK_INT(s->nsphere, 2);
  CHECK_NEAR(s->sphere[0].center.z, 0.07 - 0.01, 1e-12);
  CHECK_NEAR(s->sphere[0].radius, 0.01, 0);
  CHECK_INT(s->sphere[0].node, 1);
  CHECK_INT(s->sphere[0].parent, 0);
  CHECK_INT(s->sphere[0].label, 9);
  CHECK_NEAR(s->sphere[1].center.z, 0.2 + 0.01, 1e-12); // default fruit radius 0.01 m
  // new names get the next free ids: "leaf" 10 (leaves are read before fruits), "bud" 11
  CHECK_INT(s->sphere[1].label, 11);
  CHECK_STR(vd_plant_find_label(s, 11)->name, "bud");
  // the leaf: the built-in blade from its node along +x, 0.04 m long, 0.02 m wide
  CHECK_INT(s->nmesh, 2);
  const vd_mesh_spec* m = &s->mesh[0];
  CHECK_INT(m->label, 4);
  CHECK_INT(m->node, 2);
  CHECK_INT(m->closed, 0);
  double xmax = -1, ymax = -1, zdev = 0;
  for (int v = m->vert_start; v < m->vert_start + m->nvert; v++) {
    xmax = fmax(xmax, s->vert[v].x);
    ymax = fmax(ymax, fabs(s->vert[v].y));
    zdev = fmax(zdev, fabs(s->vert[v].z - 0.13));
  }
  CHECK_NEAR(xmax, 0.04, 1e-12);
  CHECK(ymax > 0.004 && ymax <= 0.25 * 0.02 + 1e-12);
  CHECK_NEAR(zdev, 0, 1e-12); // flat and horizontal (normal +z)
  // triangles face up (+z normal, counter-clockwise seen from above)
  for (int t = m->tri_start; t < m->tri_start + m->ntri; t++) {
    vd_vec3 a = s->vert[s->tri[3 * t]], b = s->vert[s->tri[3 * t + 1]];
    vd_vec3 c = s->vert[s->tri[3 * t + 2]];
    CHECK(vd_cross(vd_sub(b, a), vd_sub(c, a)).z > 0);
  }
  // the custom template at the stem's tip: along the tip's tangent (up), 0.05 m default length
  CHECK_INT(s->mesh[1].nvert, 3);
  CHECK_INT(s->mesh[1].ntri, 1);
  CHECK_NEAR(s->vert[s->mesh[1].vert_start + 1].z, 0.25, 1e-12);
  CHECK_INT(s->mesh[1].label, 10);
  CHECK_STR(vd_plant_find_label(s, 10)->name, "leaf");
  // instances: the curve, then one per marker
  CHECK_INT(s->seg[0].instance, 1);
  CHECK_INT(s->mesh[0].instance, 2);
  CHECK_INT(s->sphere[1].instance, 5);
  vd_model* md = NULL;
  CHECK_STATUS(vd_plant_compile(s, &md, &err), VD_OK, err);
  vd_model_destroy(md);
  vd_plant_spec_destroy(s);
  // a marker far from every curve
  const char* far = edit(text, "[0.002,0,0.07]", "[0.05,0,0.07]");
  err = (vd_error){0};
  CHECK_STATUS(build_text(far, NULL, &s, NULL, &err), VD_ERR_VALUE, err);
  CHECK(strstr(err.msg, "fruits[0].at") != NULL);
  const char* far_root = edit(text, "[0, 0.002, 0]", "[0, 0.3, 0]");
  err = (vd_error){0};
  CHECK_STATUS(build_text(far_root, NULL, &s, NULL, &err), VD_ERR_VALUE, err);
  CHECK(strstr(err.msg, "root") != NULL);
}

TEST(curves, malformed) {
  const char* ok = "{\"format\": \"verdant-curves\", \"version\": 1, \"curves\": "
                   "[{\"points\": [[0,0,0],[0,0,1]]}]";
  struct {
    const char* text;
    const char* field; // the field the message must name
  } cases[] = {
      {"[]", "top level"},
      {"{\"version\": 1, \"curves\": []}", "format"},
      {"{\"format\": \"verdant-plant\", \"version\": 1}", "format"},
      {"{\"format\": \"verdant-curves\", \"version\": 2, \"curves\": []}", "version"},
      {"{\"format\": \"verdant-curves\", \"version\": 1}", "curves"},
      {"{\"format\": \"verdant-curves\", \"version\": 1, \"units\": \"mm\", \"curves\": []}",
       "units"},
      {"{\"format\": \"verdant-curves\", \"version\": 1, \"curves\": []}", "curves"},
      {"{\"format\": \"verdant-curves\", \"version\": 1, \"curves\": [{\"points\": [[0,0,0]]}]}",
       "curves[0].points"},
      {"{\"format\": \"verdant-curves\", \"version\": 1, \"curves\": [{\"points\": "
       "[[0,0,0],[0,0,1]]},"
       " {\"points\": [[0,0,0],[1,0],[0,0,1]]}]}",
       "curves[1].points[1]"},
      {"{\"format\": \"verdant-curves\", \"version\": 1, \"curves\": [{\"points\": "
       "[[0,0,0],[0,0,\"1\"]]}]}",
       "curves[0].points[1][2]"},
      {"{\"format\": \"verdant-curves\", \"version\": 1, \"curves\": [{\"points\": "
       "[[0,0,0],[0,0,0]]}]}",
       "curves[0].points"},
      {"{\"format\": \"verdant-curves\", \"version\": 1, \"curves\": [{\"points\": "
       "[[0,0,0],[0,0,1]], \"radius\": [0.1]}]}",
       "curves[0].radius"},
      {"{\"format\": \"verdant-curves\", \"version\": 1, \"curves\": [{\"points\": "
       "[[0,0,0],[0,0,1]], \"radius\": [0.1, -1]}]}",
       "curves[0].radius[1]"},
      {"{\"format\": \"verdant-curves\", \"version\": 1, \"curves\": [{\"points\": "
       "[[0,0,0],[0,0,1]], \"raduis\": 0.1}]}",
       "curves[0].raduis"},
      {"{\"format\": \"verdant-curves\", \"version\": 1, \"curves\": [{\"points\": "
       "[[0,0,0],[0,0,1]], \"label\": [1]}]}",
       "curves[0].label"},
      {"{\"format\": \"verdant-curves\", \"version\": 1, \"curves\": [{\"points\": "
       "[[0,0,0],[0,0,1]]}], \"fruit\": []}",
       "fruit"},
      {"{\"format\": \"verdant-curves\", \"version\": 1, \"curves\": [{\"points\": "
       "[[0,0,0],[0,0,1]]}], \"fruits\": [{\"radius\": 0.01}]}",
       "fruits[0].at"},
      {"{\"format\": \"verdant-curves\", \"version\": 1, \"curves\": [{\"points\": "
       "[[0,0,0],[0,0,1]]}], \"leaves\": [{\"at\": [0,0,1], \"template\": \"palm\"}]}",
       "leaves[0].template"},
      {"{\"format\": \"verdant-curves\", \"version\": 1, \"curves\": [{\"points\": "
       "[[0,0,0],[0,0,1]]}], \"leaves\": [{\"at\": [0,0,1], \"direction\": [0,0,0]}]}",
       "leaves[0].direction"},
      {"{\"format\": \"verdant-curves\", \"version\": 1, \"curves\": [{\"points\": "
       "[[0,0,0],[0,0,1]]}], \"settings\": {\"connect\": -1}}",
       "settings.connect"},
      {"{\"format\": \"verdant-curves\", \"version\": 1, \"curves\": [{\"points\": "
       "[[0,0,0],[0,0,1]]}], \"settings\": {\"sigma\": 1}}",
       "settings.sigma"},
      {"{\"format\": \"verdant-curves\", \"version\": 1, \"curves\": [{\"points\": "
       "[[0,0,0],[0,0,1]]}], \"labels\": [{\"id\": 1, \"name\": \"a\"}, {\"id\": 1, \"name\": "
       "\"b\"}]}",
       "labels[1].id"},
      {"{\"format\": \"verdant-curves\", \"version\": 1, \"curves\": [{\"points\": "
       "[[0,0,0],[0,0,1]]}], \"templates\": {\"t\": {\"vertices\": [[0,0,0],[1,0,0],[0,1,0]], "
       "\"triangles\": [[0,1,3]]}}}",
       "templates.t.triangles[0][2]"},
      {"{\"format\": \"verdant-curves\", \"version\": 1, \"curves\": [{\"points\": "
       "[[0,0,0],[0,0,1]]}], \"templates\": {\"blade\": {\"vertices\": [[0,0,0],[1,0,0],[0,1,0]], "
       "\"triangles\": [[0,1,2]]}}}",
       "templates.blade"},
      {"{\"format\": \"verdant-curves\", \"version\": 1, \"curves\": [{\"points\": "
       "[[0,0,0],[0,0,1]]}], \"root\": [0,0]}",
       "root"},
  };
  for (size_t k = 0; k < sizeof cases / sizeof cases[0]; k++) {
    vd_error err = {0};
    vd_curves* c = NULL;
    vd_status st = vd_curves_parse(cases[k].text, strlen(cases[k].text), "bad.json", &c, &err);
    if (st != VD_ERR_FORMAT || !strstr(err.msg, cases[k].field) || strcmp(err.file, "bad.json"))
      vdt_fail(__FILE__, __LINE__, "case %zu: status %s, message \"%s\", expected field %s", k,
               vd_status_str(st), err.msg, cases[k].field);
    CHECK(c == NULL);
  }
  // broken JSON: the line and column where the parser stopped; trailing text
  vd_error err = {0};
  vd_curves* c = NULL;
  const char* broken = "{\"format\": \"verdant-curves\",\n \"version\": 1,\n \"curves\": [}";
  CHECK_STATUS(vd_curves_parse(broken, strlen(broken), "b.json", &c, &err), VD_ERR_FORMAT, err);
  CHECK_INT(err.line, 3);
  CHECK(err.col > 1);
  err = (vd_error){0};
  char trailing[512];
  snprintf(trailing, sizeof trailing, "%s} x", ok);
  CHECK_STATUS(vd_curves_parse(trailing, strlen(trailing), "b.json", &c, &err), VD_ERR_FORMAT, err);
  err = (vd_error){0};
  CHECK_STATUS(vd_curves_parse("", 0, "b.json", &c, &err), VD_ERR_FORMAT, err);
  // a missing file: an I/O error naming it
  err = (vd_error){0};
  CHECK_STATUS(vd_curves_read(vdt_path("data/no_such_curves.json"), &c, &err), VD_ERR_IO, err);
  // the well-formed one parses; bad settings passed to build are argument errors
  char good[512];
  snprintf(good, sizeof good, "%s}", ok);
  err = (vd_error){0};
  CHECK_STATUS(vd_curves_parse(good, strlen(good), "g.json", &c, &err), VD_OK, err);
  vd_curves_def def = vd_curves_file_def(c);
  def.sample_step = 0;
  vd_plant_spec* s = vd_plant_spec_create();
  CHECK_STATUS(vd_curves_build(c, &def, s, NULL, &err), VD_ERR_ARG, err);
  // too many samples for the limit
  def = vd_curves_file_def(c);
  def.max_samples = 100;
  err = (vd_error){0};
  CHECK_STATUS(vd_curves_build(c, &def, s, NULL, &err), VD_ERR_LIMIT, err);
  vd_plant_spec_destroy(s);
  vd_curves_destroy(c);
}

TEST(curves, format_name) {
  char buf[32];
  const char* a = "{\"a\": {\"format\": \"x\"}, \"b\": [1, \"}\"], \"format\": \"verdant-curves\"}";
  CHECK_STR(vd_plant_json_format(a, strlen(a), buf, sizeof buf), "verdant-curves");
  const char* b = "  {\n \"format\" : \"verdant-plant\", \"nodes\": []}";
  CHECK_STR(vd_plant_json_format(b, strlen(b), buf, sizeof buf), "verdant-plant");
  const char* none[] = {"",
                        "[]",
                        "{\"nodes\": []}",
                        "{\"format\": 1}",
                        "{\"format\": \"abc",
                        "{\"x\": \"\\\"format\\\"\"}"};
  for (size_t k = 0; k < sizeof none / sizeof none[0]; k++)
    CHECK_STR(vd_plant_json_format(none[k], strlen(none[k]), buf, sizeof buf), "");
  // truncated to the buffer
  char small[4];
  CHECK_STR(vd_plant_json_format(a, strlen(a), small, sizeof small), "ver");
}

TEST(curves, bundled_tomato) {
  vd_error err = {0};
  vd_curves* c = NULL;
  CHECK_STATUS(vd_curves_read(vdt_path("data/curves_tomato.json"), &c, &err), VD_OK, err);
  REQUIRE(c);
  vd_plant_spec* s = vd_plant_spec_create();
  vd_curves_stats st;
  CHECK_STATUS(vd_curves_build(c, NULL, s, &st, &err), VD_OK, err);
  // every curve joined; the labels of the L-system tomato
  CHECK_INT(st.nconnect, st.ncurve - 1);
  CHECK(st.ncurve >= 10);
  CHECK_STR(vd_plant_find_label(s, 1)->name, "stem");
  CHECK_STR(vd_plant_find_label(s, 4)->name, "pedicel");
  CHECK_STR(vd_plant_find_label(s, 5)->name, "fruit");
  int fruits = 0, on_pedicel = 0;
  for (int i = 0; i < s->nsphere; i++) {
    if (s->sphere[i].label != 5) continue;
    fruits++;
    on_pedicel += s->sphere[i].parent >= 0 && s->seg[s->sphere[i].parent].label == 4;
  }
  CHECK_INT(fruits, 7);
  CHECK_INT(on_pedicel, 7);
  // one tree: exactly one root segment
  int roots = 0;
  for (int i = 0; i < s->nseg; i++)
    roots += s->seg[i].parent < 0;
  CHECK_INT(roots, 1);
  // segments about sigma_distance long, none far beyond 1.5 sigma
  double longest = 0;
  for (int i = 0; i < s->nseg; i++)
    longest = fmax(longest, vd_norm(vd_sub(s->node[s->seg[i].node1], s->node[s->seg[i].node0])));
  CHECK(longest <= 1.5 * vd_curves_file_def(c).distance + 0.002);
  // deterministic: a second build writes the same bytes
  vd_plant_spec* s2 = vd_plant_spec_create();
  CHECK_STATUS(vd_curves_build(c, NULL, s2, NULL, &err), VD_OK, err);
  char p1[512], p2[512];
  snprintf(p1, sizeof p1, "%s/ct1.json", vdt_tmpdir());
  snprintf(p2, sizeof p2, "%s/ct2.json", vdt_tmpdir());
  CHECK_STATUS(vd_plant_write_json(s, p1, &err), VD_OK, err);
  CHECK_STATUS(vd_plant_write_json(s2, p2, &err), VD_OK, err);
  char *t1 = NULL, *t2 = NULL;
  size_t n1 = 0, n2 = 0;
  CHECK_STATUS(vd_file_read(p1, &t1, &n1, &err), VD_OK, err);
  CHECK_STATUS(vd_file_read(p2, &t2, &n2, &err), VD_OK, err);
  CHECK(n1 == n2 && t1 && t2 && memcmp(t1, t2, n1) == 0);
  vd_free(t1, n1 + 1);
  vd_free(t2, n2 + 1);
  // compiles and tessellates
  vd_model* m = NULL;
  CHECK_STATUS(vd_plant_compile(s, &m, &err), VD_OK, err);
  vd_model_destroy(m);
  vd_plant_spec_destroy(s);
  vd_plant_spec_destroy(s2);
  vd_curves_destroy(c);
}

TEST(curves, out_of_memory) {
  char* text = NULL;
  size_t len = 0;
  vd_error err = {0};
  REQUIRE(vd_file_read(vdt_path("data/curves_tomato.json"), &text, &len, &err) == VD_OK);
  // every allocation of parse and build fails in turn: a status, nothing leaked
  int ok_seen = 0;
  for (int budget = 0; budget < 400 && !ok_seen; budget += 1) {
    int64_t before = vd_alloc_bytes();
    vdt_oom_begin(budget);
    vd_curves* c = NULL;
    vd_plant_spec* s = NULL;
    err = (vd_error){0};
    vd_status st = vd_curves_parse(text, len, "t.json", &c, &err);
    if (!st) {
      s = vd_plant_spec_create();
      st = s ? vd_curves_build(c, NULL, s, NULL, &err) : VD_ERR_NOMEM;
    }
    vdt_oom_end();
    CHECK(st == VD_OK || st == VD_ERR_NOMEM);
    ok_seen = st == VD_OK;
    vd_plant_spec_destroy(s);
    vd_curves_destroy(c);
    CHECK_INT(vd_alloc_bytes(), before);
  }
  CHECK(ok_seen);
  vd_free(text, len + 1);
}
