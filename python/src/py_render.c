// SPDX-License-Identifier: MIT
// Pictures: the Renderer type over vd_renderer (EGL + MuJoCo, headless): plants, simulation
// states with their colliders and point clouds drawn from a preset or explicit camera into
// numpy arrays (colour, metric depth, label and instance masks) with intrinsics and pose; and
// read_png for the images the command line writes.
#include "py_internal.h"

#include <math.h>

#define PATH_CAP 4096

static int busy_check(vdpy_renderer* r) {
  if (r->busy) return (vdpy_busy("this Renderer"), 0);
  return 1;
}

static void renderer_dealloc(vdpy_renderer* r) {
  vd_render_destroy(r->r);
  Py_TYPE(r)->tp_free((PyObject*)r);
}

static PyObject* renderer_new(PyTypeObject* type, PyObject* args, PyObject* kw) {
  static char* names[] = {"size", "supersample", "shadows", "floor", "sky", "background", "legend",
                          "robot", "max_geoms", NULL};
  PyObject *size = Py_None, *ss = Py_None, *bg = Py_None, *robot = Py_None, *mg = Py_None;
  int shadows = 1, floor_ = 1, sky = 1, legend = 1;
  if (!PyArg_ParseTupleAndKeywords(args, kw, "|$OOpppOpOO:Renderer", names, &size, &ss, &shadows,
                                   &floor_, &sky, &bg, &legend, &robot, &mg))
    return NULL;
  vd_render_def def = vd_render_def_default();
  double x[3];
  int64_t v;
  if (size != Py_None) {
    if (!vdpy_vec(size, "size", 2, x)) return NULL;
    if (x[0] != floor(x[0]) || x[1] != floor(x[1]) || x[0] < 1 || x[1] < 1 || x[0] > 8192 || x[1] > 8192)
      return vdpy_arg_error("size expects (width, height), integers in 1..8192");
    def.width = (int)x[0], def.height = (int)x[1];
  }
  if (ss != Py_None) {
    if (!vdpy_i64(ss, "supersample", 1, 4, &v)) return NULL;
    def.supersample = (int)v;
  }
  if (mg != Py_None) {
    if (!vdpy_i64(mg, "max_geoms", 16, 10000000, &v)) return NULL;
    def.max_geoms = (int)v;
  }
  if (bg != Py_None) {
    if (!vdpy_vec(bg, "background", 3, x)) return NULL;
    for (int k = 0; k < 3; k++) {
      if (x[k] < 0 || x[k] > 1) return vdpy_arg_error("background expects (r, g, b) in [0, 1]");
      def.background[k] = (float)x[k];
    }
  }
  def.shadows = shadows, def.floor = floor_, def.sky = sky, def.legend = legend;
  vdpy_renderer* r = (vdpy_renderer*)type->tp_alloc(type, 0);
  if (!r) return NULL;
  if (robot != Py_None) {
    if (!vdpy_path(robot, "robot", r->robot, sizeof r->robot)) goto fail;
    def.robot_mjcf = r->robot;
  }
  r->def = def;
  {
    vd_error err = {0};
    vd_status st;
    Py_BEGIN_ALLOW_THREADS
    st = vd_render_create(&def, &r->r, &err);
    if (!st) vd_render_release(r->r);
    Py_END_ALLOW_THREADS
    if (st) {
      vdpy_raise(st, &err);
      goto fail;
    }
  }
  return (PyObject*)r;
fail:
  Py_DECREF(r);
  return NULL;
}

// ---------------------------------------------------------------------------------------------
// a frame

// what one draw adds, resolved while holding the GIL
typedef struct item {
  int kind;                // 0 plant, 1 plant state of a Sim, 2 cloud
  const vd_model* model;
  const vd_data* state;    // Nullable: rest shape
  double* stress;          // per plant segment (Pa), owned (VD_COLOR_STRESS of a Sim)
  size_t nstress;
  vd_points points;
  const vd_sim_collider* col;  // a Sim's colliders (drawn as solids)
  int ncol;
  vdpy_sim* sim;           // the Sim drawn (kept busy while drawing)
  PyObject* harvest;       // the Harvest drawn (kept busy while drawing)
} item;

static int item_of(PyObject* o, item* it, int color_by) {
  memset(it, 0, sizeof *it);
  if (PyObject_TypeCheck(o, &vdpy_plant_type)) {
    if (color_by == VD_COLOR_STRESS)
      return (vdpy_arg_error("color_by='stress' needs a Sim: a plant at rest carries no stress"), 0);
    it->kind = 0, it->model = ((vdpy_plant*)o)->model;
    return 1;
  }
  if (PyObject_TypeCheck(o, &vdpy_sim_type)) {
    vdpy_sim* s = (vdpy_sim*)o;
    if (s->busy) return (vdpy_busy("this Sim"), 0);
    it->kind = 1;
    it->sim = s;
    it->state = vdpy_sim_plant_state(o, &it->model);
    it->col = s->data->collider, it->ncol = s->data->ncollider;
    if (color_by == VD_COLOR_STRESS) {
      it->nstress = it->model->nseg ? (size_t)it->model->nseg : 1;
      it->stress = vd_calloc(it->nstress, sizeof(double));
      if (!it->stress) return (PyErr_NoMemory(), 0);
      if (it->model->nseg) vd_sim_plant_stress(s->model, s->data, it->model, it->stress);
    }
    return 1;
  }
  if (PyObject_TypeCheck(o, &vdpy_cloud_type)) {
    const vd_cloud* c = &((vdpy_cloud*)o)->cloud;
    if (color_by != VD_COLOR_LABEL && color_by != VD_COLOR_INSTANCE)
      return (vdpy_arg_error("a point cloud is coloured by label or instance"), 0);
    if (c->n > INT32_MAX) return (vdpy_arg_error("a cloud of more than 2^31 points"), 0);
    it->kind = 2;
    vd_points p = {(int)c->n, c->pos, c->label, c->instance, 0, c->labels, c->nlabel};
    it->points = p;
    return 1;
  }
  if (PyObject_TypeCheck(o, &vdpy_harvest_type)) {
    if (color_by == VD_COLOR_STRESS) return (vdpy_arg_error("color_by='stress' is for a Sim"), 0);
    if (vdpy_harvest_busy(o, -1)) return (vdpy_busy("this Harvest"), 0);
    it->kind = 1;
    it->harvest = o;
    it->state = vdpy_harvest_plant_state(o, &it->model, &it->col, &it->ncol);
    if (!it->state) return (vdpy_raise(VD_ERR_VALUE, NULL), 0);
    return 1;
  }
  PyErr_Format(PyExc_TypeError, "render draws a Plant, a Sim, a Cloud or a Harvest (or a list of them), got %s",
               Py_TYPE(o)->tp_name);
  return 0;
}

// the camera: explicit eye and lookat, or a preset fitted to the box lo..hi with the lens fov
// (the command line's --camera, --eye, --lookat, --up, --fov)
static vd_camera make_camera(int has_eye, vd_vec3 eye, vd_vec3 lookat, vd_vec3 up, double fov,
                             vd_camera_kind kind, double az, double el, vd_vec3 lo, vd_vec3 hi,
                             int w, int h) {
  vd_camera cam;
  if (has_eye) {
    cam.eye = eye, cam.lookat = lookat, cam.up = up;
    cam.fovy = fov * VD_PI / 180;
    double dist = vd_norm(vd_sub(lookat, eye));
    cam.znear = fmax(1e-3, 0.01 * dist);
    cam.zfar = 100 * dist + 60;
    return cam;
  }
  cam = vd_camera_preset(kind, az * VD_PI / 180, el * VD_PI / 180, lo, hi, w, h);
  if (fov != 45) {
    // keep the fitted view, narrow or widen the lens: move along the axis to keep the framing
    double d = vd_norm(vd_sub(cam.lookat, cam.eye)), f0 = tan(cam.fovy / 2), f1 = tan(fov * VD_PI / 360);
    vd_vec3 dir = vd_normalize(vd_sub(cam.eye, cam.lookat));
    cam.eye = vd_madd(cam.lookat, dir, d * f0 / f1);
    cam.fovy = fov * VD_PI / 180;
    cam.zfar += d * f0 / f1;
  }
  return cam;
}

// the frame's arrays copied into numpy (the renderer's buffers change with its next draw)
static PyObject* frame_dict(const vd_frame* f, unsigned layers) {
  npy_intp d3[3] = {f->height, f->width, 3}, d2[2] = {f->height, f->width};
  size_t n = (size_t)f->width * (size_t)f->height;
  PyObject* out = PyDict_New();
  if (!out) return NULL;
  PyObject* a;
  if (layers & VD_LAYER_COLOR) {
    a = PyArray_EMPTY(3, d3, NPY_UINT8, 0);
    if (!a) goto fail;
    memcpy(PyArray_DATA((PyArrayObject*)a), f->rgb, 3 * n);
    if (PyDict_SetItemString(out, "rgb", a) < 0) goto fail_a;
    Py_DECREF(a);
  }
  if (layers & VD_LAYER_DEPTH) {
    a = PyArray_EMPTY(2, d2, NPY_FLOAT32, 0);
    if (!a) goto fail;
    float* dst = PyArray_DATA((PyArrayObject*)a);
    for (size_t i = 0; i < n; i++) dst[i] = (float)f->depth[i];
    if (PyDict_SetItemString(out, "depth", a) < 0) goto fail_a;
    Py_DECREF(a);
  }
  const uint16_t* masks[2] = {f->label, f->instance};
  const char* mask_names[2] = {"label", "instance"};
  for (int m = 0; m < 2; m++) {
    if (!(layers & (m ? VD_LAYER_INSTANCE : VD_LAYER_LABEL))) continue;
    a = PyArray_EMPTY(2, d2, NPY_INT32, 0);
    if (!a) goto fail;
    int32_t* dst = PyArray_DATA((PyArrayObject*)a);
    for (size_t i = 0; i < n; i++) dst[i] = masks[m][i];
    if (PyDict_SetItemString(out, mask_names[m], a) < 0) goto fail_a;
    Py_DECREF(a);
  }
  // intrinsics (OpenCV convention) and the camera-to-world pose
  const vd_intrinsics* k = &f->K;
  npy_intp d33[2] = {3, 3}, d44[2] = {4, 4};
  PyObject* K = PyArray_ZEROS(2, d33, NPY_DOUBLE, 0);
  PyObject* pose = PyArray_ZEROS(2, d44, NPY_DOUBLE, 0);
  if (!K || !pose) {
    Py_XDECREF(K);
    Py_XDECREF(pose);
    goto fail;
  }
  double* kd = PyArray_DATA((PyArrayObject*)K);
  kd[0] = k->fx, kd[2] = k->cx, kd[4] = k->fy, kd[5] = k->cy, kd[8] = 1;
  double* pd = PyArray_DATA((PyArrayObject*)pose);
  for (int i = 0; i < 3; i++)
    for (int j = 0; j < 3; j++) pd[4 * i + j] = k->R[3 * i + j];
  pd[3] = k->t.x, pd[7] = k->t.y, pd[11] = k->t.z, pd[15] = 1;
  PyObject* legend = PyList_New(f->nlegend);
  for (int i = 0; legend && i < f->nlegend; i++) {
    const vd_legend_entry* e = &f->legend[i];
    PyObject* d = Py_BuildValue("{s:i,s:s,s:(fff)}", "id", e->id, "name", e->name, "rgb", (double)e->rgb[0],
                                (double)e->rgb[1], (double)e->rgb[2]);
    if (!d) Py_CLEAR(legend);
    else PyList_SET_ITEM(legend, i, d);
  }
  const vd_camera* c = &f->camera;
  PyObject* cam = Py_BuildValue("{s:(ddd),s:(ddd),s:(ddd),s:d,s:d,s:d}", "eye", c->eye.x, c->eye.y, c->eye.z,
                                "lookat", c->lookat.x, c->lookat.y, c->lookat.z, "up", c->up.x, c->up.y,
                                c->up.z, "fovy", c->fovy, "znear", c->znear, "zfar", c->zfar);
  PyObject* intr = Py_BuildValue("{s:i,s:i,s:d,s:d,s:d,s:d}", "width", k->width, "height", k->height, "fx", k->fx,
                                 "fy", k->fy, "cx", k->cx, "cy", k->cy);
  int bad = !legend || !cam || !intr || PyDict_SetItemString(out, "K", K) < 0 ||
            PyDict_SetItemString(out, "pose", pose) < 0 || PyDict_SetItemString(out, "intrinsics", intr) < 0 ||
            PyDict_SetItemString(out, "camera", cam) < 0 || PyDict_SetItemString(out, "legend", legend) < 0;
  if (!bad && (f->color_by == VD_COLOR_STRESS || f->color_by == VD_COLOR_DISPLACEMENT)) {
    PyObject* range = Py_BuildValue("(dd)", f->range_min, f->range_max);
    bad = !range || PyDict_SetItemString(out, "range", range) < 0;
    Py_XDECREF(range);
  }
  Py_DECREF(K);
  Py_DECREF(pose);
  Py_XDECREF(legend);
  Py_XDECREF(cam);
  Py_XDECREF(intr);
  if (bad) goto fail;
  return out;
fail_a:
  Py_DECREF(a);
fail:
  Py_DECREF(out);
  return NULL;
}

static PyObject* renderer_draw(vdpy_renderer* r, PyObject* args, PyObject* kw) {
  static char* names[] = {"objects", "camera", "azimuth", "elevation", "eye", "lookat", "up", "fov",
                          "color_by", "range", "point_size", "depth", "masks", "robot_qpos", NULL};
  PyObject *objs, *camera = Py_None, *azo = Py_None, *elo = Py_None, *eyeo = Py_None, *lookato = Py_None;
  PyObject *upo = Py_None, *fovo = Py_None, *cbo = Py_None, *rangeo = Py_None, *pso = Py_None, *qpos = Py_None;
  int depth = 1, masks = 1;
  if (!PyArg_ParseTupleAndKeywords(args, kw, "O|$OOOOOOOOOOppO:draw", names, &objs, &camera, &azo, &elo, &eyeo,
                                   &lookato, &upo, &fovo, &cbo, &rangeo, &pso, &depth, &masks, &qpos))
    return NULL;
  // options
  vd_camera_kind kind = VD_CAMERA_ORBIT;
  double az = -60, el = 20, fov = 45, x[3], point_size = 0;
  vd_vec3 eye = vd_v3(0, 0, 0), lookat = eye, up = vd_v3(0, 0, 1);
  vd_render_style style = vd_render_style_default();
  if (camera != Py_None) {
    char c[16];
    if (!vdpy_str(camera, "camera", c, sizeof c)) return NULL;
    static const char* const kinds[] = {"front", "side", "top", "orbit"};
    int found = -1;
    for (int k = 0; k < 4; k++)
      if (!strcmp(c, kinds[k])) found = k;
    if (found < 0) return vdpy_arg_error("camera expects 'front', 'side', 'top' or 'orbit', got '%s'", c);
    kind = (vd_camera_kind)found;
  }
  if (azo != Py_None && !vdpy_f64(azo, "azimuth", -1e4, 1e4, &az)) return NULL;
  if (elo != Py_None && !vdpy_f64(elo, "elevation", -90, 90, &el)) return NULL;
  if (fovo != Py_None && !vdpy_f64(fovo, "fov", 1e-3, 179.999, &fov)) return NULL;
  if ((eyeo == Py_None) != (lookato == Py_None)) return vdpy_arg_error("eye and lookat go together");
  if (eyeo != Py_None) {
    if (!vdpy_vec(eyeo, "eye", 3, x)) return NULL;
    eye = vd_v3(x[0], x[1], x[2]);
    if (!vdpy_vec(lookato, "lookat", 3, x)) return NULL;
    lookat = vd_v3(x[0], x[1], x[2]);
  }
  if (upo != Py_None) {
    if (!vdpy_vec(upo, "up", 3, x)) return NULL;
    up = vd_v3(x[0], x[1], x[2]);
  }
  if (cbo != Py_None) {
    char c[16];
    if (!vdpy_str(cbo, "color_by", c, sizeof c)) return NULL;
    static const char* const by[] = {"label", "instance", "stress", "displacement"};
    int found = -1;
    for (int k = 0; k < 4; k++)
      if (!strcmp(c, by[k])) found = k;
    if (found < 0) return vdpy_arg_error("color_by expects 'label', 'instance', 'stress' or 'displacement', got '%s'", c);
    style.color_by = (vd_color_by)found;
  }
  if (rangeo != Py_None) {
    if (!vdpy_vec(rangeo, "range", 2, x)) return NULL;
    if (!(x[1] > x[0])) return vdpy_arg_error("range expects (min, max) with min < max (Pa or m)");
    style.range_min = x[0], style.range_max = x[1];
  }
  if (pso != Py_None && !vdpy_f64(pso, "point_size", 1e-9, 1e3, &point_size)) return NULL;
  // robot joint positions
  PyArrayObject* qa = NULL;
  if (qpos != Py_None) {
    qa = (PyArrayObject*)PyArray_FROMANY(qpos, NPY_DOUBLE, 1, 1, NPY_ARRAY_CARRAY_RO);
    if (!qa) return NULL;
  }
  // what to draw
  PyObject* seq = PyList_Check(objs) || PyTuple_Check(objs) ? PySequence_Fast(objs, "objects") : PyTuple_Pack(1, objs);
  if (!seq) {
    Py_XDECREF(qa);
    return NULL;
  }
  Py_ssize_t n = PySequence_Fast_GET_SIZE(seq);
  item* it = PyMem_Calloc((size_t)n + 1, sizeof *it);
  PyObject* result = NULL;
  int ok = it != NULL;
  if (!ok) PyErr_NoMemory();
  for (Py_ssize_t i = 0; ok && i < n; i++) ok = item_of(PySequence_Fast_GET_ITEM(seq, i), &it[i], style.color_by);
  if (ok && !n) ok = (vdpy_arg_error("nothing to draw"), 0);
  if (ok) ok = busy_check(r);
  for (Py_ssize_t i = 0; ok && i < n; i++)
    if (it[i].sim || it[i].harvest) {
      if (it[i].sim && it[i].sim->busy) ok = (vdpy_busy("this Sim"), 0);  // stepping elsewhere
      for (Py_ssize_t j = 0; j < i; j++)
        if ((it[i].sim && it[j].sim == it[i].sim) || (it[i].harvest && it[j].harvest == it[i].harvest))
          ok = (vdpy_arg_error("the same Sim or Harvest twice in one picture"), 0);
    }
  if (ok) {
    r->busy = 1;
    for (Py_ssize_t i = 0; i < n; i++) {
      if (it[i].sim) it[i].sim->busy = 1;
      if (it[i].harvest) vdpy_harvest_busy(it[i].harvest, 1);
    }
    vd_error err = {0};
    vd_status st = VD_OK;
    vd_frame f;
    unsigned layers = VD_LAYER_COLOR | (depth ? VD_LAYER_DEPTH : 0) | (masks ? VD_LAYER_LABEL | VD_LAYER_INSTANCE : 0);
    int w = r->def.width, h = r->def.height;
    Py_BEGIN_ALLOW_THREADS
    vd_render_clear(r->r);
    if (qa) st = vd_render_set_robot_qpos(r->r, PyArray_DATA(qa), (int)PyArray_DIM(qa, 0), &err);
    for (Py_ssize_t i = 0; !st && i < n; i++) {
      vd_render_style s = style;
      if (it[i].kind == 2) {
        it[i].points.radius = point_size;
        st = vd_render_add_points(r->r, &it[i].points, &s, &err);
        continue;
      }
      s.seg_stress = it[i].stress;
      st = vd_render_add_plant(r->r, it[i].model, it[i].state, &s, &err);
      // a Sim's colliders as solids (planes are the floor's business, meshes are not drawn)
      for (int c = 0; !st && c < it[i].ncol; c++) {
        const vd_sim_collider* k = &it[i].col[c];
        if (k->shape == VD_SIM_PLANE || k->shape == VD_SIM_MESH) continue;
        vd_render_shape sh = {k->shape == VD_SIM_SPHERE    ? VD_RENDER_SPHERE
                              : k->shape == VD_SIM_CAPSULE ? VD_RENDER_CAPSULE
                                                           : VD_RENDER_BOX,
                              {k->size[0], k->size[1], k->size[2]}, k->pos, k->quat, {0.55f, 0.62f, 0.75f}};
        st = vd_render_add_shape(r->r, &sh, &err);
      }
    }
    if (!st) {
      vd_vec3 lo = vd_v3(-0.5, -0.5, 0), hi = vd_v3(0.5, 0.5, 1);
      vd_render_bounds(r->r, &lo, &hi);
      vd_camera cam = make_camera(eyeo != Py_None, eye, lookat, up, fov, kind, az, el, lo, hi, w, h);
      st = vd_camera_check(&cam, &err);
      if (!st) st = vd_render_draw(r->r, &cam, layers, &f, &err);
    }
    Py_END_ALLOW_THREADS
    if (st) vdpy_raise(st, &err);
    else result = frame_dict(&f, layers);
    // let go of the OpenGL context, so that another thread may draw next
    Py_BEGIN_ALLOW_THREADS
    vd_render_clear(r->r);
    vd_render_release(r->r);
    Py_END_ALLOW_THREADS
    r->busy = 0;
    for (Py_ssize_t i = 0; i < n; i++) {
      if (it[i].sim) it[i].sim->busy = 0;
      if (it[i].harvest) vdpy_harvest_busy(it[i].harvest, 0);
    }
  }
  for (Py_ssize_t i = 0; it && i < n; i++) vd_free(it[i].stress, it[i].nstress * sizeof(double));
  PyMem_Free(it);
  Py_DECREF(seq);
  Py_XDECREF(qa);
  return result;
}

static PyObject* renderer_info(vdpy_renderer* r, void* c) { return PyUnicode_FromString(vd_render_info(r->r)); }
static PyObject* renderer_size(vdpy_renderer* r, void* c) {
  return Py_BuildValue("(ii)", r->def.width, r->def.height);
}
static PyObject* renderer_max_geoms(vdpy_renderer* r, void* c) { return PyLong_FromLong(r->def.max_geoms); }

static PyGetSetDef renderer_getset[] = {
    {"info", (getter)renderer_info, NULL, "the OpenGL context drawing the pictures", NULL},
    {"size", (getter)renderer_size, NULL, "image size (width, height) in pixels", NULL},
    {"max_geoms", (getter)renderer_max_geoms, NULL, "most organ instances and cloud groups one picture holds", NULL},
    {NULL, NULL, NULL, NULL, NULL},
};

static PyMethodDef renderer_methods[] = {
    {"draw", (PyCFunction)(void (*)(void))renderer_draw, METH_VARARGS | METH_KEYWORDS,
     "draw($self, /, objects, *, camera='orbit', azimuth=-60, elevation=20, eye=None, lookat=None, up=(0,0,1), fov=45, color_by='label', range=None, point_size=None, depth=True, masks=True, robot_qpos=None)\n--\n\n"
     "draw(objects, *, camera='orbit', azimuth=-60, elevation=20, eye=None, lookat=None,\n"
     "up=(0,0,1), fov=45, color_by='label', range=None, point_size=None, depth=True, masks=True,\n"
     "robot_qpos=None) -> dict: see verdant.render."},
    {NULL, NULL, 0, NULL},
};

PyTypeObject vdpy_renderer_type = {
    PyVarObject_HEAD_INIT(NULL, 0).tp_name = "verdant._verdant.Renderer",
    .tp_basicsize = sizeof(vdpy_renderer),
    .tp_dealloc = (destructor)renderer_dealloc,
    .tp_flags = Py_TPFLAGS_DEFAULT | Py_TPFLAGS_BASETYPE,
    .tp_doc = "Renderer(*, size=(640, 480), supersample=2, shadows=True, floor=True, sky=True, background=None, "
              "legend=True, robot=None, max_geoms=20000)\n--\n\nRenderer(*, size=(640, 480), ...): an offscreen renderer (see verdant.Renderer).",
    .tp_methods = renderer_methods,
    .tp_getset = renderer_getset,
    .tp_new = renderer_new,
};

// ---------------------------------------------------------------------------------------------

PyObject* vdpy_read_png(PyObject* self, PyObject* args, PyObject* kw) {
  static char* names[] = {"path", NULL};
  PyObject* path;
  if (!PyArg_ParseTupleAndKeywords(args, kw, "O:read_png", names, &path)) return NULL;
  char p[PATH_CAP];
  if (!vdpy_path(path, "path", p, sizeof p)) return NULL;
  int w = 0, h = 0, ch = 0, bits = 0;
  uint16_t* pix = NULL;
  vd_error err = {0};
  vd_status st;
  Py_BEGIN_ALLOW_THREADS
  st = vd_render_read_png(p, &w, &h, &ch, &bits, &pix, &err);
  Py_END_ALLOW_THREADS
  if (st) return vdpy_raise(st, &err);
  npy_intp d3[3] = {h, w, ch};
  size_t n = (size_t)w * (size_t)h * (size_t)ch;
  PyObject* a = PyArray_EMPTY(ch > 1 ? 3 : 2, d3, bits == 8 ? NPY_UINT8 : NPY_UINT16, 0);
  if (a) {
    if (bits == 8) {
      uint8_t* dst = PyArray_DATA((PyArrayObject*)a);
      for (size_t i = 0; i < n; i++) dst[i] = (uint8_t)pix[i];
    } else {
      memcpy(PyArray_DATA((PyArrayObject*)a), pix, n * sizeof *pix);
    }
  }
  vd_free(pix, n * sizeof *pix);
  return a;
}
